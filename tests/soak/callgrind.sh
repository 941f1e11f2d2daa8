#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# callgrind.sh SOAK_BIN OUTDIR [soak args...] - instructions per occ_map_insert_cloud() call in
# the soak's steady state: 20 s of sensor time in a 4 MB arena (eviction running after ~5 s),
# counted by callgrind inside soak_insert() only (--toggle-collect), divided by the calls.
set -euo pipefail
bin=$1; out=$2; shift 2
mkdir -p "$out"
log=$out/callgrind.log
valgrind --tool=callgrind --toggle-collect=soak_insert --callgrind-out-file="$out/callgrind.out" \
  "$bin" "$@" --seconds 20 --arena-bytes 4000000 --watermark 12000 --check-every 0 --quiet \
  > "$log" 2> "$out/callgrind.err"
cat "$log"
calls=$(sed -n 's/.*insert calls \([0-9]*\).*/\1/p' "$log")
ir=$(sed -n 's/^summary: \([0-9]*\).*/\1/p' "$out/callgrind.out")
[ -n "$ir" ] || ir=$(sed -n 's/^totals: \([0-9]*\).*/\1/p' "$out/callgrind.out")
if [ -z "$calls" ] || [ -z "$ir" ] || [ "$calls" = 0 ]; then
  echo "callgrind: could not read the counts (see $out/callgrind.err)"; exit 1
fi
echo "callgrind: $ir instructions in $calls inserts: $((ir / calls)) instructions per insert" \
     "(occ_map_insert_cloud, scans of $(sed -n 's/.*(\([0-9]*\) scans, \([0-9]*\) sources, \([0-9]*\) points.*/\3/p' "$log") points on average)"
