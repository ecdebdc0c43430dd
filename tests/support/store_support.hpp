#pragma once
// Helpers for the tile store's tests: a grid as an ingest source, and a store's problems.
#include <string>
#include <utility>

#include <strata/gis/raster.hpp>
#include <strata/terrain/ingest.hpp>
#include <strata/terrain/tile_store.hpp>

namespace strata::test {

/// Reads windows of `src` (a copy); cells outside it are no data.
inline terrain::WindowReader gridReader(gis::Grid<float> src) {
  return [src = std::move(src)](int x0, int y0, int w, int h) -> Result<gis::Grid<float>> {
    gis::Grid<float> g(w, h, gis::kNoData);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (src.contains(x0 + x, y0 + y)) g.at(x, y) = src.at(x0 + x, y0 + y);
      }
    }
    return g;
  };
}

/// A store's one bedrock layer read through `r`.
inline terrain::IngestSource bedrock(terrain::WindowReader r) {
  return {{"bedrock", terrain::LayerKind::Bedrock, ""}, std::move(r)};
}

/// verify()'s problems, one per line (empty: none).
inline std::string problemsOf(const terrain::TileStore& s) {
  std::string out;
  for (const auto& p : s.verify()) out += p.message + "\n";
  return out;
}

}  // namespace strata::test
