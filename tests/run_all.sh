#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Runs every CMocka binary and every extra test step, counts results, prints one summary line
# "N passed, N failed, N skipped" and exits non-zero on any failure.
#
# A skip is never a pass. It is seen as:
#  - in a CMocka binary: a test that called skip() (CMocka's "[  SKIPPED ] N test(s)" summary);
#  - in a step: exit status 77 (make reports "Error 77"), or any log line starting with "SKIP"
#    (the reason, e.g. "SKIP: ../shared/data/maps absent"), or a skipped CMocka test it ran.
# Under CI=true a skip is a failure (CI runs in a clean clone with ../shared present, as root:
# nothing there may skip): it is counted as failed and its reason printed.
# usage: run_all.sh BUILD_DIR "BINARIES" "MAKE_STEPS"
set -u
build=$1; bins=$2; steps=$3
ci=false; [ "${CI:-}" = true ] && ci=true
pass=0; fail=0; skipped=0; failed_names=(); skipped_names=()
logdir=$build/test-logs; mkdir -p "$logdir"

elapsed() { local ms=$(( ($(date +%s%N) - $1) / 1000000 )); echo "$((ms / 1000)).$(( (ms % 1000) / 100 ))"; }
# Sum of CMocka's "[  PASSED  ] N test(s)" (or FAILED / SKIPPED) lines in a log.
cmocka_count() { grep -aoE "^\[  $2 *\] [0-9]+ test" "$1" | awk '{s+=$(NF-1)} END {print s+0}'; }
# Why something skipped: its SKIP lines, else the names of the tests CMocka skipped.
skip_reason() {
  local why
  why=$(grep -a '^SKIP' "$1" | sort -u | head -n 5)
  [ -n "$why" ] || why=$(grep -aE '^\[  SKIPPED \] [^0-9]' "$1" | sort -u | head -n 5)
  [ -n "$why" ] || why="exit status 77 (skip) without a SKIP line"
  echo "$why" | sed 's/^/    /'
}
# A skip under CI=true is a failure; otherwise it is counted as skipped.
count_skip() {  # what count log
  if $ci; then
    fail=$((fail + $2)); failed_names+=("${1%% (*}")
    echo "FAIL $1: $2 skipped, and under CI=true a skip is a failure - log: $3"; skip_reason "$3"
  else
    skipped=$((skipped + $2)); skipped_names+=("${1%% (*}")
    echo "SKIP $1: $2 skipped - log: $3"; skip_reason "$3"
  fi
}

for b in $bins; do
  name=$(basename "$b")
  log=$logdir/$name.log
  start=$(date +%s%N)
  CMOCKA_MESSAGE_OUTPUT=STDOUT "$b" >"$log" 2>&1; rc=$?
  secs=$(elapsed "$start")
  p=$(cmocka_count "$log" PASSED); f=$(cmocka_count "$log" FAILED); s=$(cmocka_count "$log" SKIPPED)
  f=$((f + $(grep -acE '^\[  ERROR   \] [A-Za-z_]' "$log")))   # a failed setup or teardown (leak check)
  if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi   # crash, sanitizer abort or no summary
  if [ "$p" -eq 0 ] && [ "$f" -eq 0 ] && [ "$s" -eq 0 ]; then f=1; fi  # ran no test at all
  pass=$((pass + p)); fail=$((fail + f))
  if [ "$f" -ne 0 ]; then failed_names+=("$name"); echo "FAIL $name ($p passed, $f failed, $s skipped, ${secs}s) - log: $log"; tail -n 30 "$log" | sed 's/^/    /';
  elif [ "$s" -eq 0 ]; then echo "ok   $name ($p passed, ${secs}s)"; fi
  [ "$s" -eq 0 ] || count_skip "$name ($p passed, ${secs}s)" "$s" "$log"
done
for s in $steps; do
  log=$logdir/step-$s.log
  start=$(date +%s%N)
  make --no-print-directory "$s" >"$log" 2>&1; rc=$?
  secs=$(elapsed "$start")
  skip_exit=false; grep -aqE 'Error 77$' "$log" && skip_exit=true
  skip_line=false
  if grep -aq '^SKIP' "$log" || [ "$(cmocka_count "$log" SKIPPED)" -ne 0 ]; then skip_line=true; fi
  if [ "$rc" -ne 0 ] && ! $skip_exit; then
    fail=$((fail + 1)); failed_names+=("step $s"); echo "FAIL step $s (${secs}s) - log: $log"; tail -n 30 "$log" | sed 's/^/    /'
  elif $skip_exit || $skip_line; then
    count_skip "step $s" 1 "$log"
  else
    pass=$((pass + 1)); echo "ok   step $s (${secs}s)"
  fi
done
[ ${#skipped_names[@]} -gt 0 ] && echo "skipped: ${skipped_names[*]}"
[ ${#failed_names[@]} -gt 0 ] && echo "failed: ${failed_names[*]}"
echo "$pass passed, $fail failed, $skipped skipped"
[ "$fail" -eq 0 ]
