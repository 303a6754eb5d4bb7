#!/usr/bin/env bash
# Renders the pictures of docs/coverage.md and the README with covrast itself. Needs
# ImageMagick only to crop and enlarge (installed here, not a build dependency). The test
# "docs: the pictures show what this build renders" fails when they are stale.
# Usage: scripts/make-doc-images.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/release}
if [ ! -x /usr/bin/convert ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends imagemagick >/dev/null
fi
out=docs/images
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for mode in aliased coverage-blend coverage; do
  "$build/covrast" render scenes/default.json -o "$tmp/default-$mode.png" --mode "$mode" --quiet
  # A 40x30 region where the sphere's silhouette crosses the sliver fan, enlarged 8x.
  /usr/bin/convert "$tmp/default-$mode.png" -crop 40x30+196+236 +repage -filter point \
    -resize 800% "$out/edge-$mode.png"
  "$build/covrast" render docs/scenes/seams.json -o "$tmp/seams-$mode.png" --mode "$mode" --quiet
  /usr/bin/convert "$tmp/seams-$mode.png" -crop 60x45+130+60 +repage -filter point \
    -resize 600% "$out/seams-$mode.png"
done
cp "$tmp/default-coverage.png" "$out/default-coverage.png"
"$build/covrast" render scenes/lit.json -o "$out/lit.png" --quiet
echo "wrote $out"
