// A scenario run over MPI ranks (RunOptions::distributed, what `mpirun -np N strata flood` does;
// docs/distributed.md, "Scenario runs") under mpirun on 1, 2 and 4 ranks
// (tests/scenario/CMakeLists.txt registers each). Rank 0 also runs the same scenario in one
// process; the run over the ranks must write the same maps bit for bit and the same series, for a
// flood with a spin-up, rain, conditioning (breach_inflows, fill_depressions) and open edges, and
// for an erosion run; a run stopped at a checkpoint and resumed must equal the uninterrupted one.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <strata/gis/dem_io.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>
#include <strata/scenario/scenario.hpp>

#include "../../scenario/src/breach.hpp"
#include "../../scenario/src/build_rows.hpp"
#include "../../scenario/src/domain_rows.hpp"
#include "mpi_support.hpp"
#include "scenario_fixture.hpp"

// This binary has its own main (MPI around GoogleTest), not the test support library's: the one
// helper of it the fixture uses.
namespace strata::test {
std::string dataPath(const std::string& relative) { return std::string(STRATA_DATA_DIR) + "/" + relative; }
}  // namespace strata::test

namespace strata::scenario {
namespace {

namespace fs = std::filesystem;
using namespace test_support;

using test::worldRank;
using test::worldSize;

fs::path sharedDir(const std::string& name) { return test::sharedTempDir("strata-scenario-mpi-" + name); }

// The shared fixture flood (a 20,000 m3/s river in a piece of the canyon at 600 m cells) with a
// spin-up of its first flow, rain over the whole run on a Green-Ampt soil (the ranks' model input
// carries its two maps; the river's bed keeps what it took in during the spin-up), the DEM
// conditioned, three open edges.
std::string floodText() {
  std::string text = scenarioText();
  text.replace(text.find("[region]"), 8, "breach_inflows = true\nfill_depressions = true\n[region]");
  text.replace(text.find("hydrograph = [[0, 0]"), 20, "hydrograph = [[0, 400]");
  text.replace(text.find("output_interval = \"5 min\""), 25, "output_interval = \"5 min\"\nspin_up = \"10 min\"");
  text += "[water.rain]\nrate = \"30 mm/h\"\nstart = \"0 min\"\nend = \"20 min\"\n";
  text +=
      "[water.infiltration]\nmodel = \"green_ampt\"\nconductivity = \"10 mm/h\"\nsuction = \"110 mm\"\n"
      "moisture_deficit = 0.3\n";
  return text;
}

std::string erosionText() {
  return scenarioText() +
         "[[terrain.layer]]\nmaterial = \"rock\"\nthickness = \"20 m\"\n"
         "[[terrain.layer]]\nmaterial = \"sand\"\nthickness = \"1 m\"\nat_rest = true\n"
         "[erosion]\nenabled = true\n";
}

Scenario load(const fs::path& dir, const std::string& name, const std::string& text) {
  if (worldRank() == 0) std::ofstream(dir / name) << text;
  MPI_Barrier(MPI_COMM_WORLD);
  auto s = loadScenario(dir / name);
  EXPECT_TRUE(s) << s.message();
  return s ? *s : Scenario{};
}

RunOptions options(const fs::path& out, const std::string& command) {
  RunOptions o;
  o.outDir = out;
  o.command = command;
  o.backend = Backend::kCpu;
  o.pictures = false;
  o.plots = false;
  return o;
}

// Every map of `b` equals `a`'s bit for bit, and the series agree (their balances are exact sums
// over the ranks and double row sums in one process: equal to 1e-9).
void expectSameRun(const fs::path& a, const fs::path& b, const std::vector<std::string>& maps,
                   const std::string& what) {
  for (const auto& m : maps) {
    auto ra = gis::readDem((a / "maps" / (m + ".tif")).string(), allowEmpty());
    auto rb = gis::readDem((b / "maps" / (m + ".tif")).string(), allowEmpty());
    ASSERT_TRUE(ra) << ra.message();
    ASSERT_TRUE(rb) << rb.message();
    ASSERT_EQ(ra->values.size(), rb->values.size()) << what << ": " << m;
    size_t differ = 0;
    for (size_t i = 0; i < ra->values.size(); ++i) {
      const float x = ra->values.data[i], y = rb->values.data[i];
      differ += (x == y || (std::isnan(x) && std::isnan(y))) ? 0 : 1;
    }
    EXPECT_EQ(differ, 0u) << what << ": " << m << " differs in " << differ << " cells";
  }
  const auto sa = readCsv(a / "series.csv"), sb = readCsv(b / "series.csv");
  ASSERT_EQ(sa.size(), sb.size()) << what;
  for (size_t r = 0; r < sa.size(); ++r) {
    ASSERT_EQ(sa[r].size(), sb[r].size());
    for (size_t c = 0; c < sa[r].size(); ++c) {
      EXPECT_NEAR(sa[r][c], sb[r][c], 1e-9 * std::max(1.0, std::abs(sa[r][c])))
          << what << ": series row " << r << " column " << c;
    }
  }
}

TEST(ScenarioMpi, AFloodOverTheRanksEqualsOneProcess) {
  const auto dir = sharedDir("flood");
  const Scenario s = load(dir, "flood.toml", floodText());
  if (worldRank() == 0) {
    auto one = runScenario(s, options(dir / "one", "flood"));
    ASSERT_TRUE(one) << one.message();
    EXPECT_GT(one->spinUp.storedM3, 0.0);
  }
  auto o = options(dir / "ranks", "flood");
  o.distributed = true;
  auto run = runScenario(s, o);
  ASSERT_TRUE(run) << run.message();
  EXPECT_TRUE(run->completed);
  EXPECT_EQ(run->ranks, worldSize());
  EXPECT_NE(run->backend.find(std::to_string(worldSize()) + " MPI ranks"), std::string::npos) << run->backend;
  // Each rank wrote its own checkpoint part; the model input is in the run folder.
  EXPECT_TRUE(fs::exists(
      dir / "ranks" / ("checkpoint." + std::to_string(worldRank()) + "-of-" + std::to_string(worldSize()) + ".bin")));
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() != 0) return;
  EXPECT_TRUE(fs::exists(dir / "ranks" / "input" / "base.tif"));
  EXPECT_TRUE(fs::exists(dir / "ranks" / "input" / "infiltration_suction.tif"));
  EXPECT_FALSE(fs::exists(dir / "ranks" / "checkpoint.bin"));
  const auto series = readCsv(dir / "ranks" / "series.csv");
  ASSERT_FALSE(series.empty());
  EXPECT_GT(series.back()[9], 0.0) << "infiltration_m3: the soil took nothing in";
  expectSameRun(dir / "one", dir / "ranks",
                {"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"},
                "flood on " + std::to_string(worldSize()) + " ranks");
  // The report says what ran it, and otherwise what the one process's says: every number of
  // the domain's build and of the flood (its extremes, areas and volumes are reduced over the
  // ranks), up to the list of files (checkpoint parts and model input).
  auto reportOf = [](const fs::path& folder) {
    std::ifstream report(folder / "report.md");
    return std::string((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
  };
  const std::string text = reportOf(dir / "ranks"), alone = reportOf(dir / "one");
  EXPECT_NE(text.find(std::to_string(worldSize()) + " MPI ranks"), std::string::npos);
  auto body = [](const std::string& t) {
    const auto from = t.find("## Scenario"), to = t.find("## Files");
    return from == std::string::npos || to == std::string::npos ? std::string() : t.substr(from, to - from);
  };
  EXPECT_GT(body(alone).size(), 500u);
  EXPECT_EQ(body(text), body(alone));
  fs::remove_all(dir);
}

// The ranks build the domain themselves, row by row, each from its own windows of the DEM
// (domain_rows.hpp): a polygon region, breach_inflows flooded over the ranks (breach.hpp; the
// path crosses the ranks' borders), fill_depressions tile by tile over the ranks' rows and rain,
// with a fixed level and a spin-up, or with a dam break (which a spin-up would release early).
// Maps, series, report and model input as one process's.
TEST(ScenarioMpi, ADomainBuiltByTheRanksRowByRowEqualsOneProcess) {
  std::string base = floodText();
  const auto bbox = base.find("bbox_lonlat");
  base.replace(bbox, base.find('\n', bbox) - bbox,
               "polygon_lonlat = [[-112.25, 36.02], [-112.001, 36.02], [-112.001, 36.18], [-112.25, 36.12]]");
  const std::string level =
      base +
      "[[water.level]]\nname = \"river stage\"\nline_lonlat = [[-112.0225, 36.063], [-112.0225, 36.08]]\n"
      "stage = [[0, 880]]\nstage_units = [\"min\", \"m\"]\n";
  std::string dam = base;
  dam.erase(dam.find("spin_up = \"10 min\"\n"), 19);
  dam +=
      "[[water.dam_break]]\npolygon_lonlat = [[-112.1, 36.05], [-112.02, 36.05], [-112.02, 36.1], "
      "[-112.1, 36.1]]\nsurface = \"950 m\"\n";
  for (const auto& [name, text] : {std::pair{"level", level}, std::pair{"dam", dam}}) {
    SCOPED_TRACE(name);
    const auto dir = sharedDir(std::string("rows-") + name);
    const Scenario s = load(dir, "rows.toml", text);
    if (worldRank() == 0) {
      auto one = runScenario(s, options(dir / "one", "flood"));
      ASSERT_TRUE(one) << one.message();
    }
    auto o = options(dir / "ranks", "flood");
    o.distributed = true;
    auto run = runScenario(s, o);
    ASSERT_TRUE(run) << run.message();
    EXPECT_TRUE(run->completed);
    MPI_Barrier(MPI_COMM_WORLD);
    if (worldRank() != 0) continue;
    expectSameRun(dir / "one", dir / "ranks",
                  {"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"},
                  std::string(name) + " built by rows on " + std::to_string(worldSize()) + " ranks");
    auto reportOf = [](const fs::path& folder) {
      std::ifstream report(folder / "report.md");
      const std::string t((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
      const auto from = t.find("## Scenario"), to = t.find("## Files");
      return from == std::string::npos || to == std::string::npos ? std::string() : t.substr(from, to - from);
    };
    const std::string alone = reportOf(dir / "one");
    EXPECT_NE(alone.find("depressions filled"), std::string::npos) << alone;
    EXPECT_EQ(reportOf(dir / "ranks"), alone);
    // The model input the ranks wrote is the one process's domain.
    auto domain = buildDomain(s);
    ASSERT_TRUE(domain) << domain.message();
    auto written = gis::readDem((dir / "ranks" / "input" / "base.tif").string());
    ASSERT_TRUE(written) << written.message();
    EXPECT_EQ(written->values.data, domain->input.baseM.data);
    int walls = 0;
    for (uint8_t in : domain->inside.data) walls += in ? 0 : 1;
    EXPECT_GT(walls, 100);  // the polygon cut the bounding box
    EXPECT_GT(domain->filled.cells, 0);
    // The breached path has cells in more than one rank's rows (rows [h k / n, h (k + 1) / n)).
    Scenario breachOnly = s, neither = s;
    breachOnly.terrain.fillDepressions = neither.terrain.fillDepressions = false;
    neither.terrain.breachInflows = false;
    auto breached = buildDomain(breachOnly), plain = buildDomain(neither);
    ASSERT_TRUE(breached && plain);
    EXPECT_GT(breached->breach.cells, 10);
    const int w = plain->bed.georef.width, h = plain->bed.georef.height;
    std::vector<int> bands;
    for (size_t i = 0; i < plain->input.baseM.size(); ++i) {
      if (breached->input.baseM.data[i] == plain->input.baseM.data[i]) continue;
      const int y = int(i / size_t(w));
      int band = 0;
      while (y >= int((long long)h * (band + 1) / worldSize())) ++band;
      if (std::find(bands.begin(), bands.end(), band) == bands.end()) bands.push_back(band);
    }
    EXPECT_GE(int(bands.size()), std::min(worldSize(), 2)) << "the breached path stays in one rank's rows";
    if (std::string(name) == "dam") {
      auto water = gis::readDem((dir / "ranks" / "input" / "water.tif").string(), allowEmpty());
      ASSERT_TRUE(water) << water.message();
      EXPECT_EQ(water->values.data, domain->input.waterDepthM.data);
      EXPECT_GT(domain->damBreakVolumeM3, 1e6);
    }
    fs::remove_all(dir);
  }
  // A check over every rank's rows that fails (a stage below every bed of its level) fails on
  // every rank with the one process's message, before the run folder is touched.
  std::string low = level;
  low.replace(low.find("stage = [[0, 880]]"), 18, "stage = [[0, 100]]");
  const auto dir = sharedDir("rows-refused");
  const Scenario s = load(dir, "rows.toml", low);
  auto o = options(dir / "ranks", "flood");
  o.distributed = true;
  auto refused = runScenario(s, o);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.message().find("rows.toml:" + std::to_string(s.water.levels[0].stageLine) +
                                   ": key 'water.level[0].stage': the stage (at most 100.00 m) never rises"),
            std::string::npos)
      << refused.message();
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_FALSE(fs::exists(dir / "ranks"));
  if (worldRank() == 0) fs::remove_all(dir);
}

// breach_inflows on terrain full of ties (whole-metre elevations 0..3, so many paths are as high
// and as long, and often as low in sum), on thin ranks (one to three rows each: the flood crosses
// their borders all the time): every rank's rows of the carved base, and the breach's figures,
// equal one process's, for 16 terrains and two inflows each.
TEST(ScenarioMpi, TheRanksBreachAsOneProcessWhereManyPathsTie) {
  Scenario s;
  s.terrain.breachInflows = true;
  s.model.boundaries = {Boundary::Open, Boundary::Closed, Boundary::Closed, Boundary::Closed};  // W E S N
  int carved = 0;
  for (uint32_t seed = 1; seed <= 16; ++seed) {
    const int w = 48, h = int(4 + seed % 9);
    ScenarioDomain whole;
    whole.bed.values = gis::Grid<float>(w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        uint32_t v = seed * 2654435761u ^ uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u;
        v ^= v >> 13, v *= 0x5bd1e995u, v ^= v >> 15;
        whole.bed.values.at(x, y) = float(v % 4);
      }
    }
    whole.input.baseM = whole.bed.values;
    whole.inside = gis::Grid<uint8_t>(w, h, 1);
    whole.cellAreaM2 = gis::Grid<double>(w, h, 100.0);
    std::vector<sim::Source> sources(2);
    sources[0].cells = {{w - 1, 0}, {w - 1, h / 2}};
    sources[1].cells = {{w - 2, h - 1}};
    const std::vector<std::string> names{"a", "b"};
    ScenarioDomain one = whole;
    ASSERT_TRUE(detail::breachInflowPaths(s, detail::Ranks::single(), {0, h}, sources, names, one));
    carved += one.breach.cells;

    // This rank's rows [h r / n, h (r + 1) / n) (at least 4 rows: one or more per rank).
    std::vector<int> starts;
    for (int r = 0; r <= worldSize(); ++r) starts.push_back(int((long long)h * r / worldSize()));
    const int y0 = starts[size_t(worldRank())], rows = starts[size_t(worldRank()) + 1] - y0;
    ScenarioDomain mine;
    mine.firstRow = y0;
    auto cut = [&](const auto& g) {
      std::remove_cvref_t<decltype(g)> out(w, rows);
      std::copy(g.data.begin() + ptrdiff_t(y0) * w, g.data.begin() + ptrdiff_t(y0 + rows) * w, out.data.begin());
      return out;
    };
    mine.bed.values = cut(whole.bed.values);
    mine.input.baseM = cut(whole.input.baseM);
    mine.inside = cut(whole.inside);
    mine.cellAreaM2 = cut(whole.cellAreaM2);
    ASSERT_TRUE(detail::breachInflowPaths(s, detail::Ranks::world(), starts, sources, names, mine));
    const auto expected = cut(one.input.baseM);
    EXPECT_EQ(mine.input.baseM.data, expected.data)
        << "terrain " << seed << " (" << h << " rows), rank " << worldRank();
    EXPECT_EQ(mine.breach.cells, one.breach.cells) << "terrain " << seed;
    EXPECT_EQ(mine.breach.cutM3, one.breach.cutM3) << "terrain " << seed;
    EXPECT_EQ(mine.breach.fillM3, one.breach.fillM3) << "terrain " << seed;
  }
  EXPECT_GT(carved, 40);
}

// at_rest layers settled by the ranks (settle.hpp) on a finer grid of the canyon, where cells on
// the ranks' border rows lose a layer because of a cell across the border: each rank's rows of
// every layer are the one process's, and so are the counts.
// Issue 33: the memory check is per machine. The ranks on one machine share its memory (or the
// budget given), so a region whose one-rank share just fits the budget is refused when K ranks
// run on the machine, the message saying so, and accepted with K times the budget.
TEST(ScenarioMpi, TheMemoryCheckSharesTheMachineAmongItsRanks) {
  const auto dir = sharedDir("memory");
  const Scenario s = load(dir, "flood.toml", floodText());
  const int k = detail::Ranks::world().onThisMachine();
  EXPECT_EQ(k, worldSize());  // the tests run every rank on this machine
  // The smallest budget (to 1 %) that one rank's share fits in, alone on its machine.
  uint64_t lo = 1, hi = uint64_t(1) << 40;
  while (hi > lo + lo / 100) {
    const uint64_t mid = lo + (hi - lo) / 2;
    (detail::RowBuilder::plan(s, mid, worldSize(), false, 1) ? hi : lo) = mid;
  }
  ASSERT_TRUE(detail::RowBuilder::plan(s, hi, worldSize(), false, 1));
  if (k > 1) {
    auto refused = detail::RowBuilder::plan(s, hi, worldSize(), false, k);
    ASSERT_FALSE(refused);
    EXPECT_NE(
        refused.message().find("are available to each of the " + std::to_string(k) + " MPI ranks on this machine"),
        std::string::npos)
        << refused.message();
  }
  EXPECT_TRUE(detail::RowBuilder::plan(s, hi * uint64_t(k), worldSize(), false, k));
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() == 0) fs::remove_all(dir);
}

TEST(ScenarioMpi, TheRanksSettleLayersAtRestAsOneProcess) {
  const auto dir = sharedDir("at-rest");
  std::string text = erosionText();
  text.replace(text.find("cell_size = \"600 m\""), 19, "cell_size = \"150 m\"");
  text += "[[terrain.layer]]\nmaterial = \"soil\"\nthickness = \"2 m\"\nat_rest = true\n";
  const Scenario s = load(dir, "erode.toml", text);
  auto whole = buildDomain(s);
  ASSERT_TRUE(whole) << whole.message();
  auto builder = detail::RowBuilder::plan(s, 0, worldSize(), false);
  ASSERT_TRUE(builder) << builder.message();
  auto built = detail::buildByRows(*builder, s, detail::Ranks::world());
  ASSERT_TRUE(built) << built.message();
  const auto& rows = built->rows;
  const int w = whole->input.baseM.width;
  ASSERT_EQ(rows.input.layersM.size(), whole->input.layersM.size());
  for (size_t k = 0; k < rows.input.layersM.size(); ++k) {
    const auto& mine = rows.input.layersM[k].data;
    const auto first = whole->input.layersM[k].data.begin() + ptrdiff_t(rows.firstRow) * w;
    EXPECT_TRUE(std::equal(mine.begin(), mine.end(), first)) << "layer " << k << " differs on rank " << worldRank();
  }
  EXPECT_EQ(built->shape.layerCellsTooSteep, whole->layerCellsTooSteep);
  if (worldRank() == 0) {
    std::printf("at_rest at 150 m: sand off %d cells, soil off %d\n", whole->layerCellsTooSteep[1],
                whole->layerCellsTooSteep[2]);
  }
  EXPECT_GT(whole->layerCellsTooSteep[1], 100);
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() == 0) fs::remove_all(dir);
}

// Voids filled by the ranks (each from the rows gis::voidFillRows names, beyond its own where a
// void needs them), made walls, or drained as holes: on Rainier's SRTM summit, whose voids cross
// the ranks' borders, each rank's rows of the bed and the mask, the void count and the holes'
// level are the one process's.
TEST(ScenarioMpi, TheRanksFillVoidsAsOneProcess) {
  const auto dir = sharedDir("voids");
  for (const char* mode : {"fill", "walls", "holes"}) {
    SCOPED_TRACE(mode);
    const std::string text = "[terrain]\ndem = \"" + test::dataPath("rainier/mt_rainier_90m.tif") + "\"\nvoids = \"" +
                             mode +
                             "\"\n[region]\nbbox_lonlat = [-121.80, 46.80, -121.72, 46.88]\n"
                             "[model]\nkind = \"flood\"\n[water.rain]\nrate = \"10 mm/h\"\n"
                             "[time]\nduration = \"10 min\"\n";
    const Scenario s = load(dir, std::string(mode) + ".toml", text);
    auto whole = buildDomain(s);
    ASSERT_TRUE(whole) << whole.message();
    EXPECT_GT(whole->voidCells, 20);
    auto builder = detail::RowBuilder::plan(s, 0, worldSize(), false);
    ASSERT_TRUE(builder) << builder.message();
    auto built = detail::buildByRows(*builder, s, detail::Ranks::world());
    ASSERT_TRUE(built) << built.message();
    const auto& rows = built->rows;
    const int w = whole->input.baseM.width, h = whole->input.baseM.height;
    auto same = [&](const auto& mine, const auto& all) {
      return std::equal(mine.data.begin(), mine.data.end(), all.data.begin() + ptrdiff_t(rows.firstRow) * w);
    };
    EXPECT_TRUE(same(rows.input.baseM, whole->input.baseM)) << "rank " << worldRank();
    EXPECT_TRUE(same(rows.inside, whole->inside)) << "rank " << worldRank();
    EXPECT_EQ(built->shape.voidCells, whole->voidCells);
    EXPECT_EQ(built->shape.levels.size(), whole->levels.size());
    EXPECT_EQ(built->shape.levelNames, whole->levelNames);
    if (!whole->levels.empty() && built->shape.levels.size() == whole->levels.size()) {
      EXPECT_EQ(built->shape.levels.back().cells, whole->levels.back().cells);
    }
    // The voids lie in more than one rank's rows.
    std::vector<int> bands;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!whole->voids.at(x, y)) continue;
        int band = 0;
        while (y >= int((long long)h * (band + 1) / worldSize())) ++band;
        if (std::find(bands.begin(), bands.end(), band) == bands.end()) bands.push_back(band);
      }
    }
    EXPECT_GE(int(bands.size()), std::min(worldSize(), 2));
    if (worldRank() == 0) {
      std::printf("voids = %s: %d voids over %zu ranks' rows\n", mode, whole->voidCells, bands.size());
    }
    if (std::string(mode) != "walls") continue;
    // A spring on a void made a wall is refused, on every rank with the one process's message.
    int vx = -1, vy = -1;
    for (int i = int(whole->voids.size()) - 1; i >= 0 && vx < 0; --i) {
      if (whole->voids.data[size_t(i)]) vx = i % w, vy = i / w;
    }
    const auto& c = whole->bed.georef.transform.c;
    char spring[256];
    std::snprintf(spring, sizeof spring,
                  "[[water.inflow]]\nname = \"spring\"\nat_lonlat = [%.9f, %.9f]\nhydrograph = [[0, 10], [60, 10]]\n",
                  c[0] + (vx + 0.5) * c[1], c[3] + (vy + 0.5) * c[5]);
    const Scenario onWall = load(dir, "on-wall.toml", text + spring);
    auto refused = buildDomain(onWall);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.message().find("on-wall.toml:"), std::string::npos) << refused.message();
    EXPECT_NE(refused.message().find("voids = \"walls\" makes walls"), std::string::npos) << refused.message();
    auto plan = detail::RowBuilder::plan(onWall, 0, worldSize(), false);
    ASSERT_TRUE(plan) << plan.message();
    auto byRows = detail::buildByRows(*plan, onWall, detail::Ranks::world());
    ASSERT_FALSE(byRows);
    EXPECT_EQ(byRows.message(), refused.message());
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() == 0) fs::remove_all(dir);
}

TEST(ScenarioMpi, AnErosionRunOverTheRanksEqualsOneProcess) {
  const auto dir = sharedDir("erosion");
  const Scenario s = load(dir, "erode.toml", erosionText());
  MaterialBudget reference;
  if (worldRank() == 0) {
    auto one = runScenario(s, options(dir / "one", "erode"));
    ASSERT_TRUE(one) << one.message();
    reference = *one->material;
  }
  auto o = options(dir / "ranks", "erode");
  o.distributed = true;
  auto run = runScenario(s, o);
  ASSERT_TRUE(run) << run.message();
  ASSERT_TRUE(run->material);
  if (worldRank() != 0) return;
  // The sand is left off the steepest cells (settled by the ranks against each other's border
  // rows: settle.hpp), and the report says so as one process's does.
  auto domain = buildDomain(s);
  ASSERT_TRUE(domain) << domain.message();
  std::printf("at_rest: sand left off %d cells\n", domain->layerCellsTooSteep[1]);
  EXPECT_GT(domain->layerCellsTooSteep[1], 0);
  auto reportOf = [](const fs::path& folder) {
    std::ifstream report(folder / "report.md");
    const std::string t((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
    const auto from = t.find("## Scenario"), to = t.find("## Files");
    return from == std::string::npos || to == std::string::npos ? std::string() : t.substr(from, to - from);
  };
  EXPECT_NE(reportOf(dir / "one").find("sand at rest"), std::string::npos);
  EXPECT_EQ(reportOf(dir / "ranks"), reportOf(dir / "one"));
  auto layer = gis::readDem((dir / "ranks" / "input" / "layer_2.tif").string(), allowEmpty());
  ASSERT_TRUE(layer) << layer.message();
  EXPECT_EQ(layer->values.data, domain->input.layersM[1].data);
  const auto& b = *run->material;
  std::printf("erosion on %d ranks: eroded %.6g m3 (one process %.6g), balance %.3g m3\n", worldSize(), b.erodedM3,
              reference.erodedM3, b.balanceM3());
  EXPECT_GT(b.erodedM3, 1e3);
  EXPECT_DOUBLE_EQ(b.erodedM3, reference.erodedM3);
  EXPECT_DOUBLE_EQ(b.depositedM3, reference.depositedM3);
  EXPECT_NEAR(b.suspendedM3, reference.suspendedM3, 1e-9 * std::max(1.0, reference.suspendedM3));
  EXPECT_LT(std::abs(b.balanceM3()), 1e-6 * b.initialM3Total);
  expectSameRun(dir / "one", dir / "ranks",
                {"max_depth", "final_depth", "terrain_change", "exposed_material", "suspended_sediment"},
                "erosion on " + std::to_string(worldSize()) + " ranks");
  fs::remove_all(dir);
}

// Pictures: only the lead draws, but the reads behind them (an erosion run's surface and layers)
// are collective, and so is choosing each rank's EGL device even where no context is made (a run
// with the CPU backend and pictures once aborted in MPI_Allreduce for that). The same pictures as
// one process, byte for byte.
TEST(ScenarioMpi, AnErosionRunWithPicturesDrawsTheOneProcessPictures) {
  const auto dir = sharedDir("pictures");
  const Scenario s = load(dir, "erode.toml", erosionText());
  // Drawn from every 2nd cell (the region is 37 cells wide): each rank sends its own cells of it.
  if (worldRank() == 0) {
    auto o = options(dir / "one", "erode");
    o.pictures = true;
    o.pictureCells = 24;
    auto one = runScenario(s, o);
    ASSERT_TRUE(one) << one.message();
  }
  auto o = options(dir / "ranks", "erode");
  o.pictures = true;
  o.pictureCells = 24;
  o.distributed = true;
  auto run = runScenario(s, o);
  ASSERT_TRUE(run) << run.message();
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() != 0) return;
  auto bytes = [](const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  };
  for (const char* p : {"before.png", "peak.png", "after.png", "max_depth.png"}) {
    const std::string a = bytes(dir / "one" / "pictures" / p), b = bytes(dir / "ranks" / "pictures" / p);
    EXPECT_GT(a.size(), 1000u) << p;
    EXPECT_TRUE(a == b) << p << " differs";
  }
  fs::remove_all(dir);
}

// Stopped after the first output interval (as Ctrl-C after a checkpoint leaves it), then resumed
// on the same ranks: the same as the run that was never stopped.
TEST(ScenarioMpi, AStoppedRunResumesOnItsRanks) {
  const auto dir = sharedDir("resume");
  const Scenario s = load(dir, "flood.toml", floodText());
  auto o = options(dir / "whole", "flood");
  o.distributed = true;
  ASSERT_TRUE(runScenario(s, o));
  o.outDir = dir / "stopped";
  o.stopAfterIntervals = 1;
  auto first = runScenario(s, o);
  ASSERT_TRUE(first) << first.message();
  EXPECT_FALSE(first->completed);
  o.stopAfterIntervals = -1;
  o.resume = true;
  auto second = runScenario(s, o);
  ASSERT_TRUE(second) << second.message();
  EXPECT_TRUE(second->completed);
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() == 0) {
    expectSameRun(dir / "whole", dir / "stopped",
                  {"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"},
                  "resumed on " + std::to_string(worldSize()) + " ranks");
  }
  // Issue 33: ranks stopped while the second checkpoint's parts were written. Rank 0 was killed
  // between keeping its last part as the previous one and writing the new (only its interval-1
  // part is left), rank 1 before it began (its current part is of interval 1, it has no
  // previous), the others finished (interval 2, previous 1). The resume takes interval 1 on
  // every rank and ends as the run that was never stopped.
  o.outDir = dir / "torn";
  o.resume = false;
  o.stopAfterIntervals = 2;
  auto torn = runScenario(s, o);
  ASSERT_TRUE(torn) << torn.message();
  const std::string of = "-of-" + std::to_string(worldSize());
  const fs::path part = dir / "torn" / ("checkpoint." + std::to_string(worldRank()) + of + ".bin");
  const fs::path previous = dir / "torn" / ("checkpoint." + std::to_string(worldRank()) + of + ".previous.bin");
  EXPECT_TRUE(fs::exists(part) && fs::exists(previous));
  if (worldRank() == 0) fs::remove(part);
  if (worldRank() == 1) fs::rename(previous, part);
  MPI_Barrier(MPI_COMM_WORLD);
  o.stopAfterIntervals = -1;
  o.resume = true;
  auto healed = runScenario(s, o);
  ASSERT_TRUE(healed) << healed.message();
  EXPECT_TRUE(healed->completed);
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() == 0) {
    expectSameRun(dir / "whole", dir / "torn",
                  {"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"},
                  "resumed after a torn checkpoint on " + std::to_string(worldSize()) + " ranks");
  }
  // A folder checkpointed on another number of ranks is refused on every rank, saying how many.
  if (worldRank() == 0) {
    fs::create_directories(dir / "other");
    fs::copy(dir / "stopped", dir / "other", fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    for (int r = 0; r < worldSize(); ++r) {
      for (const std::string kind : {".bin", ".previous.bin"}) {  // both parts a rank keeps
        fs::rename(
            dir / "other" / ("checkpoint." + std::to_string(r) + "-of-" + std::to_string(worldSize()) + kind),
            dir / "other" / ("checkpoint." + std::to_string(r) + "-of-" + std::to_string(worldSize() + 1) + kind));
      }
    }
  }
  MPI_Barrier(MPI_COMM_WORLD);
  o.outDir = dir / "other";
  auto refused = runScenario(s, o);
  ASSERT_FALSE(refused);
  const std::string n = std::to_string(worldSize() + 1);
  EXPECT_NE(refused.message().find("no checkpoint to resume from (the run was checkpointed on " + n +
                                   " MPI ranks: resume it with mpirun -np " + n + ")"),
            std::string::npos)
      << refused.message();
  MPI_Barrier(MPI_COMM_WORLD);
  if (worldRank() == 0) fs::remove_all(dir);
}

}  // namespace
}  // namespace strata::scenario
