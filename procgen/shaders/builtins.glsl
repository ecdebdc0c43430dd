// Built-ins of user generation scripts (docs/procgen.md, "Built-ins"). Everything is
// deterministic across drivers: integer hashing (no sin-hash), and sin/exp replaced by
// polynomials evaluated with `precise` (no fused multiply-add), so llvmpipe and a GPU give the
// same bits for the same seed.

uniform uint uSeed;    // the run's seed
uniform ivec2 uSize;   // output grid, cells
uniform int uLevels;   // wavelet levels of the pyramid

layout(r32f, binding = SLOT_DEM0) uniform readonly image2D uDem0;  // DEM 0's transform (Mallat layout)
layout(r32f, binding = SLOT_DEM1) uniform readonly image2D uDem1;  // DEM 1's transform

#define SIZE vec2(uSize)
#define LEVELS uLevels
const float PI = 3.14159265358979;

// The band of the coefficient being generated (level form): 0 LL, 1 HL, 2 LH, 3 HH.
int BAND = 0;

// --- hashing: lowbias32 (Chris Wellons), uniform floats from the top 24 bits.
uint hashU(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
uint hashCell(ivec2 c, uint salt) { return hashU(uint(c.x) ^ hashU(uint(c.y) ^ hashU(salt ^ hashU(uSeed)))); }
float toUnit(uint h) { return float(h >> 8) * (1.0 / 16777216.0); }  // [0, 1)

// --- deterministic transcendental functions.
// sin(x): reduce to t in [-0.5, 0.5) turns, then an odd polynomial of sin(2 pi t) on [-0.25, 0.25].
float dsin(float x) {
  precise float t = x * (1.0 / (2.0 * PI));
  t = t - floor(t + 0.5);                         // [-0.5, 0.5)
  if (t > 0.25) t = 0.5 - t;
  else if (t < -0.25) t = -0.5 - t;               // sin(pi - a) = sin(a)
  precise float a = t * (2.0 * PI);
  precise float a2 = a * a;
  // Taylor to a^11: error < 6e-8 on [-pi/2, pi/2].
  precise float r = a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 +
                     a2 * (1.0 / 362880.0 + a2 * (-1.0 / 39916800.0))))));
  return r;
}
float dcos(float x) { return dsin(x + 0.5 * PI); }
// exp(x) for x <= 0 (gaussians): 2^(x log2 e) = 2^n * 2^f, f in [0,1) by a degree-7 polynomial.
float dexpNeg(float x) {
  precise float y = max(x, -80.0) * 1.4426950408889634;
  const float n = floor(y);
  precise float f = (y - n) * 0.6931471805599453;  // e^f, f in [0, ln 2)
  precise float p = 1.0 + f * (1.0 + f * (0.5 + f * (1.0 / 6.0 + f * (1.0 / 24.0 + f * (1.0 / 120.0 +
                    f * (1.0 / 720.0 + f * (1.0 / 5040.0)))))));
  return ldexp(p, int(n));
}

// --- noise, all in [-1, 1] (roughly), period-free, lattice spacing 1.
float fade(float t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }  // quintic

// Value noise: lattice values uniform in [-1, 1], quintic interpolation.
float valueNoise(vec2 p, uint salt) {
  const vec2 i = floor(p);
  const vec2 f = p - i;
  const ivec2 c = ivec2(i);
  precise float v00 = toUnit(hashCell(c, salt)) * 2.0 - 1.0;
  precise float v10 = toUnit(hashCell(c + ivec2(1, 0), salt)) * 2.0 - 1.0;
  precise float v01 = toUnit(hashCell(c + ivec2(0, 1), salt)) * 2.0 - 1.0;
  precise float v11 = toUnit(hashCell(c + ivec2(1, 1), salt)) * 2.0 - 1.0;
  precise float u = fade(f.x), w = fade(f.y);
  precise float a = v00 + u * (v10 - v00), b = v01 + u * (v11 - v01);
  precise float r = a + w * (b - a);
  return r;
}
float valueNoise(vec2 p) { return valueNoise(p, 0u); }

// Gradient (Perlin) noise: one of 8 unit gradients per lattice point, quintic interpolation.
float gradDot(ivec2 c, vec2 d, uint salt) {
  const uint h = hashCell(c, salt) >> 29;  // 0..7
  const float k = 0.70710678;
  const vec2 g = h < 4u ? vec2(h == 0u ? 1.0 : h == 1u ? -1.0 : 0.0, h == 2u ? 1.0 : h == 3u ? -1.0 : 0.0)
                        : vec2((h & 1u) == 0u ? k : -k, (h & 2u) == 0u ? k : -k);
  precise float r = g.x * d.x + g.y * d.y;
  return r;
}
float gradientNoise(vec2 p, uint salt) {
  const vec2 i = floor(p);
  const vec2 f = p - i;
  const ivec2 c = ivec2(i);
  const float g00 = gradDot(c, f, salt);
  const float g10 = gradDot(c + ivec2(1, 0), f - vec2(1, 0), salt);
  const float g01 = gradDot(c + ivec2(0, 1), f - vec2(0, 1), salt);
  const float g11 = gradDot(c + ivec2(1, 1), f - vec2(1, 1), salt);
  precise float u = fade(f.x), w = fade(f.y);
  precise float a = g00 + u * (g10 - g00), b = g01 + u * (g11 - g01);
  precise float r = 1.41421356 * (a + w * (b - a));  // scaled to about [-1, 1]
  return r;
}
float gradientNoise(vec2 p) { return gradientNoise(p, 0u); }

// Fractional Brownian motion: sum over octaves i of B_i * noise(p * lacunarity^i), B_i = gain^i;
// each octave has its own hash salt (decorrelated octaves, no shared lattice origin).
float fbm(vec2 p, int octaves, float gain, float lacunarity) {
  precise float sum = 0.0, amp = 1.0, freq = 1.0;
  for (int i = 0; i < octaves; ++i) {
    sum += amp * gradientNoise(p * freq, uint(i) * 0x9e3779b9u + 1u);
    amp *= gain;
    freq *= lacunarity;
  }
  return sum;
}

// fBm with any per-octave amplitudes: sum over i < octaves (at most 16) of
// amps[i] * noise(p * lacunarity^i), same octave salts as fbm() above.
float fbmAmps(vec2 p, int octaves, float amps[16], float lacunarity) {
  precise float sum = 0.0, freq = 1.0;
  for (int i = 0; i < min(octaves, 16); ++i) {
    sum += amps[i] * gradientNoise(p * freq, uint(i) * 0x9e3779b9u + 1u);
    freq *= lacunarity;
  }
  return sum;
}

// A plane wave: amplitude * sin(2 pi (p . dir) / wavelength + phase), dir normalised by caller.
float wave(vec2 p, vec2 dir, float wavelength, float amplitude, float phase) {
  return amplitude * dsin(2.0 * PI * dot(p, dir) / wavelength + phase);
}
// A gaussian mountain: height * exp(-|p - centre|^2 / (2 radius^2)).
float peak(vec2 p, vec2 centre, float radius, float height) {
  const vec2 d = p - centre;
  return height * dexpNeg(-dot(d, d) / (2.0 * radius * radius));
}

// --- the wavelet pyramid (level form).
// Size of the low-pass region at level l (0 = full grid).
ivec2 regionSize(int l) {
  ivec2 r = uSize;
  for (int i = 0; i < l; ++i) r = (r + 1) / 2;
  return r;
}
// Spacing, in output cells, of the coefficients of level lvl (LEVELS: the coarse LL band).
float levelSpacing(int lvl) { return float(1 << min(lvl + 1, uLevels)); }

// A standard-normal-like coefficient (Irwin-Hall of 4 uniforms: mean 0, variance 1) per
// coefficient of the current band and level: white noise in the wavelet domain.
float whiteCoeff(vec2 p, int lvl) {
  const ivec2 c = ivec2(floor(p / levelSpacing(lvl)));
  const uint salt = uint(lvl * 4 + BAND) * 0x85ebca6bu + 7u;
  precise float s = toUnit(hashCell(c, salt)) + toUnit(hashCell(c, salt + 1u)) +
                    toUnit(hashCell(c, salt + 2u)) + toUnit(hashCell(c, salt + 3u));
  return (s - 2.0) * 1.7320508;
}

// The coefficient of an input DEM's transform in the current band at level lvl and position p
// (output cells); lvl == LEVELS reads the coarse LL band. 0 for a detail level read from the LL.
float demLevelOf(int which, vec2 p, int lvl) {
  lvl = clamp(lvl, 0, uLevels);
  const bool coarse = lvl == uLevels;
  if (!coarse && BAND == 0) return 0.0;
  const ivec2 r = regionSize(lvl);
  const ivec2 h = coarse ? r : (r + 1) / 2;
  const int band = coarse ? 0 : BAND;
  const ivec2 origin = ivec2((band & 1) != 0 ? h.x : 0, (band & 2) != 0 ? h.y : 0);
  const ivec2 extent = ivec2((band & 1) != 0 ? r.x - h.x : h.x, (band & 2) != 0 ? r.y - h.y : h.y);
  const ivec2 c = clamp(ivec2(floor(p / levelSpacing(lvl))), ivec2(0), extent - 1);
  return which == 0 ? imageLoad(uDem0, origin + c).r : imageLoad(uDem1, origin + c).r;
}
float dem0Level(vec2 p, int lvl) { return demLevelOf(0, p, lvl); }
float dem1Level(vec2 p, int lvl) { return demLevelOf(1, p, lvl); }
