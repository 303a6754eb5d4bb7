#!/usr/bin/env bash
# Checks the determinism promise across compilers: builds the command line with clang into
# build/clang-check and renders scenes in every mode with it and with the g++ build given
# (default build/release/covrast); every PNG must be byte-identical.
# Usage: scripts/check-compilers.sh [GXX_COVRAST]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
gxx_bin=${1:-build/release/covrast}
clang_dir=build/clang-check
cmake -S . -B "$clang_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
  -DCOVRAST_BUILD_TESTS=OFF -DCOVRAST_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$clang_dir" --target covrast_cli -j 2 >/dev/null
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
pairs=0
differ=0
check() {  # scene mode size
  local name="$1-${2//:/_}"
  "$gxx_bin" render "scenes/$1.json" -o "$out/$name-gxx.png" --mode "$2" --size "$3" --quiet
  "$clang_dir/covrast" render "scenes/$1.json" -o "$out/$name-clang.png" --mode "$2" --size "$3" --quiet
  pairs=$((pairs + 1))
  if ! cmp -s "$out/$name-gxx.png" "$out/$name-clang.png"; then
    echo "compilers differ: $1 --mode $2 --size $3"
    differ=$((differ + 1))
  fi
}
for scene in default slivers boxes near_plane overlap; do
  for mode in aliased coverage coverage-blend msaa:4 msaa:16 ssaa:4 ssaa-grid:3; do
    check "$scene" "$mode" 320x180
  done
done
check sphere_grid aliased 1920x1080
check sphere_grid coverage 1920x1080
check default reference 96x54
echo "g++ vs clang: $pairs image pairs, $differ differ"
[ "$differ" -eq 0 ]
