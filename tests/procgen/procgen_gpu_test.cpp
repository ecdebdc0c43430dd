// The GPU transform and the script generator on a real GL context (llvmpipe without a GPU).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <fstream>
#include <random>

#include <strata/procgen/generator.hpp>
#include <strata/procgen/script_file.hpp>
#include <strata/procgen/shader_slots.hpp>
#include <strata/procgen/wavelet.hpp>
#include <strata/procgen/wavelet_gpu.hpp>

#include "gl_fixture.hpp"
#include "procgen_test_support.hpp"
#include "strata_test.hpp"

namespace strata::procgen {
namespace {

using gis::Grid;
using procgen::Band;
using procgen::PyramidShape;
using test::GlTest;
namespace cpu = procgen;

float maxAbsDiff(const Grid<float>& a, const Grid<float>& b) {
  EXPECT_EQ(a.size(), b.size());
  float worst = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::abs(a.data[i] - b.data[i]));
  return worst;
}

std::string examplePath(const std::string& name) { return std::string(STRATA_SOURCE_DIR) + "/docs/examples/" + name; }

// Runs layer `layer` of an example at w x h with the example's DEMs read from disk.
Result<Grid<float>> runExample(const std::string& name, int w, int h, uint32_t seed, size_t layer = 0) {
  STRATA_TRY(auto file, loadScriptFile(examplePath(name)));
  GenerateOptions o;
  o.width = w;
  o.height = h;
  o.seed = seed;
  o.levels = file.levels;
  o.wavelet = file.wavelet;
  for (const auto& p : file.demPaths) o.dems.push_back(test::readDemForTest(p));
  o.matchDem = file.layers[layer].matchDem;
  o.matchCoarse = file.layers[layer].matchCoarse;
  return generate(file.layers[layer].script, o);
}

// The DEM as generate() sees it: no data filled, resampled to w x h.
Grid<float> preparedDem(const std::string& relative, int w, int h) {
  auto filled = cpu::fillNoData(test::readDemForTest(test::dataPath(relative)), relative);
  STRATA_CHECK(filled.ok()) << filled.message();
  return cpu::resampleBilinear(*filled, w, h);
}

double stddev(const std::vector<float>& v) {
  double m = 0, s = 0;
  for (float x : v) m += x;
  m /= double(v.size());
  for (float x : v) s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size()));
}

double correlation(const std::vector<float>& a, const std::vector<float>& b) {
  double ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= double(a.size());
  mb /= double(b.size());
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

TEST_F(GlTest, GpuTransformEqualsCpuReferenceOnGrandCanyon) {
  const auto dem = test::readDemForTest(test::dataPath("grand_canyon/grand_canyon_512.tif"));
  const int levels = cpu::maxLevels(dem.width, dem.height);
  auto wavelet = WaveletGpu::create();
  ASSERT_TRUE(wavelet) << wavelet.message();
  auto tex = uploadGrid(dem);
  wavelet->forward(tex, levels);
  const auto gpuCoeffs = downloadGrid(tex);
  const auto cpuCoeffs = cpu::forwardTransform(dem, levels);
  const float coeffErr = maxAbsDiff(gpuCoeffs, cpuCoeffs);
  // Same formulas in the same order with `precise` (no FMA): on llvmpipe the bits agree; a
  // driver may still round a division or conversion differently, so allow 1 mm on values of
  // up to ~3000 m (a wrong index or weight shows up as metres).
  EXPECT_LT(coeffErr, 1e-3f) << "max |GPU - CPU| coefficient " << coeffErr;
  wavelet->inverse(tex, levels);
  const float roundTrip = maxAbsDiff(downloadGrid(tex), dem);
  // As the CPU round trip (measured 1.2 mm there): rounding of 9 levels at 2.4e-4 m per ulp.
  EXPECT_LT(roundTrip, 4e-3f) << "max |inverse(forward(dem)) - dem| on the GPU " << roundTrip;
  std::printf("GPU vs CPU coefficients: %.3g m; GPU round trip: %.3g m\n", double(coeffErr), double(roundTrip));
}

TEST_F(GlTest, GpuCdf97EqualsCpuReferenceOnGrandCanyon) {
  const auto dem = test::readDemForTest(test::dataPath("grand_canyon/grand_canyon_512.tif"));
  const int levels = cpu::maxLevels(dem.width, dem.height);
  auto wavelet = WaveletGpu::create();
  ASSERT_TRUE(wavelet) << wavelet.message();
  auto tex = uploadGrid(dem);
  wavelet->forward(tex, levels, cpu::Wavelet::Cdf97);
  const float coeffErr = maxAbsDiff(downloadGrid(tex), cpu::forwardTransform(dem, levels, cpu::Wavelet::Cdf97));
  // The GPU recomputes each lifting step per output with the same expressions and float
  // constants as the CPU's step-by-step loops (`precise`: no FMA): equal bits on llvmpipe
  // (measured 0); 1 cm allows for another driver's rounding while a slip costs metres.
  EXPECT_LT(coeffErr, 1e-2f) << "max |GPU - CPU| coefficient " << coeffErr;
  wavelet->inverse(tex, levels, cpu::Wavelet::Cdf97);
  const float roundTrip = maxAbsDiff(downloadGrid(tex), dem);
  EXPECT_LT(roundTrip, 2e-2f) << "as the CPU round trip (Wavelet97.GrandCanyonRoundTrip, measured 7.1 mm)";
  std::printf("CDF 9/7 GPU vs CPU coefficients: %.3g m; GPU round trip: %.3g m\n", double(coeffErr), double(roundTrip));
}

TEST_F(GlTest, GpuTransformOfOddSizesMatchesCpu) {
  Grid<float> g(301, 187);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-50, 50);
  for (auto& v : g.data) v = u(rng);
  auto wavelet = WaveletGpu::create();
  ASSERT_TRUE(wavelet) << wavelet.message();
  for (auto kind : {cpu::Wavelet::Cdf53, cpu::Wavelet::Cdf97}) {
    for (int levels : {1, 3, cpu::maxLevels(g.width, g.height)}) {
      SCOPED_TRACE(std::to_string(levels) + " levels, wavelet " + std::to_string(int(kind)));
      auto tex = uploadGrid(g);
      wavelet->forward(tex, levels, kind);
      // Values up to 50 (ulp 3.8e-6) and coefficients of a few times that: 2e-4 is ~50 ulps.
      EXPECT_LT(maxAbsDiff(downloadGrid(tex), cpu::forwardTransform(g, levels, kind)), 2e-4f);
      wavelet->inverse(tex, levels, kind);
      EXPECT_LT(maxAbsDiff(downloadGrid(tex), g), 2e-4f);
    }
  }
}

TEST_F(GlTest, SyntaxErrorInUserScriptNamesTheUsersFileAndLine) {
  const auto dir = test::tempDir("procgen_syntax");
  const auto path = (dir / "broken.toml").string();
  std::ofstream(path) << "# a script with a typo\n"           // 1
                         "[[layer]]\n"                        // 2
                         "name = \"rock\"\n"                  // 3
                         "glsl = \"\"\"\n"                    // 4
                         "float height(vec2 p) {\n"           // 5
                         "  float a = fbm(p, 4, 0.5, 2.0)\n"  // 6: missing ';'
                         "  return a * 10.0;\n"               // 7
                         "}\n"                                // 8
                         "\"\"\"\n";
  auto file = loadScriptFile(path);
  ASSERT_TRUE(file) << file.message();
  GenerateOptions o;
  o.width = o.height = 16;
  auto r = generate(file->layers[0].script, o);
  ASSERT_FALSE(r);
  // Mesa reports the error where the statement ends (the 'return' on line 7); NVIDIA at 6 or 7.
  const bool names =
      r.message().find("broken.toml:7") != std::string::npos || r.message().find("broken.toml:6") != std::string::npos;
  EXPECT_TRUE(names) << r.message();
  EXPECT_EQ(r.message().find("generate.comp:"), std::string::npos) << "error blamed on the template:\n" << r.message();
  // An undefined name is reported on its own line.
  std::ofstream(path) << "[[layer]]\nname = \"rock\"\nglsl = \"\"\"\nfloat height(vec2 p) {\n\n"
                         "  return undefinedThing(p);\n}\n\"\"\"\n";
  auto file2 = loadScriptFile(path);
  ASSERT_TRUE(file2) << file2.message();
  auto r2 = generate(file2->layers[0].script, o);
  ASSERT_FALSE(r2);
  EXPECT_NE(r2.message().find("broken.toml:6"), std::string::npos) << r2.message();
}

TEST_F(GlTest, TemplateAndTransformShadersCompileOnTheirOwn) {
  // Every embedded shader must compile by itself, given procgen's binding slots (the generation
  // template falls back to a flat height() when no script is spliced in).
  for (const char* name :
       {"procgen/shaders/generate.comp", "procgen/shaders/dwt53.comp", "procgen/shaders/dwt97.comp"}) {
    auto p = gl::Program::compute(name, gl::definesFor(slots::kAll));
    EXPECT_TRUE(p) << p.message();
  }
}

TEST_F(GlTest, ShadersUseTheSlotsDeclaredInCpp) {
  // The template with a script that reads both DEMs, so that their images are active too.
  auto spliced =
      spliceScript({"dems.toml", "float level(vec2 p, int lvl) { return dem0Level(p, lvl) + dem1Level(p, lvl); }\n", 1},
                   ScriptForm::Level);
  ASSERT_TRUE(spliced) << spliced.message();
  test::expectProgramsMatchSlots("procgen/shaders/", slots::kAll,
                                 {{{"procgen/shaders/dwt53.comp"}},
                                  {{"procgen/shaders/dwt97.comp"}},
                                  {{"procgen/shaders/generate.comp"}},
                                  {{}, *spliced}});
}

TEST_F(GlTest, LevelFormRefusesMoreLevelsThanTheSizeAllows) {
  // 20 x 12: regions 20x12, 10x6, 5x3, 3x2 -> 4 levels at most.
  GenerateOptions o;
  o.width = 20;
  o.height = 12;
  o.levels = 5;
  const UserScript script{"deep.toml", "float level(vec2 p, int lvl) { return whiteCoeff(p, lvl); }\n", 3};
  auto r = generate(script, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.message().find("deep.toml"), std::string::npos) << r.message();
  EXPECT_NE(r.message().find("1..4"), std::string::npos) << r.message();
  o.levels = 4;
  auto ok = generate(script, o);
  EXPECT_TRUE(ok) << ok.message();
}

TEST_F(GlTest, SameSeedGivesTheSameBytes) {
  for (const char* name : {"fbm_waves_mountain.toml", "dem_coarse_fbm_detail.toml"}) {
    SCOPED_TRACE(name);
    auto a = runExample(name, 96, 80, 7);
    auto b = runExample(name, 96, 80, 7);
    auto c = runExample(name, 96, 80, 8);
    ASSERT_TRUE(a && b && c) << (a ? b ? c.message() : b.message() : a.message());
    EXPECT_EQ(std::memcmp(a->data.data(), b->data.data(), a->size() * sizeof(float)), 0);
    EXPECT_GT(maxAbsDiff(*a, *c), 1.0f) << "another seed must give other terrain";
  }
}

// Radially averaged periodogram of a Hann-windowed field; returns the fitted log-log slope over
// radial wavenumbers [kLo, kHi] (cycles per field).
double spectralSlope(const Grid<float>& f, int kLo, int kHi) {
  const int n = f.width;
  STRATA_CHECK(f.height == n) << "square fields only";
  double mean = 0;
  for (float v : f.data) mean += v;
  mean /= double(f.size());
  std::vector<std::complex<double>> a(static_cast<size_t>(n) * static_cast<size_t>(n)), tmp(static_cast<size_t>(n));
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double wx = 0.5 - 0.5 * std::cos(2 * M_PI * x / n), wy = 0.5 - 0.5 * std::cos(2 * M_PI * y / n);
      a[size_t(y * n + x)] = (f.at(x, y) - mean) * wx * wy;
    }
  }
  std::vector<std::complex<double>> tw(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) tw[size_t(k)] = std::polar(1.0, -2 * M_PI * k / n);
  auto dft = [&](int stride, int offset) {  // in place, plain O(n^2)
    for (int k = 0; k < n; ++k) {
      std::complex<double> s = 0;
      for (int j = 0; j < n; ++j) s += a[size_t(offset + j * stride)] * tw[size_t((k * j) % n)];
      tmp[size_t(k)] = s;
    }
    for (int k = 0; k < n; ++k) a[size_t(offset + k * stride)] = tmp[size_t(k)];
  };
  for (int y = 0; y < n; ++y) dft(1, y * n);
  for (int x = 0; x < n; ++x) dft(n, x);
  std::vector<double> power(static_cast<size_t>(n), 0.0), count(static_cast<size_t>(n), 0.0);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const int kx = x <= n / 2 ? x : x - n, ky = y <= n / 2 ? y : y - n;
      const int k = int(std::lround(std::sqrt(double(kx * kx + ky * ky))));
      if (k < n) {
        power[size_t(k)] += std::norm(a[size_t(y * n + x)]);
        count[size_t(k)] += 1;
      }
    }
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
  for (int k = kLo; k <= kHi; ++k) {
    const double lx = std::log(double(k)), ly = std::log(power[size_t(k)] / count[size_t(k)]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    m += 1;
  }
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

TEST_F(GlTest, FbmPowerSpectrumFollowsItsAmplitudes) {
  // fbm(p/32, 8, g, 2): octave i has frequency 8 * 2^i cycles per 256 cells and amplitude g^i,
  // so the 2D radially averaged power density goes as k^(2 log2 g - 2) (energy g^(2i) spread
  // over an annulus of area ~ k^2): -4 for g = 0.5, -3.03 for g = 0.7. Fit between the second
  // octave and half Nyquist (16..64), away from the first octave's roll-on and the last ones
  // cut by the grid.
  const auto outDir = test::outputDir("procgen");
  for (double gain : {0.5, 0.7}) {
    char glsl[160];
    std::snprintf(glsl, sizeof glsl, "float height(vec2 p) { return 100.0 * fbm(p / 32.0, 8, %.3f, 2.0); }\n", gain);
    GenerateOptions o;
    o.width = o.height = 256;
    o.seed = 3;
    auto field = generate({"fbm.glsl", glsl, 1}, o);
    ASSERT_TRUE(field) << field.message();
    const double slope = spectralSlope(*field, 16, 64);
    const double expected = 2.0 * std::log2(gain) - 2.0;
    // One 256^2 realisation: the periodogram's scatter per radial bin (~1/sqrt(#cells in the
    // annulus)) and the gradient noise's own band shape ripple the log-log line; 0.35 is about
    // 10% of the exponent and still separates g = 0.5 from 0.7 (0.97 apart).
    EXPECT_NEAR(slope, expected, 0.35) << "gain " << gain;
    std::printf("fbm gain %.2f: fitted spectral exponent %.3f, expected %.3f\n", gain, slope, expected);
    test::writeHillshadePng(*field, 30.0, outDir / ("fbm_gain_" + std::to_string(int(gain * 10)) + ".png"));
  }
}

TEST_F(GlTest, FbmWithExplicitAmplitudesEqualsTheGainForm) {
  // B_i = 0.5^i written out is the gain form term by term (powers of two: exact products),
  // so the two fields must agree to the bit; a third octave set to 0 must change the field.
  const char* gain = "float height(vec2 p) { return 100.0 * fbm(p / 16.0, 5, 0.5, 2.0); }\n";
  const char* amps =
      "float height(vec2 p) {\n"
      "  float b[16] = float[16](1.0, 0.5, 0.25, 0.125, 0.0625, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.);\n"
      "  return 100.0 * fbmAmps(p / 16.0, 5, b, 2.0);\n"
      "}\n";
  const char* holed =
      "float height(vec2 p) {\n"
      "  float b[16] = float[16](1.0, 0.5, 0.0, 0.125, 0.0625, 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.);\n"
      "  return 100.0 * fbmAmps(p / 16.0, 5, b, 2.0);\n"
      "}\n";
  GenerateOptions o;
  o.width = 64;
  o.height = 48;
  auto a = generate({"gain.glsl", gain, 1}, o);
  auto b = generate({"amps.glsl", amps, 1}, o);
  auto c = generate({"holed.glsl", holed, 1}, o);
  ASSERT_TRUE(a && b && c) << (a ? b ? c.message() : b.message() : a.message());
  EXPECT_EQ(std::memcmp(a->data.data(), b->data.data(), a->size() * sizeof(float)), 0);
  EXPECT_GT(maxAbsDiff(*a, *c), 1.0f);
}

TEST_F(GlTest, SynthesisLikeDemMatchesEachLevelsHistogram) {
  const int n = 256, levels = 5;
  auto synth = runExample("dem_like.toml", n, n, 5);
  ASSERT_TRUE(synth) << synth.message();
  const auto dem = preparedDem("grand_canyon/grand_canyon_512.tif", n, n);
  const auto demCoeffs = cpu::forwardTransform(dem, levels);
  const auto synthCoeffs = cpu::forwardTransform(*synth, levels);
  const PyramidShape shape{n, n, levels};
  for (int l = 0; l < levels; ++l) {
    for (Band b : {Band::HL, Band::LH, Band::HH}) {
      const auto rect = shape.band(l, b);
      const auto want = cpu::bandValues(demCoeffs, rect), got = cpu::bandValues(synthCoeffs, rect);
      const double ks = cpu::ksDistance(got, want);
      // The matched multiset survives the GPU inverse and the CPU forward transform up to float
      // rounding (~1e-4 m), which can only reorder nearly equal values: KS stays within a few
      // ranks (measured 0.0002 at level 0 with 16384 values, 1/64 at level 4 with 64). Bound:
      // 1% of the CDF or 1.5 ranks, whichever is larger; an unmatched band (gaussian noise
      // against canyon coefficients) is off by more than 0.1.
      const double bound = std::max(0.01, 1.5 / double(want.size()));
      EXPECT_LT(ks, bound) << "level " << l << " band " << int(b);
      // And it is new terrain: the coefficients are not the DEM's in place.
      EXPECT_LT(std::abs(correlation(got, want)), 0.2) << "level " << l << " band " << int(b);
      if (b == Band::HH) std::printf("like-DEM level %d HH: KS %.4f\n", l, ks);
    }
  }
  test::writeHillshadePng(*synth, 217.0, test::outputDir("procgen") / "dem_like.png");
}

TEST_F(GlTest, DemExamplesTakeTheirBandsFromTheRightDem) {
  const int n = 256, levels = 6;
  const PyramidShape shape{n, n, levels};
  // Both examples use CDF 9/7 (smooth synthesis); compare in that wavelet's domain.
  for (const char* name : {"dem_coarse_fbm_detail.toml", "dem_band_blend.toml"}) {
    auto file = loadScriptFile(examplePath(name));
    ASSERT_TRUE(file) << file.message();
    ASSERT_EQ(file->wavelet, cpu::Wavelet::Cdf97) << name;
    ASSERT_EQ(file->levels, levels) << name;
  }
  const auto kind = cpu::Wavelet::Cdf97;
  const auto gc = cpu::forwardTransform(preparedDem("grand_canyon/grand_canyon_512.tif", n, n), levels, kind);
  const auto rainier = cpu::forwardTransform(preparedDem("rainier/mt_rainier_90m.tif", n, n), levels, kind);
  auto detail = runExample("dem_coarse_fbm_detail.toml", n, n, 7);
  auto blend = runExample("dem_band_blend.toml", n, n, 7);
  ASSERT_TRUE(detail && blend) << (detail ? blend.message() : detail.message());
  const auto detailCoeffs = cpu::forwardTransform(*detail, levels, kind);
  const auto blendCoeffs = cpu::forwardTransform(*blend, levels, kind);
  auto bandDiff = [&](const Grid<float>& a, const Grid<float>& b, int l, Band band) {
    const auto x = cpu::bandValues(a, shape.band(l, band)), y = cpu::bandValues(b, shape.band(l, band));
    float worst = 0;
    for (size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::abs(x[i] - y[i]));
    return worst;
  };
  // Copied bands come back through inverse (GPU) + forward (CPU): float rounding of heights up
  // to 4400 m (ulp 4.9e-4) over 6 levels, ~30 ulps for 9/7 (see the round-trip tests); 0.05 m
  // is far below any band's spread (metres).
  const float tol = 0.05f;
  EXPECT_LT(bandDiff(detailCoeffs, gc, levels, Band::LL), tol);
  EXPECT_LT(bandDiff(blendCoeffs, rainier, levels, Band::LL), tol);
  for (int l = 0; l < levels; ++l) {
    for (Band b : {Band::HL, Band::LH, Band::HH}) {
      SCOPED_TRACE("level " + std::to_string(l) + " band " + std::to_string(int(b)));
      EXPECT_LT(bandDiff(blendCoeffs, l >= 2 ? rainier : gc, l, b), tol);
      if (l >= 2) {
        EXPECT_LT(bandDiff(detailCoeffs, gc, l, b), tol);
      } else {
        // Generated detail: 10 * 2^l * (unit-variance white noise); 10% covers the sampling
        // error of the band's standard deviation (>= 4096 coefficients at level 1).
        const double sd = stddev(cpu::bandValues(detailCoeffs, shape.band(l, b)));
        EXPECT_NEAR(sd, 10.0 * (1 << l), 0.1 * 10.0 * (1 << l));
      }
    }
  }
  const auto out = test::outputDir("procgen");
  EXPECT_TRUE(test::writeHillshadePng(*detail, 217.0 * 2, out / "dem_coarse_fbm_detail.png"));
  EXPECT_TRUE(test::writeHillshadePng(*blend, 90.0 * 1201 / n, out / "dem_band_blend.png"));
}

TEST_F(GlTest, MultiLayerExampleGivesEachLayerItsOwnField) {
  const int n = 256;
  auto bedrock = runExample("fbm_waves_mountain.toml", n, n, 7, 0);
  auto sediment = runExample("fbm_waves_mountain.toml", n, n, 7, 1);
  ASSERT_TRUE(bedrock && sediment) << (bedrock ? sediment.message() : bedrock.message());
  // Bedrock: the 600 m gaussian at the centre stands above the fBm (amplitude <= ~240 m).
  const float centre = bedrock->at(n / 2, n / 2), corner = bedrock->at(4, 4);
  EXPECT_GT(centre - corner, 300.0f);
  // Sediment: max(0, 3 + 4 * value noise) metres: within [0, 7].
  const auto [lo, hi] = std::minmax_element(sediment->data.begin(), sediment->data.end());
  EXPECT_GE(*lo, 0.0f);
  EXPECT_LE(*hi, 7.0f);
  EXPECT_GT(*hi - *lo, 2.0f);
  EXPECT_TRUE(test::writeHillshadePng(*bedrock, 30.0, test::outputDir("procgen") / "fbm_waves_mountain.png"));
}

}  // namespace
}  // namespace strata::procgen
