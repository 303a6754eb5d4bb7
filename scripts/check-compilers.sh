#!/usr/bin/env bash
# Checks the second compiler of the design card and the determinism promise across
# compilers: builds everything (library, command line, tests, benchmarks) with clang and
# -Werror into build/clang-check, runs the test suite built by clang, and renders scenes in
# every mode with the clang and the given g++ build (default build/release/covrast); every
# PNG must be byte-identical.
# With --clang-build DIR it takes an existing clang build instead (the test command passes
# the fuzz preset's: clang, -Werror, everything, its suite run by ctest) and only renders.
# Usage: scripts/check-compilers.sh [--clang-build DIR] [GXX_COVRAST]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
clang_dir=
if [[ "${1:-}" == --clang-build ]]; then
  clang_dir=${2:?usage: scripts/check-compilers.sh [--clang-build DIR] [GXX_COVRAST]}
  shift 2
  grep -q '^CMAKE_CXX_COMPILER:.*clang' "$clang_dir/CMakeCache.txt" ||
    { echo "check-compilers: $clang_dir is not a clang build" >&2; exit 1; }
fi
gxx_bin=${1:-build/release/covrast}
if [[ -z "$clang_dir" ]]; then
  clang_dir=build/clang-check
  log="$clang_dir.log"
  echo "check-compilers: building everything with clang in $clang_dir (a few minutes; log: $log)"
  cmake -S . -B "$clang_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
    -DCOVRAST_WERROR=ON >"$log" 2>&1 || { tail -40 "$log"; exit 1; }
  # Ninja's "[k/n]" lines, one in 25 and the last, as progress; the whole log on failure.
  if ! cmake --build "$clang_dir" -j 2 2>&1 | tee -a "$log" |
    awk '/^\[[0-9]+\/[0-9]+\]/ { split(substr($1, 2), k, "/"); k[2] = k[2] + 0;
          if (k[1] % 25 == 0 || k[1] == k[2]) print "check-compilers: clang build " $1 }'; then
    tail -40 "$log"
    exit 1
  fi
  echo "check-compilers: running the clang-built test suite"
  "$clang_dir/tests/covrast_tests" --order decl >>"$log" 2>&1 || { tail -40 "$log"; exit 1; }
  echo "clang build: warnings as errors, test suite passed"
fi
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
for scene in default slivers boxes near_plane overlap lit; do
  for mode in aliased coverage coverage-blend msaa:4 msaa:16 ssaa:4 ssaa-grid:3 ssaa-cmj:4; do
    check "$scene" "$mode" 320x180
  done
done
check sphere_grid aliased 1920x1080
check sphere_grid coverage 1920x1080
check default reference 96x54
check lit reference 96x54
echo "g++ vs clang: $pairs image pairs, $differ differ"
[ "$differ" -eq 0 ]
