#!/usr/bin/env bash
# Strata's second job: the erosion what-if on Mount Rainier's south-east flank
# (scenarios/rainier_erosion.toml) on the shipped data. Sets itself up (packages, build), runs
# `strata erode` (on a hardware GPU if there is one, else on the CPU backend) and writes
# runs/rainier_erosion/ (report.md, maps/*.tif, plots/*.png, pictures/*.png, series.csv). Extra
# arguments go to `strata erode` (--resume after a Ctrl-C, --overwrite to run it again).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh" --target strata >&2  # only the program it runs (scripts/test.sh builds the rest)
cd "$root"
build/apps/strata erode scenarios/rainier_erosion.toml -o runs/rainier_erosion "$@"
