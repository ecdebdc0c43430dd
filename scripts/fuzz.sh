#!/usr/bin/env bash
# Fuzzes Strata's readers of untrusted input with libFuzzer under AddressSanitizer +
# UndefinedBehaviorSanitizer, for a bounded time per target:
#   dem       the DEM reading path (tests/gis/fuzz/read_dem_fuzz.cpp)
#   manifest  the tile store's manifest reader (tests/terrain/fuzz/manifest_fuzz.cpp)
#   scenario  the scenario parser, TOML included (tests/scenario/fuzz/parse_scenario_fuzz.cpp)
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]    default 120 s each, every target
#
# Its own build in build-fuzz/ (clang++ -fsanitize=fuzzer,address,undefined over the sources a
# target needs; GDAL is the system's; toml++ with its assertions on (no NDEBUG), so an input
# reaching one of toml++ 3.3.0's defects aborts instead of passing unnoticed). Each target starts
# from its seeds and its regression inputs (every input that once crashed, run first, so a
# regression fails at once); crashes land in build-fuzz/crashes/<target>/ and make the script
# fail. The targets build and run side by side (below); each one's output is in
# build-fuzz/<target>.build.log and .run.log, printed when it fails. CI runs `scripts/fuzz.sh 30`.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-120}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(dem manifest scenario)
out="$root/build-fuzz"
data="$root/../shared/data"
common=(-std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -fno-omit-frame-pointer -I"$root/core/include")

export ASAN_OPTIONS=${ASAN_OPTIONS:-"detect_leaks=1:allocator_may_return_null=1"}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-"print_stacktrace=1:halt_on_error=1"}

build_dem() {
  clang++ "${common[@]}" -I"$root/gis/include" -I"$root/gis/src" $(pkg-config --cflags gdal geographiclib) \
    "$root"/core/src/*.cpp "$root"/gis/src/*.cpp "$root/tests/gis/fuzz/read_dem_fuzz.cpp" \
    $(pkg-config --libs gdal geographiclib) -o "$out/read_dem_fuzz"
}

# Small, valid, and varied TIFFs (types, layouts, compression, nodata, scale/offset, no georef).
seed_dem() {
  local s=$1
  [ -z "$(ls -A "$s")" ] || return 0
  local gt=(gdal_translate -q)
  "${gt[@]}" -srcwin 100 100 16 16 "$data/grand_canyon/grandcanyon_srtm_3857.tif" "$s/int16_3857.tif"
  "${gt[@]}" -srcwin 100 100 16 12 -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 -co COMPRESS=DEFLATE \
    "$data/grand_canyon/grand_canyon_512.tif" "$s/float_tiled_deflate.tif"
  "${gt[@]}" -srcwin 0 0 24 8 -co COMPRESS=LZW -co PREDICTOR=2 "$data/rainier/mt_rainier_90m.tif" "$s/int16_lzw.tif"
  "${gt[@]}" -srcwin 500 250 12 12 -a_nodata -9999 "$data/earth/etopo20.tif" "$s/float_nodata.tif"
  "${gt[@]}" -srcwin 0 0 16 8 -of GTiff "$data/moon/LDEM_4.LBL" "$s/moon_scale_offset.tif"
  "${gt[@]}" -srcwin 0 0 16 8 -of GTiff "$data/mars/mola_megdr_4ppd.vrt" "$s/mars_0_360.tif"
  "${gt[@]}" -srcwin 0 0 8 8 -co PROFILE=BASELINE "$data/grand_canyon/grand_canyon_512.tif" "$s/no_georef.tif"
  "${gt[@]}" -srcwin 0 0 16 16 -ot Float64 -co INTERLEAVE=PIXEL "$data/grand_canyon/grand_canyon_512.tif" \
    "$s/float64.tif"
  "${gt[@]}" -srcwin 0 0 32 32 -of COG -co BLOCKSIZE=16 "$data/grand_canyon/grandcanyon_srtm_3857.tif" \
    "$s/cog.tif"
  "${gt[@]}" -srcwin 0 0 8 8 -ot Byte -scale "$data/grand_canyon/grand_canyon_512.tif" "$s/byte.tif"
  rm -f "$s"/*.aux.xml
}

run_dem() {
  "$out/read_dem_fuzz" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=65536 \
    -artifact_prefix="$out/crashes/dem/" -print_final_stats=1 "$out/corpus/dem" "$out/seeds/dem" \
    "$root/tests/gis/fuzz/regressions"
}

build_manifest() {
  # Header-only toml++ without NDEBUG: its assertions and TOML_UNREACHABLE abort.
  clang++ "${common[@]}" -DTOML_HEADER_ONLY=1 -I"$root/gis/include" -I"$root/terrain/include" -I"$root/terrain/src" \
    $(pkg-config --cflags gdal) "$root"/core/src/*.cpp "$root/gis/src/body.cpp" "$root/terrain/src/manifest.cpp" \
    "$root/terrain/src/material.cpp" "$root/terrain/src/layered_terrain.cpp" \
    "$root/tests/terrain/fuzz/manifest_fuzz.cpp" -o "$out/manifest_fuzz"
}

seed_manifest() { cp "$root"/tests/terrain/fuzz/seeds/*.toml "$1"/; }

run_manifest() {
  "$out/manifest_fuzz" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=16384 \
    -artifact_prefix="$out/crashes/manifest/" -print_final_stats=1 "$out/corpus/manifest" "$out/seeds/manifest"
}

build_scenario() {
  clang++ "${common[@]}" -I"$root/scenario/include" -I"$root/sim/include" \
    "$root"/core/src/{check,files,log,progress,time_series,toml_screen}.cpp "$root/scenario/src/scenario.cpp" \
    "$root/tests/scenario/fuzz/parse_scenario_fuzz.cpp" -o "$out/parse_scenario_fuzz"
}

# The shipped scenarios and every example of docs/scenario.md's format.
seed_scenario() {
  cp "$root"/scenarios/*.toml "$root"/tests/scenario/fuzz/seeds/*.toml "$1/"
}

run_scenario() {
  "$out/parse_scenario_fuzz" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
    -dict="$root/tests/scenario/fuzz/toml.dict" -artifact_prefix="$out/crashes/scenario/" -print_final_stats=1 \
    "$out/corpus/scenario" "$out/seeds/scenario" "$root/tests/scenario/fuzz/regressions"
}

for t in "${targets[@]}"; do
  case "$t" in
    dem | manifest | scenario) ;;
    *) echo "fuzz: unknown target '$t' (dem, manifest, scenario)" >&2; exit 2 ;;
  esac
  mkdir -p "$out/seeds/$t" "$out/corpus/$t" "$out/crashes/$t"
done

# Waits for the jobs `pids` (one per target, in order); a job that failed has its log printed.
# Returns 1 when any failed.
wait_all() {
  local what=$1 failed=0 i
  for i in "${!pids[@]}"; do
    if ! wait "${pids[$i]}"; then
      echo "fuzz: $what ${targets[$i]} failed; its log, $out/${targets[$i]}.$what.log, ends:" >&2
      tail -n 80 "$out/${targets[$i]}.$what.log" >&2
      failed=1
    fi
  done
  return $failed
}

# The targets build side by side (each build is one compiler process), then fuzz side by side:
# each is given `seconds` of a core, so when targets outnumber cores each runs for
# seconds x targets / cores of wall time (CI: 3 targets on 2 cores, 45 s each).
echo "fuzz: building ${targets[*]}" >&2
pids=()
for t in "${targets[@]}"; do
  "build_$t" > "$out/$t.build.log" 2>&1 &
  pids+=($!)
done
wait_all build
for t in "${targets[@]}"; do "seed_$t" "$out/seeds/$t"; done
cores=$(nproc)
n=${#targets[@]}
[ "$n" -le "$cores" ] || seconds=$(((seconds * n + cores - 1) / cores))
echo "fuzz: running ${targets[*]} side by side for ${seconds}s each" >&2
pids=()
for t in "${targets[@]}"; do
  (cd "$out" && "run_$t") > "$out/$t.run.log" 2>&1 &
  pids+=($!)
done
status=0
wait_all run || status=1
for t in "${targets[@]}"; do
  echo "fuzz: $t: $(grep -h '^Done ' "$out/$t.run.log" | tail -n 1)" \
    "($(grep -h 'stat::new_units_added' "$out/$t.run.log" | tail -n 1 | tr -s ' '))" >&2
done
exit $status
