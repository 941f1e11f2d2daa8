/* SPDX-License-Identifier: BSD-3-Clause */
/* test_integrate.c - occ_map_insert_cloud() against OctoMap's insertPointCloud, voxel for voxel,
 * on real data (scan.dat, spherical_scan.graph, TUM depth frames), plus the error paths. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_scan.h"
#include "occmap/occ_evict.h"
#include "integrate/coarse_internal.h"
#include "support/oracle_rays.h"
#include "support/integrate_fixture.h"
#include "support/leak_check.h"

#define ARENA_BYTES ((size_t)96 << 20)
#define SCRATCH_BYTES ((size_t)192 << 20)
#define GRAPH "/usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph"

static uint8_t *arena_a, *arena_b, *scratch;
static uint64_t rng_state;

static uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}


static void oracle_insert(void *t, const it_cloud_t *c, double max_range, int discretize)
{
    const float o[3] = {c->origin.x, c->origin.y, c->origin.z};
    oracle_ins_cloud(t, (const float *)(const void *)c->p, c->n, o, max_range, discretize);
}

/* ---- comparisons: it_it_diff_oracle() (support/integrate_fixture.c) -------------------------- */
/* Insert with our map and OctoMap, compare. Returns the differences. */
static size_t run_pair(const it_cloud_t *c, float res, occ_insert_method_t meth, float max_range,
                       int discretize)
{
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, res);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = meth;
    p.max_range_m = max_range;
    occ_insert_result_t out;
    assert_int_equal(occ_map_insert_cloud(&m, &c->origin, c->p, c->n, &p, scratch, SCRATCH_BYTES,
                                          &out),
                     OCC_OK);
    assert_int_equal(occ_map_check(&m), OCC_OK);
    void *t = oracle_ins_new((double)res);
    oracle_insert(t, c, max_range > 0.0f ? (double)max_range : -1.0, discretize);
    const size_t bad = it_diff_oracle(&m, t, 0.002f);
    printf("  res %.2f method %d range %.1f: %zu points, %zu visits, %zu voxels, %zu differ\n",
           (double)res, (int)meth, (double)max_range, out.points_integrated, out.voxel_visits,
           out.voxels_updated, bad);
    oracle_ins_delete(t);
    return bad;
}

/* ---- tests ------------------------------------------------------------------------------------- */
static void test_scan_simple_discrete(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 23)) {
        skip();
    }
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_SIMPLE, -1.0f, 0), 0);
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_DISCRETE, -1.0f, 1), 0);
    assert_int_equal(run_pair(&c, 0.2f, OCC_INSERT_SIMPLE, -1.0f, 0), 0);
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_SUPER_RAYS, -1.0f, 0), 0);
    free(c.p);
}

static void test_max_range(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 31)) {
        skip();
    }
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_SIMPLE, 4.0f, 0), 0);
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_DISCRETE, 6.5f, 1), 0);
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_SUPER_RAYS, 4.0f, 0), 0);
    free(c.p);
}

static void test_tum_frames(void **state)
{
    (void)state;
    for (size_t f = 0; f < 2u; f++) {
        it_cloud_t c;
        if (!it_load_tum(&c, f * 5u, 12u)) {
            skip();
        }
        assert_int_equal(run_pair(&c, 0.05f, OCC_INSERT_SIMPLE, -1.0f, 0), 0);
        assert_int_equal(run_pair(&c, 0.05f, OCC_INSERT_DISCRETE, -1.0f, 1), 0);
        assert_int_equal(run_pair(&c, 0.05f, OCC_INSERT_SUPER_RAYS, -1.0f, 0), 0);
        free(c.p);
    }
}

/* Dense depth points at a coarse resolution: super rays really group (far fewer traversals than
 * points) and still give SIMPLE's map exactly, and OctoMap's. */
static void test_superrays_dense(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_tum(&c, 3u, 2u)) {
        skip();
    }
    const float resolutions[2] = {0.2f, 0.1f};
    for (unsigned i = 0; i < 2u; i++) {
        occ_map_t a, b;
        it_init_map(&a, arena_a, ARENA_BYTES, resolutions[i]);
        it_init_map(&b, arena_b, ARENA_BYTES, resolutions[i]);
        occ_insert_params_t p = occ_insert_params_default();
        occ_insert_result_t ra, rb;
        assert_int_equal(occ_map_insert_cloud(&a, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                              &ra),
                         OCC_OK);
        p.method = OCC_INSERT_SUPER_RAYS;
        assert_int_equal(occ_map_insert_cloud(&b, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                              &rb),
                         OCC_OK);
        printf("  res %.1f: %zu points, simple %zu rays / %zu visits, super rays %zu / %zu\n",
               (double)resolutions[i], c.n, ra.rays_cast, ra.voxel_visits, rb.rays_cast,
               rb.voxel_visits);
        assert_int_equal(it_diff_maps(&a, &b), 0);
        assert_int_equal(ra.voxels_updated, rb.voxels_updated);
        assert_int_equal(rb.points_integrated, c.n);
        if (i == 0u) {
            assert_true(rb.rays_cast * 3u < c.n);
            void *t = oracle_ins_new((double)resolutions[i]);
            oracle_insert(t, &c, -1.0, 0);
            assert_int_equal(it_diff_oracle(&b, t, 0.002f), 0);
            oracle_ins_delete(t);
        }
    }
    free(c.p);
}

static void test_graph(void **state)
{
    (void)state;
    occ_scan_frame_t *f = NULL;
    size_t n = 0;
    char msg[256];
    if (occ_scan_read_graph(GRAPH, &f, &n, msg, sizeof msg) != OCC_OK) {
        printf("SKIP: %s\n", msg);
        skip();
    }
    assert_int_equal(n, 1);
    assert_int_equal(f[0].n_points, 10201);
    it_cloud_t c = {f[0].points, 0, f[0].origin};
    for (size_t i = 0; i < f[0].n_points; i += 4u) { /* a quarter keeps the test fast */
        c.p[c.n++] = f[0].points[i];
    }
    assert_int_equal(run_pair(&c, 0.1f, OCC_INSERT_SIMPLE, -1.0f, 0), 0);
    assert_int_equal(run_pair(&c, 0.05f, OCC_INSERT_DISCRETE, -1.0f, 1), 0);
    occ_scan_frames_free(f, n);
}

/* Several scans into one map: values accumulate and clamp like OctoMap's (within the
 * fixed-point step per update). */
static void test_accumulate(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 67)) {
        skip();
    }
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, 0.2f);
    void *t = oracle_ins_new((double)0.2f);
    occ_insert_params_t p = occ_insert_params_default();
    const occ_vec3_t origins[4] = {{0, 0, 0}, {0.5f, 0.1f, 0}, {-1.0f, 2.0f, 0.3f}, {0, 0, 0}};
    for (unsigned s = 0; s < 4u; s++) {
        c.origin = origins[s];
        assert_int_equal(
            occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES, NULL),
            OCC_OK);
        oracle_insert(t, &c, -1.0, 0);
    }
    assert_int_equal(occ_map_check(&m), OCC_OK);
    assert_int_equal(it_diff_oracle(&m, t, 0.004f), 0);
    oracle_ins_delete(t);
    free(c.p);
}

static void test_fast_discrete(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 37)) {
        skip();
    }
    occ_map_t a, b;
    occ_insert_params_t p = occ_insert_params_default();
    /* d = 0 is DISCRETE exactly. */
    it_init_map(&a, arena_a, ARENA_BYTES, 0.1f);
    it_init_map(&b, arena_b, ARENA_BYTES, 0.1f);
    p.method = OCC_INSERT_DISCRETE;
    assert_int_equal(occ_map_insert_cloud(&a, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_OK);
    p.method = OCC_INSERT_FAST_DISCRETE;
    p.fast_d = 0;
    p.fast_n = 3;
    assert_int_equal(occ_map_insert_cloud(&b, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_OK);
    assert_int_equal(it_diff_maps(&a, &b), 0);
    /* d = 2, n = 0: every end point still occupied, the map checks out. */
    occ_map_clear(&b);
    p.fast_d = 2;
    p.fast_n = 0;
    occ_insert_result_t out;
    /* Exactly the documented bound is enough (and the sorted path runs with it). */
    const size_t need = occ_insert_scratch_bytes_scan(&b, &c.origin, c.p, c.n, &p);
    assert_true(need < SCRATCH_BYTES);
    assert_int_equal(occ_map_insert_cloud(&b, &c.origin, c.p, c.n, &p, scratch, need, &out),
                     OCC_OK);
    assert_int_equal(occ_map_check(&b), OCC_OK);
    size_t missed = 0;
    for (size_t i = 0; i < c.n; i++) {
        missed += occ_map_state_at(&b, c.p[i]) != OCC_STATE_OCCUPIED;
    }
    printf("  fast d=2 n=0: %zu voxels, %zu coarse nodes, %zu end points not occupied\n",
           out.voxels_updated, out.coarse_updated, missed);
    assert_int_equal(missed, 0);
    /* n = 2: exact voxels near the end, coarse marching before; dense and sorted paths agree. */
    p.fast_n = 2;
    occ_map_clear(&a);
    occ_map_clear(&b);
    assert_int_equal(occ_map_insert_cloud(&a, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          &out),
                     OCC_OK);
    const size_t need2 = occ_insert_scratch_bytes_scan(&b, &c.origin, c.p, c.n, &p);
    assert_int_equal(occ_map_insert_cloud(&b, &c.origin, c.p, c.n, &p, scratch, need2 / 4u,
                                          NULL),
                     OCC_OK);
    assert_int_equal(occ_map_check(&a), OCC_OK);
    assert_int_equal(it_diff_maps(&a, &b), 0);
    printf("  fast d=2 n=2: %zu voxels, %zu coarse nodes\n", out.voxels_updated,
           out.coarse_updated);
    assert_true(out.voxels_updated > out.voxels_occupied);
    free(c.p);
}

/* Sparse points far apart: the box is too big for the scratch, so the sorted-code path runs,
 * including compaction when the scratch is below the bound. Same map as OctoMap. */
static void test_sorted_path(void **state)
{
    (void)state;
    const size_t n = 400;
    it_cloud_t c;
    c.p = malloc(n * sizeof *c.p);
    c.n = n;
    c.origin = (occ_vec3_t){0.33f, -0.21f, 0.05f};
    for (size_t i = 0; i < n / 4u; i++) {
        const float az = (float)(rnd() % 100000u) * 6.2831853e-5f;
        const float el = ((float)(rnd() % 1000u) - 500.0f) * 1e-3f;
        const float r = 5.0f + (float)(rnd() % 10000u) * 0.004f;
        c.p[i] = (occ_vec3_t){r * cosf(az) * cosf(el), r * sinf(az) * cosf(el), r * sinf(el)};
    }
    for (size_t i = n / 4u; i < n; i++) { /* every ray four times: compaction collapses them */
        c.p[i] = c.p[i % (n / 4u)];
    }
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, 0.05f);
    occ_insert_params_t p = occ_insert_params_default();
    const size_t need = occ_insert_scratch_bytes_scan(&m, &c.origin, c.p, c.n, &p);
    const size_t sizes[3] = {need, need / 3u, need / 12u};
    void *t = oracle_ins_new((double)0.05f);
    oracle_insert(t, &c, -1.0, 0);
    for (unsigned i = 0; i < 3u; i++) {
        occ_map_clear(&m);
        const occ_err_t e = occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, sizes[i],
                                                 NULL);
        printf("  sorted path, scratch %zu of bound %zu: %s\n", sizes[i], need, occ_err_str(e));
        if (i < 2u) {
            assert_int_equal(e, OCC_OK);
        }
        if (e == OCC_OK) {
            assert_int_equal(it_diff_oracle(&m, t, 0.002f), 0);
        } else {
            assert_int_equal(e, OCC_ERR_SCRATCH);
            size_t nodes;
            (void)it_map_digest(&m, &nodes);
            assert_int_equal(nodes, 0);
        }
    }
    oracle_ins_delete(t);
    free(c.p);
}

/* coarse.c against the per-voxel update it stands for. */
static void test_coarse_apply(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 61)) {
        skip();
    }
    occ_map_t a, b;
    it_init_map(&a, arena_a, ARENA_BYTES, 0.2f);
    it_init_map(&b, arena_b, ARENA_BYTES, 0.2f);
    occ_insert_params_t p = occ_insert_params_default();
    assert_int_equal(occ_map_insert_cloud(&a, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_OK);
    assert_int_equal(occ_map_insert_cloud(&b, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_OK);
    /* Nodes at level 2 around end points and in empty space, sorted and unique. */
    const unsigned level = 2u;
    occ_code_t codes[600];
    size_t n = 0;
    for (size_t i = 0; i < c.n && n < 600u; i += 3u) {
        occ_key_t k;
        occ_vec3_t q = c.p[i];
        q.z += (float)(rnd() % 5u) * 0.3f;
        if (occ_map_key(&a, q, &k) == OCC_OK) {
            codes[n++] = occ_morton_encode(occ_key_at_level(k, level));
        }
    }
    for (size_t i = 1; i < n; i++) { /* insertion sort */
        const occ_code_t v = codes[i];
        size_t j = i;
        while (j > 0u && codes[j - 1u] > v) {
            codes[j] = codes[j - 1u];
            j--;
        }
        codes[j] = v;
    }
    size_t u = 0;
    for (size_t i = 0; i < n; i++) {
        if (u == 0u || codes[u - 1u] != codes[i]) {
            codes[u++] = codes[i];
        }
    }
    for (unsigned round = 0; round < 3u; round++) {
        const float delta = round == 1u ? 0.6f : -0.35f;
        uint64_t in, lf;
        occi_coarse_need(codes, u, level, a.cfg.depth_levels, &in, &lf);
        assert_true(occi_pool_can_supply(&a, (uint32_t)in, (uint32_t)lf));
        occi_coarse_apply(&a, codes, u, level, occ_value_from_logodds(delta));
        for (size_t i = 0; i < u; i++) {
            const occ_key_t k0 = occ_morton_decode(codes[i]);
            for (uint32_t dz = 0; dz < 4u; dz++) {
                for (uint32_t dy = 0; dy < 4u; dy++) {
                    for (uint32_t dx = 0; dx < 4u; dx++) {
                        const occ_key_t k = {{k0.k[0] + dx, k0.k[1] + dy, k0.k[2] + dz}};
                        assert_int_equal(occ_map_update_key(&b, k, delta), OCC_OK);
                    }
                }
            }
        }
        assert_int_equal(occ_map_check(&a), OCC_OK);
        assert_int_equal(it_diff_maps(&a, &b), 0);
    }
    free(c.p);
}

int main(void)
{
    const char *s = getenv("OCC_SEED");
    rng_state = s != NULL ? strtoull(s, NULL, 0) : 0xC0FFEEull;
    if (rng_state == 0u) {
        rng_state = 1u;
    }
    printf("test_integrate seed %llu (set OCC_SEED to repeat)\n", (unsigned long long)rng_state);
    arena_a = malloc(ARENA_BYTES);
    arena_b = malloc(ARENA_BYTES);
    scratch = malloc(SCRATCH_BYTES);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_scan_simple_discrete, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_max_range, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_tum_frames, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_graph, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_superrays_dense, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_accumulate, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_fast_discrete, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_sorted_path, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_coarse_apply, it_timer_setup, it_timer_teardown),
    };
    const int rc = cmocka_run_group_tests(tests, NULL, NULL);
    free(arena_a);
    free(arena_b);
    free(scratch);
    return rc;
}
