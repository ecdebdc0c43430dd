#!/usr/bin/python3
"""The flat-floodplain flood after the Environment Agency's benchmark test 4 as a user runs it:
`strata flood` on a GeoTIFF plain, both flood schemes (and the local-inertial one with local time
steps, `inertial_local`), whole-process wall time.

Writes into OUT (a new folder): plain_<cell>m.tif (flat, 2000 x 1000 m, EPSG:27700, elevation
0), <scheme>_<cell>m.toml (Manning 0.05, closed edges, the 20 m breach in the middle of the west
side, tests/support/flat_plain.hpp's hydrograph and gauges, 5 h or --hours, maps every hour, no
pictures or plots) and a run folder per scenario; runs each scheme ROUNDS times, alternated, after
one warm-up run each, and prints the best and median wall times and the report's step counts.
With --rounds 0 each scheme runs once (no warm-up): for the large grids.

    bench/flat_plain.py OUT [--cell 20] [--rounds 3] [--hours 5]
                            [--schemes finite_volume,inertial,inertial_local]
                            [--strata build/apps/strata]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

from osgeo import gdal, osr

gdal.UseExceptions()

HYDROGRAPH = "[[0, 0], [1, 20], [4, 20], [6, 0]]"  # hours, m3/s (flat_plain.hpp)
GAUGES_M = [50, 100, 200, 300, 400, 500]
X0, Y0 = 400000.0, 300000.0  # the plain's north-west corner in the British National Grid


def write_plain(path, cell):
    w, h = int(round(2000 / cell)), int(round(1000 / cell))
    ds = gdal.GetDriverByName("GTiff").Create(path, w, h, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((X0, cell, 0, Y0, 0, -cell))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(27700)
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).Fill(0.0)
    ds = None


def write_scenario(path, dem, scheme, cell, hours=5):
    h = int(round(1000 / cell))
    n = max(1, int(round(20 / cell)))  # the breach's cells, rows y0 .. y0 + n - 1 (flat_plain.hpp)
    y0 = h // 2 - n // 2
    top, bottom = Y0 - (y0 + 0.5) * cell, Y0 - (y0 + n - 0.5) * cell
    breach = (f"at_xy = [{X0 + cell / 2}, {top}]" if n == 1 else
              f"line_xy = [[{X0 + cell / 2}, {top}], [{X0 + cell / 2}, {bottom}]]")
    yg = Y0 - (h // 2 + 0.5) * cell  # the gauges' row, h / 2, and their columns d / cell (flat_plain.hpp)
    gauges = "".join(
        f'\n[[outputs.gauge]]\nname = "{d} m"\nat_xy = [{X0 + (int(d / cell) + 0.5) * cell}, {yg}]\n' for d in GAUGES_M)
    with open(path, "w", encoding="utf-8") as f:
        f.write(f'''name = "flat plain ({scheme}, {cell:g} m)"
[terrain]
dem = "{os.path.basename(dem)}"
[model]
kind = "flood"
scheme = "{scheme.removesuffix('_local')}"
local_steps = {'true' if scheme.endswith('_local') else 'false'}
manning_n = 0.05
boundary = "closed"
backend = "cpu"
[[water.inflow]]
name = "breach"
{breach}
hydrograph = {HYDROGRAPH}
hydrograph_units = ["h", "m3/s"]
[time]
duration = "{hours:g} h"
output_interval = "1 h"
[outputs]
maps = ["max_depth"]
pictures = false
plots = false
probe_interval = "5 min"
{gauges}''')


def run(strata, toml, out):
    t0 = time.perf_counter()
    subprocess.run([strata, "flood", toml, "-o", out, "--overwrite", "--no-pictures", "--no-plots"], check=True,
                   stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    with open(os.path.join(out, "report.md"), encoding="utf-8") as f:
        report = f.read()
    steps = re.search(r"([\d,]+) steps", report)
    return wall, steps.group(1) if steps else "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--cell", type=float, default=20.0)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--hours", type=float, default=5.0, help="simulated hours (EA test 4: 5)")
    ap.add_argument("--schemes", default="finite_volume,inertial", help="comma-separated")
    ap.add_argument("--strata", default=os.path.join(os.path.dirname(__file__), "..", "build", "apps", "strata"))
    a = ap.parse_args()
    schemes = a.schemes.split(",")
    if any(s not in ("finite_volume", "inertial", "inertial_local") for s in schemes):
        sys.exit(f"flat_plain.py: --schemes: finite_volume, inertial and/or inertial_local, got '{a.schemes}'")
    if not a.hours > 0 or a.rounds < 0:
        sys.exit("flat_plain.py: --hours must be > 0 and --rounds >= 0")
    if os.path.exists(a.out):
        sys.exit(f"flat_plain.py: {a.out} exists; give a new folder")
    os.makedirs(a.out)
    dem = os.path.join(a.out, f"plain_{a.cell:g}m.tif")
    write_plain(dem, a.cell)
    runs = {}
    for scheme in schemes:
        toml = os.path.join(a.out, f"{scheme}_{a.cell:g}m.toml")
        write_scenario(toml, dem, scheme, a.cell, a.hours)
        runs[scheme] = (toml, os.path.join(a.out, f"run_{scheme}"))
        if a.rounds > 0:
            run(a.strata, *runs[scheme])  # warm-up
    walls = {s: [] for s in runs}
    steps = {}
    for _ in range(max(a.rounds, 1)):
        for scheme, (toml, out) in runs.items():
            wall, n = run(a.strata, toml, out)
            walls[scheme].append(wall)
            steps[scheme] = n
    for scheme in runs:
        w = walls[scheme]
        print(f"{scheme:14s} {a.cell:g} m: best {min(w):.2f} s, median {statistics.median(w):.2f} s "
              f"over {len(w)} runs, {steps[scheme]} steps (report)")


if __name__ == "__main__":
    main()
