#!/usr/bin/env bash
# Strata set-up: installs the Debian 12 packages the project needs (only the missing ones),
# then configures and builds. Idempotent: a second run with nothing changed takes seconds.
#
#   scripts/setup.sh [--build-dir DIR] [--asan] [--no-build] [--target T]...
#
# --target: build only T and what it needs (the demos build the `strata` program: 103 of the 228
# build steps on a fresh build folder); without it everything is built (tests, benchmarks).
#
# Environment: STRATA_BUILD_TYPE (default RelWithDebInfo), STRATA_WERROR (ON in CI),
# STRATA_LINE_TABLES=1 (debug info of line tables only, as CI builds), STRATA_UNITY=0 (no unity
# batches: for editing one file at a time).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir="$root/build"
sanitize=""
do_build=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --asan) sanitize="address,undefined"; shift ;;
    --no-build) do_build=0; shift ;;
    --target) targets+=(--target "$2"); shift 2 ;;
    *) echo "setup.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done

# Keep this list the single source of what Strata needs from Debian.
packages=(
  # toolchain
  cmake ninja-build g++ pkg-config clang clang-format libclang-rt-14-dev
  # gis: raster I/O, CRS, reprojection, geodesy
  libgdal-dev gdal-bin libgeographiclib-dev
  # float fields, tiled storage (OpenEXR); OpenImageIO reads and writes test images only: its
  # 260-library chain cost every process that loaded it 0.21 s of start-up (2026-11-29), so
  # Strata's own PNGs go through GDAL's PNG driver and its EXRs through OpenEXR
  libopenimageio-dev openimageio-tools libopenexr-dev
  # GL 4.5 through EGL (Mesa llvmpipe without a GPU), windows through GLFW (X11 -> Xvfb in tests)
  libegl-dev libegl-mesa0 libgl1-mesa-dri libepoxy-dev libglfw3-dev libglm-dev xvfb xauth
  # the viewer's HUD font (stb_easy_font.h: a header-only vector font, no font file)
  libstb-dev
  # distributed runs over MPI ranks (Open MPI: mpirun, mpicxx, the library and headers)
  openmpi-bin libopenmpi-dev
  # command line, scenario files
  libcli11-dev libtomlplusplus-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # plots in reports
  python3-matplotlib python3-numpy python3-gdal
  # a run folder's maps as QGIS shows them (tests load the .qml styles in headless QGIS)
  python3-qgis
  # the Python module `strata` (python/: pybind11 over the scenario library)
  pybind11-dev python3-dev
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

[ "$do_build" -eq 1 ] || exit 0

build_type=${STRATA_BUILD_TYPE:-RelWithDebInfo}
werror=${STRATA_WERROR:-OFF}
[ "${CI:-}" = "true" ] && werror=ON

# Configure only when the build folder is new or its settings changed (cmake re-runs itself
# when a CMakeLists.txt changes).
# The sanitizer build leaves the benchmarks out (no test runs them; the normal build compiles them)
# and compiles at -Og with line tables only (-g1: enough for symbolized reports). Its compile is
# most of CI's time: -Og took the sanitized tree 378 s against 572 s at -O1 (794 / 1,179 s of
# compiler time; -O1 was itself 2.2-2.4x faster a file than -O2 -g), and its tests 578 s
# against 530 s (2 cores, one after the other, 2026-11-29; docs/testing.md). The CPU kernels keep
# their own -O3 (sim/CMakeLists.txt).
# STRATA_LINE_TABLES=1 (set by .ci/run) gives the normal build line tables only, at -O2: a cold
# build is a third of CI's time and -g1 compiles a third faster (terrain_render_test.cpp 22.0 -> 15.6 s,
# cmd_generate.cpp 20.1 -> 14.4 s, side by side); backtraces still name file and line.
bench=ON
opt_flags=()
if [ -n "$sanitize" ]; then
  bench=OFF
  opt_flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-Og -g1 -DNDEBUG")
elif [ "${STRATA_LINE_TABLES:-0}" = "1" ]; then
  opt_flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG")
fi
# Unity builds (CMakeLists.txt: STRATA_UNITY_BUILD) compile each target's sources in batches:
# STRATA_UNITY=0 compiles them one by one (an edit then recompiles one file, not its batch).
unity=ON
[ "${STRATA_UNITY:-1}" = "0" ] && unity=OFF
want="type=$build_type werror=$werror sanitize=$sanitize bench=$bench unity=$unity flags=${opt_flags[*]:-}"
stamp="$build_dir/.strata-setup"
if [ ! -f "$build_dir/build.ninja" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  cmake -S "$root" -B "$build_dir" -G Ninja \
    -DCMAKE_BUILD_TYPE="$build_type" \
    -DSTRATA_WERROR="$werror" \
    -DSTRATA_SANITIZE="$sanitize" \
    -DSTRATA_BUILD_BENCH="$bench" -DSTRATA_UNITY_BUILD="$unity" "${opt_flags[@]}" >/dev/null
  echo "$want" > "$stamp"
fi
cmake --build "$build_dir" -j "$(nproc)" "${targets[@]}"
