#!/usr/bin/env bash
# Builds the fuzz targets (the `fuzz` preset: clang, libFuzzer, ASan, UBSan; docs/testing.md)
# and runs each for SECONDS, one after the other, from the committed seeds
# (tests/fuzz/corpus/NAME) plus what earlier runs found (build/fuzz/corpus/NAME, which
# grows), with the target's dictionary. A crash, a sanitizer report, a leak, a timeout
# (-timeout, default 30 s per input) or running out of memory (-rss_limit_mb, 2048) stops
# that target and leaves the input in build/fuzz/findings/; the script runs the others and
# exits 1 when any target found something. Replay a finding with
#   build/fuzz/tests/fuzz/fuzz_NAME build/fuzz/findings/NAME-crash-...
# Usage: scripts/fuzz.sh [--no-build] SECONDS [NAME...]
#   NAME: scene_json obj gltf png manifest render (default: all)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build=1
if [[ "${1:-}" == --no-build ]]; then
  build=0
  shift
fi
seconds=${1:?usage: scripts/fuzz.sh [--no-build] SECONDS [NAME...]}
shift
names=("$@")
if [[ ${#names[@]} -eq 0 ]]; then names=(scene_json obj gltf png manifest render); fi
targets=()
for name in "${names[@]}"; do targets+=("fuzz_$name"); done

if [[ $build -eq 1 ]]; then
  bash scripts/setup.sh
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz --target "${targets[@]}"
fi

findings=build/fuzz/findings
mkdir -p "$findings"
failed=()
for name in "${names[@]}"; do
  corpus=build/fuzz/corpus/$name
  mkdir -p "$corpus"
  dict=()
  if [[ -f tests/fuzz/dict/$name.dict ]]; then dict=(-dict="tests/fuzz/dict/$name.dict"); fi
  log=$findings/$name.log
  echo "fuzz: $name for ${seconds}s (log: $log)"
  # New inputs go into the first directory; the committed seeds are only read.
  if build/fuzz/tests/fuzz/fuzz_"$name" -max_total_time="$seconds" -timeout=30 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$findings/$name-" "${dict[@]}" \
    "$corpus" "tests/fuzz/corpus/$name" >"$log" 2>&1; then
    # libFuzzer's final stats: executions, their rate and the corpus size.
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
    echo "fuzz: $name: no finding ($runs inputs, $rate/s, corpus $(ls "$corpus" | wc -l) files)"
  else
    echo "fuzz: $name: FINDING, see $log:"
    grep -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error|covrast fuzz:|artifact_prefix|Test unit written)' \
      "$log" | head -8 | sed 's/^/  /'
    failed+=("$name")
  fi
done
if [[ ${#failed[@]} -gt 0 ]]; then
  echo "fuzz: findings in: ${failed[*]}"
  exit 1
fi
echo "fuzz: ${#names[@]} targets, ${seconds}s each, no finding"
