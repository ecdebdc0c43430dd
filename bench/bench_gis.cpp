// gis baselines on the shared DEMs: a windowed read against the whole read of the same file,
// per-cell areas on a geographic grid (closed form per row) against a projected one (corners
// through PROJ + ring integral), and a mosaic warp.
//   build/bench/strata_bench_gis [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gis/mosaic.hpp>

namespace {
using namespace strata::gis;

std::string data(const char* relative) { return std::string(STRATA_DATA_DIR) + "/" + relative; }

template <class T>
T orExit(strata::Result<T> r) {
  if (!r) {
    std::fprintf(stderr, "%s\n", r.message().c_str());
    std::exit(1);
  }
  return std::move(r).value();
}

void BM_ReadWhole(benchmark::State& state) {
  const std::string path = data("rainier/mt_rainier_90m.tif");
  for (auto _ : state) benchmark::DoNotOptimize(orExit(readDem(path)));
  state.SetItemsProcessed(state.iterations() * 1201 * 1201);
}
BENCHMARK(BM_ReadWhole)->Unit(benchmark::kMillisecond);

void BM_ReadWindow256(benchmark::State& state) {
  const std::string path = data("rainier/mt_rainier_90m.tif");
  ReadOptions o;
  o.window = CellRect{512, 512, 256, 256};
  for (auto _ : state) benchmark::DoNotOptimize(orExit(readDem(path, o)));
  state.SetItemsProcessed(state.iterations() * 256 * 256);
}
BENCHMARK(BM_ReadWindow256)->Unit(benchmark::kMillisecond);

void BM_CellAreasGeographic(benchmark::State& state) {
  const Georef g = orExit(probeDem(data("mars/mola_megdr_4ppd.vrt"))).georef;
  for (auto _ : state) benchmark::DoNotOptimize(orExit(cellAreasM2(g)));
  state.SetItemsProcessed(state.iterations() * g.width * g.height);
}
BENCHMARK(BM_CellAreasGeographic)->Unit(benchmark::kMillisecond);

void BM_CellAreasProjected(benchmark::State& state) {
  const Georef g = orExit(probeDem(data("moon/LDEM_4.LBL"))).georef;
  for (auto _ : state) benchmark::DoNotOptimize(orExit(cellAreasM2(g)));
  state.SetItemsProcessed(state.iterations() * g.width * g.height);
}
BENCHMARK(BM_CellAreasProjected)->Unit(benchmark::kMillisecond);

void BM_WarpWebMercatorToGeographic512(benchmark::State& state) {
  Georef t;
  t.crsWkt = "EPSG:4326";
  t.geographic = true;
  t.width = t.height = 512;
  t.transform = GeoTransform{{-113.2, 0.35 / 512, 0, 36.31, 0, -0.28 / 512}};
  MosaicInput in;
  in.path = data("grand_canyon/grandcanyon_srtm_3857.tif");
  in.resampling = static_cast<Resampling>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(orExit(warpToGrid(in, t)));
  state.SetItemsProcessed(state.iterations() * 512 * 512);
}
BENCHMARK(BM_WarpWebMercatorToGeographic512)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
