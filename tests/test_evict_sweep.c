/* SPDX-License-Identifier: BSD-3-Clause */
/* test_evict_sweep.c - how an eviction sweep carries over between calls (occ_evict.h, "Slices"):
 * a budgeted call that stops early says so (resumable, sweep_active) and the next continues;
 * the call that ends the sweep says exhausted and no sweep is left; and a call without a budget
 * that resumes an old sweep does not believe "exhausted" from it alone - content added behind
 * the old sweep's position is still evicted in that call. The eviction rules themselves and
 * slices against one-shot: test_evict.c. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_evict.h"

static uint8_t arena[4u << 20];
static const occ_vec3_t centre = {0.0f, 0.0f, 0.0f};

/* Detailed content (alternating hits and misses, so nothing prunes) in the cube of edge
 * 2 m whose lowest corner is `lo`. */
static void add_content(occ_map_t *m, const occ_vec3_t lo)
{
    uint32_t i = 0;
    for (float x = 0.05f; x < 2.0f; x += 0.3f) {
        for (float y = 0.05f; y < 2.0f; y += 0.3f) {
            for (float z = 0.05f; z < 2.0f; z += 0.3f, i++) {
                const occ_vec3_t p = {lo.x + x, lo.y + y, lo.z + z};
                assert_int_equal(occ_map_update(m, p, (i % 2u) ? 0.85f : -0.4f), OCC_OK);
            }
        }
    }
}

/* Content only in the +x +y +z octant, 4..12 m from the centre: late in Morton order. */
static void make_map(occ_map_t *m)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(m, &cfg, arena, sizeof arena), OCC_OK);
    for (float d = 4.0f; d < 12.0f; d += 2.0f) {
        add_content(m, (occ_vec3_t){d, d * 0.5f, 1.0f});
        add_content(m, (occ_vec3_t){d * 0.5f, d, 3.0f});
    }
}

static occ_evict_policy_t policy(uint32_t budget)
{
    occ_evict_policy_t p = occ_evict_policy_default();
    p.mode = OCC_EVICT_ROBOT;
    p.shape = OCC_EVICT_SPHERE;
    p.keep_radius_m = 1.0f;
    p.budget_blocks = budget;
    return p;
}

/* A target the pools can never meet while the root is in use: every call runs until the budget
 * or the content runs out. */
static uint32_t unreachable(const occ_map_t *m)
{
    occ_map_stats_t st;
    occ_map_pool_stats(m, &st);
    return (uint32_t)(st.leaf_capacity > st.inner_capacity ? st.leaf_capacity : st.inner_capacity);
}

/* Budgeted calls until the sweep ends; returns how many it took. */
static unsigned sweep_in_slices(occ_map_t *m, uint32_t budget, unsigned max_calls,
                                occ_evict_out_t *out)
{
    const occ_evict_policy_t p = policy(budget);
    for (unsigned k = 1; k <= max_calls; k++) {
        assert_int_equal(occ_map_evict(m, &centre, &p, unreachable(m), out), OCC_OK);
        assert_int_equal(occ_map_check(m), OCC_OK);
        if (out->exhausted) {
            assert_false(out->sweep_active);
            assert_false(out->resumable);
            return k;
        }
        /* Stopped by the budget with content left: the next call continues this sweep. */
        assert_true(out->resumable);
        assert_true(out->sweep_active);
        assert_int_equal(out->sweeps, 1u);
    }
    return max_calls + 1u;
}

/* A fresh map swept in slices of 8 blocks to the end: the number of calls it takes. */
static unsigned calls_to_sweep(occ_map_t *m, occ_evict_out_t *out)
{
    make_map(m);
    occ_evict_out_init(out);
    const unsigned k = sweep_in_slices(m, 8u, 100000u, out);
    assert_true(k > 2u && k <= 100000u);
    assert_true(out->evictions > 0u);
    return k;
}

static void test_slices_flags(void **state)
{
    (void)state;
    occ_map_t m;
    occ_evict_out_t out;
    (void)calls_to_sweep(&m, &out);
    /* Nothing left: a fresh sweep finds nothing. */
    const occ_evict_policy_t p = policy(0u);
    assert_int_equal(occ_map_evict(&m, &centre, &p, unreachable(&m), &out), OCC_OK);
    assert_int_equal(out.last_evictions, 0u);
    assert_true(out.exhausted && !out.sweep_active);
}

static void test_resumed_sweep_retried(void **state)
{
    (void)state;
    occ_map_t m;
    occ_evict_out_t out;
    const unsigned k = calls_to_sweep(&m, &out);
    /* The same map again, stopped one slice before the end: the sweep stands in its last pass,
     * late in Morton order. */
    make_map(&m);
    occ_evict_out_init(&out);
    assert_int_equal(sweep_in_slices(&m, 8u, k - 1u, &out), k);
    /* That call stopped at k - 1: sweep_in_slices returned k only because it never saw
     * exhausted. New far content in the -x -y -z octant, behind the sweep's position. */
    assert_true(out.sweep_active);
    add_content(&m, (occ_vec3_t){-9.0f, -9.0f, -9.0f});
    const occ_evict_policy_t p = policy(0u);
    assert_int_equal(occ_map_evict(&m, &centre, &p, unreachable(&m), &out), OCC_OK);
    assert_true(out.exhausted && !out.sweep_active);
    assert_true(out.last_evictions > 0u);
    assert_int_equal(out.sweeps, 2u); /* the old sweep finished, then one complete fresh one */
    /* It really was exhausted: a fresh sweep finds nothing more. */
    assert_int_equal(occ_map_evict(&m, &centre, &p, unreachable(&m), &out), OCC_OK);
    assert_int_equal(out.last_evictions, 0u);
    assert_int_equal(occ_map_check(&m), OCC_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slices_flags),
        cmocka_unit_test(test_resumed_sweep_retried),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
