#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The README's "Rangefinder" snippet must compile under the core's warnings and work: extract the
# first ```c block after "### Rangefinder", put its statics at file scope and the rest in main()
# after a map and a pose history (body 1 m above the origin, level), with a 2.05 m reading and
# the reading's time between the two poses; then the floor voxel under the sensor must be
# occupied and the voxel half-way down free.
set -euo pipefail
build=$1
out=$build/readme_ranges
mkdir -p "$out"
. "$(dirname "$0")/readme_snippet.sh"
readme_snippet "Rangefinder" "$out/snippet.c"
grep -q 'sizeof scratch, NULL);' "$out/snippet.c" || { echo "the snippet's insert call changed: update $0"; exit 1; }
{
  grep '^#include' "$out/snippet.c"
  echo '#include <stdio.h>'
  grep '^static ' "$out/snippet.c"
  echo 'static uint8_t arena[OCC_ARENA_BYTES(512, 2048)];'
  echo 'static occ_err_t last = OCC_ERR_STATE;'
  echo 'int main(void) {'
  echo '    occ_map_t map; occ_map_config_t cfg = occ_map_config_default(); cfg.resolution_m = 0.1f;'
  echo '    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) { return 1; }'
  echo '    occ_pose_sample_t ring[4]; occ_pose_history_t history; const occ_pose_history_cfg_t hc = {50000u, 0u};'
  echo '    occ_pose_t level = occ_pose_identity(); level.p.z = 1.0f;'
  echo '    if (occ_pose_history_init(&history, ring, 4, &hc) != OCC_OK || occ_pose_history_push(&history, 1000u, &level) != OCC_OK ||'
  echo '        occ_pose_history_push(&history, 2000u, &level) != OCC_OK) { return 1; }'
  echo '    const uint64_t t_us = 1500u; const float distance_m = 2.05f;'
  grep -v '^#include\|^static ' "$out/snippet.c" | sed 's|^\(.*sizeof scratch, NULL);.*\)$|\1\n    last = e;|'
  echo '    const occ_vec3_t floor_pt = {0.05f, 0.05f, -1.05f}, above = {0.05f, 0.05f, 0.05f};'
  echo '    if (last != OCC_OK || occ_map_state_at(&map, floor_pt) != OCC_STATE_OCCUPIED ||'
  echo '        occ_map_state_at(&map, above) != OCC_STATE_FREE) {'
  echo '        printf("README rangefinder snippet: unexpected result (%s)\n", occ_err_str(last)); return 1; }'
  echo '    printf("README rangefinder snippet ok: the floor voxel at z = -1.05 occupied, z = 0.05 free\n");'
  echo '    return occ_map_check(&map) == OCC_OK ? 0 : 1;'
  echo '}'
} > "$out/main.c"
gcc -std=c99 -Wall -Wextra -Werror -Wno-unused-variable -Iinclude "$out/main.c" "$build/libocc.a" -lm -o "$out/main"
"$out/main"
