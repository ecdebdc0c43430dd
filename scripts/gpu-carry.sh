#!/usr/bin/env bash
# Packs what a lent GPU machine (the workplace's `device` tool: an Ubuntu image with the NVIDIA
# driver, nothing of Debian's) needs to run Strata's GPU benchmarks and tests built here, into
# folders of the checkout that .git/info/exclude ignores (each call may carry 64 MiB in all):
#   .gl/    libglvnd's EGL/GL loaders (Debian .debs, unpacked into / there)
#   .gpu/   env.sh and libs.sh to source there, and the small libraries every program needs (xz)
#   .gpub/  the stripped programs (benchmarks and GPU test binaries) as one xz tarball, and the
#           Moon, Mars and Earth DEMs of ../shared/data (the Grand Canyon's go with .gpur)
#   .gpur/  GDAL's library chain and PROJ/GDAL data as xz tarballs, the Grand Canyon DEMs
#   .gpua/  what `strata` and the render tests load beyond those (Open MPI's libraries; until
#           2026-11-29 OpenImageIO's chain, which nothing carried loads now) and the Rainier DEM
# Carry .gpur first, then .gpua in the next call while the machine is still warm (30 s): GDAL's
# and OpenImageIO's chains did not fit in one call together; .gpu/libs.sh unpacks each once
# into /tmp/sl there and keeps it for later calls on the same machine. For example:
#   run(carry [.gl .gpu .gpur .gpub]): . .gpu/env.sh; . .gpu/libs.sh; ./.gpu/unpack-programs.sh;
#       /tmp/tb/strata_bench_sim --benchmark_filter=/gl/
#   run(carry [.gl .gpu .gpua]):        . .gpu/env.sh; . .gpu/libs.sh; cd /tmp/tb;
#       ./strata_render_terrain_tests
# (STRATA_SOURCE_DIR and STRATA_DATA_DIR are compiled in as this checkout's paths: libs.sh links
# /work/main to the checkout there and copies the DEMs to /work/shared/data.)
# Each run replaces .gpu, .gpub, .gpur and .gpua (they hold nothing but its own output); .gl is
# downloaded once. Checked on an H100 (2026-11-24): call 1 ran strata_bench_gl and
# strata_sim_gpu_tests, call 2 the render goldens and strata_render_tests.
#   scripts/gpu-carry.sh [--build-dir DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$root/build
[[ ${1:-} == --build-dir ]] && build=$(cd "$2" && pwd)
cd "$root"
data=$root/../shared/data
programs=(bench/strata_bench_sim bench/strata_bench_gl bench/strata_bench_render
  tests/sim/strata_sim_gpu_tests tests/gl/strata_gl_gpu_tests tests/render/strata_render_terrain_tests
  tests/render/strata_render_tests tests/procgen/strata_procgen_gpu_tests apps/strata)
for p in "${programs[@]}"; do [[ -x $build/$p ]] || { echo "gpu-carry: $build/$p is not built" >&2; exit 1; }; done
mkdir -p .git/info
for d in .gl .gpu .gpub .gpur .gpua; do grep -qx "/$d/" .git/info/exclude 2>/dev/null || echo "/$d/" >>.git/info/exclude; done
rm -rf .gpu .gpub .gpur .gpua
mkdir -p .gl .gpu .gpub .gpur/data .gpua/data /tmp/gpu-carry
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The GL loaders, as the device tool's README says.
if ! ls .gl/*.deb >/dev/null 2>&1; then
  o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/gpu-carry/lists)
  mkdir -p /tmp/gpu-carry/lists/partial
  apt-get "${o[@]}" update >/dev/null
  (cd .gl && apt-get "${o[@]}" download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
fi

# Libraries: everything the programs load except glibc's, the C++ runtime (the image's is newer)
# and GL's (the driver's). The ones every program needs go to .gpu.
skip='/libc\.so|/libm\.so|ld-linux|libpthread|libdl\.so|librt\.so|libresolv|libGL|libEGL|libGLX|libGLdispatch|libOpenGL|libstdc\+\+|libgcc_s'
deps() { for f in "$@"; do ldd "$f" | awk '$3 ~ /^\// {print $3}'; done | grep -v -E "$skip" | sort -u; }
pack() { sed 's|^/||' "$1" >"$1.rel" && tar -C / -chf - -T "$1.rel" | xz -T0 -6 >"$2"; }  # LIST OUT
deps "$build/bench/strata_bench_sim" "$build/bench/strata_bench_gl" >"$tmp/small"
pack "$tmp/small" .gpu/libs.tar.xz
deps "$build/bench/strata_bench_render" | grep -v -x -F -f "$tmp/small" >"$tmp/gdal"
deps "$build/apps/strata" "$build/tests/render/strata_render_tests" | grep -v -x -F -f "$tmp/small" |
  grep -v -x -F -f "$tmp/gdal" >"$tmp/oiio" || true
pack "$tmp/gdal" .gpur/libs.tar.xz
tar chf - -C / usr/share/proj/proj.db usr/share/proj/proj.ini usr/share/gdal | xz -T0 -6 >.gpur/share.tar.xz
pack "$tmp/oiio" .gpua/libs.tar.xz

# Programs and data.
mkdir -p "$tmp/tb"
for p in "${programs[@]}"; do strip -o "$tmp/tb/$(basename "$p")" "$build/$p"; done
tar cJf .gpub/programs.tar.xz -C "$tmp/tb" .
cp -r "$data/earth" "$data/mars" "$data/moon" .gpub/
cp "$data"/grand_canyon/*.tif .gpur/data/
cp -r "$data/rainier" .gpua/data/

cat >.gpu/env.sh <<'EOF'
# Sourced on the device machine first: the GL loaders, then the libraries every program needs.
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
[ -e /tmp/sl0/.done ] || { mkdir -p /tmp/sl0 && tar xJf .gpu/libs.tar.xz -C /tmp/sl0 && touch /tmp/sl0/.done; }
export LD_LIBRARY_PATH=/tmp/sl0/lib/x86_64-linux-gnu:/tmp/sl0/usr/lib/x86_64-linux-gnu
[ -e /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json ] &&
  export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
EOF
cat >.gpu/libs.sh <<'EOF'
# Sourced on the device machine after env.sh: unpacks the library tarballs carried in this call
# (once per machine, into /tmp/sl), puts the DEMs and the source tree where the programs were
# compiled to find them.
for t in .gpur/libs.tar.xz .gpur/share.tar.xz .gpua/libs.tar.xz; do
  [ -f "$t" ] || continue
  m=/tmp/sl/.done_$(echo "$t" | tr '/.' '__')
  [ -e "$m" ] || { mkdir -p /tmp/sl && tar xJf "$t" -C /tmp/sl && touch "$m"; }
done
export LD_LIBRARY_PATH=$LD_LIBRARY_PATH:/tmp/sl/lib/x86_64-linux-gnu:/tmp/sl/usr/lib/x86_64-linux-gnu:/tmp/sl/lib:/tmp/sl/usr/lib
export PROJ_DATA=/tmp/sl/usr/share/proj PROJ_LIB=/tmp/sl/usr/share/proj GDAL_DATA=/tmp/sl/usr/share/gdal
mkdir -p /work/shared/data/grand_canyon
for s in earth mars moon; do [ -d ".gpub/$s" ] && cp -r ".gpub/$s" /work/shared/data/; done
[ -d .gpua/data ] && cp -r .gpua/data/* /work/shared/data/
[ -d .gpur/data ] && cp .gpur/data/*.tif /work/shared/data/grand_canyon/
[ -e /work/main ] || ln -s "$PWD" /work/main
EOF
cat >.gpu/unpack-programs.sh <<'EOF'
#!/bin/sh
# On the device machine: the carried programs into /tmp/tb (kept while the machine stays warm).
rm -rf /tmp/tb && mkdir -p /tmp/tb && tar xJf .gpub/programs.tar.xz -C /tmp/tb && ls /tmp/tb
EOF
chmod +x .gpu/unpack-programs.sh
size() { du -sb "$@" | awk '{s += $1} END {printf "%.1f", s / 1048576}'; }
tree=$(git ls-files -z | xargs -0 du -cb | tail -1 | cut -f1)
echo "gpu-carry: call 1 carries .gl .gpu .gpur .gpub: $(size .gl .gpu .gpur .gpub) MiB + the tree $((tree / 1048576)) MiB"
echo "gpu-carry: call 2 carries .gl .gpu .gpua:       $(size .gl .gpu .gpua) MiB + the tree $((tree / 1048576)) MiB"
