/* SPDX-License-Identifier: BSD-3-Clause */
/* evict_cli.c - `occmap build` flags for a fixed arena with eviction, and their JSON. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "evict_cli.h"

void evict_cli_init(evict_cli_t *const c)
{
    memset(c, 0, sizeof *c);
    c->policy = occ_evict_policy_default();
    occ_evict_out_init(&c->out);
}

/* A positive byte count with K/M/G suffixes (cli_parse_size), zero refused. */
static int parse_bytes(const char *s, size_t *out)
{
    size_t v = 0;
    if (!cli_parse_size(s, &v) || v == 0u) {
        return 0;
    }
    *out = v;
    return 1;
}

int evict_cli_parse(evict_cli_t *const c, const int argc, char **const argv, int *const i)
{
    const char *const a = argv[*i];
    const bool known = strcmp(a, "--arena-bytes") == 0 || strcmp(a, "--evict") == 0 ||
                       strcmp(a, "--keep-radius") == 0;
    if (!known) {
        return 0;
    }
    if (*i + 1 >= argc) {
        fprintf(stderr, "occmap build: %s needs a value\n", a);
        return -1;
    }
    const char *const v = argv[*i + 1];
    *i += 1;
    if (strcmp(a, "--arena-bytes") == 0) {
        if (!parse_bytes(v, &c->arena_bytes)) {
            fprintf(stderr, "occmap build: --arena-bytes wants a positive size, got '%s'\n", v);
            return -1;
        }
        c->fixed_arena = true;
    } else if (strcmp(a, "--evict") == 0) {
        if (strcmp(v, "robot") == 0) {
            c->policy.mode = OCC_EVICT_ROBOT;
        } else if (strcmp(v, "coarsen") == 0) {
            c->policy.mode = OCC_EVICT_COARSEN;
        } else {
            fprintf(stderr, "occmap build: --evict wants robot or coarsen, got '%s'\n", v);
            return -1;
        }
        c->evict = true;
    } else {
        char *end = NULL;
        const float r = strtof(v, &end);
        if (end == v || *end != '\0' || !isfinite(r) || r < 0.0f) {
            fprintf(stderr, "occmap build: --keep-radius wants metres >= 0, got '%s'\n", v);
            return -1;
        }
        c->policy.keep_radius_m = r;
        c->policy.keep_half_m.x = r;
        c->policy.keep_half_m.y = r;
        c->policy.keep_half_m.z = r;
    }
    return 1;
}

int evict_cli_finish(const evict_cli_t *const c)
{
    if (c->evict && !c->fixed_arena) {
        fprintf(stderr, "occmap build: --evict needs --arena-bytes\n");
        return -1;
    }
    if (c->fixed_arena && c->arena_bytes < OCC_ARENA_BYTES(1u, 1u)) {
        fprintf(stderr, "occmap build: --arena-bytes %zu is below one inner and one leaf block "
                        "(%zu bytes)\n", c->arena_bytes, (size_t)OCC_ARENA_BYTES(1u, 1u));
        return -1;
    }
    return 0;
}

occ_err_t evict_cli_insert(evict_cli_t *const c, occ_map_t *const map, const occ_vec3_t *const origin,
                           const occ_vec3_t *const points, const size_t n_points,
                           const occ_insert_params_t *const params, void *const scratch,
                           const size_t scratch_bytes, occ_insert_result_t *const res)
{
    if (params == NULL) {
        return OCC_ERR_ARG;
    }
    /* The core's automatic mode evicts around the origin before it fails for lack of blocks. */
    occ_insert_params_t p = *params;
    if (c->evict) {
        p.auto_evict = &c->policy;
        p.auto_evict_state = &c->out;
    }
    const uint64_t evictions_before = c->out.evictions;
    const occ_err_t e = occ_map_insert_cloud(map, origin, points, n_points, &p, scratch,
                                             scratch_bytes, res);
    if (origin != NULL && e != OCC_ERR_ARG && e != OCC_ERR_RANGE) {
        c->have_origin = true;
        c->last_origin = *origin;
    }
    if (c->out.evictions != evictions_before) {
        c->insert_retries++;
    }
    return e;
}

void evict_cli_print_json(FILE *const f, const evict_cli_t *const c)
{
    if (c->fixed_arena) {
        fprintf(f, "\"arena_bytes\": %zu, ", c->arena_bytes);
    } else {
        fprintf(f, "\"arena_bytes\": null, ");
    }
    fprintf(f, "\"evictions\": %llu, \"blocks_evicted\": %llu, ",
            (unsigned long long)c->out.evictions, (unsigned long long)c->out.blocks_freed);
    if (c->have_origin) {
        fprintf(f, "\"last_origin\": [%.6g, %.6g, %.6g]", (double)c->last_origin.x,
                (double)c->last_origin.y, (double)c->last_origin.z);
    } else {
        fprintf(f, "\"last_origin\": null");
    }
}
