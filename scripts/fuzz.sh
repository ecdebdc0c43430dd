#!/usr/bin/env bash
# Fuzzes the DEM reading path (tests/gis/fuzz/read_dem_fuzz.cpp) with libFuzzer under
# AddressSanitizer + UndefinedBehaviorSanitizer, for a bounded time.
#
#   scripts/fuzz.sh [SECONDS]        default 120
#
# Its own build in build-fuzz/ (clang++ -fsanitize=fuzzer,address,undefined over core/ and gis/
# sources; GDAL is the system library, not instrumented). Seeds are small valid TIFFs made with
# gdal_translate from the shared DEMs and generated rasters; crashes land in build-fuzz/crashes/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-120}
out="$root/build-fuzz"
data="$root/../shared/data"
mkdir -p "$out/seeds" "$out/corpus" "$out/crashes"

flags=(-std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined -fno-omit-frame-pointer
       -I"$root/core/include" -I"$root/gis/include" -I"$root/gis/src" $(pkg-config --cflags gdal geographiclib))
sources=("$root"/core/src/*.cpp "$root"/gis/src/*.cpp "$root/tests/gis/fuzz/read_dem_fuzz.cpp")
echo "fuzz: building $out/read_dem_fuzz" >&2
clang++ "${flags[@]}" "${sources[@]}" $(pkg-config --libs gdal geographiclib) -o "$out/read_dem_fuzz"

# Seeds: small, valid, and varied (types, layouts, compression, nodata, scale/offset, no georef).
s="$out/seeds"
if [ -z "$(ls -A "$s")" ]; then
  gt=(gdal_translate -q)
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
fi

echo "fuzz: running for ${seconds}s" >&2
export ASAN_OPTIONS=${ASAN_OPTIONS:-"detect_leaks=1:allocator_may_return_null=1"}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-"print_stacktrace=1:halt_on_error=1"}
cd "$out"
./read_dem_fuzz -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=65536 \
  -artifact_prefix="$out/crashes/" -print_final_stats=1 "$out/corpus" "$s"
