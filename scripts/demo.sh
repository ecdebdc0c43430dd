#!/usr/bin/env bash
# Strata's main job. Sets itself up (packages, build) and runs the most complete real thing
# the project can do today (see README "Quick start").
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh" >&2
"$root/build/apps/strata" gpu-info
