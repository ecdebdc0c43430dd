// Mosaic grids and streaming reads on real data (crops of the shared DEMs made with
// gdal_translate in a temporary folder): the union grid, halves that mosaic to the whole,
// disjoint inputs, results independent of the window size, the "lowest elevation" rule,
// assigned georeferences, poles inside projected grids, and block reads.
#include <gtest/gtest.h>

#include <ogr_spatialref.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/dem_summary.hpp>
#include <strata/gis/geodesy.hpp>
#include <strata/gis/mosaic.hpp>

#include "gis_test_util.hpp"
#include "strata_test.hpp"

namespace strata::gis {
namespace {

namespace fs = std::filesystem;

// gdal_translate SRC -> DST with extra arguments; fails the test if it fails.
std::string translate(const std::string& src, const fs::path& dst, std::vector<std::string> args) {
  args.insert(args.begin(), {"gdal_translate", "-q"});
  args.push_back(src);
  args.push_back(dst.string());
  const auto r = test::runCommand(args, true);
  EXPECT_EQ(r.status, 0) << r.out;
  return dst.string();
}

bool bitEqual(const Grid<float>& a, const Grid<float>& b) {
  if (a.width != b.width || a.height != b.height) return false;
  int bad = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const bool na = std::isnan(a.data[i]), nb = std::isnan(b.data[i]);
    if (na != nb || (!na && a.data[i] != b.data[i])) {
      if (++bad <= 5 && a.size() > 1) {
        std::cout << "differs at " << i % size_t(a.width) << "," << i / size_t(a.width) << ": " << a.data[i] << " vs "
                  << b.data[i] << "\n";
      }
    }
  }
  return bad == 0;
}

// The whole grid read in windows of `step` cells (row of windows by row of windows).
Grid<float> readInWindows(MosaicReader& r, int step) {
  const auto& g = r.grid();
  Grid<float> out(g.width, g.height, kNoData);
  for (int y = 0; y < g.height; y += step) {
    for (int x = 0; x < g.width; x += step) {
      const int w = std::min(step, g.width - x), h = std::min(step, g.height - y);
      auto win = r.read({x, y, w, h});
      EXPECT_TRUE(win) << win.message();
      if (!win) return out;
      for (int j = 0; j < h; ++j) std::copy_n(&win->data[win->index(0, j)], w, &out.data[out.index(x, y + j)]);
    }
  }
  return out;
}

const std::string kRainier = test::dataFile("rainier/mt_rainier_90m.tif");

TEST(MosaicGrid, TwoHalvesOfARealDemMosaicToTheWhole) {
  const auto dir = strata::test::tempDir("halves");
  // A 256 x 160 piece of the Rainier SRTM tile (int16, nodata -32768) and its two halves.
  const auto whole = translate(kRainier, dir / "whole.tif", {"-srcwin", "600", "500", "256", "160"});
  const auto west = translate(kRainier, dir / "west.tif", {"-srcwin", "600", "500", "128", "160"});
  const auto east = translate(kRainier, dir / "east.tif", {"-srcwin", "728", "500", "128", "160"});
  auto ref = readDem(whole);
  ASSERT_TRUE(ref) << ref.message();
  std::vector<MosaicInput> inputs{{west}, {east}};
  auto grid = mosaicGrid(inputs);
  ASSERT_TRUE(grid) << grid.message();
  // The default grid is the union at the inputs' own resolution, aligned with them: the whole's.
  EXPECT_EQ(grid->width, 256);
  EXPECT_EQ(grid->height, 160);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(grid->transform.c[i], ref->georef.transform.c[i]) << i;
  auto reader = MosaicReader::open(inputs, *grid);
  ASSERT_TRUE(reader) << reader.message();
  EXPECT_TRUE(reader->readsDirectly(0) && reader->readsDirectly(1));  // on the grid's cells: not warped
  auto all = reader->read({0, 0, 256, 160});
  ASSERT_TRUE(all) << all.message();
  EXPECT_TRUE(bitEqual(*all, ref->values));
  // The same whatever the window size (tiles of 32 or 100 cells).
  EXPECT_TRUE(bitEqual(readInWindows(*reader, 32), ref->values));
  EXPECT_TRUE(bitEqual(readInWindows(*reader, 100), ref->values));
}

TEST(MosaicGrid, ADisjointDemExtendsTheGridOrIsNamed) {
  const auto dir = strata::test::tempDir("disjoint");
  const auto a = translate(kRainier, dir / "a.tif", {"-srcwin", "100", "100", "64", "48"});
  const auto b = translate(kRainier, dir / "b.tif", {"-srcwin", "300", "130", "40", "40"});
  auto ra = readDem(a), rb = readDem(b);
  ASSERT_TRUE(ra && rb);
  std::vector<MosaicInput> inputs{{a}, {b}};
  auto grid = mosaicGrid(inputs);
  ASSERT_TRUE(grid) << grid.message();
  // The union: columns 100..340, rows 100..170 of the tile.
  EXPECT_EQ(grid->width, 240);
  EXPECT_EQ(grid->height, 70);
  auto reader = MosaicReader::open(inputs, *grid);
  ASSERT_TRUE(reader) << reader.message();
  auto all = reader->read({0, 0, grid->width, grid->height});
  ASSERT_TRUE(all);
  int gap = 0;
  for (int y = 0; y < grid->height; ++y) {
    for (int x = 0; x < grid->width; ++x) {
      const float v = all->at(x, y);
      if (x < 64 && y < 48) {
        ASSERT_TRUE(bitEqual(Grid<float>(1, 1, v), Grid<float>(1, 1, ra->values.at(x, y))));
      } else if (x >= 200 && y >= 30) {
        ASSERT_TRUE(bitEqual(Grid<float>(1, 1, v), Grid<float>(1, 1, rb->values.at(x - 200, y - 30))));
      } else {
        ASSERT_TRUE(std::isnan(v)) << x << "," << y;
        ++gap;
      }
    }
  }
  EXPECT_GT(gap, 0);
  // An explicit extent that leaves b out names it.
  MosaicGridOptions o;
  const auto& t = ra->georef.transform;
  o.extent = std::array<double, 4>{t.c[0], t.y(0, 48), t.x(64, 0), t.c[3]};
  auto refused = mosaicGrid(inputs, o);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find(b + ": lies outside --extent"), std::string::npos) << refused.message();
  // A grid too large to hold is refused before anything is allocated.
  o.extent = std::array<double, 4>{-180, -90, 180, 90};
  o.resolution = std::array<double, 2>{1e-6, 1e-6};
  auto huge = mosaicGrid(inputs, o);
  ASSERT_FALSE(huge);
  EXPECT_NE(huge.message().find("360000000 x 180000000 cells, more than allowed"), std::string::npos) << huge.message();
}

TEST(MosaicGrid, AWarpedInputDoesNotDependOnTheWindowSize) {
  // The Web Mercator SRTM DEM onto a geographic grid: every cell is warped (bilinear); reading
  // the grid in windows of 64 or 100 cells gives the same bits as reading it whole.
  const auto dir = strata::test::tempDir("windows");
  const auto src = translate(test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif"), dir / "srtm.tif",
                             {"-srcwin", "100", "80", "200", "160"});
  std::vector<MosaicInput> inputs{{src}};
  MosaicGridOptions o;
  o.crs = "EPSG:4326";
  auto grid = mosaicGrid(inputs, o);
  ASSERT_TRUE(grid) << grid.message();
  EXPECT_TRUE(grid->geographic);
  auto reader = MosaicReader::open(inputs, *grid);
  ASSERT_TRUE(reader) << reader.message();
  EXPECT_FALSE(reader->readsDirectly(0));
  auto whole = reader->read({0, 0, grid->width, grid->height});
  ASSERT_TRUE(whole) << whole.message();
  size_t valid = 0;
  for (float v : whole->data) valid += !std::isnan(v);
  EXPECT_GT(valid, whole->data.size() / 2);
  EXPECT_TRUE(bitEqual(readInWindows(*reader, 64), *whole));
  EXPECT_TRUE(bitEqual(readInWindows(*reader, 100), *whole));
}

// Issue 33: the Grand Canyon's EPSG:4326 DEM mosaicked with its EPSG:3857 one was said to differ
// from `gdalwarp -r bilinear -et 0` on the same grid in one block of 304 x 81 cells (by up to 14
// m). The block is gdalwarp's: it warps in chunks and, unless told, sets each chunk's kernel
// scale from that chunk's source window, which the source's east edge clips (its debug output
// shows the chunk boundaries at column 482 and row 1402, the block's). Given one kernel scale for
// the whole grid (-wo XSCALE=1 -wo YSCALE=1: the sources' cells are not coarser than the grid's),
// gdalwarp agrees with the mosaic within 0.01 m in every cell (0.00024 m measured), whatever the
// windows the mosaic is read in.
TEST(MosaicGrid, TwoCrsMosaicEqualsGdalwarpWithOneKernelScale) {
  const auto dir = strata::test::tempDir("gdalwarp");
  const std::string a = test::dataFile("grand_canyon/grand_canyon_512.tif");
  const std::string b = test::dataFile("grand_canyon/grandcanyon_srtm_3857.tif");
  std::vector<MosaicInput> inputs{{a}, {b}};
  auto grid = mosaicGrid(inputs);
  ASSERT_TRUE(grid) << grid.message();
  auto reader = MosaicReader::open(inputs, *grid);
  ASSERT_TRUE(reader) << reader.message();
  const auto& t = grid->transform.c;
  auto num = [](double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", v);
    return std::string(text);
  };
  const fs::path warped = dir / "gdalwarp.tif";
  const auto r = test::runCommand({"gdalwarp",
                                   "-q",
                                   "-overwrite",
                                   "-r",
                                   "bilinear",
                                   "-et",
                                   "0",
                                   "-wo",
                                   "XSCALE=1",
                                   "-wo",
                                   "YSCALE=1",
                                   "-t_srs",
                                   "EPSG:4326",
                                   "-te",
                                   num(t[0]),
                                   num(t[3] + grid->height * t[5]),
                                   num(t[0] + grid->width * t[1]),
                                   num(t[3]),
                                   "-ts",
                                   std::to_string(grid->width),
                                   std::to_string(grid->height),
                                   "-ot",
                                   "Float32",
                                   "-dstnodata",
                                   "nan",
                                   a,
                                   b,
                                   warped.string()},
                                  true);
  ASSERT_EQ(r.status, 0) << r.out;
  ReadOptions all;
  all.allowAllNoData = true;
  auto expected = readDem(warped.string(), all);
  ASSERT_TRUE(expected) << expected.message();
  for (const int step : {0, 300}) {  // whole, and in windows of 300 cells
    Grid<float> mosaic;
    if (step == 0) {
      auto whole = reader->read({0, 0, grid->width, grid->height});
      ASSERT_TRUE(whole) << whole.message();
      mosaic = std::move(*whole);
    } else {
      mosaic = readInWindows(*reader, step);
    }
    ASSERT_EQ(mosaic.data.size(), expected->values.data.size());
    size_t both = 0, far = 0;
    double worst = 0;
    for (size_t i = 0; i < mosaic.data.size(); ++i) {
      const float m = mosaic.data[i], g = expected->values.data[i];
      if (std::isnan(m) || std::isnan(g)) continue;
      ++both;
      worst = std::max(worst, double(std::abs(m - g)));
      far += std::abs(m - g) > 0.01f;
    }
    EXPECT_GT(both, mosaic.data.size() / 2) << step;
    EXPECT_EQ(far, 0u) << "windows of " << step << ": worst " << worst << " m";
  }
}

TEST(MosaicGrid, MinimumIfCoarserKeepsTheLowestCell) {
  const auto dir = strata::test::tempDir("lowest");
  const auto src = translate(kRainier, dir / "piece.tif", {"-srcwin", "400", "400", "128", "96"});
  auto ref = readDem(src);
  ASSERT_TRUE(ref);
  MosaicInput in{src};
  in.resampling = Resampling::MinimumIfCoarser;
  // 4 x 4 source cells per target cell, aligned: each target cell is the lowest of its 16.
  const auto& t = ref->georef.transform;
  MosaicGridOptions coarse;
  coarse.resolution = std::array<double, 2>{4 * t.c[1], -4 * t.c[5]};
  auto g = mosaicGrid({&in, 1}, coarse);
  ASSERT_TRUE(g) << g.message();
  ASSERT_EQ(g->width, 32);
  ASSERT_EQ(g->height, 24);
  auto low = warpToGrid(in, *g);
  ASSERT_TRUE(low) << low.message();
  int compared = 0;
  for (int y = 0; y < g->height; ++y) {
    for (int x = 0; x < g->width; ++x) {
      float m = std::numeric_limits<float>::infinity();
      for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
          const float v = ref->values.at(4 * x + i, 4 * y + j);
          if (!std::isnan(v)) m = std::min(m, v);
        }
      }
      if (std::isinf(m)) continue;
      ASSERT_EQ(low->values.at(x, y), m) << x << "," << y;
      ++compared;
    }
  }
  EXPECT_GT(compared, 700);
  // On a finer grid it is bilinear.
  MosaicGridOptions fine;
  fine.resolution = std::array<double, 2>{t.c[1] / 2, -t.c[5] / 2};
  auto gf = mosaicGrid({&in, 1}, fine);
  ASSERT_TRUE(gf);
  MosaicInput bilinear = in;
  bilinear.resampling = Resampling::Bilinear;
  auto a = warpToGrid(in, *gf), b = warpToGrid(bilinear, *gf);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(bitEqual(a->values, b->values));
}

TEST(AssignGeoref, ADemWithoutOneIsReadPlacedAndDescribed) {
  const auto dir = strata::test::tempDir("assign");
  const auto src = translate(kRainier, dir / "piece.tif", {"-srcwin", "500", "600", "64", "40"});
  const auto bare =
      translate(kRainier, dir / "bare.tif", {"-srcwin", "500", "600", "64", "40", "-co", "PROFILE=BASELINE"});
  fs::remove(bare + ".aux.xml");
  auto ref = readDem(src);
  ASSERT_TRUE(ref);
  auto has = georefPresence(bare);
  ASSERT_TRUE(has);
  EXPECT_FALSE(has->crs || has->transform);
  EXPECT_FALSE(readDem(bare));
  ReadOptions o;
  o.crs = "EPSG:4326";
  o.transform = ref->georef.transform;
  auto r = readDem(bare, o);
  ASSERT_TRUE(r) << r.message();
  EXPECT_EQ(r->georef.epsg, 4326);
  EXPECT_TRUE(bitEqual(r->values, ref->values));
  // Placed by a mosaic: read directly onto the original's grid, cell for cell.
  MosaicInput in{bare};
  in.assignCrs = "EPSG:4326";
  in.assignTransform = ref->georef.transform;
  auto grid = mosaicGrid({&in, 1});
  ASSERT_TRUE(grid) << grid.message();
  for (int i = 0; i < 6; ++i) EXPECT_EQ(grid->transform.c[i], ref->georef.transform.c[i]);
  auto placed = warpToGrid(in, *grid);
  ASSERT_TRUE(placed) << placed.message();
  EXPECT_TRUE(bitEqual(placed->values, ref->values));
  // Described like the original.
  auto a = summarizeDem(src), b = summarizeDem(bare, o);
  ASSERT_TRUE(a && b) << (b ? "" : b.message());
  EXPECT_EQ(a->minLat, b->minLat);
  EXPECT_EQ(a->maxLon, b->maxLon);
  EXPECT_EQ(a->meanM, b->meanM);
  // Geotransforms as text.
  auto gt = parseGeoTransform("500000, 30, 0, 4100000, 0, -30", "--assign-geotransform");
  ASSERT_TRUE(gt);
  EXPECT_EQ(gt->c[3], 4100000.0);
  EXPECT_EQ(parseGeoTransform("1 2 3", "k").message(),
            "k: '1 2 3' needs 6 numbers (c0,c1,c2,c3,c4,c5 as GDAL orders them)");
  EXPECT_EQ(parseGeoTransform("0,1,0,0,0,nan", "k").message(), "k: 'nan' is not a finite number");
  EXPECT_EQ(parseGeoTransform("0,0,0,0,0,-1", "k").message(), "k: the pixel size is degenerate (c1 c5 - c2 c4 = 0)");
}

TEST(Summary, APoleInsideAProjectedGridIsItsExtremeLatitude) {
  // An Antarctic polar stereographic grid (EPSG:3031) of 100 km cells, +-4000 km: the boundary
  // reaches 52.3 S at its corners' nearest points, the pole lies in the middle.
  const auto dir = strata::test::tempDir("pole");
  const std::string path = (dir / "antarctica.tif").string();
  test::SyntheticRaster s;
  s.width = s.height = 80;
  s.crs = "EPSG:3031";
  s.gt = std::array<double, 6>{-4e6, 1e5, 0, 4e6, 0, -1e5};
  ASSERT_TRUE(test::writeSynthetic(path, s));
  auto sum = summarizeDem(path);
  ASSERT_TRUE(sum) << sum.message();
  // PROJ's own bounds of the rectangle (densified, and pole-aware).
  OGRSpatialReference src, dst;
  src.importFromEPSG(3031);
  dst.importFromEPSG(4326);
  dst.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> ct(OGRCreateCoordinateTransformation(&src, &dst));
  ASSERT_TRUE(ct);
  double xmin, ymin, xmax, ymax;
  ASSERT_TRUE(ct->TransformBounds(-4e6, -4e6, 4e6, 4e6, &xmin, &ymin, &xmax, &ymax, 21));
  EXPECT_EQ(ymin, -90.0);
  EXPECT_EQ(sum->minLat, -90.0);
  EXPECT_NEAR(sum->maxLat, ymax, 1e-3);  // the boundary, densified to 64 points an edge
  EXPECT_EQ(sum->minLon, -180.0);
  EXPECT_EQ(sum->maxLon, 180.0);
  std::cout << "EPSG:3031 +-4000 km: lat " << sum->minLat << " .. " << sum->maxLat << " (PROJ " << ymin << " .. "
            << ymax << ")\n";
}

// Bytes this process has read through read(2) so far (/proc/self/io rchar).
long long bytesRead() {
  std::ifstream in("/proc/self/io");
  std::string key;
  long long v = 0;
  while (in >> key >> v) {
    if (key == "rchar:") return v;
  }
  return -1;
}

TEST(DemFile, AStripedFileIsReadOnceWindowByWindow) {
  // Rainier as a striped, DEFLATE-compressed GeoTIFF (16 rows a strip), read in 64 x 64 windows
  // row by row, as an ingest does: about the file's bytes are read, not once per window column.
  const auto dir = strata::test::tempDir("striped");
  const auto path =
      translate(kRainier, dir / "striped.tif", {"-co", "TILED=NO", "-co", "COMPRESS=DEFLATE", "-co", "BLOCKYSIZE=16"});
  auto info = probeDem(path);
  ASSERT_TRUE(info);
  ASSERT_EQ(info->blockWidth, 1201);
  const auto fileBytes = static_cast<long long>(fs::file_size(path));
  auto ref = readDem(path);
  ASSERT_TRUE(ref);
  auto file = DemFile::open(path, {.allowAllNoData = true});
  ASSERT_TRUE(file);
  const long long before = bytesRead();
  for (int y = 0; y < 1201; y += 64) {
    for (int x = 0; x < 1201; x += 64) {
      const CellRect w{x, y, std::min(64, 1201 - x), std::min(64, 1201 - y)};
      auto r = file->read(w);
      ASSERT_TRUE(r) << r.message();
      for (int j = 0; j < w.height; ++j) {
        for (int i = 0; i < w.width; ++i) {
          ASSERT_TRUE(bitEqual(Grid<float>(1, 1, r->values.at(i, j)), Grid<float>(1, 1, ref->values.at(x + i, y + j))));
        }
      }
    }
  }
  const long long once = bytesRead() - before;
  // Each window opened anew (what ingest did before) reads the strips once per window column.
  const long long before2 = bytesRead();
  for (int y = 0; y < 1201; y += 64) {
    for (int x = 0; x < 1201; x += 64) {
      ReadOptions o;
      o.window = CellRect{x, y, std::min(64, 1201 - x), std::min(64, 1201 - y)};
      o.allowAllNoData = true;
      ASSERT_TRUE(readDem(path, o));
    }
  }
  const long long reopened = bytesRead() - before2;
  std::cout << "striped file " << fileBytes << " B: read " << once << " B window by window through one DemFile, "
            << reopened << " B reopening it per window\n";
  EXPECT_LT(once, fileBytes * 3 / 2);  // the file once, plus headers
  EXPECT_GT(reopened, 5 * once);
}

TEST(WriteGeoTiff, NeverReplacesAFileUnlessAskedAndCarriesMetadata) {
  const auto dir = strata::test::tempDir("write");
  const std::string path = (dir / "out.tif").string();
  auto ref = readDem(translate(kRainier, dir / "piece.tif", {"-srcwin", "0", "0", "16", "16"}));
  ASSERT_TRUE(ref);
  WriteOptions o;
  o.overwrite = false;
  o.metadata = {{"STRATA_MAX_ERROR_M", "0.25"}};
  ASSERT_TRUE(writeGeoTiff(path, *ref, o));
  auto again = writeGeoTiff(path, *ref, o);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.message(), path + ": already exists (not overwritten)");
  o.overwrite = true;
  EXPECT_TRUE(writeGeoTiff(path, *ref, o));
  const auto info = test::runCommand({"gdalinfo", path});
  EXPECT_NE(info.out.find("STRATA_MAX_ERROR_M=0.25"), std::string::npos) << info.out;
  int leftovers = 0;
  for (const auto& e : fs::directory_iterator(dir)) leftovers += e.path().string().find(".tmp") != std::string::npos;
  EXPECT_EQ(leftovers, 0);
}

}  // namespace
}  // namespace strata::gis
