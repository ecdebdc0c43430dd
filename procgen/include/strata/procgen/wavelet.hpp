#pragma once
// CPU reference of the CDF 5/3 (LeGall) and CDF 9/7 biorthogonal wavelet transforms by lifting,
// multi-level,
// separable (rows then columns), with whole-sample symmetric extension so any size >= 2 works,
// and the coefficients in Mallat layout. The GPU transform (procgen/shaders, wavelet_gpu.hpp) computes the same
// formulas; docs/procgen.md has the maths. No GL here.

#include <cstdint>
#include <span>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::procgen {

using gis::Grid;

/// Bands of one level of a 2D transform: LL (coarse approximation, only at the coarsest level),
/// HL (high in x), LH (high in y), HH (high in both).
enum class Band : int { LL = 0, HL = 1, LH = 2, HH = 3 };

/// A rectangle of coefficients in the Mallat layout (cells).
struct BandRect {
  int x0 = 0, y0 = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
};

/// Which biorthogonal wavelet: CDF 5/3 (weights 1/2, 1/4: exact products, piecewise-linear
/// synthesis) or CDF 9/7 (four lifting steps and a scaling: smoother synthesis).
enum class Wavelet : int { Cdf53 = 0, Cdf97 = 1 };

/// Sizes of the low-pass region at each level: sizes[0] = (w, h), sizes[l+1] = ceil(sizes[l] / 2).
struct PyramidShape {
  int width = 0, height = 0, levels = 0;
  /// Width and height of the region transformed at level l (0 = finest), l in [0, levels].
  int regionWidth(int l) const;
  int regionHeight(int l) const;
  /// Where band `b` of detail level l (0 = finest) lies; Band::LL only for l == levels.
  BandRect band(int l, Band b) const;
};

/// The most levels a w x h grid supports: every transformed region must be at least 2 x 2.
int maxLevels(int width, int height);

/// Checks 1 <= levels <= maxLevels(w, h); the message names the sizes.
Status validateLevels(int width, int height, int levels);

/// 1D forward CDF 5/3 lifting of n >= 2 samples: out[0, ceil(n/2)) = s, out[ceil(n/2), n) = d.
///   d[i] = x[2i+1] - (x[2i] + x[2i+2]) / 2,   s[i] = x[2i] + (d[i-1] + d[i]) / 4,
/// with x mirrored about its end samples (x[n] = x[n-2]) and d clamped (d[-1] = d[0]).
void forward53(std::span<const float> x, std::span<float> out);
/// Inverse of forward53 (same layout), exact up to float rounding.
void inverse53(std::span<const float> coeffs, std::span<float> x);

/// 1D forward CDF 9/7 lifting (same layout and extension as forward53), with
///   d1 = x_odd + a (x_even + x_even'), s1 = x_even + b (d1' + d1), d2 = d1 + c (s1 + s1'),
///   s2 = s1 + e (d2' + d2), s = s2 / K, d = d2 K   (a..e, K: Daubechies-Sweldens 1998),
/// so that s has DC gain 1.
void forward97(std::span<const float> x, std::span<float> out);
/// Inverse of forward97, exact up to float rounding.
void inverse97(std::span<const float> coeffs, std::span<float> x);

/// Multi-level 2D forward transform (Mallat layout, same size as the input). levels must pass
/// validateLevels.
Grid<float> forwardTransform(const Grid<float>& heights, int levels, Wavelet wavelet = Wavelet::Cdf53);
/// Inverse of forwardTransform.
Grid<float> inverseTransform(const Grid<float>& coeffs, int levels, Wavelet wavelet = Wavelet::Cdf53);

/// Replaces `values` by the values of `reference` at the same ranks (quantile mapping; the
/// reference's empirical quantile function is interpolated linearly when the sizes differ), so
/// that the result has the reference's histogram. Deterministic: ties keep their input order.
void matchHistogram(std::span<float> values, std::span<const float> reference);

/// Histogram matching of each detail band (and the coarse LL band when `includeCoarse`) of a
/// coefficient pyramid to the same band of a reference pyramid of the same shape.
void matchLevels(Grid<float>& coeffs, const Grid<float>& reference, int levels, bool includeCoarse);

/// Copies of the coefficients of one band.
std::vector<float> bandValues(const Grid<float>& coeffs, const BandRect& rect);

/// Two-sample Kolmogorov-Smirnov distance: the largest gap between the empirical CDFs (0..1).
double ksDistance(std::span<const float> a, std::span<const float> b);

/// Bilinear resampling to w x h, corner-aligned (the corner cells map onto the corner cells).
Grid<float> resampleBilinear(const Grid<float>& src, int width, int height);

/// Fills NaN (no data) from the edges of each void inwards, each cell taking the mean of its
/// valid 4-neighbours; fails when no cell is valid.
Result<Grid<float>> fillNoData(Grid<float> grid, const std::string& what);

}  // namespace strata::procgen
