/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_castray.c - occ_cast_ray against OctoMap's own castRay on geb079.bt (loaded through
 * liboctomap and copied leaf by leaf into occmap with occ_map_set_key): >= 10,000 random rays,
 * the same hit voxel or the same no-hit. Line of sight against the brute-force segment oracle on
 * random maps, and hand-computed cases. Random seed printed, OCC_SEED to repeat.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "occmap/occmap.h"
#include "support/oracle_query.h"
#include "support/query_shapes.h"

#define GEB "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"
#define N_RAYS 12000u
#define ARENA_BYTES (48u << 20)

static uint8_t arena[ARENA_BYTES];
static occ_map_t map;
static uint64_t rng;
static uint64_t codes[200000];
static uint8_t amb[200000];

static int setup(void **state)
{
    (void)state;
    rng = qs_seed("test_castray");
    return 0;
}

static occ_key_t key3(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

static void test_hand_cases(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default(); /* res 0.1, depth 16: key 32768 = [0, 0.1) */
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const uint32_t c = 32768u;
    for (uint32_t x = c; x < c + 10u; x++) {
        assert_int_equal(occ_map_set_key(&map, key3(x, c, c), 0, -1.0f), OCC_OK);
    }
    assert_int_equal(occ_map_set_key(&map, key3(c + 10u, c, c), 0, 2.0f), OCC_OK);
    const occ_vec3_t o = {0.05f, 0.05f, 0.05f}, dx = {2.0f, 0.0f, 0.0f};
    occ_ray_result_t r;
    assert_int_equal(occ_cast_ray(&map, o, dx, false, -1.0f, &r), OCC_OK);
    assert_true(r.hit);
    assert_int_equal(r.stop, OCC_RAY_HIT);
    assert_int_equal(r.key.k[0], c + 10u);
    assert_true(fabsf(r.end.x - 1.05f) < 1e-5f && fabsf(r.end.y - 0.05f) < 1e-5f);
    /* Max range 0.52: voxel centres at 0.1, 0.2 .. 0.5 from the origin pass; the centre at
     * 0.6 (key c+6) is the first beyond, the ray stops there with no hit. */
    assert_int_equal(occ_cast_ray(&map, o, dx, false, 0.52f, &r), OCC_OK);
    assert_false(r.hit);
    assert_int_equal(r.stop, OCC_RAY_MAX_RANGE);
    assert_int_equal(r.key.k[0], c + 6u);
    /* Backwards: the first voxel behind is unknown. */
    const occ_vec3_t mdx = {-1.0f, 0.0f, 0.0f};
    assert_int_equal(occ_cast_ray(&map, o, mdx, false, -1.0f, &r), OCC_OK);
    assert_false(r.hit);
    assert_int_equal(r.stop, OCC_RAY_UNKNOWN);
    assert_int_equal(r.key.k[0], c - 1u);
    /* Through a gap of unknown space with ignore_unknown. */
    assert_int_equal(occ_map_forget_key(&map, key3(c + 4u, c, c), 0), OCC_OK);
    assert_int_equal(occ_cast_ray(&map, o, dx, false, -1.0f, &r), OCC_OK);
    assert_false(r.hit);
    assert_int_equal(r.key.k[0], c + 4u);
    assert_int_equal(occ_cast_ray(&map, o, dx, true, -1.0f, &r), OCC_OK);
    assert_true(r.hit);
    assert_int_equal(r.key.k[0], c + 10u);
    /* Origin inside the occupied voxel. */
    const occ_vec3_t oo = {1.01f, 0.02f, 0.03f};
    assert_int_equal(occ_cast_ray(&map, oo, dx, false, -1.0f, &r), OCC_OK);
    assert_true(r.hit);
    assert_true(fabsf(r.end.x - 1.05f) < 1e-5f);
    /* Line of sight along the row. */
    bool vis = false;
    const occ_vec3_t a = {0.01f, 0.05f, 0.05f}, b = {0.95f, 0.05f, 0.05f}, bb = {1.02f, 0.05f, 0.05f};
    assert_int_equal(occ_line_of_sight(&map, a, b, OCC_UNKNOWN_SAFE, &vis, &r), OCC_OK);
    assert_true(vis);
    assert_int_equal(occ_line_of_sight(&map, a, b, OCC_UNKNOWN_UNSAFE, &vis, &r), OCC_OK);
    assert_false(vis); /* the forgotten voxel at 0.4..0.5 */
    assert_int_equal(r.key.k[0], c + 4u);
    assert_int_equal(occ_line_of_sight(&map, a, bb, OCC_UNKNOWN_SAFE, &vis, &r), OCC_OK);
    assert_false(vis);
    assert_int_equal(r.key.k[0], c + 10u);
    /* Bad input. */
    const occ_vec3_t zero = {0, 0, 0}, nan3 = {NAN, 0, 0}, far = {1e6f, 0, 0};
    assert_int_equal(occ_cast_ray(&map, o, zero, false, -1.0f, &r), OCC_ERR_ARG);
    assert_int_equal(occ_cast_ray(&map, nan3, dx, false, -1.0f, &r), OCC_ERR_ARG);
    assert_int_equal(occ_cast_ray(&map, o, nan3, false, -1.0f, &r), OCC_ERR_ARG);
    assert_int_equal(occ_cast_ray(&map, o, dx, false, NAN, &r), OCC_ERR_ARG);
    assert_int_equal(occ_cast_ray(&map, far, dx, false, -1.0f, &r), OCC_ERR_RANGE);
    assert_int_equal(occ_cast_ray(NULL, o, dx, false, -1.0f, &r), OCC_ERR_ARG);
    assert_int_equal(occ_line_of_sight(&map, a, far, OCC_UNKNOWN_SAFE, &vis, NULL), OCC_ERR_RANGE);
    assert_int_equal(occ_line_of_sight(&map, a, nan3, OCC_UNKNOWN_SAFE, &vis, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_line_of_sight(&map, a, b, (occ_unknown_policy_t)7, &vis, NULL), OCC_ERR_ARG);
    /* The map edge: a small all-free map. */
    cfg.depth_levels = 4;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    assert_int_equal(occ_map_set_key(&map, key3(0, 0, 0), 4, -1.0f), OCC_OK);
    assert_int_equal(occ_cast_ray(&map, o, dx, false, -1.0f, &r), OCC_OK);
    assert_false(r.hit);
    assert_int_equal(r.stop, OCC_RAY_MAP_EDGE);
    assert_int_equal(r.key.k[0], 15u);
}

/* n_rays random rays from inside [mn, mx] (both unknown modes, bounded and unbounded ranges)
 * cast in `map` and in OctoMap's tree `o` holding the same voxels: same hit, same end voxel. */
static void compare_casts(oracle_q_octo_t *o, const double mn[3], const double mx[3],
                          unsigned n_rays, const char *label)
{
    unsigned hits = 0, same = 0, bad = 0;
    for (unsigned i = 0; i < n_rays; i++) {
        float org[3], dir[3];
        for (int k = 0; k < 3; k++) {
            org[k] = (float)qs_uniform(&rng, mn[k], mx[k]);
            dir[k] = (float)qs_uniform(&rng, -1, 1);
        }
        if (i % 17u == 0u) {
            dir[i % 3u] = 0.0f; /* axis-parallel planes: exercise the zero-step axes */
        }
        const bool ignore = (qs_rand(&rng) & 1u) != 0u;
        /* A float range, as the API takes it: OctoMap then squares the same value. */
        double range = (double)(float)qs_uniform(&rng, 0.3, 15.0);
        if (!ignore && (qs_rand(&rng) & 1u)) {
            range = -1.0; /* unbounded: stops at the first unknown voxel */
        }
        float oend[3];
        const bool ohit = oracle_q_octo_cast(o, org, dir, ignore, range, oend);
        occ_ray_result_t r;
        const occ_vec3_t ov = {org[0], org[1], org[2]}, dv = {dir[0], dir[1], dir[2]};
        assert_int_equal(occ_cast_ray(&map, ov, dv, ignore, (float)range, &r), OCC_OK);
        const bool end_same = fabsf(r.end.x - oend[0]) < 1e-4f && fabsf(r.end.y - oend[1]) < 1e-4f &&
                              fabsf(r.end.z - oend[2]) < 1e-4f;
        if (r.hit != ohit || !end_same) {
            if (bad++ < 10u) {
                printf("ray %u: o %.7g,%.7g,%.7g d %.7g,%.7g,%.7g ignore %d range %g: occmap %d "
                       "(%.4f,%.4f,%.4f) octomap %d (%.4f,%.4f,%.4f)\n",
                       i, (double)org[0], (double)org[1], (double)org[2], (double)dir[0],
                       (double)dir[1], (double)dir[2], ignore, range, r.hit, (double)r.end.x,
                       (double)r.end.y, (double)r.end.z, ohit, (double)oend[0], (double)oend[1],
                       (double)oend[2]);
            }
        } else {
            same++;
        }
        hits += ohit ? 1u : 0u;
    }
    printf("%s: %u rays, %u hits, %u identical, %u differ\n", label, n_rays, hits, same, bad);
    assert_int_equal(bad, 0);
    assert_true(hits > n_rays / 10u);
    assert_true(hits < n_rays - n_rays / 10u);
}

static void test_octomap_geb079(void **state)
{
    (void)state;
    if (access(GEB, R_OK) != 0) {
        printf("SKIP: %s not found (liboctomap-dev examples)\n", GEB);
        skip();
    }
    oracle_q_octo_t *o = oracle_q_octo_load(GEB);
    assert_non_null(o);
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = (float)oracle_q_octo_resolution(o);
    cfg.depth_levels = 16;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    size_t mismatch = 99;
    assert_int_equal(oracle_q_octo_copy(o, &map, &mismatch), OCC_OK);
    assert_int_equal(mismatch, 0);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    double mn[3], mx[3];
    oracle_q_octo_bbox(o, mn, mx);
    compare_casts(o, mn, mx, N_RAYS, "geb079");
    /* search() agrees on random points too. */
    for (unsigned i = 0; i < 20000u; i++) {
        float p[3];
        for (int k = 0; k < 3; k++) {
            p[k] = (float)qs_uniform(&rng, mn[k], mx[k]);
        }
        /* Every point, borders included: occ_map_key and OctoMap's search use the same decimal
         * resolution (the file's header). Every fourth point is put on a voxel border. */
        if ((i & 3u) == 0u) {
            const int axis = (int)(i >> 2) % 3;
            const double res = oracle_q_octo_resolution(o);
            p[axis] = (float)(floor((double)p[axis] / res) * res);
        }
        const int os = oracle_q_octo_search(o, p);
        const occ_vec3_t pv = {p[0], p[1], p[2]};
        const occ_state_t s = occ_map_state_at(&map, pv);
        assert_int_equal(s, os < 0 ? OCC_STATE_UNKNOWN : (os ? OCC_STATE_OCCUPIED : OCC_STATE_FREE));
    }
    oracle_q_octo_free(o);
}

/* Random scenes built in OctoMap (large pruned free nodes, unknown gaps, occupied boxes): the
 * walk passes whole nodes without occupied (or unknown) voxels below; the voxels it stops at must
 * still be OctoMap's. */
static void test_octomap_random_scenes(void **state)
{
    (void)state;
    for (uint64_t seed = 1; seed <= 4u; seed++) {
        oracle_q_octo_t *o = oracle_q_octo_random(seed, 0.1);
        assert_non_null(o);
        occ_map_config_t cfg = occ_map_config_default();
        cfg.resolution_m = 0.1f;
        cfg.depth_levels = 16;
        assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
        size_t mismatch = 99;
        assert_int_equal(oracle_q_octo_copy(o, &map, &mismatch), OCC_OK);
        assert_int_equal(mismatch, 0);
        const double mn[3] = {-3.2, -3.2, -3.2}, mx[3] = {3.2, 3.2, 3.2};
        char label[32];
        snprintf(label, sizeof label, "random scene %u", (unsigned)seed);
        compare_casts(o, mn, mx, 3000u, label);
        oracle_q_octo_free(o);
    }
}

/* Line of sight against the voxels the segment crosses (brute force, Eigen). */
static void test_line_of_sight_random(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.25f;
    cfg.depth_levels = 6;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    assert_int_equal(oracle_q_random_map(&map, qs_rand(&rng), 2500u), OCC_OK);
    unsigned vis_n = 0, blk_n = 0, skipped = 0;
    for (unsigned i = 0; i < 3000u; i++) {
        double a[3], b[3];
        for (int k = 0; k < 3; k++) {
            a[k] = (double)(float)qs_uniform(&rng, -6, 6);
            b[k] = (double)(float)(a[k] + qs_uniform(&rng, -4, 4));
            b[k] = b[k] < -7.9 ? -7.9 : (b[k] > 7.9 ? 7.9 : b[k]);
        }
        const occ_unknown_policy_t pol = (i & 1u) ? OCC_UNKNOWN_SAFE : OCC_UNKNOWN_UNSAFE;
        const unsigned states = OCC_PRED_OCCUPIED | (pol == OCC_UNKNOWN_UNSAFE ? OCC_PRED_UNKNOWN : 0u);
        oracle_q_shape_t *s = oracle_q_segment(a, b);
        const size_t n = oracle_q_collect(&map, s, states, 0, codes, amb, 200000);
        oracle_q_free(s);
        size_t definite = 0;
        for (size_t j = 0; j < n; j++) {
            definite += amb[j] ? 0u : 1u;
        }
        bool vis = false;
        const occ_vec3_t av = {(float)a[0], (float)a[1], (float)a[2]};
        const occ_vec3_t bv = {(float)b[0], (float)b[1], (float)b[2]};
        occ_ray_result_t r;
        assert_int_equal(occ_line_of_sight(&map, av, bv, pol, &vis, &r), OCC_OK);
        if (definite > 0u) {
            if (vis) {
                fail_msg("los %u: %f,%f,%f -> %f,%f,%f policy %d: visible, oracle has %zu blockers",
                         i, a[0], a[1], a[2], b[0], b[1], b[2], pol, definite);
            }
            blk_n++;
        } else if (n == 0u) {
            if (!vis) {
                fail_msg("los %u: %f,%f,%f -> %f,%f,%f policy %d: blocked at %u,%u,%u, oracle none",
                         i, a[0], a[1], a[2], b[0], b[1], b[2], pol, r.key.k[0], r.key.k[1], r.key.k[2]);
            }
            vis_n++;
        } else {
            skipped++;
        }
    }
    printf("line of sight: %u visible, %u blocked, %u ambiguous (skipped)\n", vis_n, blk_n, skipped);
    assert_true(vis_n > 100u && blk_n > 100u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_cases),
        cmocka_unit_test(test_octomap_random_scenes),
        cmocka_unit_test(test_line_of_sight_random),
        cmocka_unit_test(test_octomap_geb079),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
