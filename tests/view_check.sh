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
        --host-resolver-rules="MAP * ~NOTFOUND")
url="file://$(realpath "$page")"
shot=$(realpath -m "$work/shot.png")
# Headless Chromium with a virtual-time budget now and then never exits (a known Chromium
# behaviour, not the page's: it draws once and has no timers). CI hit it once (killed after
# 180 s), this machine once in 25 runs; a run takes ~8 s here. An attempt that has not finished
# in 60 s is killed and retried with a fresh profile, at most 3 times. Each attempt's log is
# kept; only the outputs of an attempt that exited cleanly are judged below.
ran=0
for attempt in 1 2 3; do
  log=$work/chromium.$attempt.log
  rm -rf "$shot" "$work/dom.html" "$work/profile"
  timeout -k 5 60 "${chrome[@]}" --user-data-dir="$(realpath -m "$work/profile")" \
    --screenshot="$shot" --dump-dom "$url" >"$work/dom.html" 2>"$log"
  rc=$?
  if [ $rc -eq 0 ]; then ran=1; break; fi
  echo "test-view: chromium attempt $attempt exited $rc$([ $rc -ge 124 ] && echo ' (killed after 60 s)'); log $log:"
  grep -v 'dbus' "$log" | tail -5 | sed 's/^/    /'
done
[ $ran -eq 1 ] || fail "chromium failed 3 times (logs: $work/chromium.*.log)"
[ $attempt -eq 1 ] || echo "test-view: chromium finished on attempt $attempt"
status=$(grep -o '<div id="status"[^>]*>' "$work/dom.html")
err=$(sed -n 's/.*data-error="\([^"]*\)".*/\1/p' <<<"$status")
[ -z "$err" ] || fail "the page reports: $err"
drawn=$(sed -n 's/.*data-drawn="\([-0-9.]*\)".*/\1/p' <<<"$status")
[ "$drawn" = "$want" ] || fail "Chromium drew $drawn occupied cubes, the map has $want occupied leaves"
echo "PASS test-view: Chromium drew $drawn occupied cubes = occmap info's occupied_leaves ($want)"
[ -s "$shot" ] || fail "chromium wrote no screenshot (log: $log)"
python3 tests/view_png.py "$shot" || fail "the screenshot $shot looks blank"
echo "PASS test-view: screenshot $shot shows the map (offline page, $(stat -c %s "$page") bytes)"
