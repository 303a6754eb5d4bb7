#!/usr/bin/env bash
# Installs missing dependencies, then configures and builds one CMake preset
# (CMakePresets.json; default: release). Usage: scripts/build.sh [preset]
set -euo pipefail

preset="${1:-release}"
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
cmake --preset "$preset"
cmake --build --preset "$preset"
