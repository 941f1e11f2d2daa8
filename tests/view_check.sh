#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# test-view (tools/view.mk): `occmap view` on a real map, opened in headless Chromium offline.
#  - the page is one file: no src/href to anything outside it, and Chromium runs with every host
#    name unresolvable;
#  - the number of occupied cubes the renderer drew (the page writes it into #status after its
#    first frame) equals the map's occupied leaf count from `occmap info --json`, and so does the
#    page's own array (and its free array holds occmap info's free leaf count);
#  - the screenshot is not blank and shows the height colours (tests/view_png.py).
# usage: view_check.sh BUILD_DIR MAP
set -uo pipefail
build=$1; map=$2
work=$build/view-test
mkdir -p "$work"
fail() { echo "FAIL test-view: $*"; exit 1; }
command -v chromium >/dev/null || { echo "SKIP: test-view: chromium not installed"; exit 77; }
[ -r "$map" ] || { echo "SKIP: test-view: $map absent (Debian's liboctomap-dev)"; exit 77; }

info=$("$build/occmap" info "$map" --json) || fail "occmap info --json $map"
leaves() { python3 -c 'import json,sys; print(json.loads(sys.argv[1])[sys.argv[2] + "_leaves"])' "$info" "$1"; }
want=$(leaves occupied); want_free=$(leaves free)
page=$work/map.html
"$build/occmap" view "$map" -o "$page" || fail "occmap view $map"
[ "$(grep -cE '<(script|link|img|iframe)[^>]*(src|href)=' "$page")" -eq 0 ] || fail "the page loads something from outside"
in_page=$(grep -o '"occupied": {"n": [0-9]*' "$page" | grep -o '[0-9]*$')
[ "$in_page" = "$want" ] || fail "the page holds $in_page occupied leaves, occmap info says $want"
in_page=$(grep -o '"free": {"n": [0-9]*' "$page" | grep -o '[0-9]*$')
[ "$in_page" = "$want_free" ] || fail "the page holds $in_page free leaves, occmap info says $want_free"

# Root in a container: no sandbox; WebGL on SwiftShader (no GPU); no network.
chrome=(chromium --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader
        --hide-scrollbars --window-size=960,540 --virtual-time-budget=2000
        --host-resolver-rules="MAP * ~NOTFOUND" --user-data-dir="$(realpath -m "$work/profile")")
url="file://$(realpath "$page")"
shot=$(realpath -m "$work/shot.png")
rm -f "$shot"
timeout 180 "${chrome[@]}" --screenshot="$shot" --dump-dom "$url" >"$work/dom.html" 2>"$work/chromium.log" \
  || fail "chromium (log: $work/chromium.log)"
status=$(grep -o '<div id="status"[^>]*>' "$work/dom.html")
err=$(sed -n 's/.*data-error="\([^"]*\)".*/\1/p' <<<"$status")
[ -z "$err" ] || fail "the page reports: $err"
drawn=$(sed -n 's/.*data-drawn="\([-0-9.]*\)".*/\1/p' <<<"$status")
[ "$drawn" = "$want" ] || fail "Chromium drew $drawn occupied cubes, the map has $want occupied leaves"
echo "PASS test-view: Chromium drew $drawn occupied cubes = occmap info's occupied_leaves ($want)"
[ -s "$shot" ] || fail "chromium wrote no screenshot (log: $work/chromium.log)"
python3 tests/view_png.py "$shot" || fail "the screenshot $shot looks blank"
echo "PASS test-view: screenshot $shot shows the map (offline page, $(stat -c %s "$page") bytes)"
