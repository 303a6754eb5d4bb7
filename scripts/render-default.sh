#!/usr/bin/env bash
# From a fresh checkout: installs dependencies, builds the release preset, renders
# scenes/default.json to out/default.png and prints the PNG's absolute path.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/build.sh release >&2
mkdir -p out
build/release/covrast render scenes/default.json -o out/default.png --quiet
echo "$(pwd)/out/default.png"
