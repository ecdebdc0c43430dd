#pragma once
// Elevation streamed from a terrain tile store for the terrain renderers: a clipmap-style stack
// centred on the viewer, one N x N layer per level of detail 0..C-1 of a texture array,
// addressed toroidally (level texel g lives at g mod N), refilled page by page from the GPU tile
// cache (GpuTileCache) as the viewer moves, with a per-frame page budget; plus the always-
// resident coarse level C (the smallest level that fits in N x N) as an ordinary 2D texture with
// its mip chain, covering the whole terrain. The vertex shader samples, at each point, the level
// max(wanted level, finest level whose pages there are resident), so a page that has not arrived
// yet shows a coarser stand-in instead of a hole (render/shaders/terrain_common.glsl,
// streamedHeight). docs/render-rings.md, "Streaming".

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>
#include <strata/gl/objects.hpp>
#include <strata/render/gpu_tile_cache.hpp>

namespace strata::terrain {
class TileStore;
}

namespace strata::render {

/// How elevation is streamed.
struct StreamParams {
  int clipSize = 256;                        ///< N: texels a side of each level's window (a multiple of pageSize)
  int pageSize = 64;                         ///< P: texels a side of a page (the unit of refill; power of two)
  int uploadPagesPerFrame = 16;              ///< pages copied into the stack per frame at most (0: none)
  size_t gpuBudgetBytes = size_t(96) << 20;  ///< stack + coarse level + page flags + GPU tile cache (bytes)
  std::string field = "bedrock";             ///< the store field drawn as elevation (m)
  /// true: a page whose tiles are not decoded in the store's RAM cache is read from disk in the
  /// frame (offline renders: every frame copies its full budget). false: it is requested from
  /// the store's background loader and copied on a later frame; a frame never waits for the disk.
  bool waitForDisk = true;
};

/// What streaming did since creation.
struct StreamStats {
  uint64_t frames = 0;            ///< update() calls
  uint64_t pagesCopied = 0;       ///< pages copied from the GPU tile cache into the stack
  int lastFramePagesCopied = 0;   ///< in the latest update()
  int lastFramePagesWaiting = 0;  ///< pages passed over in the latest update(): tiles not in RAM yet (requested)
  int pending = 0;                ///< pages of the current windows not resident yet
  size_t gpuBytes = 0;            ///< all GPU storage of the streamed elevation (<= budget)
  size_t gpuBudgetBytes = 0;
  GpuCacheStats cache;  ///< the GPU tile cache's own counters
};

class StreamedElevation {
 public:
  /// Takes the store; reads its coarse level C (whole terrain) and uploads it. `wrapLongitude`:
  /// the grid spans 360 degrees and is drawn on the body (planetary mode), so windows continue
  /// across the seam (page columns are taken modulo the grid by the store's global reads).
  /// Fails on bad parameters, a missing field, or a budget too small for the stack plus one page.
  static Result<std::unique_ptr<StreamedElevation>> create(strata::terrain::TileStore store,
                                                           const StreamParams& params = {}, bool wrapLongitude = false);
  ~StreamedElevation();

  /// Centres the windows on the viewer at base-grid position `cell` (cells from the grid's
  /// top-left corner) and copies up to the per-frame budget of the pages still missing, coarse
  /// levels first, then nearest first. Never does more than the budget: the rest waits. Without
  /// waitForDisk a page whose tiles are not decoded yet is requested and passed over (the next
  /// one takes its place in the budget), so update() never decodes a tile file.
  Status update(glm::dvec2 cell);
  void setUploadPagesPerFrame(int pages) { params_.uploadPagesPerFrame = pages; }

  /// C: levels 0..C-1 are in the stack; level C is the coarse texture (whole terrain).
  int coarseLevel() const { return coarse_; }
  /// Window corner of stack level `level` (level texels; a multiple of P).
  glm::ivec2 windowOrigin(int level) const { return origins_[size_t(level)]; }
  /// Whether page (px, py) of stack level `level` is resident (or lies outside the level's cells).
  bool pageReady(int level, int px, int py) const;
  const StreamParams& params() const { return params_; }
  int field() const { return field_; }
  int width() const;  ///< base grid (cells)
  int height() const;
  /// Level extent in texels: ceil(size / 2^level).
  glm::ivec2 levelSize(int level) const;

  const gl::Texture& coarseTexture() const { return coarseTex_; }
  const gl::Texture& clipTexture() const { return clip_; }
  const gl::Texture& pageFlags() const { return flags_; }
  /// Elevation range of the field over the store (m).
  float minElevationM() const { return minM_; }
  /// The elevation a void takes at base-cell coordinates (x, y) (cell (i, j) spans [i, i+1)):
  /// the filled coarse level, bilinear (its voids filled from the cells around them).
  float voidFill(double x, double y) const;
  /// Fills a page's voids from the page and a page-wide margin around it, as the whole-DEM
  /// render fills its grid (GDAL's fill); texels outside the level, or with no data around,
  /// take voidFill. False (wait false) while the margin's tiles are being read.
  Result<bool> fillPage(const PageKey& key, gis::Grid<float>& page, bool wait);
  float maxElevationM() const { return maxM_; }
  /// The four base-grid samples (i, j), (i+1, j), (i, j+1), (i+1, j+1), NaN filled with the
  /// minimum, through the store's RAM cache (the coarse level's samples if a tile cannot be read,
  /// or, without waitForDisk, while its tile is being decoded).
  std::array<float, 4> cellQuad(int i, int j);

  /// The whole terrain at the finest level of the store at most `maxSide` cells a side (or the
  /// coarsest it has), voids filled, and that level's grid (cells 2^level base cells a side,
  /// from the same corner; the last row and column may reach past the base grid's extent). For
  /// what is computed once over the whole terrain: shadows, the graticule's lon/lat.
  Result<gis::Raster> overview(int maxSide);
  /// The grid overview(maxSide) reads (its level's cells), without reading anything.
  gis::Georef overviewGrid(int maxSide) const;

  StreamStats stats() const;
  size_t gpuBytes() const;
  GpuTileCache& cache() { return *cache_; }
  strata::terrain::TileStore& store() { return *store_; }

 private:
  struct Pending {
    int level, px, py;
  };
  StreamedElevation() = default;
  void moveWindow(int level, glm::ivec2 origin);
  int overviewLevel(int maxSide) const;
  bool inWindow(int level, int px, int py) const;
  int slots() const { return params_.clipSize / params_.pageSize; }
  size_t flagIndex(int level, int px, int py) const;

  std::unique_ptr<strata::terrain::TileStore> store_;
  std::unique_ptr<GpuTileCache> cache_;
  StreamParams params_;
  int field_ = 0, coarse_ = 0;
  float minM_ = 0, maxM_ = 0;
  bool placed_ = false, wrapX_ = false;
  std::vector<glm::ivec2> origins_;
  std::vector<uint32_t> flagsCpu_;  // slots^2 per stack level, 1: the slot holds its window's page
  bool flagsDirty_ = true;
  std::vector<Pending> pending_;
  gis::Grid<float> coarseCpu_;
  gl::Texture coarseTex_, clip_, flags_;
  StreamStats stats_;
};

}  // namespace strata::render
