#!/usr/bin/env python3
"""The Python module against the command line (issue 32): the shipped flood scenario at a coarse
cell size, run by strata.run and by `strata flood`, gives the same max-depth map bit for bit; a
run cancelled by its progress callback raises Cancelled and resumes to the same answer; a bad key
raises ScenarioError naming it; maps come with their geotransform and CRS.

    test_module.py STRATA_CLI SOURCE_DIR WORK_DIR      (PYTHONPATH holds build/python)
"""
import os
import shutil
import subprocess
import sys
import tomllib

import numpy as np

import strata


def check(cond, what):
    if not cond:
        sys.exit("FAILED: " + what)
    print("ok:", what)


def same(a, b):
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


def check_solver(source):
    """strata.Solver on a 48 x 40 window of the canyon DEM: a spring of 200 m3/s for 10 min on the
    CPU; the water balance closes, the water is where it was poured; the GL backend (llvmpipe
    here) agrees with the CPU to 1e-4 m; bad input raises."""
    dem = os.path.join(source, "..", "shared", "data", "grand_canyon", "grand_canyon_512.tif")
    runs = {}
    for backend in ("cpu", "gpu"):
        sv = strata.Solver(dem, window=(400, 150, 48, 40), backend=backend, manning_n=0.04, open_edges=[])
        sv.add_inflow([(24, 20)], [(0, 200), (600, 200)])
        sv.set_rain(10)
        sv.advance(600)
        st = sv.stats
        check(abs(sv.time_s - 600) < 1e-9 and sv.depth.shape == (40, 48), f"{sv.backend}: 600 s on a 48 x 40 window")
        check(abs(st["inflow_m3"] - 200 * 600) < 1e-6 * 200 * 600 and st["rain_m3"] > 0,
              f"{backend}: inflow {st['inflow_m3']:.1f} m3 = 200 m3/s x 600 s, rain {st['rain_m3']:.1f} m3")
        check(abs(st["balance_m3"]) < 1e-5 * (st["inflow_m3"] + st["rain_m3"]), f"{backend}: balance {st['balance_m3']:.2e} m3")
        check(sv.depth[20, 24] > 0.1, f"{backend}: {sv.depth[20, 24]:.2f} m of water at the spring")
        u, v = sv.velocity
        check(u.shape == v.shape == (40, 48) and np.isfinite(sv.bed).all(), f"{backend}: velocity and bed")
        runs[backend] = sv.depth
    diff = float(np.abs(runs["cpu"] - runs["gpu"]).max())
    check(diff < 1e-4, f"GL agrees with the CPU to {diff:.1e} m")
    for bad, what in ((lambda: strata.Solver(dem, window=(500, 0, 48, 40)), "a window outside the DEM"),
                      (lambda: sv.add_inflow([(99, 0)], [(0, 1)]), "a cell outside the grid"),
                      (lambda: sv.add_inflow([(1, 1)], [(5, 1), (0, 1)]), "a hydrograph going back in time"),
                      (lambda: sv.set_rain_raster(np.zeros((3, 3), np.float32)), "a rain raster of the wrong shape")):
        try:
            bad()
            check(False, what + " raises")
        except ValueError as e:
            check(True, f"{what}: {e}")


def check_erosion_solver(source, work):
    """strata.Solver with material layers and erosion on a 48 x 40 window of Rainier's flank (2 m of
    soil under 1 m of sand, 40 mm/h of rain for 15 min, the shear law, slopes relaxing): the layers'
    change equals, bit for bit, the terrain_change map of strata.run on the same window as a
    scenario (the same cells, layers, rain and law); the material balance closes; the GL backend
    agrees with the CPU; a material that does not exist raises."""
    dem = os.path.join(source, "..", "shared", "data", "rainier", "mt_rainier_90m.tif")
    x0, y0, w, h = 436, 212, 48, 40
    changes = {}
    for backend in ("cpu", "gpu"):
        sv = strata.Solver(dem, window=(x0, y0, w, h), backend=backend, manning_n=0.05,
                           layers=[("soil", 2.0), ("sand", np.full((h, w), 1.0, np.float32))], erosion="shear")
        sv.set_rain(40)
        sv.advance(900)
        st = sv.stats
        check(abs(st["material_balance_m3"]) < 1e-8 * st["initial_material_m3"],
              f"{backend}: material balance {st['material_balance_m3']:.2e} of {st['initial_material_m3']:.4g} m3")
        changes[backend] = sum(sv.layers) - 3.0
        check(len(sv.layers) == 2 and sv.suspended.shape == (h, w), f"{backend}: two layers and the suspended sediment")
        check(changes[backend].min() < -0.5 and changes[backend].max() > 0.5,
              f"{backend}: the sand moves (cut {changes[backend].min():.2f} m, fill {changes[backend].max():.2f} m)")
    diff = float(np.abs(changes["cpu"] - changes["gpu"]).max())
    check(diff < 1e-3, f"GL's layers agree with the CPU's to {diff:.1e} m")
    gt = strata.read_map(dem)["geotransform"]  # north-up: x = gt[0] + col gt[1], y = gt[3] + row gt[5]
    c0, c1 = gt[0] + (x0 + 0.25) * gt[1], gt[0] + (x0 + w - 0.25) * gt[1]
    r0, r1 = gt[3] + (y0 + h - 0.25) * gt[5], gt[3] + (y0 + 0.25) * gt[5]
    d = {"terrain": {"dem": dem, "layer": [{"material": "soil", "thickness": "2 m"},
                                           {"material": "sand", "thickness": "1 m"}]},
         "region": {"bbox_xy": [c0, r0, c1, r1]},  # the window's cells (their centres inside)
         "model": {"kind": "flood", "manning_n": 0.05, "boundary": "open"},
         "erosion": {"enabled": True, "law": "shear", "thermal": True},
         "water": {"rain": {"rate": "40 mm/h"}},
         "time": {"duration": "900 s", "output_interval": "900 s"},
         "outputs": {"maps": ["terrain_change"]}}
    run = strata.run(strata.scenario_from_dict(d, work, "erosion.toml"), os.path.join(work, "erosion"))
    check(same(run.map("terrain_change")["values"], changes["cpu"]),
          "the Solver's erosion equals the scenario run's terrain_change bit for bit")
    try:
        strata.Solver(dem, window=(x0, y0, w, h), layers=[("gravel", 1.0)])
        check(False, "an unknown material raises")
    except ValueError as e:
        check("gravel" in str(e), f"an unknown material raises: {e}")


def main():
    cli, source, work = sys.argv[1:4]
    prefix = os.environ.get("STRATA_EXPECT_PREFIX")  # the install test: the module must come from there
    if prefix:
        check(strata.__file__.startswith(prefix), f"strata imported from {os.path.dirname(strata.__file__)}")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scenarios = os.path.join(source, "scenarios")
    with open(os.path.join(scenarios, "grand_canyon_flood.toml"), "rb") as f:
        d = tomllib.load(f)
    # Coarse and short: 1.5 km cells, 30 min after a spin-up of at most 2 h.
    d["terrain"]["dem"] = os.path.normpath(os.path.join(scenarios, d["terrain"]["dem"]))
    d["region"]["cell_size"] = "1500 m"
    d["time"].update(duration="30 min", output_interval="10 min", spin_up="2 h")
    s = strata.scenario_from_dict(d, work, "coarse.toml")
    check(s.duration_s == 1800 and s.output_interval_s == 600, "scenario_from_dict reads the dict's times")
    with open(os.path.join(work, "coarse.toml"), "w") as f:
        f.write(strata.scenario_toml(d))
    check(strata.load_scenario(os.path.join(work, "coarse.toml")).name == s.name, "load_scenario reads the same file")

    calls, lines = [], []
    run = strata.run(s, os.path.join(work, "module"), progress=lambda t, total: calls.append((t, total)),
                     log=lambda *line: lines.append(line))
    check(any(level == "info" and category == "flood" and "running on CPU" in message
              for level, category, message in lines), f"the log callback got the run's {len(lines)} lines")
    check(run.completed and run.backend.startswith("CPU"), f"the module's run completed on the CPU ({run!r})")
    check(len(calls) >= 3 and calls[-1] == (1800.0, 1800.0), f"progress was called {len(calls)} times, ending at the end")
    with open(os.path.join(work, "module", "scenario.toml")) as f:
        check(f.read() == strata.scenario_toml(d), "the run folder's scenario.toml is the dict's TOML")
    subprocess.run([cli, "flood", os.path.join(work, "coarse.toml"), "-o", os.path.join(work, "cli"), "--backend",
                    "cpu", "--no-pictures", "--no-plots"], check=True, stdout=subprocess.DEVNULL)
    mine = run.map("max_depth")
    theirs = strata.read_map(os.path.join(work, "cli", "maps", "max_depth.tif"))
    check(mine["values"].dtype == np.float32 and mine["values"].ndim == 2, "a map is a 2-D float32 array")
    check(same(mine["values"], theirs["values"]), "max_depth equals the command line's bit for bit")
    check(np.nanmax(mine["values"]) > 1.0, f"the river is deep ({np.nanmax(mine['values']):.1f} m)")
    check(mine["geotransform"] == theirs["geotransform"] and "WGS 84" in mine["crs_wkt"],
          f"geotransform {mine['geotransform'][:2]}... and CRS WKT come with it")
    series = run.series
    check(len(series["time_s"]) == 3 and abs(series["balance_error_rel"]).max() < 1e-6,
          f"the series' columns (balance {abs(series['balance_error_rel']).max():.1e})")

    # Cancelled at the first callback after the first interval: a resumable folder.
    stop = os.path.join(work, "stopped")
    try:
        strata.run(s, stop, progress=lambda t, total: t < 600)
        check(False, "a cancelled run raises")
    except strata.Cancelled as e:
        check("can be resumed" in str(e), f"Cancelled: {e}")
    check(os.path.exists(os.path.join(stop, "checkpoint.bin")), "the stopped run left its checkpoint")
    resumed = strata.run(s, stop, resume=True)
    check(resumed.completed and same(resumed.map("max_depth")["values"], mine["values"]),
          "resumed, it ends with the uninterrupted run's max_depth")

    bad = dict(d, time=dict(d["time"], duraton="1 h"))
    try:
        strata.scenario_from_dict(bad, work, "bad.toml")
        check(False, "a bad key raises")
    except strata.ScenarioError as e:
        check("bad.toml:" in str(e) and "key 'time.duraton': unknown key" in str(e),
              f"ScenarioError: {str(e).splitlines()[0]}")
        check(e.file.endswith("bad.toml") and isinstance(e.line, int) and e.key == "time.duraton",
              f"its file, line and key: {os.path.basename(e.file)}, {e.line}, {e.key}")
    try:
        strata.run(s, os.path.join(work, "module"))
        check(False, "an existing run folder is not overwritten")
    except strata.ScenarioError as e:
        check("overwrite" in str(e), f"refused: {str(e).splitlines()[0][:120]}")
    check_solver(source)
    check_erosion_solver(source, work)
    print("python module: all checks passed")


main()
