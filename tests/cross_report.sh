#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Size of every cross-compiled core object and the worst stack frame, per target; then the worst
# call-chain stack of every public entry point against port/baremetal/stack_budgets.txt (fails
# the build when one is over its budget or its class limit; tests/stack_budget.py), also written
# to JSON when given (make fw-readme reads it).
set -eu
root=$1
json=${2:-}   # where stack_budget.py writes every entry point's bound and class (fw_table.py)
for t in m4 m0; do
  [ -d "$root/$t" ] || continue
  echo "== $t: arm-none-eabi-size (bytes)"
  find "$root/$t" -name '*.o' | sort | xargs arm-none-eabi-size -t | sed 's|'"$root/$t/"'||'
  echo "== $t: largest stack frames (-fstack-usage)"
  find "$root/$t" -name '*.su' -exec cat {} + | sort -t$'\t' -k2 -n -r | head -5 | sed 's|'"$root/$t/"'||'
done
m4_flags=${CROSS_M4_FLAGS:--mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard}
m0_flags=${CROSS_M0_FLAGS:--mcpu=cortex-m0plus -mthumb -mfloat-abi=soft}
python3 tests/stack_budget.py ${json:+--json "$json"} port/baremetal/stack_budgets.txt include/occmap \
  "m4=$root/m4/src=$m4_flags" "m0=$root/m0/src=$m0_flags"
echo "(libccd's support callbacks are not on these chains: src/query/collide_ccd.c is host-only, outside the firmware build)"
