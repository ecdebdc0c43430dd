#include <strata/terrain/tile_store.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>

#include <strata/core/files.hpp>
#include <strata/core/log.hpp>

#include "exr_codec.hpp"
#include "tile_store_impl.hpp"

namespace strata::terrain {

namespace fs = std::filesystem;
using gis::Grid;
using namespace detail;

namespace {

std::vector<std::string> fieldsOf(const Manifest& m) {
  std::vector<std::string> names;
  for (const auto& f : m.desc.fields) names.push_back(f.name);
  return names;
}

}  // namespace

TileStore::Impl::Impl(fs::path d, detail::Manifest m, CacheOptions c)
    : dir(std::move(d)),
      man(std::move(m)),
      fieldNames(fieldsOf(man)),
      footprint(1 << man.desc.metric.maxExp),
      loader(dir, fieldNames, c) {}

std::string TileStore::Impl::tileTag(int tx, int ty, int exp) const {
  const auto& g = man.desc.georef;
  const double col = double(tx) * footprint, row = double(ty) * footprint;
  const auto& c = g.transform.c;
  char crc[16];
  std::snprintf(crc, sizeof crc, "%08x", unsigned(crc32Of(g.crsWkt.data(), g.crsWkt.size())));
  return "x=" + std::to_string(tx) + " y=" + std::to_string(ty) + " exp=" + std::to_string(exp) +
         " footprint=" + std::to_string(footprint) + " origin=" + shortest(g.transform.x(col, row)) + "," +
         shortest(g.transform.y(col, row)) + " cell=" + shortest(c[1]) + "," + shortest(c[2]) + "," + shortest(c[4]) +
         "," + shortest(c[5]) + " epsg=" + std::to_string(g.epsg.value_or(0)) + " wkt_crc32=" + crc;
}

Result<DecodedPtr> TileStore::Impl::get(int tx, int ty, int need, bool prefetch, bool* missing) {
  const int mip = std::max(0, rec(tx, ty).exp - need);
  bool decoded = false;
  STRATA_TRY(DecodedPtr d, loader.get(ref(tx, ty), mip, missing, &decoded));
  if (decoded && prefetch && loader.prefetching()) prefetchAround(tx, ty, need);
  return d;
}

void TileStore::Impl::prefetchAround(int tx, int ty, int need) {
  std::vector<std::pair<TileRef, int>> levels;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (!dx && !dy) continue;
      int nx = tx + dx;
      const int ny = ty + dy;
      if (man.desc.layout == TileLayout::Global) nx = (nx + man.tilesX) % man.tilesX;
      if (nx < 0 || ny < 0 || nx >= man.tilesX || ny >= man.tilesY || !rec(nx, ny).present) continue;
      levels.emplace_back(ref(nx, ny), std::max(0, rec(nx, ny).exp - need));
    }
  }
  loader.prefetch(std::move(levels));
}

Status TileStore::Impl::readRect(int field, int lod, int sx, int sy, int w, int h, Grid<float>& dst, int dx, int dy,
                                 bool* missing) {
  const int tileCells = footprint >> lod;
  const int need = maxExp() - lod;
  for (int ty = sy / tileCells; ty <= (sy + h - 1) / tileCells; ++ty) {
    for (int tx = sx / tileCells; tx <= (sx + w - 1) / tileCells; ++tx) {
      const auto& r = rec(tx, ty);
      const int x0 = std::max(sx, tx * tileCells), x1 = std::min(sx + w, (tx + 1) * tileCells);
      const int y0 = std::max(sy, ty * tileCells), y1 = std::min(sy + h, (ty + 1) * tileCells);
      if (!r.present) {
        for (int y = y0; y < y1; ++y) {
          for (int x = x0; x < x1; ++x) dst.at(dx + x - sx, dy + y - sy) = gis::kNoData;
        }
        continue;
      }
      const int rep = r.exp >= need ? 1 : 1 << (need - r.exp);  // piecewise-constant upsampling
      STRATA_TRY(DecodedPtr d, get(tx, ty, need, true, missing));
      if (!d) continue;  // requested: the read is not complete anyway
      const auto& g = d->fields[size_t(field)];
      for (int y = y0; y < y1; ++y) {
        const float* src = &g.data[g.index(0, (y - ty * tileCells) / rep)];
        float* out = &dst.data[dst.index(dx + x0 - sx, dy + y - sy)];
        if (rep == 1) {
          std::copy(src + (x0 - tx * tileCells), src + (x1 - tx * tileCells), out);
        } else {
          const int shift = std::countr_zero(unsigned(rep));  // rep is a power of two
          for (int x = x0; x < x1; ++x) out[x - x0] = src[(x - tx * tileCells) >> shift];
        }
      }
    }
  }
  return {};
}

Result<std::vector<Grid<float>>> TileStore::Impl::loadFull(int tx, int ty) {
  const auto& r = rec(tx, ty);
  if (!r.present) return std::vector<Grid<float>>(nf(), Grid<float>(footprint, footprint, gis::kNoData));
  STRATA_TRY(DecodedPtr d, get(tx, ty, maxExp(), false));
  std::vector<Grid<float>> out;
  for (const auto& g : d->fields) out.push_back(replicateUpsample(g, 1 << (maxExp() - r.exp)));
  return out;
}

Status TileStore::Impl::store(int tx, int ty, Fit f) {
  // The mip chain: box means of the level before. A field whose samples are whole numbers (an
  // integer DEM's: SRTM, ETOPO, MOLA) has its means rounded to whole numbers, as GDAL's overviews
  // of an integer raster are (each within 0.5 of the exact mean): the tile then stores as integers
  // (exr_codec.cpp), where the exact means would carry two more fractional bits each level.
  std::vector<bool> whole;
  for (const auto& g : f.samples) {
    whole.push_back(
        std::all_of(g.data.begin(), g.data.end(), [](float v) { return std::isnan(v) || v == std::nearbyint(v); }));
  }
  std::vector<Grid<float>> exact = f.samples;
  std::vector<std::vector<Grid<float>>> levels;
  levels.push_back(std::move(f.samples));
  while (levels.back()[0].width > 1) {
    std::vector<Grid<float>> next;
    for (size_t c = 0; c < exact.size(); ++c) {
      exact[c] = boxDownsample(exact[c], 2);
      next.push_back(exact[c]);
      if (whole[c]) {
        for (float& v : next.back().data) v = std::nearbyint(v);
      }
    }
    levels.push_back(std::move(next));
  }
  const auto bytes = detail::encodeTileExr(fieldNames, levels, tileTag(tx, ty, f.exp));
  auto& r = rec(tx, ty);
  const uint64_t gen = man.nextGeneration++;
  const std::string file = detail::tileFileName(tx, ty, gen);
  STRATA_TRY_STATUS(writeTileFile(dir / file, bytes.data(), bytes.size()));
  r.present = true;
  r.exp = f.exp;
  r.generation = gen;
  r.file = file;
  r.crc32 = crc32Of(bytes.data(), bytes.size());
  r.bytes = bytes.size();
  r.minV = std::move(f.lo);
  r.maxV = std::move(f.hi);
  r.validCells = std::move(f.valid);
  r.maxErrorM = std::move(f.maxErr);
  r.rmsErrorM = std::move(f.rmsErr);
  return {};
}

std::vector<float> TileStore::Impl::evalRange() const {
  std::vector<float> g(nf());
  for (size_t f = 0; f < nf(); ++f) g[f] = man.rangeHi[f] - man.rangeLo[f];
  return g;
}

void TileStore::Impl::stats(int tx, int ty, const std::vector<Grid<float>>& fields, std::vector<float>& lo,
                            std::vector<float>& hi) const {
  const auto [wIn, hIn] = inGrid(tx, ty);
  fieldRanges(fields, wIn, hIn, lo, hi);
}

Status TileStore::Impl::put(int tx, int ty, const std::vector<Grid<float>>& full, bool edit, bool keep) {
  STRATA_TRY_STATUS(writerLock.take(dir));
  const auto [wIn, hIn] = inGrid(tx, ty);
  const TileRecord old = rec(tx, ty);
  Fit f = fitTile(full, wIn, hIn, man.desc.metric, evalRange(), keep ? &old : nullptr);
  if (f.empty()) {
    rec(tx, ty) = TileRecord{};
    return {};
  }
  if (keep && f.exp == old.exp) return {};
  if (edit && old.present) {
    for (size_t k = 0; k < nf(); ++k) {
      f.maxErr[k] += old.maxErrorM[k];
      f.rmsErr[k] += old.rmsErrorM[k];
    }
  }
  return store(tx, ty, std::move(f));
}

Status TileStore::Impl::resample(int tx, int ty) {
  STRATA_TRY(auto full, loadFull(tx, ty));
  log::debug("terrain") << "tile " << tx << "," << ty << ": resampling from 2^" << rec(tx, ty).exp;
  return put(tx, ty, full, true, true);
}

Status TileStore::Impl::applyRange(const std::vector<float>& lo, const std::vector<float>& hi,
                                   const std::set<size_t>& skip) {
  bool changed = false;
  for (size_t f = 0; f < nf(); ++f) changed |= !sameValue(lo[f], man.rangeLo[f]) || !sameValue(hi[f], man.rangeHi[f]);
  if (!changed) return {};
  man.rangeLo = lo;
  man.rangeHi = hi;
  if (man.desc.metric.kind != TileMetric::Range) return {};
  const auto g = evalRange();
  for (int ty = 0; ty < man.tilesY; ++ty) {
    for (int tx = 0; tx < man.tilesX; ++tx) {
      const size_t i = size_t(ty) * size_t(man.tilesX) + size_t(tx);
      const auto& r = man.tiles[i];
      if (!r.present || skip.count(i)) continue;
      std::vector<float> range(nf());
      for (size_t f = 0; f < nf(); ++f) range[f] = r.maxV[f] - r.minV[f];
      if (chooseTileExp(range, g, minExp(), maxExp()) != r.exp) STRATA_TRY_STATUS(resample(tx, ty));
    }
  }
  return {};
}

void TileStore::Impl::unionRange(const std::set<size_t>& skip, const std::vector<std::vector<float>>& extraLo,
                                 const std::vector<std::vector<float>>& extraHi, std::vector<float>& lo,
                                 std::vector<float>& hi) {
  lo.assign(nf(), std::numeric_limits<float>::infinity());
  hi.assign(nf(), -std::numeric_limits<float>::infinity());
  auto add = [&](const std::vector<float>& a, const std::vector<float>& b) {
    for (size_t f = 0; f < nf(); ++f) {
      if (std::isnan(a[f])) continue;
      lo[f] = std::min(lo[f], a[f]);
      hi[f] = std::max(hi[f], b[f]);
    }
  };
  for (size_t i = 0; i < man.tiles.size(); ++i) {
    if (man.tiles[i].present && !skip.count(i)) add(man.tiles[i].minV, man.tiles[i].maxV);
  }
  for (size_t k = 0; k < extraLo.size(); ++k) add(extraLo[k], extraHi[k]);
  for (size_t f = 0; f < nf(); ++f) {
    if (lo[f] > hi[f]) lo[f] = hi[f] = gis::kNoData;
  }
}

TileStore::TileStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TileStore::TileStore(TileStore&&) noexcept = default;
TileStore& TileStore::operator=(TileStore&&) noexcept = default;
TileStore::~TileStore() = default;

Result<TileStore> TileStore::create(const fs::path& dir, StoreDesc desc, CacheOptions cache) {
  auto valid = detail::validateDesc(desc);
  if (!valid) return fail(dir.string() + ": " + valid.message());
  std::error_code ec;
  fs::create_directories(dir / "tiles", ec);
  if (ec) return fail(dir.string() + ": cannot create: " + ec.message());
  detail::Manifest m;
  const int footprint = 1 << desc.metric.maxExp;
  m.tilesX = detail::tilesAlong(desc.georef.width, footprint);
  m.tilesY = detail::tilesAlong(desc.georef.height, footprint);
  m.rangeLo.assign(desc.fields.size(), gis::kNoData);
  m.rangeHi.assign(desc.fields.size(), gis::kNoData);
  m.tiles.assign(size_t(m.tilesX) * size_t(m.tilesY), TileRecord{});
  m.state.complete = false;
  m.state.pass = 1;
  m.desc = std::move(desc);
  TileStore s(std::make_unique<Impl>(dir, std::move(m), cache));
  // Locked before looking: two creators of one folder cannot both find it empty.
  STRATA_TRY_STATUS(s.impl_->writerLock.take(s.impl_->dir));
  if (fs::exists(dir / detail::kManifestName, ec)) return fail(dir.string() + ": already holds a tile store");
  for (const auto& e : fs::directory_iterator(dir / "tiles", ec)) {
    if (isTileFileName(e.path().filename().string())) {
      return fail(dir.string() + ": tiles/ holds tile files (" + e.path().filename().string() +
                  ") but there is no manifest: not a store this ingest started; use an empty folder");
    }
  }
  STRATA_TRY_STATUS(s.commit());
  return s;
}

Result<TileStore> TileStore::open(const fs::path& dir, CacheOptions cache, OpenOptions options) {
  const fs::path path = dir / detail::kManifestName;
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(path.string() + ": cannot read (not a Strata tile store?)");
  std::stringstream text;
  text << in.rdbuf();
  STRATA_TRY(auto m, detail::parseManifest(text.str(), path.string()));
  if (!m.state.complete && !options.allowIncomplete) {
    return fail(dir.string() + ": incomplete store: its ingest stopped in pass " + std::to_string(m.state.pass) +
                " after " + std::to_string(m.state.tilesDone) + " of " + std::to_string(int64_t(m.tilesX) * m.tilesY) +
                " tiles; finish it with `strata ingest --resume` (same arguments)");
  }
  return TileStore(std::make_unique<Impl>(dir, std::move(m), cache));
}

const StoreDesc& TileStore::desc() const { return impl_->man.desc; }
const fs::path& TileStore::dir() const { return impl_->dir; }
int TileStore::width() const { return impl_->man.desc.georef.width; }
int TileStore::height() const { return impl_->man.desc.georef.height; }
int TileStore::footprint() const { return impl_->footprint; }
int TileStore::tilesX() const { return impl_->man.tilesX; }
int TileStore::tilesY() const { return impl_->man.tilesY; }
int TileStore::maxLod() const { return impl_->maxExp(); }
int TileStore::levelWidth(int lod) const { return (width() + (1 << lod) - 1) >> lod; }
int TileStore::levelHeight(int lod) const { return (height() + (1 << lod) - 1) >> lod; }

int TileStore::fieldIndex(const std::string& name) const {
  for (size_t i = 0; i < impl_->fieldNames.size(); ++i) {
    if (impl_->fieldNames[i] == name) return int(i);
  }
  return -1;
}

const TileRecord& TileStore::tile(int tx, int ty) const {
  STRATA_CHECK(tx >= 0 && ty >= 0 && tx < tilesX() && ty < tilesY()) << "tile " << tx << "," << ty;
  return impl_->rec(tx, ty);
}

std::pair<float, float> TileStore::globalRange(int field) const {
  STRATA_CHECK(field >= 0 && size_t(field) < impl_->nf()) << "field " << field;
  return {impl_->man.rangeLo[size_t(field)], impl_->man.rangeHi[size_t(field)]};
}

Result<Grid<float>> TileStore::readWindow(int field, gis::CellRect w, int lod) { return read(field, w, lod, nullptr); }

Result<std::optional<Grid<float>>> TileStore::tryReadWindow(int field, gis::CellRect w, int lod) {
  bool missing = false;
  STRATA_TRY(auto g, read(field, w, lod, &missing));
  if (missing) return std::optional<Grid<float>>();
  return std::optional<Grid<float>>(std::move(g));
}

void TileStore::clearRequests() { impl_->loader.clearRequests(); }
int TileStore::requestsPending() const { return impl_->loader.requestsPending(); }

Result<Grid<float>> TileStore::read(int field, gis::CellRect w, int lod, bool* missing) {
  auto& I = *impl_;
  if (field < 0 || size_t(field) >= I.nf()) return fail(I.dir.string() + ": no field " + std::to_string(field));
  if (lod < 0 || lod > maxLod()) {
    return fail(I.dir.string() + ": level " + std::to_string(lod) + " outside 0.." + std::to_string(maxLod()));
  }
  if (w.width < 0 || w.height < 0) return fail(I.dir.string() + ": window with a negative size");
  Grid<float> out(w.width, w.height, gis::kNoData);
  const int lw = levelWidth(lod), lh = levelHeight(lod);
  if (desc().layout == TileLayout::Planar) {
    const int x0 = std::max(0, w.x), y0 = std::max(0, w.y);
    const int x1 = std::min(lw, w.x + w.width), y1 = std::min(lh, w.y + w.height);
    if (x0 < x1 && y0 < y1)
      STRATA_TRY_STATUS(I.readRect(field, lod, x0, y0, x1 - x0, y1 - y0, out, x0 - w.x, y0 - w.y, missing));
    return out;
  }
  // Global: three bands of rows. Rows above the north pole (y < 0) continue down the meridian
  // half a turn away (row -1-y, longitude + 180); likewise below the south pole. Columns wrap.
  struct Band {
    int outY0, outY1;  // output rows
    bool folded;
  };
  const Band bands[3] = {{std::max(0, -lh - w.y), std::min(w.height, -w.y), true},
                         {std::max(0, -w.y), std::min(w.height, lh - w.y), false},
                         {std::max(0, lh - w.y), std::min(w.height, 2 * lh - w.y), true}};
  for (const auto& b : bands) {
    if (b.outY0 >= b.outY1) continue;
    auto srcRow = [&](int j) {
      const int y = w.y + j;
      return y < 0 ? -1 - y : y >= lh ? 2 * lh - 1 - y : y;
    };
    const int s0 = std::min(srcRow(b.outY0), srcRow(b.outY1 - 1));
    const int rows = b.outY1 - b.outY0;
    const int shift = b.folded ? lw / 2 : 0;
    Grid<float> tmp(w.width, rows, gis::kNoData);
    for (int i = 0; i < w.width;) {
      const int sx = (((w.x + i + shift) % lw) + lw) % lw;
      const int len = std::min(w.width - i, lw - sx);
      STRATA_TRY_STATUS(I.readRect(field, lod, sx, s0, len, rows, tmp, i, 0, missing));
      i += len;
    }
    for (int j = b.outY0; j < b.outY1; ++j) {
      const int tj = srcRow(j) - s0;
      std::copy_n(&tmp.data[tmp.index(0, tj)], w.width, &out.data[out.index(0, j)]);
    }
  }
  return out;
}

Status TileStore::writeWindow(int field, int x, int y, const Grid<float>& values) {
  auto& I = *impl_;
  if (field < 0 || size_t(field) >= I.nf()) return fail(I.dir.string() + ": no field " + std::to_string(field));
  if (x < 0 || y < 0 || x + values.width > width() || y + values.height > height()) {
    return fail(I.dir.string() + ": window " + std::to_string(values.width) + "x" + std::to_string(values.height) +
                " at " + std::to_string(x) + "," + std::to_string(y) + " is not inside the " + std::to_string(width()) +
                "x" + std::to_string(height()) + " grid");
  }
  if (values.size() == 0) return {};
  const int F = I.footprint;
  // 1. The affected tiles at full resolution with the new cells pasted in, and their new ranges.
  std::vector<std::pair<int, int>> tiles;
  std::vector<std::vector<Grid<float>>> merged;
  std::vector<std::vector<float>> los, his;
  std::set<size_t> touched;
  for (int ty = y / F; ty <= (y + values.height - 1) / F; ++ty) {
    for (int tx = x / F; tx <= (x + values.width - 1) / F; ++tx) {
      STRATA_TRY(auto full, I.loadFull(tx, ty));
      auto& g = full[size_t(field)];
      const int x0 = std::max(x, tx * F), x1 = std::min(x + values.width, (tx + 1) * F);
      const int y0 = std::max(y, ty * F), y1 = std::min(y + values.height, (ty + 1) * F);
      for (int yy = y0; yy < y1; ++yy) {
        for (int xx = x0; xx < x1; ++xx) g.at(xx - tx * F, yy - ty * F) = values.at(xx - x, yy - y);
      }
      std::vector<float> lo, hi;
      I.stats(tx, ty, full, lo, hi);
      tiles.emplace_back(tx, ty);
      merged.push_back(std::move(full));
      los.push_back(std::move(lo));
      his.push_back(std::move(hi));
      touched.insert(size_t(ty) * size_t(tilesX()) + size_t(tx));
    }
  }
  // 2. A moved global range re-evaluates every other tile; 3. the affected tiles are stored.
  std::vector<float> lo, hi;
  I.unionRange(touched, los, his, lo, hi);
  STRATA_TRY_STATUS(I.applyRange(lo, hi, touched));
  for (size_t k = 0; k < tiles.size(); ++k) STRATA_TRY_STATUS(I.put(tiles[k].first, tiles[k].second, merged[k], true));
  return {};
}

Status TileStore::putTile(int tx, int ty, const std::vector<Grid<float>>& fields) {
  auto& I = *impl_;
  STRATA_CHECK(tx >= 0 && ty >= 0 && tx < tilesX() && ty < tilesY()) << "tile " << tx << "," << ty;
  STRATA_CHECK(fields.size() == I.nf()) << fields.size() << " fields given, the store has " << I.nf();
  for (const auto& g : fields) {
    STRATA_CHECK(g.width == I.footprint && g.height == I.footprint) << "tile field " << g.width << "x" << g.height;
  }
  return I.put(tx, ty, fields, false);
}

void TileStore::setEvaluationRange(int field, float lo, float hi) {
  STRATA_CHECK(field >= 0 && size_t(field) < impl_->nf()) << "field " << field;
  impl_->man.rangeLo[size_t(field)] = lo;
  impl_->man.rangeHi[size_t(field)] = hi;
}

Status TileStore::reevaluate() {
  std::vector<float> lo, hi;
  impl_->unionRange({}, {}, {}, lo, hi);
  return impl_->applyRange(lo, hi, {});
}

Status TileStore::commit() {
  auto& I = *impl_;
  STRATA_TRY_STATUS(I.writerLock.take(I.dir));
  const fs::path tiles = I.dir / "tiles";
  // The tile files' data and names reach the disk before the manifest that names them.
  syncDir(tiles, true);
  const std::string text = detail::manifestToToml(I.man);
  STRATA_TRY_STATUS(writeFileAtomic(I.dir / detail::kManifestName, text));
  syncDir(I.dir, false);
  // Superseded tiles, and leftovers of writers that died before their commit: only files named
  // like tiles (or their temporaries); anything else someone put in the folder stays.
  std::set<std::string> live;
  for (const auto& r : I.man.tiles) {
    if (r.present) live.insert(fs::path(r.file).filename().string());
  }
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(tiles, ec)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file(ec) && isTileFileName(name) && !live.count(name)) fs::remove(e.path(), ec);
  }
  // The manifest's own temporaries only (writeFileAtomic's manifest.toml.tmp-PID-N): a user's
  // manifest.toml.tmp-mydraft stays.
  for (const auto& e : fs::directory_iterator(I.dir, ec)) {
    if (e.is_regular_file(ec) && isTemporaryNameOf(e.path().filename().string(), detail::kManifestName)) {
      fs::remove(e.path(), ec);
    }
  }
  return {};
}

Status TileStore::lockForWriting() { return impl_->writerLock.take(impl_->dir); }

const BuildState& TileStore::buildState() const { return impl_->man.state; }
void TileStore::setBuildState(BuildState state) { impl_->man.state = std::move(state); }

gis::Georef TileStore::windowGeoref(gis::CellRect window, int lod) const {
  gis::Georef g = desc().georef;
  const double s = double(1 << lod);
  const auto& c = desc().georef.transform.c;
  g.transform.c[0] = c[0] + window.x * s * c[1] + window.y * s * c[2];
  g.transform.c[3] = c[3] + window.x * s * c[4] + window.y * s * c[5];
  g.transform.c[1] = c[1] * s;
  g.transform.c[2] = c[2] * s;
  g.transform.c[4] = c[4] * s;
  g.transform.c[5] = c[5] * s;
  g.width = window.width;
  g.height = window.height;
  return g;
}

Result<LayeredTerrain> TileStore::readTerrain(gis::CellRect window) {
  LayeredTerrain t;
  t.georef = windowGeoref(window, 0);
  t.materials = desc().materials;
  t.bedrockM = Grid<float>(window.width, window.height, 0.0f);
  t.waterM = Grid<float>(window.width, window.height, 0.0f);
  for (size_t f = 0; f < impl_->nf(); ++f) {
    const auto& sf = desc().fields[f];
    STRATA_TRY(auto g, readWindow(int(f), window, 0));
    switch (sf.kind) {
      case LayerKind::Bedrock: t.bedrockM = std::move(g); break;
      case LayerKind::Water: t.waterM = std::move(g); break;
      case LayerKind::Material:
        t.layers.push_back({sf.name, findMaterial(t.materials, sf.material), std::move(g)});
        break;
    }
  }
  return t;
}

CacheStats TileStore::cacheStats() const { return impl_->loader.cache().stats(); }
void TileStore::resetCacheStats() { impl_->loader.cache().resetStats(); }
void TileStore::clearCache() { impl_->loader.cache().clear(); }

}  // namespace strata::terrain
