// A raster grid as the compute kernels see it. Mirrors strata::test::GridParams
// (tests/gl/grid_params.hpp); tests/gl checks that the two agree.
struct GridParams {
  ivec2 size;       // cells (x, y)
  vec2 cellSizeM;   // cell size in metres (x, y)
  float datumM;     // elevations are stored relative to this datum (m)
  float noData;     // value marking no data
  uint flags;       // bit 0: has no data
  uint pad0;
  vec4 sun;         // xyz: unit vector towards the sun (x east, y north, z up); w: vertical exaggeration
};

bool inside(GridParams g, ivec2 p) { return all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, g.size)); }
int cellIndex(GridParams g, ivec2 p) { return p.y * g.size.x + p.x; }
