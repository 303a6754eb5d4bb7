#!/usr/bin/env bash
# From a fresh checkout: installs what building needs (not the test-only packages), builds
# the covrast executable of the release preset (not the tests and benchmarks), renders
# scenes/default.json to out/default.png and prints the PNG's absolute path.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."

start=$SECONDS
bash scripts/setup.sh --build-only >&2
cmake --preset release >&2
cmake --build --preset release --target covrast_cli >&2
echo "render-default: built build/release/covrast in $((SECONDS - start)) s" >&2
mkdir -p out
build/release/covrast render scenes/default.json -o out/default.png --quiet
echo "$(pwd)/out/default.png"
