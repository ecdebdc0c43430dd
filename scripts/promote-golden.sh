#!/usr/bin/env bash
# Promotes approved golden-image results: copies build/test-output/render/<name>.actual.png to
# tests/render/golden/<name>.png. Look at each actual image (and its .diff.png) first.
#   scripts/promote-golden.sh [--build-dir DIR] NAME...   promote these
#   scripts/promote-golden.sh [--build-dir DIR] --all     promote every *.actual.png there
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir="$root/build"
names=()
all=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    --all) all=1; shift ;;
    -*) echo "promote-golden.sh: unknown option '$1'" >&2; exit 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
out="$build_dir/test-output/render"
if [ "$all" -eq 1 ]; then
  for f in "$out"/*.actual.png; do
    [ -e "$f" ] || { echo "promote-golden.sh: no *.actual.png in $out" >&2; exit 1; }
    n=$(basename "$f" .actual.png)
    names+=("$n")
  done
fi
[ ${#names[@]} -gt 0 ] || { echo "usage: promote-golden.sh [--build-dir DIR] NAME... | --all" >&2; exit 2; }
for n in "${names[@]}"; do
  src="$out/$n.actual.png"
  [ -f "$src" ] || { echo "promote-golden.sh: $src does not exist (run the gpu tests first)" >&2; exit 1; }
  cp "$src" "$root/tests/render/golden/$n.png"
  echo "promoted $n"
done
