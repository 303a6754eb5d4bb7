#!/usr/bin/env bash
# Installs missing dependencies, builds one preset (default: release) and runs the whole test
# suite: for the release preset first the g++-vs-clang byte-identity check
# (scripts/check-compilers.sh), then ctest, then the robustness steps (docs/testing.md): the
# suite under AddressSanitizer and UndefinedBehaviorSanitizer (the fuzz preset's build, which
# also replays the fuzz seeds and regressions), each fuzz target for 20 s, and the aarch64
# byte-identity check under emulation (a subset).
# Each step prints its wall time. Usage: scripts/test.sh [preset]
set -euo pipefail

preset="${1:-release}"
cd "$(dirname "${BASH_SOURCE[0]}")/.."

step() {  # NAME COMMAND...: runs the command and prints its wall time
  local name=$1 start=$SECONDS
  shift
  echo "test: $name"
  "$@"
  echo "test: $name: $((SECONDS - start)) s"
}

step "build $preset" bash scripts/build.sh "$preset"
if [ "$preset" = release ]; then
  step "g++ vs clang" bash scripts/check-compilers.sh "build/$preset/covrast"
fi
step "ctest $preset" ctest --preset "$preset"
[ "$preset" = release ] || exit 0

# ASan + UBSan: one clang build (-O1) serves the whole suite and the fuzz targets. Sanitizer
# builds do not register the tests tagged [sanitizer-slow]; the black-box report, Chromium and
# install tests ran above (docs/testing.md says which and why).
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
step "build fuzz (ASan+UBSan)" bash scripts/build.sh fuzz
step "ctest fuzz (ASan+UBSan)" ctest --preset fuzz -E '^(report_quick|report_in_chromium|install_consumer)$'
step "fuzz targets, 20 s each" bash scripts/fuzz.sh --no-build 20

# No TSan step: with Debian's oneTBB (not built with TSan) the [threads] tests give about a
# thousand reports, all on data handed between workers through TBB (docs/testing.md).

step "aarch64 (qemu, subset)" bash scripts/check-aarch64.sh --quick "build/$preset/covrast"
