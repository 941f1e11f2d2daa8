/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_stats.c - `occmap stats --scan FILE --res R [--json]`: mark a scan's endpoints occupied
 * (one hit per distinct voxel, no ray clearing) and print the map statistics. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "occmap/host/occ_scan.h"

static void usage(void)
{
    printf("usage: occmap stats --scan FILE --res R [--depth D] [--arena-bytes N] [--json]\n"
           "  Reads a plain 'x y z' scan (metres), marks each endpoint voxel occupied once,\n"
           "  prints the map statistics (JSON keys: see README).\n");
}

static int cmp_code(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a, y = *(const occ_code_t *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

typedef struct {
    const char *scan;
    float res;
    bool json;
    unsigned depth;
    size_t arena_bytes;
} stats_opts_t;

/* argv into `o`: -1 to go on, or the exit status (0 after --help, 2 after a message). */
static int parse_args(stats_opts_t *o, int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        const bool has = i + 1 < argc;
        if (strcmp(argv[i], "--help") == 0) {
            usage();
            return 0;
        } else if (strcmp(argv[i], "--scan") == 0 && has) {
            o->scan = argv[++i];
        } else if (strcmp(argv[i], "--res") == 0 && has) {
            if (!cli_parse_floats(argv[++i], &o->res, 1) || !(o->res > 0.0f)) {
                cli_error("stats", "bad --res '%s'", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--depth") == 0 && has) {
            o->depth = (unsigned)strtoul(argv[++i], NULL, 10); /* occ_map_init checks it */
        } else if (strcmp(argv[i], "--arena-bytes") == 0 && has) {
            if (!cli_parse_size(argv[++i], &o->arena_bytes)) {
                cli_error("stats", "bad --arena-bytes '%s'", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--json") == 0) {
            o->json = true;
        } else {
            cli_error("stats", "unknown option '%s' (see --help)", argv[i]);
            return 2;
        }
    }
    if (o->scan == NULL) {
        cli_error("stats", "--scan FILE is required");
        return 2;
    }
    return -1;
}

/* The distinct voxels of the points as sorted hit codes in `codes` (room for n); returns how
 * many, *skipped = points off the map. */
static size_t endpoint_codes(const occ_map_t *map, const occ_vec3_t *pts, const size_t n,
                             occ_code_t *codes, size_t *skipped)
{
    size_t m = 0;
    *skipped = 0;
    for (size_t i = 0; i < n; i++) {
        occ_key_t key;
        if (occ_map_key(map, pts[i], &key) == OCC_OK) {
            codes[m++] = occ_morton_encode(key);
        } else {
            (*skipped)++;
        }
    }
    qsort(codes, m, sizeof *codes, cmp_code);
    size_t u = 0;
    for (size_t i = 0; i < m; i++) {
        if (u == 0 || codes[i] != codes[u - 1]) {
            codes[u++] = codes[i];
        }
    }
    for (size_t i = 0; i < u; i++) {
        codes[i] |= OCC_CODE_HIT_BIT;
    }
    return u;
}

static void print_stats(const stats_opts_t *o, const occ_map_t *map, const size_t n,
                        const size_t skipped, const size_t u)
{
    occ_map_stats_t st;
    occ_map_stats(map, &st);
    if (o->json) {
        printf("{");
        cli_print_stats_json(stdout, map, &st);
        printf(", \"points\": %zu, \"points_skipped\": %zu, \"voxels_updated\": %zu, "
               "\"bytes_per_leaf_voxel\": %.3f}\n",
               n, skipped, u,
               st.occupied_voxels ? (double)st.bytes_used / (double)st.occupied_voxels : 0.0);
    } else {
        printf("scan              %s: %zu points, %zu skipped, %zu distinct voxels\n", o->scan, n,
               skipped, u);
        cli_print_stats_text(stdout, map, &st);
    }
}

/* The endpoints into a new map, its statistics printed, the map checked. Returns the exit
 * status. */
static int mark_endpoints(const stats_opts_t *o, const occ_vec3_t *pts, const size_t n)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = o->res;
    cfg.depth_levels = (uint8_t)o->depth;
    void *const arena = malloc(o->arena_bytes);
    occ_code_t *const codes = malloc((n > 0 ? n : 1) * sizeof *codes);
    occ_map_t map;
    int rc = 0;
    occ_err_t e;
    if (arena == NULL || codes == NULL) {
        cli_error("stats", "out of memory");
        rc = 1;
    } else if ((e = occ_map_init(&map, &cfg, arena, o->arena_bytes)) != OCC_OK) {
        cli_error("stats", "bad map configuration (%s)", occ_err_str(e));
        rc = 2;
    } else {
        size_t skipped = 0;
        const size_t u = endpoint_codes(&map, pts, n, codes, &skipped);
        e = occ_map_observe_codes(&map, codes, u, NULL);
        if (e != OCC_OK) {
            cli_error("stats", "integration failed: %s (arena %zu bytes)", occ_err_str(e),
                      o->arena_bytes);
            rc = 1;
        } else {
            print_stats(o, &map, n, skipped, u);
            e = occ_map_check(&map);
            if (e != OCC_OK) {
                cli_error("stats", "map self-check failed: %s", occ_err_str(e));
                rc = 1;
            }
        }
    }
    free(codes);
    free(arena);
    return rc;
}

int cmd_stats(int argc, char **argv)
{
    stats_opts_t o = {NULL, 0.1f, false, 16, 256u << 20};
    const int parsed = parse_args(&o, argc, argv);
    if (parsed >= 0) {
        return parsed;
    }
    occ_vec3_t *pts = NULL;
    size_t n = 0;
    char msg[256] = "";
    const occ_err_t e = occ_scan_read_xyz(o.scan, &pts, &n, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error("stats", "%s (%s)", msg[0] ? msg : o.scan, occ_err_str(e));
        return 1;
    }
    const int rc = mark_endpoints(&o, pts, n);
    free(pts);
    return rc;
}
