#!/usr/bin/env bash
# Installs the Debian packages covrast needs to build and test (Debian 12); with --build-only,
# just what building the executable needs (no clang). Idempotent: asks
# dpkg-query which packages are missing and installs only those; when none is missing it does
# not call apt-get at all. Runs as root (the CI case) or through sudo when available.
set -euo pipefail

# What building the covrast executable needs (configuring also finds Catch2 and Google
# Benchmark, so they are here too: two small header/library packages).
build_packages=(
  cmake ninja-build g++ pkg-config
  libglm-dev libtbb-dev libspng-dev libturbojpeg0-dev libstb-dev catch2 libbenchmark-dev libhwy-dev
  nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libcli11-dev libdraco-dev
)
# What the whole test suite needs besides: clang for the second-compiler check, python3 for
# the scene and report scripts, chromium to load covrast test's HTML report headless.
test_packages=(clang python3 chromium)

# Usage: scripts/setup.sh [--build-only]
packages=("${build_packages[@]}")
if [[ "${1:-}" != --build-only ]]; then
  packages+=("${test_packages[@]}")
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
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing[@]}"
