#!/usr/bin/env bash
# The determinism promise on 64-bit ARM: cross-builds the command line for aarch64 with
# Debian's g++-aarch64-linux-gnu (cmake/aarch64-linux-gnu.cmake) into build/aarch64, renders
# bundled scenes in every mode under qemu-aarch64-static and requires the pixels to equal
# those of the given x86-64 build (default build/release/covrast), checked with
# `covrast compare --max-diff 0`; it also counts the PNG files that differ in bytes only.
# aarch64 builds compile the kernels for NEON only (CMakeLists.txt says why): each emulated
# CPU prints the Highway target it ran, which must be NEON. Installs what it needs first
# (scripts/setup.sh --aarch64).
# Usage: scripts/check-aarch64.sh [--quick] [X86_COVRAST]
#   --quick: one scene per mode on one emulated CPU, the test command's subset.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

quick=0
if [[ "${1:-}" == --quick ]]; then
  quick=1
  shift
fi
x86_bin=${1:-build/release/covrast}
[[ -x "$x86_bin" ]] || { echo "check-aarch64: no x86-64 covrast at $x86_bin" >&2; exit 1; }

bash scripts/setup.sh --aarch64
build=build/aarch64
log="$build.log"
echo "check-aarch64: cross-building the command line in $build (log: $log)"
if ! { cmake -S . -B "$build" -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
         -DCMAKE_BUILD_TYPE=Release -DCOVRAST_WERROR=ON -DCOVRAST_BUILD_TESTS=OFF \
         -DCOVRAST_BUILD_BENCHMARKS=OFF -DCOVRAST_WITH_OPENEXR=OFF &&
       cmake --build "$build" --target covrast_cli -j 2; } >"$log" 2>&1; then
  tail -40 "$log"
  exit 1
fi
arm_bin="$build/covrast"
file -b "$arm_bin" | grep -q 'ARM aarch64' || { echo "check-aarch64: $arm_bin is not aarch64" >&2; exit 1; }

# Emulated CPUs (QEMU_CPU is qemu-user's -cpu): a NEON-only core, and one with SVE, where
# Highway must still pick NEON (the only target compiled).
cpus=(cortex-a72 a64fx)
if [[ $quick -eq 1 ]]; then cpus=(cortex-a72); fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
pairs=0
differ=0
bytes_differ=0
render_pair() {  # scene (under scenes/, without .json) mode size
  local name="${1//[\/.]/_}-${2//:/_}-$3"
  local x86="$out/$name-x86.png"
  [[ -f "$x86" ]] || "$x86_bin" render "scenes/$1.json" -o "$x86" --mode "$2" --size "$3" --quiet
  local arm="$out/$name-arm.png"
  QEMU_CPU="$cpu" qemu-aarch64-static "$arm_bin" render "scenes/$1.json" -o "$arm" \
    --mode "$2" --size "$3" --quiet --threads 2
  pairs=$((pairs + 1))
  if ! "$x86_bin" compare "$x86" "$arm" --max-diff 0 >"$out/compare.txt" 2>&1; then
    echo "aarch64 ($simd) differs from x86-64: $1 --mode $2 --size $3"
    sed 's/^/  /' "$out/compare.txt"
    differ=$((differ + 1))
  elif ! cmp -s "$x86" "$arm"; then
    bytes_differ=$((bytes_differ + 1))
  fi
}
modes=(aliased msaa:4 ssaa:4 coverage coverage-blend fxaa)
for cpu in "${cpus[@]}"; do
  simd=$(QEMU_CPU="$cpu" qemu-aarch64-static "$arm_bin" render scenes/boxes.json \
    -o "$out/probe.png" --size 16x16 --quiet --stats | sed -n 's/.*"simd":"\([^"]*\)".*/\1/p')
  echo "check-aarch64: qemu -cpu $cpu: Highway target $simd"
  if [[ "$simd" != NEON ]]; then
    echo "check-aarch64: expected the NEON target, got '$simd'" >&2
    exit 1
  fi
  if [[ $quick -eq 1 ]]; then
    for i in "${!modes[@]}"; do
      scenes=(default boxes slivers near_plane lit overlap)
      render_pair "${scenes[$i]}" "${modes[$i]}" 160x90
    done
    render_pair lit reference 48x27
    # Image-based lighting and tone mapping: libm's sin, cos, acos, atan2 and log2 on both.
    render_pair studio coverage 160x90
    # The glTF material extensions' layers (clear coat, sheen, thin film: libm's pow, exp, cos).
    render_pair ../docs/scenes/clearcoat coverage 160x60
    render_pair ../docs/scenes/sheen coverage 160x90
    render_pair ../docs/scenes/iridescence coverage 160x60
  else
    for scene in default boxes slivers near_plane lit overlap sphere_closed studio; do
      for mode in "${modes[@]}"; do render_pair "$scene" "$mode" 160x90; done
    done
    render_pair default reference 48x27
    render_pair lit reference 48x27
    render_pair ../docs/scenes/clearcoat coverage 160x60
    render_pair ../docs/scenes/sheen coverage 160x90
    render_pair ../docs/scenes/iridescence coverage 160x60
  fi
done
echo "aarch64 vs x86-64: $pairs image pairs, $differ differ in pixels," \
  "$bytes_differ more differ only in file bytes"
[[ $differ -eq 0 ]]
