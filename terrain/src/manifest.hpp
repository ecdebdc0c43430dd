#pragma once
// Private: the store manifest (manifest.toml), its text form and its validated parse.

#include <cstdint>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::terrain::detail {

inline constexpr const char* kManifestName = "manifest.toml";
inline constexpr const char* kFormatName = "strata-tile-store";
inline constexpr int kFormatVersion = 1;

/// Everything the manifest holds.
struct Manifest {
  StoreDesc desc;
  int tilesX = 0, tilesY = 0;
  std::vector<float> rangeLo, rangeHi;  ///< per field: the range the tile exponents were chosen against
  uint64_t nextGeneration = 1;
  std::vector<TileRecord> tiles;  ///< tilesX * tilesY, row-major
};

/// Tiles across and down for a base grid and footprint.
inline int tilesAlong(int cells, int footprint) { return (cells + footprint - 1) / footprint; }

/// Checks a description for create(): sizes, metric exponents, field names and materials.
Status validateDesc(const StoreDesc& desc);

std::string manifestToToml(const Manifest& m);
/// Parses and validates; errors name `path` and the field.
Result<Manifest> parseManifest(const std::string& text, const std::string& path);

}  // namespace strata::terrain::detail
