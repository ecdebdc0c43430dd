// CPU reference of the CDF 5/3 lifting transform (docs/procgen.md, "Transform").
#include <strata/procgen/wavelet.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace strata::procgen {

int PyramidShape::regionWidth(int l) const {
  int w = width;
  for (int i = 0; i < l; ++i) w = (w + 1) / 2;
  return w;
}

int PyramidShape::regionHeight(int l) const {
  int h = height;
  for (int i = 0; i < l; ++i) h = (h + 1) / 2;
  return h;
}

BandRect PyramidShape::band(int l, Band b) const {
  STRATA_CHECK(l >= 0 && l <= levels) << "level " << l << " of " << levels;
  const int w = regionWidth(l), h = regionHeight(l);
  const int ws = (w + 1) / 2, hs = (h + 1) / 2;
  switch (b) {
    case Band::LL: STRATA_CHECK(l == levels) << "LL exists only at the coarsest level"; return {0, 0, w, h};
    case Band::HL: return {ws, 0, w - ws, hs};
    case Band::LH: return {0, hs, ws, h - hs};
    case Band::HH: return {ws, hs, w - ws, h - hs};
  }
  return {};
}

int maxLevels(int width, int height) {
  int levels = 0;
  while (width >= 2 && height >= 2) {
    ++levels;
    width = (width + 1) / 2;
    height = (height + 1) / 2;
  }
  return levels;
}

Status validateLevels(int width, int height, int levels) {
  const int most = maxLevels(width, height);
  if (levels < 1 || levels > most) {
    return fail("wavelet: " + std::to_string(levels) + " levels asked for a " + std::to_string(width) + "x" +
                std::to_string(height) + " grid (1.." + std::to_string(most) + " possible)");
  }
  return {};
}

void forward53(std::span<const float> x, std::span<float> out) {
  const int n = int(x.size());
  STRATA_CHECK(n >= 2 && out.size() == x.size()) << "forward53 of " << n << " samples";
  const int ns = (n + 1) / 2, nd = n / 2;
  auto xm = [&](int j) { return x[size_t(j >= n ? 2 * n - 2 - j : j)]; };
  auto d = [&](int i) {
    i = std::clamp(i, 0, nd - 1);
    return xm(2 * i + 1) - 0.5f * (xm(2 * i) + xm(2 * i + 2));
  };
  for (int i = 0; i < nd; ++i) out[size_t(ns + i)] = d(i);
  for (int i = 0; i < ns; ++i) out[size_t(i)] = xm(2 * i) + 0.25f * (d(i - 1) + d(i));
}

void inverse53(std::span<const float> c, std::span<float> x) {
  const int n = int(c.size());
  STRATA_CHECK(n >= 2 && x.size() == c.size()) << "inverse53 of " << n << " samples";
  const int ns = (n + 1) / 2, nd = n / 2;
  auto d = [&](int i) { return c[size_t(ns + std::clamp(i, 0, nd - 1))]; };
  // Even samples first (they only need s and d), then odd ones from their even neighbours.
  auto even = [&](int i) { return c[size_t(i)] - 0.25f * (d(i - 1) + d(i)); };
  for (int i = 0; i < ns; ++i) x[size_t(2 * i)] = even(i);
  for (int i = 0; i < nd; ++i) {
    const int right = 2 * i + 2 < n ? i + 1 : i;  // x[n] mirrors to x[n-2]
    x[size_t(2 * i + 1)] = d(i) + 0.5f * (even(i) + even(right));
  }
}

namespace {

// CDF 9/7 lifting constants (Daubechies & Sweldens 1998); the same decimal literals as
// procgen/shaders/dwt97.comp, so both round them to the same floats.
constexpr float kAlpha = -1.586134342059924f;
constexpr float kBeta = -0.052980118572961f;
constexpr float kGamma = 0.882911075530934f;
constexpr float kDelta = 0.443506852043971f;
constexpr float kK = 1.230174104914001f;
constexpr float kInvK = 0.8128930661159609f;

}  // namespace

void forward97(std::span<const float> x, std::span<float> out) {
  const int n = int(x.size());
  STRATA_CHECK(n >= 2 && out.size() == x.size()) << "forward97 of " << n << " samples";
  const int ns = (n + 1) / 2, nd = n / 2;
  auto cs = [&](int k) { return size_t(std::clamp(k, 0, ns - 1)); };
  auto cd = [&](int i) { return size_t(std::clamp(i, 0, nd - 1)); };
  std::vector<float> s(static_cast<size_t>(ns)), d(static_cast<size_t>(nd));
  for (int i = 0; i < nd; ++i) d[size_t(i)] = x[size_t(2 * i + 1)] + kAlpha * (x[2 * cs(i)] + x[2 * cs(i + 1)]);
  for (int k = 0; k < ns; ++k) s[size_t(k)] = x[2 * size_t(k)] + kBeta * (d[cd(k - 1)] + d[cd(k)]);
  for (int i = 0; i < nd; ++i) d[size_t(i)] = d[size_t(i)] + kGamma * (s[size_t(i)] + s[cs(i + 1)]);
  for (int k = 0; k < ns; ++k) s[size_t(k)] = s[size_t(k)] + kDelta * (d[cd(k - 1)] + d[cd(k)]);
  for (int k = 0; k < ns; ++k) out[size_t(k)] = s[size_t(k)] * kInvK;
  for (int i = 0; i < nd; ++i) out[size_t(ns + i)] = d[size_t(i)] * kK;
}

void inverse97(std::span<const float> c, std::span<float> x) {
  const int n = int(c.size());
  STRATA_CHECK(n >= 2 && x.size() == c.size()) << "inverse97 of " << n << " samples";
  const int ns = (n + 1) / 2, nd = n / 2;
  auto cs = [&](int k) { return size_t(std::clamp(k, 0, ns - 1)); };
  auto cd = [&](int i) { return size_t(std::clamp(i, 0, nd - 1)); };
  std::vector<float> s(static_cast<size_t>(ns)), d(static_cast<size_t>(nd));
  for (int k = 0; k < ns; ++k) s[size_t(k)] = c[size_t(k)] * kK;
  for (int i = 0; i < nd; ++i) d[size_t(i)] = c[size_t(ns + i)] * kInvK;
  for (int k = 0; k < ns; ++k) s[size_t(k)] = s[size_t(k)] - kDelta * (d[cd(k - 1)] + d[cd(k)]);
  for (int i = 0; i < nd; ++i) d[size_t(i)] = d[size_t(i)] - kGamma * (s[size_t(i)] + s[cs(i + 1)]);
  for (int k = 0; k < ns; ++k) x[2 * size_t(k)] = s[size_t(k)] - kBeta * (d[cd(k - 1)] + d[cd(k)]);
  for (int i = 0; i < nd; ++i) {
    x[size_t(2 * i + 1)] = d[size_t(i)] - kAlpha * (x[2 * cs(i)] + x[2 * cs(i + 1)]);
  }
}

namespace {

// Applies a 1D transform to the rows (axis 0) or columns (axis 1) of the w x h top-left region.
template <class F>
void apply(Grid<float>& g, int w, int h, int axis, F&& f) {
  const int n = axis == 0 ? w : h, count = axis == 0 ? h : w;
  std::vector<float> in(static_cast<size_t>(n)), out(static_cast<size_t>(n));
  for (int k = 0; k < count; ++k) {
    for (int i = 0; i < n; ++i) in[size_t(i)] = axis == 0 ? g.at(i, k) : g.at(k, i);
    f(std::span<const float>(in), std::span<float>(out));
    for (int i = 0; i < n; ++i) (axis == 0 ? g.at(i, k) : g.at(k, i)) = out[size_t(i)];
  }
}

}  // namespace

Grid<float> forwardTransform(const Grid<float>& heights, int levels, Wavelet wavelet) {
  const auto f = wavelet == Wavelet::Cdf97 ? forward97 : forward53;
  STRATA_CHECK(validateLevels(heights.width, heights.height, levels).ok()) << "bad level count " << levels;
  Grid<float> g = heights;
  const PyramidShape shape{heights.width, heights.height, levels};
  for (int l = 0; l < levels; ++l) {
    const int w = shape.regionWidth(l), h = shape.regionHeight(l);
    apply(g, w, h, 0, f);
    apply(g, w, h, 1, f);
  }
  return g;
}

Grid<float> inverseTransform(const Grid<float>& coeffs, int levels, Wavelet wavelet) {
  const auto f = wavelet == Wavelet::Cdf97 ? inverse97 : inverse53;
  STRATA_CHECK(validateLevels(coeffs.width, coeffs.height, levels).ok()) << "bad level count " << levels;
  Grid<float> g = coeffs;
  const PyramidShape shape{coeffs.width, coeffs.height, levels};
  for (int l = levels - 1; l >= 0; --l) {
    const int w = shape.regionWidth(l), h = shape.regionHeight(l);
    apply(g, w, h, 1, f);
    apply(g, w, h, 0, f);
  }
  return g;
}

void matchHistogram(std::span<float> values, std::span<const float> reference) {
  const size_t n = values.size(), m = reference.size();
  STRATA_CHECK(m > 0 || n == 0) << "histogram matching against an empty reference";
  if (n == 0) return;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return values[a] < values[b]; });
  std::vector<float> ref(reference.begin(), reference.end());
  std::sort(ref.begin(), ref.end());
  for (size_t r = 0; r < n; ++r) {
    float v;
    if (n == m) {
      v = ref[r];
    } else {
      const double q = n == 1 ? 0.5 * double(m - 1) : double(r) * double(m - 1) / double(n - 1);
      const size_t i = std::min(size_t(q), m - 1), j = std::min(i + 1, m - 1);
      v = float(double(ref[i]) + (q - double(i)) * (double(ref[j]) - double(ref[i])));
    }
    values[order[r]] = v;
  }
}

std::vector<float> bandValues(const Grid<float>& coeffs, const BandRect& rect) {
  std::vector<float> out;
  out.reserve(size_t(std::max(0, rect.width * rect.height)));
  for (int y = rect.y0; y < rect.y0 + rect.height; ++y) {
    for (int x = rect.x0; x < rect.x0 + rect.width; ++x) out.push_back(coeffs.at(x, y));
  }
  return out;
}

void matchLevels(Grid<float>& coeffs, const Grid<float>& reference, int levels, bool includeCoarse) {
  STRATA_CHECK(coeffs.width == reference.width && coeffs.height == reference.height)
      << "pyramids of different sizes: " << coeffs.width << "x" << coeffs.height << " and " << reference.width << "x"
      << reference.height;
  const PyramidShape shape{coeffs.width, coeffs.height, levels};
  auto matchRect = [&](const BandRect& rect) {
    if (rect.empty()) return;
    auto values = bandValues(coeffs, rect);
    matchHistogram(values, bandValues(reference, rect));
    size_t k = 0;
    for (int y = rect.y0; y < rect.y0 + rect.height; ++y) {
      for (int x = rect.x0; x < rect.x0 + rect.width; ++x) coeffs.at(x, y) = values[k++];
    }
  };
  for (int l = 0; l < levels; ++l) {
    for (Band b : {Band::HL, Band::LH, Band::HH}) matchRect(shape.band(l, b));
  }
  if (includeCoarse) matchRect(shape.band(levels, Band::LL));
}

double ksDistance(std::span<const float> a, std::span<const float> b) {
  if (a.empty() || b.empty()) return a.empty() && b.empty() ? 0.0 : 1.0;
  std::vector<float> x(a.begin(), a.end()), y(b.begin(), b.end());
  std::sort(x.begin(), x.end());
  std::sort(y.begin(), y.end());
  size_t i = 0, j = 0;
  double worst = 0;
  while (i < x.size() && j < y.size()) {
    const float v = std::min(x[i], y[j]);
    while (i < x.size() && x[i] == v) ++i;
    while (j < y.size() && y[j] == v) ++j;
    worst = std::max(worst, std::abs(double(i) / double(x.size()) - double(j) / double(y.size())));
  }
  return worst;
}

Grid<float> resampleBilinear(const Grid<float>& src, int width, int height) {
  STRATA_CHECK(src.width >= 1 && src.height >= 1 && width >= 1 && height >= 1)
      << "resample to " << width << "x" << height;
  Grid<float> out(width, height);
  const double sx = width > 1 ? double(src.width - 1) / double(width - 1) : 0.0;
  const double sy = height > 1 ? double(src.height - 1) / double(height - 1) : 0.0;
  for (int y = 0; y < height; ++y) {
    const double fy = y * sy;
    const int y0 = std::min(int(fy), src.height - 1), y1 = std::min(y0 + 1, src.height - 1);
    const double ty = fy - y0;
    for (int x = 0; x < width; ++x) {
      const double fx = x * sx;
      const int x0 = std::min(int(fx), src.width - 1), x1 = std::min(x0 + 1, src.width - 1);
      const double tx = fx - x0;
      const double top = src.at(x0, y0) * (1 - tx) + src.at(x1, y0) * tx;
      const double bottom = src.at(x0, y1) * (1 - tx) + src.at(x1, y1) * tx;
      out.at(x, y) = float(top * (1 - ty) + bottom * ty);
    }
  }
  return out;
}

Result<Grid<float>> fillNoData(Grid<float> grid, const std::string& what) {
  // Grow inwards from the edges of each hole: every pass gives the no-data cells that touch
  // valid ones (4-neighbours) the mean of those neighbours, so a void takes the heights around
  // it (a summit void stays high) instead of a global value.
  std::vector<size_t> holes;
  for (size_t i = 0; i < grid.size(); ++i) {
    if (gis::isNoData(grid.data[i])) holes.push_back(i);
  }
  if (holes.size() == grid.size()) return fail(what + ": every cell is no data");
  std::vector<std::pair<size_t, float>> filled;
  while (!holes.empty()) {
    filled.clear();
    std::vector<size_t> still;
    for (size_t i : holes) {
      const int x = int(i % size_t(grid.width)), y = int(i / size_t(grid.width));
      double sum = 0;
      int count = 0;
      for (auto [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        if (!grid.contains(x + dx, y + dy)) continue;
        const float v = grid.at(x + dx, y + dy);
        if (!gis::isNoData(v)) {
          sum += v;
          ++count;
        }
      }
      if (count > 0) {
        filled.emplace_back(i, float(sum / count));
      } else {
        still.push_back(i);
      }
    }
    for (auto [i, v] : filled) grid.data[i] = v;
    holes = std::move(still);
  }
  return grid;
}

}  // namespace strata::procgen
