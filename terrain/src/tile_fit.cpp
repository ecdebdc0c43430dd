#include "tile_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <strata/core/log.hpp>

namespace strata::terrain {

using gis::Grid;

int chooseTileExp(const std::vector<float>& tileRange, const std::vector<float>& globalRange, int minExp, int maxExp) {
  STRATA_CHECK(minExp <= maxExp) << "minExp " << minExp << " > maxExp " << maxExp;
  double m = 0;
  for (size_t f = 0; f < tileRange.size() && f < globalRange.size(); ++f) {
    const double t = tileRange[f], g = globalRange[f];
    if (!(t > 0) || !(g > 0)) continue;  // also skips NaN: a field without data is not complex
    m = std::max(m, std::min(1.0, t / g));
  }
  const int bins = maxExp - minExp + 1;
  return minExp + std::min(bins - 1, int(std::floor(m * bins)));
}

Grid<float> boxDownsample(const Grid<float>& src, int factor) {
  STRATA_CHECK(factor >= 1 && src.width % factor == 0 && src.height % factor == 0)
      << src.width << "x" << src.height << " by " << factor;
  if (factor == 1) return src;
  Grid<float> out(src.width / factor, src.height / factor, gis::kNoData);
  std::vector<double> sum(size_t(out.width));
  std::vector<int> count(size_t(out.width));
  for (int oy = 0; oy < out.height; ++oy) {
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(count.begin(), count.end(), 0);
    for (int y = oy * factor; y < (oy + 1) * factor; ++y) {
      const float* row = &src.data[src.index(0, y)];
      for (int x = 0; x < src.width; ++x) {
        if (!std::isnan(row[x])) {
          sum[size_t(x / factor)] += row[x];
          ++count[size_t(x / factor)];
        }
      }
    }
    for (int ox = 0; ox < out.width; ++ox) {
      if (count[size_t(ox)]) out.at(ox, oy) = float(sum[size_t(ox)] / count[size_t(ox)]);
    }
  }
  return out;
}

Grid<float> replicateUpsample(const Grid<float>& src, int factor) {
  STRATA_CHECK(factor >= 1) << "factor " << factor;
  if (factor == 1) return src;
  Grid<float> out(src.width * factor, src.height * factor);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) out.at(x, y) = src.at(x / factor, y / factor);
  }
  return out;
}

namespace detail {

bool Fit::empty() const {
  return std::all_of(valid.begin(), valid.end(), [](uint64_t v) { return v == 0; });
}

void fieldRanges(const std::vector<Grid<float>>& fields, int wIn, int hIn, std::vector<float>& lo,
                 std::vector<float>& hi, std::vector<uint64_t>* valid) {
  lo.assign(fields.size(), gis::kNoData);
  hi.assign(fields.size(), gis::kNoData);
  if (valid) valid->assign(fields.size(), 0);
  for (size_t f = 0; f < fields.size(); ++f) {
    float a = std::numeric_limits<float>::infinity(), b = -a;
    uint64_t cells = 0;
    for (int y = 0; y < hIn; ++y) {
      for (int x = 0; x < wIn; ++x) {
        const float v = fields[f].at(x, y);
        if (std::isnan(v)) continue;
        a = std::min(a, v);
        b = std::max(b, v);
        ++cells;
      }
    }
    if (cells) lo[f] = a, hi[f] = b;
    if (valid) (*valid)[f] = cells;
  }
}

uint64_t cellsInGrid(int bx, int by, int b, int wIn, int hIn) {
  const int64_t cx = std::clamp<int64_t>(int64_t(wIn) - int64_t(bx) * b, 0, b);
  const int64_t cy = std::clamp<int64_t>(int64_t(hIn) - int64_t(by) * b, 0, b);
  return uint64_t(cx * cy);
}

namespace {

// Block sums of one field: level j has (F >> j)^2 blocks of 2^j x 2^j base cells, counting only
// cells inside the grid (the tile's first wIn x hIn cells).
struct Pyramid {
  struct Level {
    int n = 0;
    std::vector<double> sum;
    std::vector<uint32_t> cnt;
    std::vector<float> mn, mx;
  };
  std::vector<Level> levels;  // levels[j - 1] is level j (level 0 is the tile itself)
};

Pyramid buildPyramid(const Grid<float>& full, int wIn, int hIn, int top) {
  Pyramid p;
  const int F = full.width;
  for (int j = 1; j <= top; ++j) {
    Pyramid::Level L;
    L.n = F >> j;
    const size_t nb = size_t(L.n) * size_t(L.n);
    L.sum.assign(nb, 0.0);
    L.cnt.assign(nb, 0);
    L.mn.assign(nb, std::numeric_limits<float>::infinity());
    L.mx.assign(nb, -std::numeric_limits<float>::infinity());
    for (int by = 0; by < L.n; ++by) {
      for (int bx = 0; bx < L.n; ++bx) {
        const size_t b = size_t(by) * size_t(L.n) + size_t(bx);
        for (int k = 0; k < 4; ++k) {
          const int cx = 2 * bx + (k & 1), cy = 2 * by + (k >> 1);
          if (j == 1) {
            if (cx >= wIn || cy >= hIn) continue;
            const float v = full.at(cx, cy);
            if (std::isnan(v)) continue;
            L.sum[b] += v;
            ++L.cnt[b];
            L.mn[b] = std::min(L.mn[b], v);
            L.mx[b] = std::max(L.mx[b], v);
          } else {
            const auto& c = p.levels.back();
            const size_t ci = size_t(cy) * size_t(c.n) + size_t(cx);
            if (!c.cnt[ci]) continue;
            L.sum[b] += c.sum[ci];
            L.cnt[b] += c.cnt[ci];
            L.mn[b] = std::min(L.mn[b], c.mn[ci]);
            L.mx[b] = std::max(L.mx[b], c.mx[ci]);
          }
        }
      }
    }
    p.levels.push_back(std::move(L));
  }
  return p;
}

// The stored sample of a block: the float mean, NaN when it has no data.
float blockSample(const Pyramid::Level& L, size_t b) { return L.cnt[b] ? float(L.sum[b] / L.cnt[b]) : gis::kNoData; }

// Whether level j of every field keeps voids void (no block mixes data and no data inside the
// grid) and, when `tolM` is set, reconstructs every cell within tolM.
bool levelFits(const std::vector<Pyramid>& pyr, int j, int wIn, int hIn, std::optional<double> tolM) {
  if (j == 0) return true;
  for (const auto& p : pyr) {
    const auto& L = p.levels[size_t(j - 1)];
    for (int by = 0; by < L.n; ++by) {
      for (int bx = 0; bx < L.n; ++bx) {
        const size_t b = size_t(by) * size_t(L.n) + size_t(bx);
        if (!L.cnt[b]) continue;
        if (L.cnt[b] != cellsInGrid(bx, by, 1 << j, wIn, hIn)) return false;
        if (tolM) {
          const double m = blockSample(L, b);
          if (std::max(double(L.mx[b]) - m, m - double(L.mn[b])) > *tolM) return false;
        }
      }
    }
  }
  return true;
}

}  // namespace

Fit fitTile(const std::vector<Grid<float>>& full, int wIn, int hIn, const TileMetricParams& metric,
            const std::vector<float>& evalRange, const TileRecord* keep) {
  const int minExp = metric.minExp, maxExp = metric.maxExp, footprint = 1 << maxExp;
  Fit f;
  const size_t n = full.size();
  f.maxErr.assign(n, 0.0f);
  f.rmsErr.assign(n, 0.0f);
  fieldRanges(full, wIn, hIn, f.lo, f.hi, &f.valid);
  if (f.empty()) return f;
  const int top = maxExp - minExp;  // coarsest level considered
  std::vector<Pyramid> pyr;
  for (size_t k = 0; k < n; ++k) pyr.push_back(buildPyramid(full[k], wIn, hIn, top));
  int j = 0;
  if (metric.kind == TileMetric::MaxError) {
    for (j = top; j > 0 && !levelFits(pyr, j, wIn, hIn, metric.maxErrorM); --j) {
    }
  } else {
    std::vector<float> range(n);
    for (size_t k = 0; k < n; ++k) range[k] = keep ? keep->maxV[k] - keep->minV[k] : f.hi[k] - f.lo[k];
    j = maxExp - chooseTileExp(range, evalRange, minExp, maxExp);
    while (j > 0 && !levelFits(pyr, j, wIn, hIn, std::nullopt)) --j;
  }
  f.exp = maxExp - j;
  for (size_t k = 0; k < n; ++k) {
    if (j == 0) {
      Grid<float> g(footprint, footprint, gis::kNoData);
      for (int y = 0; y < hIn; ++y) std::copy_n(&full[k].data[full[k].index(0, y)], wIn, &g.data[g.index(0, y)]);
      f.samples.push_back(std::move(g));
      continue;
    }
    const auto& L = pyr[k].levels[size_t(j - 1)];
    Grid<float> g(L.n, L.n, gis::kNoData);
    double maxE = 0;
    for (size_t b = 0; b < g.data.size(); ++b) {
      g.data[b] = blockSample(L, b);
      if (L.cnt[b]) maxE = std::max({maxE, double(L.mx[b]) - g.data[b], double(g.data[b]) - L.mn[b]});
    }
    double sumSq = 0;
    for (int y = 0; y < hIn; ++y) {
      for (int x = 0; x < wIn; ++x) {
        const float v = full[k].at(x, y);
        if (std::isnan(v)) continue;
        const double e = double(v) - double(g.at(x >> j, y >> j));
        sumSq += e * e;
      }
    }
    f.maxErr[k] = float(maxE);
    f.rmsErr[k] = float(f.valid[k] ? std::sqrt(sumSq / double(f.valid[k])) : 0.0);
    f.samples.push_back(std::move(g));
  }
  if (keep) f.lo = keep->minV, f.hi = keep->maxV;
  return f;
}

}  // namespace detail

}  // namespace strata::terrain
