/* SPDX-License-Identifier: BSD-3-Clause */
/* sectors_bench.c - the cost of one 72-sector update on a real map (OctoMap's geb079.bt).
 * usage: sectors_bench MAP.bt [--callgrind]
 * Poses walk the corridor (x -5..26 m) with a turning heading. Per pose the update runs 7 times
 * and the fastest counts; we print the median, p90 and max over poses for two configurations:
 *   default: 72 x 5 deg, R = 20 m, band +-0.5 m at z = 1.0 m (occ_sectors_config_default)
 *   demo:    72 x 5 deg, R = 6 m,  band +-0.15 m at z = 0.6 m (what make demo flies)
 * --callgrind: one update per pose (default config) and nothing else, for
 *   valgrind --tool=callgrind --toggle-collect=occ_sectors_compute. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "occmap/occ_sectors.h"
#include "occmap/host/occ_file.h"

static double now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* Pose n of the walk: level, heading 0.37 n rad (map ENU). */
static occ_pose_t bench_pose(float x, float y, float z, int n)
{
    occ_pose_t p;
    p.p.x = x;
    p.p.y = y;
    p.p.z = z;
    p.q = occ_quat_from_euler(0.0f, 0.0f, (float)n * 0.37f);
    return p;
}

#define MAXP 256
static occ_sectors_t out;

static void run(const char *name, const occ_map_t *map, const occ_sectors_config_t *cfg, float z)
{
    static double t[MAXP];
    static double nodes[MAXP];
    int n = 0;
    for (float x = -5.0f; x <= 26.0f && n < MAXP; x += 0.25f, n++) {
        const occ_pose_t p = bench_pose(x, (n & 1) ? -0.1f : -0.5f, z, n);
        double best = 1e30;
        for (int r = 0; r < 7; r++) {
            const double a = now_us();
            if (occ_sectors_compute(map, &p, cfg, &out) != OCC_OK) {
                fprintf(stderr, "sectors_bench: compute failed at x=%.2f\n", (double)x);
                exit(1);
            }
            const double d = now_us() - a;
            best = d < best ? d : best;
        }
        t[n] = best;
        nodes[n] = (double)out.nodes_read;
    }
    qsort(t, (size_t)n, sizeof t[0], cmp_d);
    qsort(nodes, (size_t)n, sizeof nodes[0], cmp_d);
    printf("sectors %-8s %3d poses  median %7.1f us  p90 %7.1f us  max %7.1f us  "
           "(median %5.0f nodes read)  R %.0f m band +-%.2f m\n",
           name, n, t[n / 2], t[(n * 9) / 10], t[n - 1], nodes[n / 2],
           (double)cfg->max_distance_cm / 100.0, (double)cfg->band_below_m);
}

/* The baseline the hierarchy is measured against: read every voxel of the search cylinder's
 * band (what a dense grid would do), without the per-sector geometry. */
static void naive(const occ_map_t *map, const occ_sectors_config_t *cfg, float z)
{
    const float res = map->cfg.resolution_m;
    const float R = (float)cfg->max_distance_cm / 100.0f;
    double total = 0.0;
    long reads = 0;
    int n = 0;
    for (float x = -5.0f; x <= 26.0f; x += 6.0f, n++) {
        const double a = now_us();
        for (float dx = -R; dx <= R; dx += res) {
            for (float dy = -R; dy <= R; dy += res) {
                if (dx * dx + dy * dy > R * R) {
                    continue;
                }
                for (float dz = -cfg->band_below_m; dz < cfg->band_above_m; dz += res) {
                    occ_node_info_t info;
                    occ_vec3_t p = {x + dx, -0.3f + dy, z + dz};
                    (void)occ_map_read(map, p, 0, &info);
                    reads++;
                }
            }
        }
        total += now_us() - a;
    }
    printf("naive    voxel scan of the band, R %.0f m: %.0f us per update (%ld voxel reads)\n",
           (double)R, total / n, reads / n);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: sectors_bench MAP.bt [--callgrind]\n");
        return 2;
    }
    const bool cg = argc > 2 && strcmp(argv[2], "--callgrind") == 0;
    occ_map_t map;
    void *arena = NULL;
    char msg[256];
    if (occ_file_load_alloc(argv[1], NULL, &map, 0, &arena, NULL, msg, sizeof msg) != OCC_OK) {
        fprintf(stderr, "sectors_bench: %s: %s\n", argv[1], msg);
        return 1;
    }
    occ_sectors_config_t def = occ_sectors_config_default();
    occ_sectors_config_t demo = def;
    demo.max_distance_cm = 600;
    demo.band_below_m = demo.band_above_m = 0.15f;
    if (cg) {
        int n = 0;
        for (float x = -5.0f; x <= 26.0f; x += 0.25f, n++) {
            const occ_pose_t p = bench_pose(x, (n & 1) ? -0.1f : -0.5f, 1.0f, n);
            (void)occ_sectors_compute(&map, &p, &def, &out);
        }
        printf("callgrind: %d updates\n", n);
    } else {
        run("default", &map, &def, 1.0f);
        run("demo", &map, &demo, 0.6f);
        naive(&map, &demo, 0.6f);
    }
    free(arena);
    return 0;
}
