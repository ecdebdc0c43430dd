#pragma once
// Private: the store manifest (manifest.toml), its text form and its validated parse.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::terrain::detail {

inline constexpr const char* kManifestName = "manifest.toml";
inline constexpr const char* kFormatName = "strata-tile-store";
inline constexpr int kFormatVersion = 2;

/// Everything the manifest holds.
struct Manifest {
  StoreDesc desc;
  int tilesX = 0, tilesY = 0;
  std::vector<float> rangeLo, rangeHi;  ///< per field: the range the tile exponents were chosen against
  uint64_t nextGeneration = 1;
  BuildState state;
  std::vector<TileRecord> tiles;  ///< tilesX * tilesY, row-major
};

/// Tiles across and down for a base grid and footprint.
inline int tilesAlong(int cells, int footprint) { return (cells + footprint - 1) / footprint; }

/// A tile's file name (relative to the store folder): tiles/x<X>_y<Y>_g<G>.exr.
std::string tileFileName(int tx, int ty, uint64_t generation);

/// Checks a description for create(): sizes, metric exponents, field names and materials.
Status validateDesc(const StoreDesc& desc);

/// The manifest's text: a small, fixed subset of TOML written by Strata itself (deterministic:
/// the same store gives the same bytes).
std::string manifestToToml(const Manifest& m);
/// Parses and validates; errors name `path`, the line where known, and the key. Every number is
/// checked finite and in range; text that the TOML parser cannot take safely is refused before
/// it reaches it (strata/core/toml_screen.hpp; a manifest is ASCII).
Result<Manifest> parseManifest(const std::string& text, const std::string& path);

}  // namespace strata::terrain::detail
