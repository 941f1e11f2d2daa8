#!/usr/bin/env bash
# Runs every CMocka binary and every extra test step, counts results, prints one summary line
# "N passed, N failed" and exits non-zero on any failure.
# usage: run_all.sh BUILD_DIR "BINARIES" "MAKE_STEPS"
set -u
build=$1; bins=$2; steps=$3
pass=0; fail=0; failed_names=()
logdir=$build/test-logs; mkdir -p "$logdir"
for b in $bins; do
  name=$(basename "$b")
  log=$logdir/$name.log
  start=$(date +%s%N)
  CMOCKA_MESSAGE_OUTPUT=STDOUT "$b" >"$log" 2>&1; rc=$?
  ms=$(( ($(date +%s%N) - start) / 1000000 )); secs=$((ms / 1000)).$(( (ms % 1000) / 100 ))
  p=$(grep -aoE '^\[  PASSED  \] [0-9]+' "$log" | awk '{s+=$4} END {print s+0}')
  f=$(grep -aoE '^\[  FAILED  \] [0-9]+ test' "$log" | awk '{s+=$4} END {print s+0}')
  if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi   # crash, sanitizer abort or no summary
  if [ "$p" -eq 0 ] && [ "$f" -eq 0 ]; then f=1; fi     # a binary that ran no test is a failure
  pass=$((pass + p)); fail=$((fail + f))
  if [ "$f" -ne 0 ]; then failed_names+=("$name"); echo "FAIL $name ($p passed, $f failed, ${secs}s) - log: $log"; tail -n 30 "$log" | sed 's/^/    /';
  else echo "ok   $name ($p passed, ${secs}s)"; fi
done
for s in $steps; do
  log=$logdir/step-$s.log
  start=$(date +%s%N)
  make --no-print-directory "$s" >"$log" 2>&1; rc=$?
  ms=$(( ($(date +%s%N) - start) / 1000000 )); secs=$((ms / 1000)).$(( (ms % 1000) / 100 ))
  if [ "$rc" -eq 0 ]; then pass=$((pass + 1)); echo "ok   step $s (${secs}s)";
  else fail=$((fail + 1)); failed_names+=("step $s"); echo "FAIL step $s (${secs}s) - log: $log"; tail -n 30 "$log" | sed 's/^/    /'; fi
done
[ ${#failed_names[@]} -gt 0 ] && echo "failed: ${failed_names[*]}"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
