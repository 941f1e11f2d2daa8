/* SPDX-License-Identifier: BSD-3-Clause */
/* lookup_probes.h - probe points for the point-lookup tests (test_lookup_index, test_lookup_batch:
 * every answer must equal occ_map_state_at), the real maps they load and a hand-made map
 * (prefix lp_). */
#ifndef OCC_LOOKUP_PROBES_H_INCLUDED
#define OCC_LOOKUP_PROBES_H_INCLUDED

#include <stddef.h>
#include <stdint.h>

#include "occmap/occmap.h"

#define LP_GEB079 "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"
#define LP_FR079 "../shared/data/maps/fr_079_t1_model.ot"

/* A hand-made map (0.1 m, depth 16, OctoMap's defaults): voxel (0.05, 0.05, 0.05) occupied (key
 * 32768 per axis), the level-3 node of (1.0, 1.0, 1.0) free (keys 32778 -> node 32776..32783
 * per axis: [0.8, 1.6) m), nothing else observed. */
typedef struct {
    occ_map_t map;
    uint8_t arena[OCC_ARENA_BYTES(64, 64)];
} lp_small_t;
void lp_small_init(lp_small_t *s);

/* Points make_probes writes at most for n_random random ones. */
size_t lp_probe_cap(size_t n_random);
/* Probes for a map whose observed box is [mn, mx] (metres): n_random random in the box grown by
 * 10 % (every 64th far off the map), n_random / 4 x 3 on voxel borders and one float ulp either
 * side, then NaN, Inf and -Inf in each coordinate. A fixed xorshift sequence continued from call
 * to call (reproducible per test binary). Returns the count (<= lp_probe_cap(n_random)). */
size_t lp_make_probes(const occ_map_t *map, occ_vec3_t mn, occ_vec3_t mx, occ_vec3_t *pts,
                      size_t n_random);
/* Load a map file into *map (arena malloc'd: free() the return value). NULL, with a SKIP line
 * printed, when the file is absent (a ../shared map on a machine without it); any load error
 * fails the test. */
void *lp_load_map(const char *path, occ_map_t *map);

#endif
