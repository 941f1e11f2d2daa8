/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * evict_cli.h - the `occmap build` flags for a fixed arena with eviction (issue 9):
 *   --arena-bytes N          build inside one arena of exactly N bytes (K/M/G suffixes), allocated
 *                            once; without --evict a full arena makes inserts fail (NOMEM)
 *   --evict robot|coarsen    evict far content when the arena is short (occ_evict.h)
 *   --keep-radius R          protected radius around the sensor, metres (default 3)
 * and the JSON members the build prints: "arena_bytes", "evictions", "blocks_evicted",
 * "last_origin". Self-contained (stdio only), so tests can compile it in.
 */
#ifndef OCC_TOOLS_EVICT_CLI_H_INCLUDED
#define OCC_TOOLS_EVICT_CLI_H_INCLUDED

#include <stdio.h>

#include "occmap/occmap.h"
#include "occmap/occ_evict.h"

typedef struct {
    bool fixed_arena;          /* --arena-bytes given */
    size_t arena_bytes;
    bool evict;                /* --evict given */
    occ_evict_policy_t policy; /* mode from --evict, keep_radius_m from --keep-radius */
    occ_evict_out_t out;       /* eviction state and totals */
    bool have_origin;
    occ_vec3_t last_origin;    /* sensor origin of the last scan given to evict_cli_insert */
    unsigned insert_retries;   /* inserts that needed an eviction first */
} evict_cli_t;

void evict_cli_init(evict_cli_t *c);

/* Look at argv[*i]: if it is one of the flags above, consume it and its value (advancing *i
 * past the value) and return 1; return 0 for any other argument; -1 after printing a message
 * to stderr for a bad or missing value (--keep-radius without --evict is accepted). */
int evict_cli_parse(evict_cli_t *c, int argc, char **argv, int *i);

/* After parsing: -1 with a message when the flags do not fit together (--evict or
 * --keep-radius without --arena-bytes, an arena smaller than one inner + one leaf block). */
int evict_cli_finish(const evict_cli_t *c);

/* occ_map_insert_cloud() with the automatic mode: on OCC_ERR_NOMEM (pools short) and --evict,
 * evict around `origin` (occ_map_evict_for, doubling the request from 4096 blocks of each
 * kind) and retry, until the insert fits or nothing evictable is left (then OCC_ERR_NOMEM).
 * Records the origin as last_origin. Other errors are returned as they come. */
occ_err_t evict_cli_insert(evict_cli_t *c, occ_map_t *map, const occ_vec3_t *origin,
                           const occ_vec3_t *points, size_t n_points,
                           const occ_insert_params_t *params, void *scratch,
                           size_t scratch_bytes, occ_insert_result_t *res);

/* Print `"arena_bytes": N, "evictions": N, "blocks_evicted": N, "last_origin": [x, y, z]`
 * (members only, no braces and no trailing comma; last_origin is null before any scan;
 * arena_bytes is null without --arena-bytes). */
void evict_cli_print_json(FILE *f, const evict_cli_t *c);

#endif
