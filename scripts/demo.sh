#!/usr/bin/env bash
# Strata's main job: the Grand Canyon flood what-if (scenarios/grand_canyon_flood.toml) on the
# shipped data. Sets itself up (packages, build), runs the scenario (on a hardware GPU if there
# is one, else on the CPU backend; pictures through llvmpipe) and writes runs/grand_canyon_flood/ (report.md, maps/*.tif, plots/*.png,
# series.csv). Extra arguments go to `strata flood` (e.g. --resume after a Ctrl-C, or --overwrite
# to run it again: an earlier run's outputs are never replaced unasked).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh" --target strata >&2  # only the program it runs (scripts/test.sh builds the rest)
cd "$root"
build/apps/strata gpu-info | sed -n '1p;5p' >&2
build/apps/strata flood scenarios/grand_canyon_flood.toml -o runs/grand_canyon_flood "$@"
