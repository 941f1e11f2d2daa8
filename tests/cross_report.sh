#!/usr/bin/env bash
# Size of every cross-compiled core object and the worst stack frame, per target.
set -eu
root=$1
for t in m4 m0; do
  [ -d "$root/$t" ] || continue
  echo "== $t: arm-none-eabi-size (bytes)"
  find "$root/$t" -name '*.o' | sort | xargs arm-none-eabi-size -t | sed 's|'"$root/$t/"'||'
  echo "== $t: largest stack frames (-fstack-usage)"
  find "$root/$t" -name '*.su' -exec cat {} + | sort -t$'\t' -k2 -n -r | head -5 | sed 's|'"$root/$t/"'||'
done
