#!/usr/bin/env bash
# Installs missing dependencies, builds one preset (default: release) and runs the whole test
# suite with ctest. Usage: scripts/test.sh [preset]
set -euo pipefail

preset="${1:-release}"
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/build.sh "$preset"
ctest --preset "$preset"
