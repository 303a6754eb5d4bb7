#!/usr/bin/env bash
# Renders the pictures of docs/coverage.md and the README with covrast itself, and the
# screenshot of docs/ci.md with headless Chromium. Needs ImageMagick only to crop and enlarge
# (installed here, not a build dependency). The test "docs: the pictures show what this build
# renders" fails when the renders are stale.
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
"$build/covrast" render docs/scenes/clearcoat.json -o "$out/clearcoat.png" --quiet
"$build/covrast" render docs/scenes/sheen.json -o "$out/sheen.png" --quiet
"$build/covrast" render docs/scenes/iridescence.json -o "$out/iridescence.png" --quiet
"$build/covrast" render docs/scenes/anisotropy.json -o "$out/anisotropy.png" --quiet
"$build/covrast" render docs/scenes/transmission.json -o "$out/transmission.png" --quiet
# covrast test's HTML report (docs/ci.md): two cases, one of whose goldens is wrong (an
# aliased render), as Chromium shows the page. Paths relative to the manifest's folder.
mkdir -p "$tmp/ci/goldens"
ln -s "$PWD/scenes" "$tmp/ci/scenes"
cat >"$tmp/ci/goldens.json" <<'JSON'
{"defaults": {"size": "320x180"},
 "cases": [{"name": "boxes", "scene": "scenes/boxes.json", "golden": "goldens/boxes.png"},
           {"name": "default", "scene": "scenes/default.json", "golden": "goldens/default.png"}]}
JSON
covrast=$(realpath "$build/covrast")
(
  cd "$tmp/ci"
  "$covrast" test goldens.json --update --quiet >/dev/null
  "$covrast" render scenes/boxes.json -o goldens/boxes.png --size 320x180 --mode aliased --quiet
  "$covrast" test goldens.json --report report --quiet >/dev/null || true
  chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$tmp/profile" --window-size=1200,860 --screenshot="$tmp/ci-report.png" \
    "file://$tmp/ci/report/index.html" >/dev/null 2>&1
)
cp "$tmp/ci-report.png" "$out/ci-report.png"
echo "wrote $out"
