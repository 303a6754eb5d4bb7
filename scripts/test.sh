#!/usr/bin/env bash
# Installs missing dependencies, builds one preset (default: release) and runs the whole test
# suite: for the release preset first the g++-vs-clang byte-identity check
# (scripts/check-compilers.sh), then ctest. Usage: scripts/test.sh [preset]
set -euo pipefail

preset="${1:-release}"
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/build.sh "$preset"
if [ "$preset" = release ]; then
  bash scripts/check-compilers.sh "build/$preset/covrast"
fi
ctest --preset "$preset"
