#!/usr/bin/env bash
# Installs Strata to a fresh prefix and runs a short flood scenario with the installed `strata`
# from a folder outside the source and build trees: the plots must be written (their scripts are
# compiled in), and every installed scenario (the main job's and the second job's) must name a DEM
# that is installed.
#   installed_run.sh BUILD_DIR DEM
set -euo pipefail
build=$1
dem=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cd "$work"
cat > short.toml <<TOML
name = "installed run"
[terrain]
dem = "$dem"
[region]
bbox_lonlat = [-112.25, 36.02, -112.001, 36.18]
cell_size = "600 m"
[[water.inflow]]
line_lonlat = [[-112.0225, 36.063], [-112.0225, 36.08]]
hydrograph = [[0, 0], [5, 20000], [20, 20000]]
hydrograph_units = ["min", "m3/s"]
[time]
duration = "10 min"
output_interval = "5 min"
TOML
"$work/prefix/bin/strata" flood short.toml -o run --backend cpu --no-pictures
for f in run/report.md run/plots/water.png run/plots/max_depth.png run/maps/max_depth.tif; do
  [ -s "$f" ] || { echo "installed run: $f missing" >&2; exit 1; }
done
# Every installed scenario (the main job and the second, erosion, job) names a DEM installed beside it.
for installed in "$work"/prefix/share/strata/scenarios/*.toml; do
  dem_line=$(grep '^dem' "$installed")
  rel=${dem_line#*\"}
  rel=${rel%\"*}
  [ -s "$(dirname "$installed")/$rel" ] || { echo "installed $(basename "$installed") names a missing DEM: $rel" >&2; exit 1; }
done
[ -s "$work/prefix/share/strata/scenarios/rainier_erosion.toml" ] || { echo "the second job's scenario is not installed" >&2; exit 1; }
# The Python module (when built): imported from the prefix's site-packages, tests/python/test_module.py
# runs against the installed strata (the shipped flood scenario, bit for bit, cancel and resume, the
# Solver).
if [ -d "$build/python/strata" ]; then
  src=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
  STRATA_EXPECT_PREFIX="$work/prefix" PYTHONPATH="$work/prefix/lib/python3/dist-packages" \
    /usr/bin/python3 "$src/tests/python/test_module.py" "$work/prefix/bin/strata" "$src" "$work/python" |
    grep -q "python module: all checks passed" || { echo "the installed Python module failed its test" >&2; exit 1; }
  [ -s "$work/prefix/lib/python3/dist-packages/strata/__init__.pyi" ] || { echo "the type stubs are not installed" >&2; exit 1; }
  # The QGIS plugin: installed where QGIS looks (QGIS_PLUGINPATH for this prefix), finding the
  # prefix's module and command.
  plugin="$work/prefix/share/qgis/python/plugins/strata_processing"
  [ -s "$plugin/metadata.txt" ] || { echo "the QGIS plugin is not installed" >&2; exit 1; }
  (cd "$plugin" && /usr/bin/python3 -c '
import os, sys
import locations
sys.exit(0 if os.path.isfile(os.path.join(locations.PYTHON_DIR, "strata", "__init__.py")) and
         os.access(locations.EXECUTABLE, os.X_OK) else "the installed plugin does not find its module and command")
') || exit 1
fi
echo "installed run: report, plots and maps written from $work"
