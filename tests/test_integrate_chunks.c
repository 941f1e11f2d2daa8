// SPDX-License-Identifier: BSD-3-Clause
/* test_integrate_chunks.c - occ_map_insert_cloud() in bounded scratch (issue 22): when the scan's
 * sorted key sets do not fit, SIMPLE and DISCRETE run in Morton-range windows. The result must
 * equal the one-shot batch voxel for voxel (and OctoMap), at several scratch sizes down to the
 * documented minimum; below it OCC_ERR_SCRATCH and a pool too small OCC_ERR_NOMEM, both with the
 * map unchanged. Real data: OctoMap's scan.dat. */
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
#include "support/integrate_fixture.h"

#define ARENA_BYTES ((size_t)64 << 20)
#define SCRATCH_BYTES ((size_t)96 << 20)
/* Every 3rd point at 0.1 m for the sizes that take a few windows; every 160th at 0.2 m for the
 * minimum (hundreds of windows, each a traversal of the scan). */
#define RES 0.1f
#define EVERY 3u
#define RES_MIN 0.2f
#define EVERY_MIN 160u

static uint8_t *arena_a, *arena_b, *scratch;

/* The documented minimum (occ_integrate.h): the fixed term, DISCRETE's end voxels, and 16 bytes
 * per code for the longest ray's bound plus one (DISCRETE: at least n_points codes). */
static size_t min_scratch(const occ_map_t *m, const it_cloud_t *c, const occ_insert_params_t *p)
{
    size_t worst = 0;
    for (size_t i = 0; i < c->n; i++) {
        const size_t b = occ_insert_scratch_bytes_scan(m, &c->origin, &c->p[i], 1u, p) -
                         OCC_INSERT_SCRATCH_FIXED_BYTES;
        worst = b > worst ? b : worst; /* 8 + 16 * (keys + 1) */
    }
    const size_t codes = (worst - 8u) / 16u + 1u; /* keys of the ray + its hit + one */
    if (p->method == OCC_INSERT_DISCRETE) {
        return OCC_INSERT_SCRATCH_FIXED_BYTES + 8u * c->n + 16u * (codes > c->n ? codes : c->n);
    }
    return OCC_INSERT_SCRATCH_FIXED_BYTES + 16u * codes;
}

/* What the one-shot call's sorted path holds: the scan's collapsed codes and the sort's
 * temporary (the dense path writes far less, so its scratch_used is no measure of it). */
static size_t sorted_bytes(const occ_insert_result_t *const r)
{
    return 16u * r->voxels_updated;
}

static void check_method(const occ_insert_method_t method, const float res, const size_t every,
                         const bool at_min)
{
    it_cloud_t c;
    if (!it_load_scan(&c, every)) {
        skip();
    }
    occ_map_t ref, m;
    it_init_map(&ref, arena_a, ARENA_BYTES, res);
    it_init_map(&m, arena_b, ARENA_BYTES, res);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = method;
    occ_insert_result_t r0, r;
    assert_int_equal(occ_map_insert_cloud(&ref, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          &r0),
                     OCC_OK);
    void *t = oracle_ins_new((double)res);
    const float o[3] = {c.origin.x, c.origin.y, c.origin.z};
    oracle_ins_cloud(t, (const float *)(const void *)c.p, c.n, o, -1.0,
                     method == OCC_INSERT_DISCRETE);
    assert_int_equal(it_diff_oracle(&ref, t, 0.002f), 0);
    const size_t lo = min_scratch(&m, &c, &p);
    const size_t sizes[] = {lo, lo + 4096u, sorted_bytes(&r0) / 8u, sorted_bytes(&r0) / 3u};
    for (size_t i = at_min ? 0u : 2u; i < (at_min ? 2u : 4u); i++) {
        const size_t s = sizes[i] > lo ? sizes[i] : lo;
        occ_map_clear(&m);
        assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, s, &r),
                         OCC_OK);
        printf("  method %d scratch %zu (one-shot sorted codes %zu): %zu voxels\n", (int)method, s,
               sorted_bytes(&r0), r.voxels_updated);
        assert_true(r.scratch_used <= s);
        assert_int_equal(r.voxels_updated, r0.voxels_updated);
        assert_int_equal(r.voxels_occupied, r0.voxels_occupied);
        assert_int_equal(r.voxels_changed, r0.voxels_changed);
        assert_int_equal(r.voxel_visits, r0.voxel_visits);
        assert_int_equal(r.points_integrated, r0.points_integrated);
        assert_int_equal(it_diff_maps(&ref, &m), 0);
        assert_int_equal(it_diff_maps(&m, &ref), 0);
        assert_int_equal(it_diff_oracle(&m, t, 0.002f), 0);
        assert_true(occ_map_check(&m) == OCC_OK);
    }
    /* Below the minimum: OCC_ERR_SCRATCH, map unchanged (it holds the last scan: insert again). */
    size_t nodes0, nodes1;
    const uint64_t d0 = it_map_digest(&m, &nodes0);
    const uint32_t oom0 = m.oom_count;
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, lo - 40u, &r),
                     OCC_ERR_SCRATCH);
    assert_int_equal(it_map_digest(&m, &nodes1), d0);
    assert_int_equal(nodes0, nodes1);
    assert_int_equal(m.oom_count, oom0);
    oracle_ins_delete(t);
    free(c.p);
}

static void test_simple_chunks(void **state)
{
    (void)state;
    check_method(OCC_INSERT_SIMPLE, RES, EVERY, false);
}

static void test_discrete_chunks(void **state)
{
    (void)state;
    check_method(OCC_INSERT_DISCRETE, RES, EVERY, false);
}

static void test_simple_min(void **state)
{
    (void)state;
    check_method(OCC_INSERT_SIMPLE, RES_MIN, EVERY_MIN, true);
}

static void test_discrete_min(void **state)
{
    (void)state;
    check_method(OCC_INSERT_DISCRETE, RES_MIN, EVERY_MIN, true);
}

/* A pool that holds half the scan: the chunked call refuses with OCC_ERR_NOMEM before its first
 * write (map unchanged, oom_count bumped) at several scratch sizes. */
static void test_pool_full_unchanged(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, EVERY)) {
        skip();
    }
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, RES);
    occ_insert_params_t p = occ_insert_params_default();
    occ_insert_result_t r0, r;
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          &r0),
                     OCC_OK);
    occ_map_stats_t ps;
    occ_map_pool_stats(&m, &ps);
    const size_t half = ps.bytes_used / 2u;
    occ_map_t small;
    it_init_map(&small, arena_b, half, RES);
    /* Something in the map first: the scan's first tenth. */
    assert_int_equal(occ_map_insert_cloud(&small, &c.origin, c.p, c.n / 10u, &p, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_OK);
    const size_t sizes[] = {sorted_bytes(&r0) / 8u, sorted_bytes(&r0) / 3u};
    for (size_t i = 0; i < 2u; i++) {
        size_t n0, n1;
        const uint64_t d0 = it_map_digest(&small, &n0);
        const uint32_t oom0 = small.oom_count;
        assert_int_equal(occ_map_insert_cloud(&small, &c.origin, c.p, c.n, &p, scratch, sizes[i],
                                              &r),
                         OCC_ERR_NOMEM);
        assert_int_equal(it_map_digest(&small, &n1), d0);
        assert_int_equal(n0, n1);
        assert_int_equal(small.oom_count, oom0 + 1u);
        assert_true(occ_map_check(&small) == OCC_OK);
    }
    free(c.p);
}

int main(void)
{
    arena_a = malloc(ARENA_BYTES);
    arena_b = malloc(ARENA_BYTES);
    scratch = malloc(SCRATCH_BYTES);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_simple_chunks, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_discrete_chunks, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_simple_min, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_discrete_min, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_pool_full_unchanged, it_timer_setup,
                                        it_timer_teardown),
    };
    const int rc = cmocka_run_group_tests(tests, NULL, NULL);
    free(arena_a);
    free(arena_b);
    free(scratch);
    return rc;
}
