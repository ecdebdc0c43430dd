// What a store checks and summarises about itself: its tiles' error, `strata check`'s verify, the
// resolution map and the storage footprint.
#include <strata/terrain/tile_store.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <strata/gis/geodesy.hpp>

#include "exr_codec.hpp"
#include "tile_store_impl.hpp"

namespace strata::terrain {

namespace fs = std::filesystem;
using gis::Grid;
using namespace detail;

ErrorSummary TileStore::errorSummary(int field, std::optional<gis::CellRect> w) const {
  STRATA_CHECK(field >= 0 && size_t(field) < impl_->nf()) << "field " << field;
  const int F = footprint();
  int tx0 = 0, ty0 = 0, tx1 = tilesX() - 1, ty1 = tilesY() - 1;
  if (w) {
    tx0 = std::max(0, w->x / F);
    ty0 = std::max(0, w->y / F);
    tx1 = std::min(tilesX() - 1, (w->x + w->width - 1) / F);
    ty1 = std::min(tilesY() - 1, (w->y + w->height - 1) / F);
  }
  ErrorSummary e;
  double sumSq = 0;
  for (int ty = ty0; ty <= ty1; ++ty) {
    for (int tx = tx0; tx <= tx1; ++tx) {
      const auto& r = impl_->rec(tx, ty);
      if (!r.present) continue;
      const auto f = size_t(field);
      e.maxM = std::max(e.maxM, double(r.maxErrorM[f]));
      sumSq += double(r.rmsErrorM[f]) * double(r.rmsErrorM[f]) * double(r.validCells[f]);
      e.cells += r.validCells[f];
    }
  }
  e.rmsM = e.cells ? std::sqrt(sumSq / double(e.cells)) : 0.0;
  return e;
}

std::vector<TileProblem> TileStore::verify() const {
  auto& I = *impl_;
  std::vector<TileProblem> problems;
  const std::string manifest = detail::kManifestName;
  auto problem = [&](const std::string& file, const std::string& message) { problems.push_back({file, message}); };

  // The CRS: parseable, and the manifest's EPSG code, name, kind and body are its own.
  const auto& g = desc().georef;
  if (!g.crsWkt.empty() || g.epsg) {
    auto crs = gis::describeCrs(g.crsWkt.empty() ? "EPSG:" + std::to_string(*g.epsg) : g.crsWkt);
    if (!crs) {
      problem(manifest, manifest + ": georef.crs_wkt does not parse: " + crs.message());
    } else {
      auto differs = [&](const std::string& key, const std::string& have, const std::string& want) {
        problem(manifest, manifest + ": georef." + key + " = " + have + " but crs_wkt says " + want);
      };
      auto epsgText = [](const std::optional<int>& e) { return e ? std::to_string(*e) : std::string("none"); };
      if (!g.crsWkt.empty() && crs->epsg != g.epsg) differs("epsg", epsgText(g.epsg), epsgText(crs->epsg));
      if (!g.crsWkt.empty() && crs->crsName != g.crsName)
        differs("crs_name", "'" + g.crsName + "'", "'" + crs->crsName + "'");
      if (crs->geographic != g.geographic)
        differs("geographic", g.geographic ? "true" : "false", crs->geographic ? "true" : "false");
      if (std::abs(crs->body.semiMajorM - g.body.semiMajorM) > 1e-6 * crs->body.semiMajorM ||
          std::abs(crs->body.flattening - g.body.flattening) > 1e-9) {
        differs("body_semi_major_m / body_flattening",
                shortest(g.body.semiMajorM) + " / " + shortest(g.body.flattening),
                shortest(crs->body.semiMajorM) + " / " + shortest(crs->body.flattening));
      }
    }
  }

  // Every present tile: size, checksum, decoding, its place, its samples against its record.
  std::vector<float> lo(I.nf(), std::numeric_limits<float>::infinity()), hi(I.nf(), -lo[0]);
  std::set<std::string> live;
  for (int ty = 0; ty < tilesY(); ++ty) {
    for (int tx = 0; tx < tilesX(); ++tx) {
      const auto& r = I.rec(tx, ty);
      if (!r.present) continue;
      live.insert(fs::path(r.file).filename().string());
      for (size_t f = 0; f < I.nf(); ++f) {
        if (std::isnan(r.minV[f])) continue;
        lo[f] = std::min(lo[f], r.minV[f]);
        hi[f] = std::max(hi[f], r.maxV[f]);
      }
      const TileRef ref = I.ref(tx, ty);
      auto bytes = readTileBytes(I.dir, ref);
      if (!bytes) {
        problem(r.file, bytes.message());
        continue;
      }
      auto finest = detail::decodeTileExrLevel(r.file, *bytes, I.fieldNames, 0);
      auto coarsest = detail::decodeTileExrLevel(r.file, *bytes, I.fieldNames, r.exp);
      auto tag = detail::decodeTileExrTag(r.file, *bytes);
      if (!finest || !coarsest || !tag) {
        problem(r.file, !finest ? finest.message() : !coarsest ? coarsest.message() : tag.message());
        continue;
      }
      if ((*finest)[0].width != 1 << r.exp || (*coarsest)[0].width != 1) {
        problem(r.file, r.file + ": " + std::to_string((*finest)[0].width) + " samples a side, the manifest says 2^" +
                            std::to_string(r.exp));
        continue;
      }
      if (*tag != I.tileTag(tx, ty, r.exp)) {
        problem(r.file, r.file + ": made for another place or grid (tile says '" + *tag + "', the manifest '" +
                            I.tileTag(tx, ty, r.exp) + "')");
        continue;
      }
      // Samples are block means of cells in [min, max]; each extreme is within the tile's error of
      // some sample; the blocks with data cover exactly the valid cells.
      const int j = maxLod() - r.exp;
      const auto [wIn, hIn] = I.inGrid(tx, ty);
      for (size_t f = 0; f < I.nf(); ++f) {
        const auto& sm = (*finest)[f];
        float smin = std::numeric_limits<float>::infinity(), smax = -smin;
        uint64_t cells = 0;
        for (int y = 0; y < sm.height; ++y) {
          for (int x = 0; x < sm.width; ++x) {
            const float v = sm.at(x, y);
            if (std::isnan(v)) continue;
            smin = std::min(smin, v);
            smax = std::max(smax, v);
            cells += cellsInGrid(x, y, 1 << j, wIn, hIn);
          }
        }
        const std::string what = r.file + ": field '" + I.fieldNames[f] + "': ";
        if (cells != r.validCells[f]) {
          problem(r.file, what + std::to_string(cells) + " cells with data, the manifest says " +
                              std::to_string(r.validCells[f]));
          continue;
        }
        if (!cells) continue;
        const double tol =
            double(r.maxErrorM[f]) + 1e-6 * std::max(std::abs(double(r.maxV[f])), std::abs(double(r.minV[f]))) + 1e-6;
        if (smin < r.minV[f] || smax > r.maxV[f] || double(r.maxV[f]) - smax > tol || double(smin) - r.minV[f] > tol) {
          problem(r.file, what + "samples span " + shortest(smin) + " .. " + shortest(smax) + ", the manifest says " +
                              shortest(r.minV[f]) + " .. " + shortest(r.maxV[f]) + " within " +
                              shortest(r.maxErrorM[f]) + " m");
        }
      }
    }
  }
  for (size_t f = 0; f < I.nf(); ++f) {
    if (lo[f] > hi[f]) lo[f] = hi[f] = gis::kNoData;
    if (!sameValue(lo[f], I.man.rangeLo[f]) || !sameValue(hi[f], I.man.rangeHi[f])) {
      if (buildState().complete) {  // an ingest sets the ranges when it finishes
        problem(manifest, manifest + ": field '" + I.fieldNames[f] + "': range " + shortest(I.man.rangeLo[f]) + " .. " +
                              shortest(I.man.rangeHi[f]) + ", the tiles span " + shortest(lo[f]) + " .. " +
                              shortest(hi[f]));
      }
    }
  }
  // Tile files the manifest does not name for a tile it lists as absent: a deleted entry (its
  // data lost to readers). Other unnamed tile files are harmless leftovers of a writer that died
  // (superseded generations of listed tiles, or uncommitted writes), which its next commit
  // removes.
  std::error_code ec;
  std::vector<std::string> orphans;
  for (const auto& e : fs::directory_iterator(I.dir / "tiles", ec)) {
    const std::string name = e.path().filename().string();
    if (!isTileFileName(name) || name.find(".tmp") != std::string::npos || live.count(name)) continue;
    const auto tx = std::strtoull(name.c_str() + 1, nullptr, 10);
    const auto ty = std::strtoull(name.c_str() + name.find("_y") + 2, nullptr, 10);
    const auto gen = std::strtoull(name.c_str() + name.find("_g") + 2, nullptr, 10);
    const bool listed = tx < uint64_t(tilesX()) && ty < uint64_t(tilesY()) && I.rec(int(tx), int(ty)).present;
    if (!listed && gen < I.man.nextGeneration) orphans.push_back(name);
  }
  std::sort(orphans.begin(), orphans.end());
  for (const auto& o : orphans) {
    problem("tiles/" + o, "tiles/" + o +
                              ": a tile file for a tile the manifest lists as absent (its entry deleted from the "
                              "manifest?); its data is not read");
  }
  return problems;
}

Grid<float> TileStore::resolutionMap() const {
  Grid<float> m(tilesX(), tilesY(), gis::kNoData);
  for (int ty = 0; ty < tilesY(); ++ty) {
    for (int tx = 0; tx < tilesX(); ++tx) {
      if (impl_->rec(tx, ty).present) m.at(tx, ty) = float(impl_->rec(tx, ty).exp);
    }
  }
  return m;
}

StorageFootprint TileStore::footprintStats() const {
  StorageFootprint s;
  const uint64_t nf = impl_->nf();
  s.denseSamples = uint64_t(width()) * uint64_t(height()) * nf;
  for (int ty = 0; ty < tilesY(); ++ty) {
    for (int tx = 0; tx < tilesX(); ++tx) {
      const auto& r = impl_->rec(tx, ty);
      if (!r.present) continue;
      const auto [wIn, hIn] = impl_->inGrid(tx, ty);
      // Samples of block side b covering the wIn x hIn cells inside the grid, level by level.
      auto covering = [w = uint64_t(wIn), h = uint64_t(hIn)](uint64_t b) {
        return ((w + b - 1) / b) * ((h + b - 1) / b);
      };
      uint64_t b = uint64_t(1) << (maxLod() - r.exp);
      s.storedSamples += covering(b) * nf;
      for (int level = r.exp; level >= 0; --level, b *= 2) s.storedWithMips += covering(b) * nf;
      s.fileBytes += r.bytes;
    }
  }
  return s;
}

}  // namespace strata::terrain
