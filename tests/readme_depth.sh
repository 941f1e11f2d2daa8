#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The README's "Depth camera" snippet must compile under the core's warnings and work: extract the
# first ```c block after "### Depth camera", put its statics at file scope and the rest in main()
# after a map, a pose history (body at the origin, level, looking east) and a frame (a wall
# 2.05 m from the camera, which is mounted 0.1 m ahead of the body), then check the wall voxel.
set -euo pipefail
build=$1
out=$build/readme_depth
mkdir -p "$out"
. "$(dirname "$0")/readme_snippet.sh"
readme_snippet "Depth camera" "$out/snippet.c"
{
  grep '^#include' "$out/snippet.c"
  echo '#include <stdio.h>'
  grep '^static ' "$out/snippet.c"
  echo 'static uint8_t arena[OCC_ARENA_BYTES(2048, 8192)];'
  echo 'static occ_err_t last = OCC_ERR_STATE; static size_t hits;'
  echo 'int main(void) {'
  echo '    occ_map_t map; occ_map_config_t cfg = occ_map_config_default(); cfg.resolution_m = 0.1f;'
  echo '    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) { return 1; }'
  echo '    occ_pose_sample_t ring[4]; occ_pose_history_t hist; const occ_pose_history_cfg_t hc = {50000u, 0u};'
  echo '    const occ_pose_t level = occ_pose_identity();'
  echo '    if (occ_pose_history_init(&hist, ring, 4, &hc) != OCC_OK || occ_pose_history_push(&hist, 1000u, &level) != OCC_OK ||'
  echo '        occ_pose_history_push(&hist, 2000u, &level) != OCC_OK) { return 1; }'
  echo '    const uint64_t frame_us = 1500u;'
  echo '    for (int v = 0; v < 120; v++) { for (int u = 0; u < 160; u++) { depth_mm[v][u] = 2050u; } }'
  grep -v '^#include\|^static ' "$out/snippet.c" | sed 's|^\(.*sizeof scratch, &r);.*\)$|\1\n    last = e; hits = r.insert.voxels_occupied;|'
  echo '    const occ_vec3_t wall = {2.15f, 0.0f, 0.0f}, before = {1.15f, 0.0f, 0.0f};'
  echo '    if (last != OCC_OK || hits == 0u || occ_map_state_at(&map, wall) != OCC_STATE_OCCUPIED ||'
  echo '        occ_map_state_at(&map, before) != OCC_STATE_FREE) {'
  echo '        printf("README depth snippet: unexpected result (%s, %zu hits)\n", occ_err_str(last), hits); return 1; }'
  echo '    printf("README depth snippet ok: %zu voxels hit, the wall at x = 2.15 occupied\n", hits);'
  echo '    return occ_map_check(&map) == OCC_OK ? 0 : 1;'
  echo '}'
} > "$out/main.c"
gcc -std=c99 -Wall -Wextra -Werror -Wno-unused-variable -Iinclude "$out/main.c" "$build/libocc.a" -lm -o "$out/main"
"$out/main"
