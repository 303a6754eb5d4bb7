#!/usr/bin/env bash
# Installs missing dependencies, builds one preset (default: release) and runs the whole test
# suite: ctest, then for the release preset the robustness steps (docs/testing.md): one clang
# build of everything under AddressSanitizer and UndefinedBehaviorSanitizer (the fuzz preset)
# runs the suite, replays the fuzz seeds and regressions, serves the g++-vs-clang byte-identity
# check (scripts/check-compilers.sh) and runs each fuzz target for a few seconds; a
# ThreadSanitizer build runs the [threads] tests; and the aarch64 byte-identity check runs
# under emulation (a subset).
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
step "ctest $preset" ctest --preset "$preset"
[ "$preset" = release ] || exit 0

# ASan + UBSan: one clang build (-O1, -Werror, everything) serves the whole suite, the fuzz
# targets and the comparison with g++. Sanitizer builds do not register the tests tagged
# [sanitizer-slow]; the black-box report, Chromium, install and documentation tests ran above
# (docs/testing.md says which and why).
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
step "build fuzz (clang, ASan+UBSan)" bash scripts/build.sh fuzz
step "ctest fuzz (ASan+UBSan)" ctest --preset fuzz -E '^(report_quick|report_in_chromium|install_consumer|docs_examples)$'
step "g++ vs clang" bash scripts/check-compilers.sh --clang-build build/fuzz "build/$preset/covrast"
step "fuzz targets, 10 s each" bash scripts/fuzz.sh --no-build 10

# TSan: the tests that run work on several threads, in a clang build whose kernels are
# compiled for one SIMD target (the other targets' kernels hold no shared state).
step "build tsan" bash -c 'cmake --preset tsan >/dev/null && cmake --build --preset tsan --target covrast_thread_tests'
step "TSan: [threads] tests, renders" bash scripts/tsan.sh

step "aarch64 (qemu, subset)" bash scripts/check-aarch64.sh --quick "build/$preset/covrast"
