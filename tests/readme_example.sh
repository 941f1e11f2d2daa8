#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The README's embedding example must compile under the core's warnings and run: extract the
# first ```c block after "## Embedding", wrap its statements in main(), build against libocc.a.
set -euo pipefail
build=$1
out=$build/readme_example
mkdir -p "$out"
awk '/^## Embedding/{f=1} f&&/^```c/{g=1;next} g&&/^```/{exit} g{print}' README.md > "$out/snippet.c"
[ -s "$out/snippet.c" ] || { echo "no C example found in README.md"; exit 1; }
{
  grep '^#include' "$out/snippet.c"
  echo '#include <stdio.h>'
  grep '^static ' "$out/snippet.c"
  echo 'int main(void) {'
  grep -v '^#include\|^static ' "$out/snippet.c"
  echo '    if (e != OCC_OK || !(occ_map_state_at(&map, p) == OCC_STATE_OCCUPIED) || unsafe != true) {'
  echo '        printf("README example: unexpected result\n"); return 1; }'
  echo '    printf("README example ok: e=%d state=%d\n", (int)e, (int)occ_map_state_at(&map, p));'
  echo '    return occ_map_check(&map) == OCC_OK ? 0 : 1;'
  echo '}'
} > "$out/main.c"
gcc -std=c99 -Wall -Wextra -Werror -Wno-unused-variable -Iinclude "$out/main.c" "$build/libocc.a" -lm -o "$out/main"
"$out/main"
