"""Strata from Python: scenario runs through the C++ libraries (issue 32; docs/python.md).

    import strata
    s = strata.load_scenario("flood.toml")            # or strata.scenario_from_dict({...})
    r = strata.run(s, "out", progress=lambda t, total: print(f"{t / total:.0%}"))
    depth = r.map("max_depth")                        # values (numpy, NaN = no data), geotransform, crs_wkt
    r.series["water_volume_m3"]                       # series.csv's columns as numpy arrays

For step-by-step work, strata.Solver("dem.tif", window=(x, y, w, h), backend="cpu") steps one
flood-mode solver over a window of a DEM: add_inflow, add_level, set_rain, advance, then depth,
velocity, bed and stats. layers=[("soil", 2.0), ("sand", 1.0)] lays material on the DEM and
erosion="shear" (or "force-based") works it: then layers and suspended too.

A refused scenario raises ScenarioError with the command line's message (file, line, key); a
progress callback that returns False stops the run and raises Cancelled, leaving a folder that
strata.run(..., resume=True) continues.
"""
import os

# OpenMP threads that wait by sleeping, not spinning (strata/core/process.hpp): libgomp reads
# this when it is loaded, with the extension below, unless the user has set it.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from ._strata import (Cancelled, Scenario, ScenarioError, Solver, load_scenario, read_map, read_series,
                      scenario_from_dict, scenario_toml)
from . import _strata

__all__ = ["Cancelled", "Run", "Scenario", "ScenarioError", "Solver", "load_scenario", "read_map", "read_series",
           "run", "scenario_from_dict", "scenario_toml"]


class Run:
    """A finished (or stopped) run's folder and what the run said of itself."""

    def __init__(self, folder, info):
        self.folder = os.fspath(folder)
        self.completed = info["completed"]
        self.backend = info["backend"]
        self.simulated_s = info["simulated_s"]
        self.wall_s = info["wall_s"]
        self.steps = info["steps"]
        self.files = list(info["files"])

    def map(self, name):
        """maps/NAME.tif as a dict: values (float32 numpy array, rows north to south, NaN where
        there is no data), geotransform (GDAL's six numbers), crs_wkt."""
        return read_map(os.path.join(self.folder, "maps", name + ".tif"))

    @property
    def series(self):
        """series.csv's columns by name, each a float64 numpy array (one value per output interval)."""
        return read_series(os.path.join(self.folder, "series.csv"))

    def __repr__(self):
        state = "completed" if self.completed else "stopped"
        return f"<strata.Run {self.folder!r}: {state}, {self.simulated_s:.0f} s simulated on {self.backend}>"


def run(scenario, out_dir, *, backend="cpu", pictures=False, plots=False, resume=False, overwrite=False,
        progress=None, log=None):
    """Runs `scenario` (a Scenario) into the folder `out_dir` and returns a Run.

    backend: "cpu", "gpu" (the GL backend) or "auto", as the command line's --backend
    progress(time_s, duration_s) is called a few times a second; returning False stops the run
    (Cancelled is raised; resume=True continues it). The run refuses to overwrite an earlier run's
    outputs unless overwrite=True, as `strata flood` does.
    log(level, category, message) receives the lines the command line prints on stderr (level
    "debug", "info", "warning" or "error"; category e.g. "flood") instead of stderr, from the
    calling thread: at each progress call and at the end."""
    info = _strata.run(scenario, os.fspath(out_dir), backend, pictures, plots, resume, overwrite, progress, log)
    return Run(out_dir, info)
