#pragma once
// Mosaics: DEMs of any CRS, resolution and extent resampled (GDAL warp) onto one target grid and
// combined, in the order given, into a named layer with a blend mode. The target grid is chosen
// explicitly or is the union of the inputs (mosaicGrid). See docs/gis.md ("Mosaics").

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// How an input combines with the layer where both have data. Where the input has no data the
/// layer is unchanged. Where the layer has no data yet: replace, max and min take the input's
/// value (they composite images); add, subtract and multiply leave it no data (they correct
/// data that is there) unless the input says `fillNoData`.
enum class BlendMode { Replace, Add, Subtract, Multiply, Max, Min };

/// Resampling kernel used when warping an input onto the target grid.
/// Minimum: each target cell takes the lowest source cell it covers (GDAL's "min"); coarsening a
/// DEM this way keeps narrow channels connected, which flow routing needs.
/// MinimumIfCoarser: Minimum where the target's cells are coarser than the input's along either
/// axis (the "lowest elevation" rule), Bilinear where they are as fine or finer.
enum class Resampling { Nearest, Bilinear, Cubic, Minimum, MinimumIfCoarser };

/// "replace", "add", "subtract", "multiply", "max", "min".
std::string_view toString(BlendMode mode);
/// Parses a blend mode name (as toString writes it); the error names the field's value.
Result<BlendMode> parseBlendMode(std::string_view name);

/// A blend mode with its rule for cells where the layer has no data.
struct BlendSpec {
  BlendMode mode = BlendMode::Replace;
  bool fillNoData = false;
};
/// "MODE" or "MODE+fill" (add+fill: where the layer has no data, take the input's value).
Result<BlendSpec> parseBlendSpec(std::string_view text);

/// One input of a mosaic: a DEM file (any raster GDAL reads; its scale/offset, vertical unit and
/// nodata are honoured), or an in-memory raster when `raster` is set.
struct MosaicInput {
  std::string path;
  std::optional<Raster> raster = std::nullopt;
  BlendMode mode = BlendMode::Replace;
  Resampling resampling = Resampling::Bilinear;
  int band = 1;  ///< 1-based band of the file
  /// Add / subtract / multiply into a cell where the layer has no data: false leaves it no data,
  /// true takes the input's value there.
  bool fillNoData = false;
  /// A CRS and/or geotransform assigned to the file, replacing its own (for DEMs without one).
  std::optional<std::string> assignCrs = std::nullopt;
  std::optional<GeoTransform> assignTransform = std::nullopt;
  /// With `raster`: the raster is a window of a larger one whose georeference is `within` (its
  /// cells from cell (withinX, withinY) of it), warped as that larger raster is: a target cell
  /// whose kernel lies on the cells held gets the bits a warp of the larger raster gives it (the
  /// source cell of each target cell is found on the larger raster's grid, not the window's).
  std::optional<Georef> within = std::nullopt;
  int withinX = 0, withinY = 0;
};

/// The input's name in messages: its path, or "in-memory raster".
std::string inputName(const MosaicInput& input);

/// A named terrain layer: a raster on the target grid, NaN where no input has data.
struct Layer {
  std::string name;
  Raster raster;
};

/// Resamples one input onto `target` (metres; NaN where the input does not cover a cell). An
/// input already on the target's grid (same CRS and cell size, origin whole cells apart) is read
/// cell for cell, not warped. Fails when the input cannot be read, has no georeference, or lives
/// on another body.
Result<Raster> warpToGrid(const MosaicInput& input, const Georef& target);

/// Combines `src` into `layer` cell by cell with `mode` (sizes must match); `fillNoData` as in
/// MosaicInput.
void blendInto(Grid<float>& layer, const Grid<float>& src, BlendMode mode, bool fillNoData = false);

/// Warps every input onto `target` and blends them in order into a layer named `name`.
Result<Layer> buildMosaic(const std::string& name, const Georef& target, std::span<const MosaicInput> inputs);

/// How to choose a mosaic's output grid. Unset parts default to: the first input's CRS; the
/// union of the inputs' extents in that CRS; the finest input cell size (per axis) in it. The
/// default grid is aligned with the first input on that CRS and cell size (its cells are kept).
struct MosaicGridOptions {
  std::optional<std::string> crs;                   ///< "EPSG:n", WKT or PROJ
  std::optional<std::array<double, 4>> extent;      ///< xmin, ymin, xmax, ymax in the grid's CRS
  std::optional<std::array<double, 2>> resolution;  ///< cell width, height (> 0) in CRS units
  int64_t maxCells = int64_t(1) << 40;              ///< larger grids are refused
};

/// The output grid of a mosaic of `inputs` (north-up). Every input must overlap it: with an
/// explicit extent, an input outside it is an error naming the input. Sizes beyond 2^30 cells a
/// side or `maxCells` in all are refused, naming the size.
Result<Georef> mosaicGrid(std::span<const MosaicInput> inputs, const MosaicGridOptions& options = {});

/// A mosaic opened once and read window by window (streaming ingest): each input is opened and
/// its footprint on the grid computed once; a window warps only the inputs that reach it (inputs
/// on the grid's own cells are read directly, through DemFile). Not thread-safe.
class MosaicReader {
 public:
  static Result<MosaicReader> open(std::vector<MosaicInput> inputs, const Georef& grid);
  MosaicReader(MosaicReader&&) noexcept;
  MosaicReader& operator=(MosaicReader&&) noexcept;
  ~MosaicReader();

  const Georef& grid() const;
  /// Cells [x, x+w) x [y, y+h) of the grid (the window may reach past it: NaN there).
  Result<Grid<float>> read(const CellRect& window);
  /// Whether input `i` is read cell for cell (on the grid's cells) rather than warped.
  bool readsDirectly(size_t i) const;

 private:
  struct Impl;
  explicit MosaicReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace strata::gis
