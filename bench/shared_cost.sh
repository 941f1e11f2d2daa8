#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# shared_cost.sh OCCMAP OCCMAP_NOSHARED OUTDIR TUM_DIR - what the shared-map mode costs a map that
# is never shared (issue 20): instructions inside occ_map_insert_cloud() per scan (callgrind,
# --toggle-collect: exact and independent of the machine's load), `occmap build` of the default
# library against one built with -DOCC_SHARED=0, on scan.dat (SIMPLE, 0.1 m) and on the first
# TUM pioneer frame (SIMPLE, 0.05 m, every pixel; skipped without TUM_DIR).
set -euo pipefail
with=$1; without=$2; out=$3; tum=$4
mkdir -p "$out"
# instructions BIN NAME ARGS... - Ir inside occ_map_insert_cloud per scan ("scans" of the JSON).
instructions() {
  local bin=$1 name=$2; shift 2
  valgrind --tool=callgrind --toggle-collect=occ_map_insert_cloud \
    --callgrind-out-file="$out/$name.out" "$bin" build "$@" --json > "$out/$name.json" \
    2> "$out/$name.err"
  local ir scans
  ir=$(sed -n 's/^summary: \([0-9]*\).*/\1/p' "$out/$name.out")
  [ -n "$ir" ] || ir=$(sed -n 's/^totals: \([0-9]*\).*/\1/p' "$out/$name.out")
  scans=$(sed -n 's/.*"scans": \([0-9]*\).*/\1/p' "$out/$name.json")
  if [ -z "$ir" ] || [ -z "$scans" ] || [ "$scans" = 0 ]; then
    echo "shared-cost: could not read the counts of $name (see $out/$name.err)" >&2; exit 1
  fi
  echo $((ir / scans))
}
compare() {  # what name args...
  local what=$1 name=$2; shift 2
  local a b
  a=$(instructions "$with" "$name" "$@")
  b=$(instructions "$without" "$name-noshared" "$@")
  cmp -s <(sed 's/"integrate_ms": [0-9.e+-]*//' "$out/$name.json") \
         <(sed 's/"integrate_ms": [0-9.e+-]*//' "$out/$name-noshared.json") ||
    { echo "shared-cost: $what: the two builds made different maps"; exit 1; }
  local pct
  pct=$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%+.2f", 100.0 * (a - b) / b }')
  echo "shared-cost: $what: $a instructions per scan in occ_map_insert_cloud (default build," \
       "never shared) vs $b with -DOCC_SHARED=0: $((a - b)) more ($pct%)"
}
compare "scan.dat SIMPLE 0.1 m" scan --scan build/data/scan.dat --res 0.1 --method simple
if [ -r "$tum/my_association.txt" ]; then
  compare "TUM pioneer frame 1, SIMPLE 0.05 m, every pixel" tum --depth-dir "$tum" --frames 1 \
    --res 0.05 --method simple
else
  echo "SKIP: $tum absent: the TUM frame is not measured"
fi
