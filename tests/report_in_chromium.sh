#!/usr/bin/env bash
# ctest: the HTML report of `covrast test` in headless Chromium. A manifest of two cases, one
# of whose goldens is wrong, gives a report; Chromium loads it offline (the page must not
# need the network) and runs its script: the DOM must show the zoom set by the script, the
# failing case with its three images sized by it, and the passing case only in the table;
# a screenshot of the page is written (build/.../report-chromium/shot.png) for a person to
# look at. Usage: report_in_chromium.sh COVRAST SOURCE_DIR OUT_DIR
set -euo pipefail
covrast=$1
source_dir=$2
out=$3
rm -rf "$out"
mkdir -p "$out/goldens"
cat >"$out/manifest.json" <<JSON
{"defaults": {"size": "96x54"},
 "cases": [
  {"name": "boxes", "scene": "$source_dir/scenes/boxes.json", "golden": "goldens/boxes.png"},
  {"name": "default", "scene": "$source_dir/scenes/default.json", "golden": "goldens/default.png"}]}
JSON
"$covrast" test "$out/manifest.json" --update --quiet >/dev/null
"$covrast" render "$source_dir/scenes/boxes.json" -o "$out/goldens/boxes.png" --size 96x54 \
  --mode aliased --quiet
if "$covrast" test "$out/manifest.json" --report "$out/report" --quiet >"$out/test.txt"; then
  echo "FAIL: covrast test passed with a wrong golden"
  exit 1
fi

flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run
  --disable-background-networking --disable-component-update --disable-sync
  --user-data-dir="$out/profile" --window-size=1200,900)
page="file://$out/report/index.html"
timeout 120 chromium "${flags[@]}" --dump-dom "$page" >"$out/dom.html" 2>"$out/chromium.log"
timeout 120 chromium "${flags[@]}" --screenshot="$out/shot.png" "$page" >>"$out/chromium.log" 2>&1

check() {  # check DESCRIPTION PATTERN: PATTERN must occur in the DOM after the script ran
  if ! grep -Eq "$2" "$out/dom.html"; then
    echo "FAIL: $1 (pattern '$2' not in $out/dom.html)"
    exit 1
  fi
}
check "the script set the zoom" 'id="zoom-value">[1-8]x<'
check "the failing case has a section" '<div class="case" id="boxes">'
check "its golden is sized by the zoom" '<img alt="golden" data-width="96" src="data:image/png;base64,[^"]+" style="width: [0-9]+px;"'
check "its heat map is shown" '<img alt="difference'
check "the passing case is in the table" '<td>default</td><td class="passed">passed</td>'
if grep -q '<div class="case" id="default">' "$out/dom.html"; then
  echo "FAIL: the passing case is shown as a failure"
  exit 1
fi
# The screenshot is a PNG of the window's size.
python3 - "$out/shot.png" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read(24)
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
width, height = struct.unpack(">II", data[16:24])
assert (width, height) == (1200, 900), f"screenshot is {width}x{height}"
PY
echo "report in Chromium: 6 checks passed, screenshot $out/shot.png"
