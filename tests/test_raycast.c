/* SPDX-License-Identifier: BSD-3-Clause */
/* test_raycast.c - occ_ray_keys() against OctoMap's computeRayKeys, key by key. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "support/oracle_rays.h"

#define CAP 20000u

static uint64_t rng_state;

static uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static float urand(float lo, float hi)
{
    return lo + (hi - lo) * (float)((double)(rnd() >> 11) / 9007199254740992.0);
}

static occ_key_t keys_ours[CAP];
static uint32_t keys_ref[3 * CAP];
static uint8_t arena[OCC_ARENA_BYTES(4, 4)];

static void init_map(occ_map_t *m, float res)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    assert_int_equal(occ_map_init(m, &cfg, arena, sizeof arena), OCC_OK);
}

/* One ray both ways; returns the number of keys compared. */
static size_t check_ray(const occ_map_t *m, const float o[3], const float e[3])
{
    size_t n_ref = 0, n = 0;
    const int ok = oracle_ray_keys((double)m->cfg.resolution_m, o, e, keys_ref, CAP, &n_ref);
    const occ_vec3_t vo = {o[0], o[1], o[2]}, ve = {e[0], e[1], e[2]};
    const occ_err_t err = occ_ray_keys(m, vo, ve, keys_ours, CAP, &n);
    if (!ok) {
        assert_int_equal(err, OCC_ERR_RANGE);
        return 0;
    }
    assert_int_equal(err, OCC_OK);
    if (n != n_ref) {
        fprintf(stderr, "res %.9g o (%.9g %.9g %.9g) e (%.9g %.9g %.9g): %zu keys, OctoMap %zu\n",
                (double)m->cfg.resolution_m, (double)o[0], (double)o[1], (double)o[2],
                (double)e[0], (double)e[1], (double)e[2], n, n_ref);
    }
    assert_int_equal(n, n_ref);
    assert_true(n <= occ_ray_max_keys(m, vo, ve));
    for (size_t i = 0; i < n; i++) {
        for (unsigned a = 0; a < 3u; a++) {
            if (keys_ours[i].k[a] != keys_ref[3 * i + a]) {
                fprintf(stderr, "key %zu axis %u: %u vs %u\n", i, a, keys_ours[i].k[a],
                        keys_ref[3 * i + a]);
            }
            assert_int_equal(keys_ours[i].k[a], keys_ref[3 * i + a]);
        }
    }
    return n;
}

static void test_random_rays(void **state)
{
    (void)state;
    static const float resolutions[] = {0.05f, 0.1f, 0.2f, 0.37f, 1.0f, 0.013f};
    occ_map_t m;
    size_t rays = 0, keys = 0;
    for (size_t r = 0; r < sizeof resolutions / sizeof resolutions[0]; r++) {
        const float res = resolutions[r];
        init_map(&m, res);
        for (unsigned i = 0; i < 18000u; i++) {
            const float span = res * (rnd() % 4u == 0u ? 400.0f : 40.0f);
            float o[3], e[3];
            const unsigned kind = (unsigned)(rnd() % 6u);
            for (unsigned a = 0; a < 3u; a++) {
                o[a] = urand(-span, span);
                e[a] = urand(-span, span);
            }
            if (kind == 1u) { /* axis-aligned */
                const unsigned ax = (unsigned)(rnd() % 3u);
                for (unsigned a = 0; a < 3u; a++) {
                    if (a != ax) {
                        e[a] = o[a];
                    }
                }
            } else if (kind == 2u) { /* in an axis plane */
                e[rnd() % 3u] = o[rnd() % 3u == 0u ? 0u : 1u];
            } else if (kind == 3u || kind == 4u) { /* voxel corners and edges */
                for (unsigned a = 0; a < 3u; a++) {
                    const int io = (int)(rnd() % 200u) - 100, ie = (int)(rnd() % 200u) - 100;
                    o[a] = (float)io * res;
                    e[a] = kind == 3u ? (float)ie * res : o[a] + (float)(ie / 10) * res;
                }
                if (kind == 4u && rnd() % 2u) { /* 45-degree diagonals through edges */
                    const float d = (float)((int)(rnd() % 40u) - 20) * res;
                    e[0] = o[0] + d;
                    e[1] = o[1] + d;
                    e[2] = o[2] + (rnd() % 2u ? d : 0.0f);
                }
            } else if (kind == 5u) { /* short rays */
                for (unsigned a = 0; a < 3u; a++) {
                    e[a] = o[a] + urand(-3.0f * res, 3.0f * res);
                }
            }
            keys += check_ray(&m, o, e);
            rays++;
        }
    }
    /* Out of the map: both refuse. */
    init_map(&m, 0.1f);
    const float o[3] = {0, 0, 0}, far[3] = {5000.0f, 0, 0};
    check_ray(&m, o, far);
    printf("%zu rays, %zu keys compared\n", rays, keys);
    assert_true(rays >= 100000u);
}

static void test_errors(void **state)
{
    (void)state;
    occ_map_t m;
    init_map(&m, 0.1f);
    size_t n = 99;
    const occ_vec3_t o = {0.05f, 0.05f, 0.05f}, e = {1.05f, 0.05f, 0.05f};
    const occ_vec3_t bad = {NAN, 0, 0}, out = {0, 1e6f, 0};
    assert_int_equal(occ_ray_keys(&m, bad, e, keys_ours, CAP, &n), OCC_ERR_ARG);
    assert_int_equal(occ_ray_keys(&m, o, out, keys_ours, CAP, &n), OCC_ERR_RANGE);
    assert_int_equal(occ_ray_keys(NULL, o, e, keys_ours, CAP, &n), OCC_ERR_ARG);
    assert_int_equal(occ_ray_keys(&m, o, e, keys_ours, 3, &n), OCC_ERR_NOMEM);
    assert_int_equal(n, 10);
    assert_int_equal(occ_ray_keys(&m, o, e, keys_ours, CAP, &n), OCC_OK);
    assert_int_equal(n, 10);
    for (unsigned i = 0; i < 10u; i++) { /* hand-computed: x keys 32768..32777 */
        assert_int_equal(keys_ours[i].k[0], 32768u + i);
        assert_int_equal(keys_ours[i].k[1], 32768u);
    }
    assert_int_equal(occ_ray_keys(&m, o, o, keys_ours, CAP, &n), OCC_OK);
    assert_int_equal(n, 0);
}

int main(void)
{
    const char *s = getenv("OCC_SEED");
    rng_state = s != NULL ? strtoull(s, NULL, 0) : 0x5EED1234ull;
    if (rng_state == 0u) {
        rng_state = 1u;
    }
    printf("test_raycast seed %llu (set OCC_SEED to repeat)\n", (unsigned long long)rng_state);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_rays),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
