#!/usr/bin/env bash
# Generates the three seed examples and renders each with the concentric-ring renderer into
# docs/examples/<example>.png (the pictures docs/procgen.md shows).
#   docs/examples/render.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
strata=${1:-$root/build}/apps/strata
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# example, output layer, camera: easting northing height-above-ground heading pitch (m, m, m, deg, deg),
# from the south-west corner looking north-east
render() {
  local name=$1 layer=$2
  shift 2
  "$strata" generate "$root/docs/examples/$name.toml" -o "$out/$name" --seed 7 --size 512x512 >/dev/null
  "$strata" render "$out/$name/$layer.tif" --overwrite -o "$root/docs/examples/$name.png" --size 640x360 \
    --lon "$1" --lat "$2" --agl "$3" --heading "$4" --pitch "$5"
}
render fbm_waves_mountain bedrock 381500 4016000 3000 45 -25
render dem_coarse_fbm_detail terrain 306000 3995000 20000 45 -25
render dem_band_blend terrain 306000 3995000 20000 45 -25
