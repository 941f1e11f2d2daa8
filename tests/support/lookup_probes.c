/* SPDX-License-Identifier: BSD-3-Clause */
/* lookup_probes.c - probe points, real maps and a hand-made map for the point-lookup tests
 * (lookup_probes.h). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "lookup_probes.h"
#include "iotest.h"

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

size_t lp_probe_cap(const size_t n_random)
{
    return n_random + 3u * (n_random / 4u) + 12u;
}

size_t lp_make_probes(const occ_map_t *map, occ_vec3_t mn, occ_vec3_t mx, occ_vec3_t *pts,
                      size_t n_random)
{
    const float lo[3] = {mn.x, mn.y, mn.z}, hi[3] = {mx.x, mx.y, mx.z};
    const double res = (double)map->cfg.resolution_m;
    size_t n = 0;
    for (size_t i = 0; i < n_random; i++) {
        float c[3];
        for (unsigned a = 0; a < 3u; a++) {
            const double ext = (double)(hi[a] - lo[a]);
            c[a] = (float)((double)lo[a] - 0.1 * ext + 1.2 * ext * urand());
        }
        if (i % 64u == 63u) {
            c[i % 3u] = (float)(1e6 * (urand() - 0.5));
        }
        pts[n++] = (occ_vec3_t){c[0], c[1], c[2]};
    }
    /* Voxel borders: a random face key k, the face (k - half) * res as the map computes it in
     * double then rounded to float, and its float neighbours. */
    occ_vec3_t base = pts[0];
    for (size_t i = 0; i < n_random / 4u; i++) {
        const unsigned a = (unsigned)(i % 3u);
        const double t = (double)lo[a] + (double)(hi[a] - lo[a]) * urand();
        const float face = (float)(floor(t / res) * res);
        const float f[3] = {nextafterf(face, -INFINITY), face, nextafterf(face, INFINITY)};
        base = pts[i];
        for (unsigned j = 0; j < 3u; j++) {
            occ_vec3_t q = base;
            if (a == 0u) q.x = f[j];
            if (a == 1u) q.y = f[j];
            if (a == 2u) q.z = f[j];
            pts[n++] = q;
        }
    }
    const float bad[4] = {NAN, INFINITY, -INFINITY, -NAN};
    for (unsigned j = 0; j < 4u; j++) {
        pts[n++] = (occ_vec3_t){bad[j], 0.0f, 0.0f};
        pts[n++] = (occ_vec3_t){mn.x, bad[j], mn.z};
        pts[n++] = (occ_vec3_t){mn.x, mn.y, bad[j]};
    }
    return n;
}

void *lp_load_map(const char *path, occ_map_t *map)
{
    size_t len = 0;
    uint8_t *const file = iotest_read_file(path, &len);
    if (file == NULL) {
        printf("SKIP: %s absent\n", path);
        return NULL;
    }
    occ_err_t e = OCC_OK;
    void *const arena = iotest_load(map, file, len, 0u, &e, NULL);
    free(file);
    assert_int_equal(e, OCC_OK);
    assert_non_null(arena);
    return arena;
}

void lp_small_init(lp_small_t *s)
{
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(&s->map, &cfg, s->arena, sizeof s->arena), OCC_OK);
    assert_int_equal(occ_map_update(&s->map, (occ_vec3_t){0.05f, 0.05f, 0.05f}, 2.0f), OCC_OK);
    const occ_key_t k = {{32778u, 32778u, 32778u}};
    assert_int_equal(occ_map_set_key(&s->map, k, 3u, -1.0f), OCC_OK);
}
