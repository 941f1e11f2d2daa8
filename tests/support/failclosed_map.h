/* SPDX-License-Identifier: BSD-3-Clause */
/* failclosed_map.h - the map the fail-closed tests share (test_failclosed.c,
 * test_stale_handles.c; tests/support/failclosed_map.c): 0.1 m, depth 16, one occupied voxel
 * x in [1.0, 1.1), y and z in [0, 0.1); a free 10 x 10 slab of voxels x, y in [-0.5, 0.5),
 * z in [0, 0.1); the rest unknown. */
#ifndef FAILCLOSED_MAP_H
#define FAILCLOSED_MAP_H

#include <stddef.h>
#include <stdint.h>

#include "occmap/occmap.h"

static const occ_vec3_t P_OCC = {1.05f, 0.05f, 0.05f};
static const occ_vec3_t P_FREE = {0.05f, 0.05f, 0.05f};

static inline occ_vec3_t v3(float x, float y, float z)
{
    occ_vec3_t v = {x, y, z};
    return v;
}

/* Build the map above on `arena`; a failure fails the test. */
void fc_make_map(occ_map_t *map, uint8_t *arena, size_t arena_bytes);
/* The key of p (must be inside the map). */
occ_key_t fc_key_of(const occ_map_t *map, occ_vec3_t p);
/* Teardown: forget the content (not occ_map_clear, which resets the counters); 0 when the map
 * checks and every block came back to the pools, else -1. */
int fc_forget_all(occ_map_t *map);
/* A node handle that reads unobserved and UNKNOWN, without children (what a refused node call
 * leaves). */
void fc_assert_unknown_node(const occ_node_t *n);

#endif
