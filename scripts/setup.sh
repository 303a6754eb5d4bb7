#!/usr/bin/env bash
# Installs the Debian packages covrast needs to build and test (Debian 12); with --build-only,
# just what building the executable needs (no clang); with --aarch64, what cross-building for
# 64-bit ARM and running it under emulation needs (scripts/check-aarch64.sh): the arm64
# architecture is added to dpkg first if it is missing. With --list, prints the packages of the
# chosen set on one line, space-separated, and installs nothing (CI images and docs/ci.md
# install from it). Idempotent: asks
# dpkg-query which packages are missing and installs only those; when none is missing it does
# not call apt-get at all. Runs as root (the CI case) or through sudo when available.
set -euo pipefail

# What building the covrast executable needs (configuring also finds Catch2 and Google
# Benchmark, so they are here too: two small header/library packages).
build_packages=(
  cmake ninja-build g++ pkg-config
  libglm-dev libtbb-dev libspng-dev libturbojpeg0-dev libstb-dev catch2 libbenchmark-dev libhwy-dev
  nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libcli11-dev libdraco-dev libopenexr-dev libwebp-dev libmeshoptimizer-dev
)
# What the whole test suite needs besides: clang for the second-compiler check, python3 for
# the scene and report scripts, chromium to load covrast test's HTML report headless.
# libclang-rt-14-dev holds libFuzzer and the sanitizer runtimes (the fuzz, asan, ubsan and
# tsan presets); llvm-14 holds llvm-symbolizer, without which sanitizer reports have no
# function names and tests/tsan.supp (which matches function names) matches nothing
# (clang-14 only recommends it, and recommendations are not installed here).
test_packages=(clang libclang-rt-14-dev llvm-14 python3 chromium)
# Cross-building for aarch64: the cross compiler, the emulator, `file` (the script checks the
# executable's architecture) and the arm64 builds of every library with compiled code or an
# architecture-specific package (the header-only glm, nlohmann-json and CLI11 are
# architecture-independent and come with the build packages).
aarch64_packages=(
  g++-aarch64-linux-gnu qemu-user-static file
  libtbb-dev:arm64 libhwy-dev:arm64 libspng-dev:arm64 libstb-dev:arm64 libdraco-dev:arm64
  libtinyobjloader-dev:arm64 libtinygltf-dev:arm64 libturbojpeg0-dev:arm64 libwebp-dev:arm64
  libmeshoptimizer-dev:arm64
)

# Usage: scripts/setup.sh [--list] [--build-only | --aarch64]
set_name="test"
list=0
for arg in "$@"; do
  case "$arg" in
    --build-only) set_name=build ;;
    --aarch64) set_name=aarch64 ;;
    --list) list=1 ;;
    *)
      echo "setup: error: unknown argument '$arg' (usage: scripts/setup.sh [--list] [--build-only | --aarch64])" >&2
      exit 2
      ;;
  esac
done
packages=("${build_packages[@]}")
case "$set_name" in
  build) ;;
  aarch64) packages+=("${aarch64_packages[@]}") ;;
  test) packages+=("${test_packages[@]}") ;;
esac
if [[ $list -eq 1 ]]; then
  echo "${packages[*]}"
  exit 0
fi

missing=()
for package in "${packages[@]}"; do
  # One line per installed architecture (e.g. amd64 and i386); any "installed" one will do.
  status=$(dpkg-query -W -f='${db:Status-Status}\n' "$package" 2>/dev/null || true)
  if ! grep -qx installed <<<"$status"; then
    missing+=("$package")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "setup: all ${#packages[@]} packages are installed"
  exit 0
fi

if [[ $(id -u) -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "setup: error: missing packages (${missing[*]}) and not root, and sudo is not available" >&2
  exit 1
fi

echo "setup: installing ${missing[*]}"
if [[ "$set_name" == aarch64 ]] && ! dpkg --print-foreign-architectures | grep -qx arm64; then
  echo "setup: adding the arm64 architecture to dpkg"
  "${as_root[@]}" dpkg --add-architecture arm64
fi
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing[@]}"
