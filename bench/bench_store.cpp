// Tile store benchmark: a plain program printing one JSON object (Google Benchmark's repeated
// timing does not fit a one-shot multi-GiB ingest).
//
//   build/bench/strata_bench_store [--size 32768] [--dir /tmp/strata-bench-store] [--no-gdal]
//   build/bench/strata_bench_store --striped 16384 [--dir DIR]
//   build/bench/strata_bench_store --reads STORE
//
// --reads STORE: cold reads of whole tiles at levels 0, 1 and 2 (the cache cleared before each),
// every full-resolution tile of the store in turn, three rounds: the best round's mean ms per
// tile, and the bytes of the store's tile files.
//
// --striped N: the ingest benchmark. A real-relief N x N striped GeoTIFF (Mount Rainier's
// SRTM tile resampled by gdalwarp -r cubic, float32, DEFLATE, one row a strip) is made in DIR;
// then, one after the other on that file, `strata ingest` with its defaults and
// `gdal_translate -co TILED=YES` + `gdaladdo -r average`, each a child process whose wall time
// and peak RSS (wait4) are reported.
//
// 1. Ingest of a synthetic size x size float32 DEM generated on the fly (the streaming
//    check): seconds, MB/s of input, peak RSS of the process (getrusage) right after it.
// 2. The same DEM written once as a raw float32 file with a GDAL VRT header; then, side by side
//    on that file: our ingest (reading windows with pread) against gdal_translate -co TILED=YES
//    (DEFLATE, float predictor) + gdaladdo -r average (the comparable "tiled pyramid" job).
// 3. Random full-resolution tile reads (cold cache) against GDAL RasterIO of the same windows
//    in the tiled GeoTIFF (GDAL block cache flushed before each read), and a random walk of
//    512 x 512 windows through the store's cache (hit rate, prefetch) against the same walk
//    through GDAL's block cache.
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gdal_priv.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <strata/terrain/ingest.hpp>
#include <strata/terrain/synthetic.hpp>
#include <strata/terrain/tile_store.hpp>

namespace {

namespace fs = std::filesystem;
using namespace strata;
using namespace strata::terrain;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
double peakRssMiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

gis::Georef benchGeoref(int n) {
  gis::Georef g;
  g.epsg = 3857;
  g.crsName = "WGS 84 / Pseudo-Mercator";
  g.transform = {{0.0, 30.0, 0.0, 0.0, 0.0, -30.0}};
  g.width = n;
  g.height = n;
  return g;
}

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "strata_bench_store: %s\n", what.c_str());
  std::exit(1);
}

// A child process started with an argument vector (no shell), its output to `log`: exit status,
// wall seconds and peak resident set (MiB, from wait4).
struct ChildRun {
  int status = -1;
  double seconds = 0, peakRssMiB = 0;
};
ChildRun run(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  ChildRun r;
  pid_t pid = 0;
  const auto t0 = Clock::now();
  const int rc = posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) die(args[0] + ": cannot start: " + std::strerror(rc));
  int status = 0;
  rusage u{};
  wait4(pid, &status, 0, &u);
  r.seconds = since(t0);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.peakRssMiB = double(u.ru_maxrss) / 1024.0;
  if (r.status != 0) die(args[0] + " failed (see " + log.string() + ")");
  return r;
}

// --striped N: strata ingest against gdal_translate + gdaladdo on one real-relief striped GeoTIFF.
int stripedBenchmark(int n, const fs::path& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path log = dir / "tools.log", input = dir / "striped.tif", tiled = dir / "tiled.tif";
  const std::string size = std::to_string(n);
  std::fprintf(stderr, "making %s (%d x %d, striped)\n", input.c_str(), n, n);
  run({"gdalwarp", "-q", "-ts", size, size, "-r", "cubic", "-ot", "Float32", "-co", "COMPRESS=DEFLATE", "-co",
       "PREDICTOR=3", "-co", "TILED=NO", "-co", "BIGTIFF=YES", STRATA_DATA_DIR "/rainier/mt_rainier_90m.tif",
       input.string()},
      log);
  GDALAllRegister();
  auto* probe = static_cast<GDALDataset*>(GDALOpen(input.c_str(), GA_ReadOnly));
  if (!probe) die(input.string() + ": cannot open");
  int bx = 0, by = 0;
  probe->GetRasterBand(1)->GetBlockSize(&bx, &by);
  GDALClose(probe);
  const double inputMB = double(fs::file_size(input)) / 1e6;
  ::sync();
  std::fprintf(stderr, "strata ingest\n");
  const auto ours = run({STRATA_CLI, "ingest", (dir / "store").string(), "--dem", input.string()}, log);
  auto store = TileStore::open(dir / "store", {.budgetBytes = size_t(16) << 20, .prefetch = false});
  if (!store) die(store.message());
  const auto fp = store->footprintStats();
  const auto err = store->errorSummary(0);
  ::sync();
  std::fprintf(stderr, "gdal_translate + gdaladdo\n");
  const auto translate = run({"gdal_translate", "-q", "-co", "TILED=YES", "-co", "COMPRESS=DEFLATE", "-co",
                              "PREDICTOR=3", "-co", "BIGTIFF=YES", input.string(), tiled.string()},
                             log);
  const auto addo = run(
      {"gdaladdo", "-q", "-r", "average", tiled.string(), "2", "4", "8", "16", "32", "64", "128", "256", "512", "1024"},
      log);
  const double gdalSeconds = translate.seconds + addo.seconds;
  const double gdalRss = std::max(translate.peakRssMiB, addo.peakRssMiB);
  std::printf(
      "{\"size\": %d, \"input\": {\"file_mb\": %.1f, \"block\": [%d, %d]},\n"
      " \"strata_ingest\": {\"seconds\": %.1f, \"peak_rss_mib\": %.1f, \"file_mb\": %.1f, \"saved_fraction\": %.4f, "
      "\"max_error_m\": %.4g, \"rms_error_m\": %.4g},\n"
      " \"gdal\": {\"translate_seconds\": %.1f, \"translate_peak_rss_mib\": %.1f, \"gdaladdo_seconds\": %.1f, "
      "\"gdaladdo_peak_rss_mib\": %.1f, \"seconds\": %.1f, \"peak_rss_mib\": %.1f, \"file_mb\": %.1f},\n"
      " \"strata_over_gdal\": {\"time\": %.2f, \"peak_rss\": %.3f}}\n",
      n, inputMB, bx, by, ours.seconds, ours.peakRssMiB, double(fp.fileBytes) / 1e6, fp.savedFraction(), err.maxM,
      err.rmsM, translate.seconds, translate.peakRssMiB, addo.seconds, addo.peakRssMiB, gdalSeconds, gdalRss,
      double(fs::file_size(tiled)) / 1e6, ours.seconds / gdalSeconds, ours.peakRssMiB / gdalRss);
  return 0;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[size_t(p * double(v.size() - 1))];
}

}  // namespace

// Reads every rough (2^10) tile of a store built from the default synthetic scene at full
// resolution and compares it with the generator cell for cell. Returns {tiles, mismatching cells}.
std::pair<int, long> checkRoughTiles(const fs::path& store) {
  auto s = TileStore::open(store, {.budgetBytes = size_t(64) << 20, .prefetch = false});
  if (!s) die(s.message());
  const SyntheticScene scene;
  int tiles = 0;
  long bad = 0;
  for (int ty = 0; ty < s->tilesY(); ++ty) {
    for (int tx = 0; tx < s->tilesX(); ++tx) {
      if (syntheticBlockKind(scene, tx, ty) != SyntheticBlock::Rough) continue;
      if (s->tile(tx, ty).exp != 10) ++bad;
      auto g = s->readWindow(0, {tx * 1024, ty * 1024, 1024, 1024}, 0);
      if (!g) die(g.message());
      for (int y = 0; y < 1024; ++y) {
        for (int x = 0; x < 1024; ++x) bad += g->at(x, y) != syntheticElevation(scene, tx * 1024 + x, ty * 1024 + y);
      }
      ++tiles;
    }
  }
  return {tiles, bad};
}

// --reads STORE (see the top).
int readsBenchmark(const fs::path& path) {
  auto store = TileStore::open(path, {.budgetBytes = size_t(256) << 20, .prefetch = false});
  if (!store) die(store.message());
  const int fp = store->footprint();
  std::vector<std::pair<int, int>> tiles;
  for (int ty = 0; ty < store->tilesY(); ++ty) {
    for (int tx = 0; tx < store->tilesX(); ++tx) {
      if (store->tile(tx, ty).present && store->tile(tx, ty).exp == store->desc().metric.maxExp)
        tiles.push_back({tx, ty});
    }
  }
  if (tiles.empty()) die(path.string() + ": no full-resolution tile");
  std::printf("{\"store\": \"%s\", \"tiles\": %zu", path.c_str(), tiles.size());
  for (int level : {0, 1, 2}) {
    double best = 1e300;
    for (int round = 0; round < 3; ++round) {
      auto t0 = Clock::now();
      for (auto [tx, ty] : tiles) {
        store->clearCache();
        const int side = fp >> level;
        if (!store->readWindow(0, {tx * side, ty * side, side, side}, level)) die("read failed");
      }
      best = std::min(best, since(t0) * 1e3 / double(tiles.size()));
    }
    std::printf(", \"level%d_ms_per_tile\": %.2f", level, best);
  }
  uint64_t bytes = 0;
  for (const auto& e : fs::directory_iterator(path / "tiles")) bytes += e.file_size();
  std::printf(", \"tile_bytes\": %llu}\n", static_cast<unsigned long long>(bytes));
  return 0;
}

int main(int argc, char** argv) {
  int n = 32768;
  fs::path dir = fs::temp_directory_path() / "strata-bench-store";
  bool gdal = true;
  int striped = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--striped" && i + 1 < argc) {
      striped = std::atoi(argv[++i]);
    } else if (a == "--size" && i + 1 < argc) {
      n = std::atoi(argv[++i]);
    } else if (a == "--dir" && i + 1 < argc) {
      dir = argv[++i];
    } else if (a == "--no-gdal") {
      gdal = false;
    } else if (a == "--reads" && i + 1 < argc) {
      return readsBenchmark(argv[++i]);
    } else if (a == "--check" && i + 1 < argc) {
      const auto [tiles, bad] = checkRoughTiles(argv[++i]);
      std::printf("{\"rough_tiles_checked\": %d, \"mismatching_cells\": %ld}\n", tiles, bad);
      return bad ? 1 : 0;
    } else {
      die("unknown argument '" + a +
          "' (use --size N, --dir DIR, --no-gdal, --striped N, --reads STORE, or --check STORE)");
    }
  }
  if (striped) {
    if (striped < 1024 || striped > 65536) die("--striped: 1024..65536");
    return stripedBenchmark(striped, dir);
  }
  if (n < 1024 || n % 1024) die("--size must be a multiple of 1024");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const double inputMB = double(n) * n * 4 / 1e6;
  SyntheticScene scene;  // 1024-cell blocks: 20% rough, 30% ramps, 50% flat
  IngestOptions opts;    // the seed's defaults: tiles of 2^10 cells, resolutions 2^5..2^10
  opts.cache.prefetch = false;

  // 1. Streaming ingest from the generator.
  auto t0 = Clock::now();
  auto gen =
      ingest(dir / "gen.store", benchGeoref(n), {{{"bedrock", LayerKind::Bedrock, ""}, syntheticReader(scene)}}, opts);
  if (!gen) die(gen.message());
  const double genSeconds = since(t0);
  const double genPeakRss = peakRssMiB();
  std::fprintf(stderr, "generated ingest: %.1f s, peak RSS %.0f MiB\n", genSeconds, genPeakRss);
  const auto [roughTiles, mismatches] = checkRoughTiles(dir / "gen.store");
  fs::remove_all(dir / "gen.store");

  std::printf("{\"size\": %d, \"input_mb\": %.1f,\n", n, inputMB);
  std::printf(
      " \"generated_ingest\": {\"seconds\": %.2f, \"mb_per_s\": %.1f, \"peak_rss_mib\": %.1f, "
      "\"saved_fraction\": %.4f, \"saved_fraction_with_mips\": %.4f, \"file_mb\": %.1f, "
      "\"rough_tiles_checked\": %d, \"mismatching_cells\": %ld}",
      genSeconds, inputMB / genSeconds, genPeakRss, gen->footprint.savedFraction(),
      1.0 - double(gen->footprint.storedWithMips) / double(gen->footprint.denseSamples),
      double(gen->footprint.fileBytes) / 1e6, roughTiles, mismatches);
  if (!gdal) {
    std::printf("}\n");
    return 0;
  }

  // 2. The same DEM as a raw file + VRT, ingested by both.
  const fs::path raw = dir / "dem.f32", vrt = dir / "dem.vrt";
  {
    std::FILE* f = std::fopen(raw.c_str(), "wb");
    if (!f) die(raw.string() + ": cannot create");
    std::vector<float> row(size_t(n) * 16);
    for (int y = 0; y < n; y += 16) {
      for (int r = 0; r < 16; ++r) {
        for (int x = 0; x < n; ++x) row[size_t(r) * size_t(n) + size_t(x)] = syntheticElevation(scene, x, y + r);
      }
      std::fwrite(row.data(), sizeof(float), row.size(), f);
    }
    std::fclose(f);
    std::ofstream(vrt) << "<VRTDataset rasterXSize=\"" << n << "\" rasterYSize=\"" << n << "\">\n"
                       << "  <SRS>EPSG:3857</SRS>\n  <GeoTransform>0, 30, 0, 0, 0, -30</GeoTransform>\n"
                       << "  <VRTRasterBand dataType=\"Float32\" band=\"1\" subClass=\"VRTRawRasterBand\">\n"
                       << "    <SourceFilename relativeToVRT=\"1\">dem.f32</SourceFilename>\n"
                       << "    <ImageOffset>0</ImageOffset><PixelOffset>4</PixelOffset><LineOffset>" << 4L * n
                       << "</LineOffset><ByteOrder>LSB</ByteOrder>\n  </VRTRasterBand>\n</VRTDataset>\n";
  }
  const int fd = ::open(raw.c_str(), O_RDONLY);
  WindowReader rawReader = [fd, n](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
    gis::Grid<float> g(w, h);
    for (int r = 0; r < h; ++r) {
      const off_t at = (off_t(y + r) * n + x) * 4;
      if (::pread(fd, &g.data[g.index(0, r)], size_t(w) * 4, at) != ssize_t(w) * 4) return strata::fail("short read");
    }
    return g;
  };
  ::sync();
  t0 = Clock::now();
  auto ours = ingest(dir / "raw.store", benchGeoref(n), {{{"bedrock", LayerKind::Bedrock, ""}, rawReader}}, opts);
  if (!ours) die(ours.message());
  const double oursSeconds = since(t0);
  ::sync();
  const fs::path tif = dir / "dem_tiled.tif";
  const auto translate =
      run({"gdal_translate", "-q", "-of", "GTiff", "-co", "TILED=YES", "-co", "BLOCKXSIZE=256", "-co", "BLOCKYSIZE=256",
           "-co", "COMPRESS=DEFLATE", "-co", "PREDICTOR=3", "-co", "BIGTIFF=YES", vrt.string(), tif.string()},
          dir / "tools.log");
  const auto addo = run(
      {"gdaladdo", "-q", "-r", "average", tif.string(), "2", "4", "8", "16", "32", "64", "128", "256", "512", "1024"},
      dir / "tools.log");
  const double translateSeconds = translate.seconds, addoSeconds = addo.seconds;
  const double gdalSeconds = translateSeconds + addoSeconds;
  std::printf(
      ",\n \"raw_ingest\": {\"ours_seconds\": %.2f, \"ours_mb_per_s\": %.1f, \"gdal_translate_seconds\": %.2f, "
      "\"gdaladdo_seconds\": %.2f, \"gdal_mb_per_s\": %.1f, \"ours_speed_over_gdal\": %.2f, "
      "\"ours_file_mb\": %.1f, \"gdal_file_mb\": %.1f}",
      oursSeconds, inputMB / oursSeconds, translateSeconds, addoSeconds, inputMB / gdalSeconds,
      gdalSeconds / oursSeconds, double(ours->footprint.fileBytes) / 1e6, double(fs::file_size(tif)) / 1e6);
  ::close(fd);
  fs::remove(raw);

  // 3. Random full-resolution tile reads, cold.
  // Cold reads without the prefetcher (it would compete for the cores being timed).
  auto store = TileStore::open(dir / "raw.store", {.budgetBytes = size_t(256) << 20, .prefetch = false});
  if (!store) die(store.message());
  GDALAllRegister();
  GDALSetCacheMax64(int64_t(256) << 20);
  auto* ds = static_cast<GDALDataset*>(GDALOpen(tif.c_str(), GA_ReadOnly));
  if (!ds) die(tif.string() + ": GDAL cannot open it");
  GDALRasterBand* band = ds->GetRasterBand(1);
  std::mt19937 rng(7);
  const int tiles = n / 1024, reads = 64;
  std::vector<double> oursMs, gdalMs;
  std::vector<float> buf(size_t(1024) * 1024);
  for (int i = 0; i < reads; ++i) {
    const int tx = int(rng() % unsigned(tiles)), ty = int(rng() % unsigned(tiles));
    store->clearCache();
    t0 = Clock::now();
    auto g = store->readWindow(0, {tx * 1024, ty * 1024, 1024, 1024}, 0);
    if (!g) die(g.message());
    oursMs.push_back(since(t0) * 1e3);
    band->FlushCache();
    t0 = Clock::now();
    if (band->RasterIO(GF_Read, tx * 1024, ty * 1024, 1024, 1024, buf.data(), 1024, 1024, GDT_Float32, 0, 0) !=
        CE_None) {
      die("GDAL RasterIO failed");
    }
    gdalMs.push_back(since(t0) * 1e3);
  }
  std::printf(
      ",\n \"random_tile_read_1024\": {\"reads\": %d, \"ours_ms_mean\": %.2f, \"ours_ms_p95\": %.2f, "
      "\"gdal_ms_mean\": %.2f, \"gdal_ms_p95\": %.2f, \"ours_speed_over_gdal\": %.2f}",
      reads,
      [&] {
        double s = 0;
        for (double v : oursMs) s += v;
        return s / reads;
      }(),
      percentile(oursMs, 0.95),
      [&] {
        double s = 0;
        for (double v : gdalMs) s += v;
        return s / reads;
      }(),
      percentile(gdalMs, 0.95),
      [&] {
        double a = 0, b = 0;
        for (int i = 0; i < reads; ++i) a += oursMs[size_t(i)], b += gdalMs[size_t(i)];
        return b / a;
      }());

  // Random walk of 512 x 512 windows (steps of up to 384 cells), both through their caches.
  store = TileStore::open(dir / "raw.store", {.budgetBytes = size_t(256) << 20, .prefetch = true});
  if (!store) die(store.message());
  band->FlushCache();
  const int steps = 400;
  int x = n / 2, y = n / 2;
  std::vector<std::pair<int, int>> walk;
  for (int i = 0; i < steps; ++i) {
    x = std::clamp(x + int(rng() % 769) - 384, 0, n - 512);
    y = std::clamp(y + int(rng() % 769) - 384, 0, n - 512);
    walk.emplace_back(x, y);
  }
  t0 = Clock::now();
  for (auto [wx, wy] : walk) {
    if (!store->readWindow(0, {wx, wy, 512, 512}, 0)) die("walk read failed");
  }
  const double oursWalk = since(t0);
  const auto st = store->cacheStats();
  t0 = Clock::now();
  for (auto [wx, wy] : walk) {
    if (band->RasterIO(GF_Read, wx, wy, 512, 512, buf.data(), 512, 512, GDT_Float32, 0, 0) != CE_None) {
      die("GDAL RasterIO failed");
    }
  }
  const double gdalWalk = since(t0);
  std::printf(
      ",\n \"random_walk_512\": {\"steps\": %d, \"ours_seconds\": %.3f, \"gdal_seconds\": %.3f, "
      "\"ours_speed_over_gdal\": %.2f, \"hit_rate\": %.3f, \"hits\": %llu, \"misses\": %llu, "
      "\"prefetch_loads\": %llu, \"prefetch_hits\": %llu, \"cache_budget_mib\": 256}}\n",
      steps, oursWalk, gdalWalk, gdalWalk / oursWalk, st.hitRate(), (unsigned long long)st.hits,
      (unsigned long long)st.misses, (unsigned long long)st.prefetchLoads, (unsigned long long)st.prefetchHits);
  GDALClose(ds);
  return 0;
}
