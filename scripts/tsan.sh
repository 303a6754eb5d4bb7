#!/usr/bin/env bash
# ThreadSanitizer over the work covrast spreads across threads, in the tsan preset's build
# (clang, -fsanitize=thread; build it with
#   cmake --preset tsan && cmake --build --preset tsan --target covrast_thread_tests):
# a canary (tests/tsan/canary.cpp) that must pass ordered hand-offs and must have its
# deliberate race reported, the Catch2 tests tagged [threads] (byte identity over thread
# counts and tiles, the parallel loop of the public API), then the command line rendering
# bundled scenes in every mode on two threads. Any report fails the run (halt_on_error). oneTBB's own bookkeeping is
# suppressed (tests/tsan.supp says why and how narrowly); covrast's hand-offs through TBB
# are announced to TSan in src/core/fork_join.hpp.
# Usage: scripts/tsan.sh [BUILD_DIR]   (default build/tsan)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
build=${1:-build/tsan}
# The suppressions name functions, so reports must be symbolized: without llvm-symbolizer
# every frame is <null>, nothing matches, and oneTBB's bookkeeping shows up as races.
symbolizer=
for candidate in /usr/lib/llvm-14/bin/llvm-symbolizer "$(command -v llvm-symbolizer || true)"; do
  if [[ -n "$candidate" && -x "$candidate" ]]; then
    symbolizer=$candidate
    break
  fi
done
if [[ -z "$symbolizer" ]]; then
  echo "tsan: error: llvm-symbolizer not found (Debian package llvm-14, which scripts/setup.sh" \
    "installs): without it TSan's reports have no function names and tests/tsan.supp matches" \
    "nothing" >&2
  exit 1
fi
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/tests/tsan.supp:external_symbolizer_path=$symbolizer"

# The canary first: the same suppressions must pass ordered hand-offs and catch a real race.
"$build/tests/tsan_canary" ordered
if "$build/tests/tsan_canary" racy >"$build/tsan-canary.log" 2>&1 ||
  ! grep -q 'SUMMARY: ThreadSanitizer: data race .*canary.cpp' "$build/tsan-canary.log"; then
  echo "tsan: the canary's deliberate race was not reported (see $build/tsan-canary.log)" >&2
  exit 1
fi
echo "tsan: canary: ordered hand-offs pass, the deliberate race is reported"

echo "tsan: covrast_thread_tests [threads]"
"$build/tests/covrast_thread_tests" "[threads]"

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
renders=0
for scene in default lit overlap sphere_grid; do
  for mode in aliased coverage coverage-blend msaa:4 ssaa:4 fxaa; do
    "$build/covrast" render "scenes/$scene.json" -o "$out/image.png" --mode "$mode" \
      --size 160x90 --threads 2 --quiet
    renders=$((renders + 1))
  done
done
"$build/covrast" render scenes/lit.json -o "$out/image.png" --mode reference --size 24x16 \
  --threads 2 --quiet
echo "tsan: [threads] tests and $((renders + 1)) renders on 2 threads, no report"
