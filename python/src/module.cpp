// The Python module `strata` (issue 32): the scenario library from Python, not through the command
// line. Load a scenario from a file or a dict (the command line's checks and messages, raised as
// strata.ScenarioError), run it with a progress callback that can cancel it (strata.Cancelled; the
// folder stays resumable), and read a run's maps and series as numpy arrays with their CRS.
// python/strata/__init__.py re-exports this and documents it; docs/python.md shows it in use.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include <strata/core/interrupt.hpp>
#include <strata/core/log.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gl/context.hpp>
#include <strata/scenario/domain.hpp>
#include <strata/scenario/run.hpp>
#include <strata/scenario/scenario.hpp>
#include <strata/sim/cpu_solver.hpp>
#include <strata/sim/gl/gl_solver.hpp>
#include <strata/terrain/material.hpp>

namespace py = pybind11;
namespace fs = std::filesystem;
using strata::scenario::Backend;
using strata::scenario::RunOptions;
using strata::scenario::RunSummary;
using strata::scenario::Scenario;

namespace {

namespace gis = strata::gis;
namespace sim = strata::sim;

// The module's exceptions (created in PYBIND11_MODULE).
py::object gScenarioError, gCancelled;

[[noreturn]] void raise(const py::object& type, const std::string& message) {
  PyErr_SetString(type.ptr(), message.c_str());
  throw py::error_already_set();
}

// A ScenarioError whose message starts "FILE:LINE: key 'KEY': " (the scenario parser's form)
// carries them as attributes too (file, line, key; None where the message has none).
[[noreturn]] void raiseScenario(const std::string& message) {
  py::object e = gScenarioError(message);
  py::object file = py::none(), line = py::none(), key = py::none();
  static const std::regex form(R"(^(.*?):(\d+): key '([^']*)': )");
  if (std::smatch m; std::regex_search(message, m, form)) {
    file = py::str(m[1].str());
    line = py::int_(std::stoi(m[2].str()));
    key = py::str(m[3].str());
  }
  e.attr("file") = file;
  e.attr("line") = line;
  e.attr("key") = key;
  PyErr_SetObject(gScenarioError.ptr(), e.ptr());
  throw py::error_already_set();
}

// A Python value as TOML: dicts as tables, lists and tuples as arrays, bool, int, float, str.
toml::node_type insert(toml::table& t, const std::string& key, const py::handle& v, const std::string& where);
void append(toml::array& a, const py::handle& v, const std::string& where);

toml::table tableOf(const py::dict& d, const std::string& where) {
  toml::table t;
  for (const auto& [k, v] : d) {
    if (!py::isinstance<py::str>(k)) raise(gScenarioError, where + ": a key that is not a string");
    const std::string key = k.cast<std::string>();
    insert(t, key, v, where.empty() ? key : where + "." + key);
  }
  return t;
}

toml::array arrayOf(const py::handle& seq, const std::string& where) {
  toml::array a;
  size_t i = 0;
  for (const auto& v : seq) append(a, v, where + "[" + std::to_string(i++) + "]");
  return a;
}

toml::node_type insert(toml::table& t, const std::string& key, const py::handle& v, const std::string& where) {
  if (py::isinstance<py::bool_>(v)) return t.insert(key, v.cast<bool>()).first->second.type();
  if (py::isinstance<py::int_>(v)) return t.insert(key, v.cast<int64_t>()).first->second.type();
  if (py::isinstance<py::float_>(v)) return t.insert(key, v.cast<double>()).first->second.type();
  if (py::isinstance<py::str>(v)) return t.insert(key, v.cast<std::string>()).first->second.type();
  if (py::isinstance<py::dict>(v)) return t.insert(key, tableOf(v.cast<py::dict>(), where)).first->second.type();
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    return t.insert(key, arrayOf(v, where)).first->second.type();
  }
  raise(gScenarioError, where + ": a " + std::string(py::str(v.get_type().attr("__name__"))) +
                            " (expected a dict, list, str, number or bool)");
}

void append(toml::array& a, const py::handle& v, const std::string& where) {
  if (py::isinstance<py::bool_>(v)) {
    a.push_back(v.cast<bool>());
  } else if (py::isinstance<py::int_>(v)) {
    a.push_back(v.cast<int64_t>());
  } else if (py::isinstance<py::float_>(v)) {
    a.push_back(v.cast<double>());
  } else if (py::isinstance<py::str>(v)) {
    a.push_back(v.cast<std::string>());
  } else if (py::isinstance<py::dict>(v)) {
    a.push_back(tableOf(v.cast<py::dict>(), where));
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    a.push_back(arrayOf(v, where));
  } else {
    raise(gScenarioError, where + ": a " + std::string(py::str(v.get_type().attr("__name__"))) +
                              " (expected a dict, list, str, number or bool)");
  }
}

Scenario loadFile(const fs::path& path) {
  auto s = strata::scenario::loadScenario(path);
  if (!s) raiseScenario(s.message());
  return std::move(s).value();
}

// The dict written as TOML text and read as a scenario file named `name` in `baseDir` (relative
// paths in it are relative to baseDir; messages name that file and the TOML text's lines).
std::pair<Scenario, std::string> loadDict(const py::dict& d, const fs::path& baseDir, const std::string& name) {
  std::ostringstream text;
  text << tableOf(d, "");
  auto s = strata::scenario::parseScenario(text.str(), baseDir / name);
  if (!s) raiseScenario(s.message() + "\n(the dict as TOML:\n" + text.str() + ")");
  return {std::move(s).value(), text.str()};
}

// A map or DEM: values as a float32 array (rows north to south, NaN where there is no data),
// GDAL's geotransform and the CRS as WKT.
py::dict readMap(const fs::path& path) {
  strata::gis::ReadOptions o;
  o.allowAllNoData = true;
  auto r = strata::gis::readDem(path.string(), o);
  if (!r) throw std::runtime_error(r.message());
  const auto& g = r->georef;
  py::array_t<float> values({g.height, g.width});
  std::copy(r->values.data.begin(), r->values.data.end(), values.mutable_data());
  const auto& c = g.transform.c;
  py::dict out;
  out["values"] = values;
  out["geotransform"] = py::make_tuple(c[0], c[1], c[2], c[3], c[4], c[5]);
  out["crs_wkt"] = g.crsWkt;
  return out;
}

// series.csv as a dict of float64 arrays by column name (scenario::readSeriesCsv).
py::dict readSeries(const fs::path& path) {
  auto cols = strata::scenario::readSeriesCsv(path);
  if (!cols) throw std::runtime_error(cols.message());
  py::dict out;
  for (const auto& [name, values] : *cols) out[py::str(name)] = py::array_t<double>(values.size(), values.data());
  return out;
}

// The run's log lines (strata::log: "warning: ..." on stderr from the command line) for a Python
// callback log(level, category, message). They are held while the run goes on and handed over
// from the thread that holds the GIL (at each progress call and at the end): the sink itself
// never waits for the GIL, so no thread logging with the GIL held can deadlock against it.
class LogRelay {
 public:
  using Callback = std::function<void(std::string, std::string, std::string)>;
  explicit LogRelay(Callback callback) : callback_(std::move(callback)) {
    if (!callback_) return;
    strata::log::setSink([this](strata::log::Level level, std::string_view category, std::string_view message) {
      std::lock_guard lock(mutex_);
      pending_.push_back({levelName(level), std::string(category), std::string(message)});
    });
  }
  ~LogRelay() {
    if (callback_) strata::log::resetSink();
  }
  LogRelay(const LogRelay&) = delete;
  LogRelay& operator=(const LogRelay&) = delete;
  /// Hands the lines over; the caller holds the GIL.
  void flush() {
    if (!callback_) return;
    std::vector<std::array<std::string, 3>> lines;
    {
      std::lock_guard lock(mutex_);
      lines.swap(pending_);
    }
    for (auto& [level, category, message] : lines) callback_(level, category, message);
  }

 private:
  static std::string levelName(strata::log::Level level) {
    switch (level) {
      case strata::log::Level::Debug: return "debug";
      case strata::log::Level::Warn: return "warning";
      case strata::log::Level::Error: return "error";
      default: return "info";
    }
  }
  Callback callback_;
  std::mutex mutex_;
  std::vector<std::array<std::string, 3>> pending_;
};

// Runs with Python's own SIGINT and SIGTERM handlers put back afterwards (the run installs its
// own, which stop it cleanly); the GIL released while it runs and taken for each callback.
py::dict run(const Scenario& s, const fs::path& outDir, const std::string& backend, bool pictures, bool plots,
             bool resume, bool overwrite, const std::function<py::object(double, double)>& progress,
             const LogRelay::Callback& log) {
  RunOptions o;
  o.outDir = outDir;
  o.resume = resume;
  o.overwrite = overwrite;
  o.pictures = pictures;
  o.plots = plots;
  if (backend == "cpu") {
    o.backend = Backend::kCpu;
  } else if (backend == "gpu") {
    o.backend = Backend::kGpu;
  } else if (backend == "auto") {
    o.backend = Backend::kAuto;
  } else {
    throw py::value_error("backend \"" + backend + "\": expected \"cpu\", \"gpu\" or \"auto\"");
  }
  bool cancelled = false;
  std::string callbackError;
  LogRelay relay(log);
  if (progress || log) {
    o.onProgress = [&](double t, double duration) {
      py::gil_scoped_acquire gil;
      try {
        relay.flush();
        if (progress) {
          const py::object answer = progress(t, duration);
          if (!answer.is_none() && !answer.cast<bool>()) cancelled = true;
        }
      } catch (py::error_already_set& e) {
        callbackError = e.what();
        cancelled = true;
      }
      return !cancelled;
    };
  }
  struct sigaction oldInt {
  }, oldTerm{};
  sigaction(SIGINT, nullptr, &oldInt);
  sigaction(SIGTERM, nullptr, &oldTerm);
  strata::setInterrupted(false);
  strata::Result<RunSummary> r = strata::fail("not run");
  {
    py::gil_scoped_release release;
    r = strata::scenario::runScenario(s, o);
  }
  sigaction(SIGINT, &oldInt, nullptr);
  sigaction(SIGTERM, &oldTerm, nullptr);
  const bool interrupted = strata::interrupted();
  strata::setInterrupted(false);
  if (callbackError.empty()) {
    try {
      relay.flush();
    } catch (py::error_already_set& e) {
      callbackError = e.what();
    }
  }
  if (!r) raiseScenario(r.message());
  if (!callbackError.empty()) throw std::runtime_error("the progress or log callback raised: " + callbackError);
  if (!r->completed && cancelled) {
    char at[64];
    std::snprintf(at, sizeof at, "cancelled at t = %.0f s; ", r->simulatedS);
    raise(gCancelled, at + outDir.string() + " can be resumed from its last output (strata.run(..., resume=True))");
  }
  if (!r->completed && interrupted) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);  // a Ctrl-C during the run: the folder is resumable
    throw py::error_already_set();
  }
  py::dict out;
  out["completed"] = r->completed;
  out["backend"] = r->backend;
  out["simulated_s"] = r->simulatedS;
  out["wall_s"] = r->wallS;
  out["steps"] = r->steps;
  out["files"] = r->files;
  return out;
}

// A grid as a float32 array (rows north to south) and back.
py::array_t<float> arrayOf(const gis::Grid<float>& g, float add = 0.0f) {
  py::array_t<float> a({g.height, g.width});
  float* out = a.mutable_data();
  for (size_t i = 0; i < g.size(); ++i) out[i] = g.data[i] + add;
  return a;
}
gis::Grid<float> gridOf(const py::array_t<float, py::array::c_style | py::array::forcecast>& a, int w, int h,
                        const char* what) {
  if (a.ndim() != 2 || a.shape(0) != h || a.shape(1) != w) {
    throw py::value_error(std::string(what) + ": expected an array of " + std::to_string(h) + " rows and " +
                          std::to_string(w) + " columns");
  }
  gis::Grid<float> g(w, h);
  std::copy(a.data(), a.data() + g.size(), g.data.begin());
  return g;
}
std::vector<std::pair<int, int>> cellsOf(const std::vector<std::pair<int, int>>& cells, const sim::CellGrid& grid) {
  if (cells.empty()) throw py::value_error("no cells");
  for (const auto& [x, y] : cells) {
    if (x < 0 || y < 0 || x >= grid.width || y >= grid.height) {
      throw py::value_error("cell (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                            std::to_string(grid.width) + " x " + std::to_string(grid.height) + " grid");
    }
  }
  return cells;
}
strata::TimeSeries seriesOf(const std::vector<std::array<double, 2>>& samples, const char* what) {
  auto t = strata::TimeSeries::create(samples);
  if (!t) throw py::value_error(std::string(what) + ": " + t.message());
  return std::move(t).value();
}

// Step-by-step use of one solver over a window of a DEM (flood mode): the scenario's cell sizes
// (geodesic) and model parameters, the CPU or GL backend. Material layers lie on the DEM's
// surface as a scenario's [[terrain.layer]] do (bare rock when none), and erosion, when asked for,
// works them with the scenario's laws and the default materials' constants.
using LayerSpec = std::pair<std::string, py::object>;  // (material, thickness: metres or an array)

class PySolver {
 public:
  PySolver(const fs::path& dem, std::optional<std::array<int, 4>> window, const std::string& backend, double manningN,
           double cfl, double maxStepS, const std::vector<std::string>& openEdges, const std::vector<LayerSpec>& layers,
           const std::optional<std::string>& erosion, bool thermal) {
    gis::ReadOptions ro;
    auto r = gis::readDem(dem.string(), ro);
    if (!r) throw std::runtime_error(r.message());
    georef_ = r->georef;
    const auto [x0, y0, w, h] = window.value_or(std::array<int, 4>{0, 0, georef_.width, georef_.height});
    if (w < 2 || h < 2 || x0 < 0 || y0 < 0 || x0 + w > georef_.width || y0 + h > georef_.height) {
      throw py::value_error("window (" + std::to_string(x0) + ", " + std::to_string(y0) + ", " + std::to_string(w) +
                            ", " + std::to_string(h) + ") is not inside the " + std::to_string(georef_.width) + " x " +
                            std::to_string(georef_.height) + " DEM (and at least 2 x 2)");
    }
    sim::SimInput in;
    in.baseM = gis::Grid<float>(w, h);
    double lo = 1e300;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const float v = r->values.at(x0 + x, y0 + y);
        if (!std::isfinite(v)) throw py::value_error(dem.string() + ": the window has cells without data");
        in.baseM.at(x, y) = v;
        lo = std::min(lo, double(v));
      }
    }
    georef_.transform.c[0] = r->georef.transform.x(x0, y0);
    georef_.transform.c[3] = r->georef.transform.y(x0, y0);
    georef_.width = w;
    georef_.height = h;
    auto sizes = strata::scenario::measureCells(georef_);
    if (!sizes) throw std::runtime_error(sizes.message());
    in.dyM = sizes->dyM;
    in.rowDxM = sizes->rowDxM;
    in.datumM = std::floor(lo);
    const auto table = strata::terrain::defaultMaterials();
    auto material = [&](const std::string& name) {
      const int i = strata::terrain::findMaterial(table, name);
      if (i < 0) {
        std::string names;
        for (const auto& m : table) names += (names.empty() ? "" : ", ") + m.name;
        throw py::value_error("layer material \"" + name + "\": expected one of " + names);
      }
      return table[size_t(i)];
    };
    for (const auto& [name, thickness] : layers) {
      in.materials.push_back(material(name));
      gis::Grid<float> t(w, h, 0.0f);
      if (py::isinstance<py::float_>(thickness) || py::isinstance<py::int_>(thickness)) {
        const double v = thickness.cast<double>();
        if (!(v >= 0) || !std::isfinite(v)) throw py::value_error("layer \"" + name + "\": a thickness >= 0 in m");
        std::fill(t.data.begin(), t.data.end(), float(v));
      } else {
        t = gridOf(thickness.cast<py::array_t<float, py::array::c_style | py::array::forcecast>>(), w, h,
                   ("layer \"" + name + "\" thickness").c_str());
        for (float v : t.data) {
          if (!(v >= 0) || !std::isfinite(v)) throw py::value_error("layer \"" + name + "\": thicknesses >= 0 in m");
        }
      }
      in.layersM.push_back(std::move(t));
    }
    if (layers.empty()) {  // bare rock: one layer of zero thickness so erosion has a material to read
      in.materials.push_back(material("rock"));
      in.layersM.push_back(gis::Grid<float>(w, h, 0.0f));
    }
    Scenario s;
    if (erosion) {
      s.erosion.enabled = true;
      s.erosion.thermal = thermal;
      if (*erosion == "shear") {
        s.erosion.law = sim::ErosionLaw::kShearStress;
      } else if (*erosion == "force-based") {
        s.erosion.law = sim::ErosionLaw::kForceBased;
      } else {
        throw py::value_error("erosion \"" + *erosion + "\": expected \"shear\", \"force-based\" or None");
      }
    }
    s.model.manningN = manningN;
    s.model.cfl = cfl;
    s.model.maxStepS = maxStepS;
    const char* names[4] = {"west", "east", "south", "north"};
    for (int e = 0; e < 4; ++e) s.model.boundaries[size_t(e)] = strata::scenario::Boundary::Closed;
    for (const auto& o : openEdges) {
      const auto* at = std::find(std::begin(names), std::end(names), o);
      if (at == std::end(names)) throw py::value_error("open edge \"" + o + "\": expected west, east, south or north");
      s.model.boundaries[size_t(at - std::begin(names))] = strata::scenario::Boundary::Open;
    }
    const sim::SimParams p = strata::scenario::modelParams(s);
    if (backend == "gpu") {
      auto ctx = strata::gl::HeadlessContext::create();
      if (!ctx) throw std::runtime_error("the GPU backend needs a GL 4.5 context: " + ctx.message());
      context_.emplace(std::move(ctx).value());
      auto g = sim::GlSolver::create(in, p);
      if (!g) throw std::runtime_error(g.message());
      solver_ = std::make_unique<sim::GlSolver>(std::move(g).value());
    } else if (backend == "cpu") {
      auto c = sim::CpuSolver::create(in, p);
      if (!c) throw std::runtime_error(c.message());
      solver_ = std::make_unique<sim::CpuSolver>(std::move(c).value());
    } else {
      throw py::value_error("backend \"" + backend + "\": expected \"cpu\" or \"gpu\"");
    }
  }

  void setRain(double mmPerHour) {
    auto p = solver_->params();
    p.rainMmPerHour = float(mmPerHour);
    check(solver_->setParams(p));
  }
  void setRainRaster(const std::optional<py::array_t<float, py::array::c_style | py::array::forcecast>>& a) {
    const auto& g = solver_->grid();
    check(solver_->setRainRaster(a ? gridOf(*a, g.width, g.height, "rain raster") : gis::Grid<float>()));
  }
  void addInflow(const std::vector<std::pair<int, int>>& cells, const std::vector<std::array<double, 2>>& q) {
    check(solver_->addSource({cellsOf(cells, solver_->grid()), seriesOf(q, "hydrograph")}));
  }
  void addLevel(const std::vector<std::pair<int, int>>& cells, const std::vector<std::array<double, 2>>& stage) {
    check(solver_->addLevel({cellsOf(cells, solver_->grid()), seriesOf(stage, "stage")}));
  }
  void step(int n) {
    if (n < 0) throw py::value_error("a negative number of steps");
    py::gil_scoped_release release;
    solver_->step(n);
  }
  void advance(double seconds) {
    if (!(seconds >= 0) || !std::isfinite(seconds)) throw py::value_error("advance: a duration >= 0 in seconds");
    py::gil_scoped_release release;
    solver_->advance(seconds);
  }
  py::array_t<float> depth() const { return arrayOf(solver_->readWaterDepth()); }
  py::tuple velocity() const {
    const auto v = solver_->readVelocity();
    return py::make_tuple(arrayOf(v.uMS), arrayOf(v.vMS));
  }
  py::array_t<float> bed() const { return arrayOf(solver_->readBed(), float(solver_->grid().datumM)); }
  py::list layers() const {
    py::list out;
    for (const auto& l : solver_->readLayers()) out.append(arrayOf(l));
    return out;
  }
  py::array_t<float> suspended() const { return arrayOf(solver_->readSuspended()); }
  double timeS() const { return solver_->timeS(); }
  py::dict stats() const {
    const auto st = solver_->stats();
    py::dict d;
    d["time_s"] = st.timeS;
    d["steps"] = st.steps;
    d["stored_water_m3"] = st.storedWaterM3;
    d["initial_water_m3"] = st.initialWaterM3;
    d["rain_m3"] = st.rainM3;
    d["inflow_m3"] = st.inflowM3;
    d["outflow_m3"] = st.outflowM3;
    d["evaporated_m3"] = st.evaporatedM3;
    d["infiltrated_m3"] = st.infiltratedM3;
    d["balance_m3"] = st.waterBalanceM3();
    d["max_depth_m"] = st.maxDepthM;
    d["material_m3"] = st.materialM3;
    d["initial_material_m3"] = st.initialMaterialM3;
    d["suspended_m3"] = st.suspendedM3;
    d["sediment_outflow_m3"] = st.sedimentOutflowM3;
    d["material_balance_m3"] = st.materialM3 + st.sedimentOutflowM3 - st.initialMaterialM3;
    return d;
  }
  py::tuple geotransform() const {
    const auto& c = georef_.transform.c;
    return py::make_tuple(c[0], c[1], c[2], c[3], c[4], c[5]);
  }
  std::string crsWkt() const { return georef_.crsWkt; }
  std::string backendName() const { return solver_->backendName(); }

 private:
  static void check(const strata::Status& s) {
    if (!s) throw py::value_error(s.message());
  }
  std::optional<strata::gl::HeadlessContext> context_;  // before the solver: destroyed after it
  std::unique_ptr<sim::Solver> solver_;
  gis::Georef georef_;
};

}  // namespace

PYBIND11_MODULE(_strata, m) {
  m.doc() = "Strata's scenario runs from Python (see the strata package).";
  gScenarioError = py::reinterpret_borrow<py::object>(
      PyErr_NewExceptionWithDoc("strata.ScenarioError",
                                "A scenario refused: the message names the file, the line and the key, as the "
                                "command line's; the attributes file, line and key hold them (None where the "
                                "message has none).",
                                PyExc_ValueError, nullptr));
  gCancelled = py::reinterpret_borrow<py::object>(PyErr_NewExceptionWithDoc(
      "strata.Cancelled", "A run stopped by its progress callback; its folder can be resumed.", PyExc_RuntimeError,
      nullptr));
  m.attr("ScenarioError") = gScenarioError;
  m.attr("Cancelled") = gCancelled;

  py::class_<Scenario>(m, "Scenario", "A checked scenario (strata.load_scenario, strata.scenario_from_dict).")
      .def_property_readonly("name", [](const Scenario& s) { return s.name; })
      .def_property_readonly("duration_s", [](const Scenario& s) { return s.durationS; })
      .def_property_readonly("output_interval_s", [](const Scenario& s) { return s.outputIntervalS; })
      .def_property_readonly("maps", [](const Scenario& s) { return s.outputs.maps; });
  m.def("load_scenario", &loadFile, py::arg("path"), "Reads and checks a scenario file (TOML).");
  m.def(
      "scenario_from_dict",
      [](const py::dict& d, const fs::path& baseDir, const std::string& name) {
        return loadDict(d, baseDir, name).first;
      },
      py::arg("scenario"), py::arg("base_dir") = fs::path("."), py::arg("name") = "scenario.toml",
      "Checks a scenario given as a dict of the TOML file's tables.");
  m.def(
      "scenario_toml",
      [](const py::dict& d) {
        std::ostringstream text;
        text << tableOf(d, "");
        return text.str();
      },
      py::arg("scenario"), "The TOML text of a scenario dict (what scenario_from_dict checks).");
  m.def("run", &run, py::arg("scenario"), py::arg("out_dir"), py::arg("backend") = "cpu", py::arg("pictures") = false,
        py::arg("plots") = false, py::arg("resume") = false, py::arg("overwrite") = false,
        py::arg("progress") = std::function<py::object(double, double)>(), py::arg("log") = LogRelay::Callback(),
        "Runs a scenario into out_dir.");
  py::class_<PySolver>(m, "Solver",
                       "One flood-mode solver over a window of a DEM, stepped from Python (docs/python.md).")
      .def(py::init<const fs::path&, std::optional<std::array<int, 4>>, const std::string&, double, double, double,
                    const std::vector<std::string>&, const std::vector<LayerSpec>&, const std::optional<std::string>&,
                    bool>(),
           py::arg("dem"), py::arg("window") = std::nullopt, py::arg("backend") = "cpu", py::arg("manning_n") = 0.035,
           py::arg("cfl") = 0.45, py::arg("max_step_s") = 30.0,
           py::arg("open_edges") = std::vector<std::string>{"west", "east", "south", "north"},
           py::arg("layers") = std::vector<LayerSpec>{}, py::arg("erosion") = std::nullopt, py::arg("thermal") = true)
      .def("set_rain", &PySolver::setRain, py::arg("mm_per_hour"), "Uniform rain from the next step on.")
      .def("set_rain_raster", &PySolver::setRainRaster, py::arg("mm_per_hour"),
           "Rain per cell (an array of the grid's shape, mm/h) from the next step on; None: none.")
      .def("add_inflow", &PySolver::addInflow, py::arg("cells"), py::arg("hydrograph"),
           "Inflow over cells [(x, y), ...] with a hydrograph [(time s, m3/s), ...].")
      .def("add_level", &PySolver::addLevel, py::arg("cells"), py::arg("stage"),
           "A fixed water level on cells with a stage [(time s, water surface m), ...].")
      .def("step", &PySolver::step, py::arg("n") = 1, "Takes n steps of the CFL length.")
      .def("advance", &PySolver::advance, py::arg("seconds"), "Steps until that much more time has passed.")
      .def_property_readonly("depth", &PySolver::depth, "Water depth (m), rows north to south.")
      .def_property_readonly("velocity", &PySolver::velocity, "(u east, v south) in m/s.")
      .def_property_readonly("bed", &PySolver::bed, "Bed elevation (m): the DEM plus the material layers.")
      .def_property_readonly("layers", &PySolver::layers, "Each layer's thickness (m), bottom first.")
      .def_property_readonly("suspended", &PySolver::suspended, "Suspended sediment (m of material).")
      .def_property_readonly("time_s", &PySolver::timeS)
      .def_property_readonly("stats", &PySolver::stats, "The water and material budgets since the start (m3).")
      .def_property_readonly("geotransform", &PySolver::geotransform)
      .def_property_readonly("crs_wkt", &PySolver::crsWkt)
      .def_property_readonly("backend", &PySolver::backendName);
  m.def("read_map", &readMap, py::arg("path"), "A GeoTIFF map or DEM: values, geotransform, crs_wkt.");
  m.def("read_series", &readSeries, py::arg("path"), "A run's series.csv as arrays by column.");
}
