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

#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include <strata/core/interrupt.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/scenario/run.hpp>
#include <strata/scenario/scenario.hpp>

namespace py = pybind11;
namespace fs = std::filesystem;
using strata::scenario::Backend;
using strata::scenario::RunOptions;
using strata::scenario::RunSummary;
using strata::scenario::Scenario;

namespace {

// The module's exceptions (created in PYBIND11_MODULE).
py::object gScenarioError, gCancelled;

[[noreturn]] void raise(const py::object& type, const std::string& message) {
  PyErr_SetString(type.ptr(), message.c_str());
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
  if (!s) raise(gScenarioError, s.message());
  return std::move(s).value();
}

// The dict written as TOML text and read as a scenario file named `name` in `baseDir` (relative
// paths in it are relative to baseDir; messages name that file and the TOML text's lines).
std::pair<Scenario, std::string> loadDict(const py::dict& d, const fs::path& baseDir, const std::string& name) {
  std::ostringstream text;
  text << tableOf(d, "");
  auto s = strata::scenario::parseScenario(text.str(), baseDir / name);
  if (!s) raise(gScenarioError, s.message() + "\n(the dict as TOML:\n" + text.str() + ")");
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

// series.csv as a dict of float64 arrays by column name.
py::dict readSeries(const fs::path& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path.string() + ": cannot read the series");
  std::string line;
  std::getline(f, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string n; std::getline(header, n, ',');) names.push_back(n);
  std::vector<std::vector<double>> cols(names.size());
  while (std::getline(f, line)) {
    std::stringstream row(line);
    size_t k = 0;
    for (std::string v; std::getline(row, v, ',') && k < cols.size(); ++k) cols[k].push_back(std::stod(v));
  }
  py::dict out;
  for (size_t k = 0; k < names.size(); ++k)
    out[py::str(names[k])] = py::array_t<double>(cols[k].size(), cols[k].data());
  return out;
}

// Runs with Python's own SIGINT and SIGTERM handlers put back afterwards (the run installs its
// own, which stop it cleanly); the GIL released while it runs and taken for each callback.
py::dict run(const Scenario& s, const fs::path& outDir, const std::string& backend, bool pictures, bool plots,
             bool resume, bool overwrite, const std::function<py::object(double, double)>& progress) {
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
  if (progress) {
    o.onProgress = [&](double t, double duration) {
      py::gil_scoped_acquire gil;
      try {
        const py::object answer = progress(t, duration);
        if (!answer.is_none() && !answer.cast<bool>()) cancelled = true;
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
  if (!r) raise(gScenarioError, r.message());
  if (!callbackError.empty()) throw std::runtime_error("the progress callback raised: " + callbackError);
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

}  // namespace

PYBIND11_MODULE(_strata, m) {
  m.doc() = "Strata's scenario runs from Python (see the strata package).";
  gScenarioError = py::reinterpret_borrow<py::object>(
      PyErr_NewExceptionWithDoc("strata.ScenarioError",
                                "A scenario refused: the message names the file, the line and the key, as the "
                                "command line's.",
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
        py::arg("progress") = std::function<py::object(double, double)>(), "Runs a scenario into out_dir.");
  m.def("read_map", &readMap, py::arg("path"), "A GeoTIFF map or DEM: values, geotransform, crs_wkt.");
  m.def("read_series", &readSeries, py::arg("path"), "A run's series.csv as arrays by column.");
}
