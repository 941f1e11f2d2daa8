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

int cmd_stats(int argc, char **argv)
{
    const char *scan = NULL;
    float res = 0.1f;
    int json = 0;
    unsigned depth = 16;
    size_t arena_bytes = 256u << 20;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0) {
            usage();
            return 0;
        } else if (strcmp(argv[i], "--scan") == 0 && i + 1 < argc) {
            scan = argv[++i];
        } else if (strcmp(argv[i], "--res") == 0 && i + 1 < argc) {
            if (!cli_parse_floats(argv[++i], &res, 1) || !(res > 0.0f)) {
                cli_error("stats", "bad --res '%s'", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--depth") == 0 && i + 1 < argc) {
            depth = (unsigned)strtoul(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--arena-bytes") == 0 && i + 1 < argc) {
            if (!cli_parse_size(argv[++i], &arena_bytes)) {
                cli_error("stats", "bad --arena-bytes '%s'", argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else {
            cli_error("stats", "unknown option '%s' (see --help)", argv[i]);
            return 2;
        }
    }
    if (scan == NULL) {
        cli_error("stats", "--scan FILE is required");
        return 2;
    }
    occ_vec3_t *pts = NULL;
    size_t n = 0;
    char msg[256] = "";
    occ_err_t e = occ_scan_read_xyz(scan, &pts, &n, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error("stats", "%s (%s)", msg[0] ? msg : scan, occ_err_str(e));
        return 1;
    }
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    cfg.depth_levels = (uint8_t)depth;
    void *arena = malloc(arena_bytes);
    occ_map_t map;
    occ_code_t *codes = malloc((n > 0 ? n : 1) * sizeof *codes);
    if (arena == NULL || codes == NULL) {
        cli_error("stats", "out of memory");
        return 1;
    }
    e = occ_map_init(&map, &cfg, arena, arena_bytes);
    if (e != OCC_OK) {
        cli_error("stats", "bad map configuration (%s)", occ_err_str(e));
        return 2;
    }
    size_t m = 0, skipped = 0;
    for (size_t i = 0; i < n; i++) {
        occ_key_t key;
        if (occ_map_key(&map, pts[i], &key) == OCC_OK) {
            codes[m++] = occ_morton_encode(key);
        } else {
            skipped++;
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
    e = occ_map_observe_codes(&map, codes, u, NULL);
    if (e != OCC_OK) {
        cli_error("stats", "integration failed: %s (arena %zu bytes)", occ_err_str(e), arena_bytes);
        return 1;
    }
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    if (json) {
        printf("{");
        cli_print_stats_json(stdout, &map, &st);
        printf(", \"points\": %zu, \"points_skipped\": %zu, \"voxels_updated\": %zu, "
               "\"bytes_per_leaf_voxel\": %.3f}\n",
               n, skipped, u, st.occupied_voxels ? (double)st.bytes_used / (double)st.occupied_voxels : 0.0);
    } else {
        printf("scan              %s: %zu points, %zu skipped, %zu distinct voxels\n", scan, n,
               skipped, u);
        cli_print_stats_text(stdout, &map, &st);
    }
    const occ_err_t check = occ_map_check(&map);
    free(codes);
    free(arena);
    free(pts);
    if (check != OCC_OK) {
        cli_error("stats", "map self-check failed: %s", occ_err_str(check));
        return 1;
    }
    return 0;
}
