/* SPDX-License-Identifier: BSD-3-Clause */
/* test_integrate_rays.c - the integration's ray walks (raycast.c: the dense set's marking walk and
 * the sorted path's code walk) against OctoMap's insertPointCloud on rays made to hit its ties:
 * origins and ends on voxel corners, axis-aligned and in-plane rays, 45-degree diagonals, rays
 * of every octant long enough to cross many 32-voxel chunks, rays of a few voxels. Each batch
 * goes in with ample scratch (the dense set where the box fits) and with half the sorted path's
 * bound above its fixed part (codes, sorted and collapsed as they come), into maps that
 * accumulate the batches. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>

#include "occmap/occmap.h"
#include "support/oracle_rays.h"
#include "support/integrate_fixture.h"
#include "support/test_rng.h"

#define ARENA_BYTES ((size_t)48 << 20)
#define SCRATCH_BYTES ((size_t)64 << 20)
#define RAYS 240u

static uint8_t *arena_a, *arena_b, *scratch;

/* A point `cells` voxels (integer) from the origin per axis: on voxel corners and edges when
 * the origin is on one. */
static occ_vec3_t grid_point(const occ_vec3_t o, const float res, const int cx, const int cy,
                             const int cz)
{
    const occ_vec3_t p = {o.x + (float)cx * res, o.y + (float)cy * res, o.z + (float)cz * res};
    return p;
}

/* End point i of a batch: one of the tie-prone kinds, or a plain random point. */
static occ_vec3_t end_point(const occ_vec3_t o, const float res, const float span)
{
    const int r = (int)(span / res);
    const int a = (int)(rnd() % (unsigned)(2 * r + 1)) - r, b = (int)(rnd() % (unsigned)(2 * r + 1)) - r,
              c = (int)(rnd() % (unsigned)(2 * r + 1)) - r;
    switch (rnd() % 7u) {
    case 0: /* axis-aligned */
        return rnd() % 3u == 0u ? grid_point(o, res, a, 0, 0)
                                : (rnd() % 2u ? grid_point(o, res, 0, b, 0) : grid_point(o, res, 0, 0, c));
    case 1: /* in an axis plane */
        return rnd() % 2u ? grid_point(o, res, a, b, 0) : grid_point(o, res, 0, b, c);
    case 2: /* 45-degree diagonals */
        return rnd() % 2u ? grid_point(o, res, a, a, rnd() % 2u ? a : -a) : grid_point(o, res, a, -a, 0);
    case 3: /* whole voxels away */
        return grid_point(o, res, a, b, c);
    case 4: { /* a few voxels */
        const occ_vec3_t p = {o.x + urand(-3.0f * res, 3.0f * res), o.y + urand(-3.0f * res, 3.0f * res),
                              o.z + urand(-3.0f * res, 3.0f * res)};
        return p;
    }
    default: {
        const occ_vec3_t p = {o.x + urand(-span, span), o.y + urand(-span, span), o.z + urand(-span, span)};
        return p;
    }
    }
}

/* One batch with both scratch sizes into a and b, and into OctoMap's tree t. */
static void insert_batch(occ_map_t *a, occ_map_t *b, void *t, const it_cloud_t *c,
                         const occ_insert_method_t meth)
{
    occ_insert_params_t p = occ_insert_params_default();
    p.method = meth;
    occ_insert_result_t ra, rb;
    assert_int_equal(occ_map_insert_cloud(a, &c->origin, c->p, c->n, &p, scratch, SCRATCH_BYTES, &ra),
                     OCC_OK);
    const size_t bound = occ_insert_scratch_bytes_scan(b, &c->origin, c->p, c->n, &p);
    /* super rays are not windowed: they get the bound, which the dense set rarely fits */
    const size_t half = meth == OCC_INSERT_SUPER_RAYS
                            ? bound
                            : OCC_INSERT_SCRATCH_FIXED_BYTES + (bound - OCC_INSERT_SCRATCH_FIXED_BYTES) / 2u;
    assert_int_equal(occ_map_insert_cloud(b, &c->origin, c->p, c->n, &p, scratch, half, &rb), OCC_OK);
    assert_int_equal(ra.voxels_updated, rb.voxels_updated);
    assert_int_equal(ra.voxels_occupied, rb.voxels_occupied);
    const float o[3] = {c->origin.x, c->origin.y, c->origin.z};
    oracle_ins_cloud(t, (const float *)(const void *)c->p, c->n, o, -1.0,
                     meth == OCC_INSERT_DISCRETE ? 1 : 0);
}

/* Batches of RAYS rays from origins on voxel corners, centres and anywhere. */
static void run_res(const float res, const occ_insert_method_t meth, const unsigned batches)
{
    occ_map_t a, b;
    it_init_map(&a, arena_a, ARENA_BYTES, res);
    it_init_map(&b, arena_b, ARENA_BYTES, res);
    void *t = oracle_ins_new((double)res);
    occ_vec3_t pts[RAYS];
    it_cloud_t c = {pts, RAYS, {0.0f, 0.0f, 0.0f}};
    for (unsigned k = 0; k < batches; k++) {
        const int ox = (int)(rnd() % 41u) - 20, oy = (int)(rnd() % 41u) - 20, oz = (int)(rnd() % 41u) - 20;
        const float shift = rnd() % 3u == 0u ? 0.0f : (rnd() % 2u ? 0.5f * res : urand(0.0f, res));
        c.origin = (occ_vec3_t){(float)ox * res + shift, (float)oy * res, (float)oz * res + shift};
        /* spans up to 150 voxels cross many 32-voxel chunks in every octant */
        const float span = res * (rnd() % 3u == 0u ? 150.0f : 40.0f);
        for (unsigned i = 0; i < RAYS; i++) {
            pts[i] = end_point(c.origin, res, span);
        }
        insert_batch(&a, &b, t, &c, meth);
    }
    assert_int_equal(occ_map_check(&a), OCC_OK);
    const size_t bad_a = it_diff_oracle(&a, t, 0.003f * (float)batches);
    const size_t bad_b = it_diff_oracle(&b, t, 0.003f * (float)batches);
    printf("  res %.3f method %d: %u batches of %u rays, %zu / %zu leaves differ\n", (double)res,
           (int)meth, batches, RAYS, bad_a, bad_b);
    assert_int_equal(bad_a, 0);
    assert_int_equal(bad_b, 0);
    assert_int_equal(it_diff_maps(&a, &b), 0);
    oracle_ins_delete(t);
}

static void test_tie_rays(void **state)
{
    (void)state;
    static const float resolutions[] = {0.1f, 0.05f, 0.37f, 0.013f};
    for (size_t r = 0; r < sizeof resolutions / sizeof resolutions[0]; r++) {
        rng_state = 0x9E3779B97F4A7C15ull + r;
        run_res(resolutions[r], OCC_INSERT_SIMPLE, 24u);
    }
}

static void test_tie_rays_discrete_superrays(void **state)
{
    (void)state;
    rng_state = 0x2545F4914F6CDD1Dull;
    run_res(0.1f, OCC_INSERT_DISCRETE, 16u);
    rng_state = 0x2545F4914F6CDD1Eull;
    run_res(0.05f, OCC_INSERT_SUPER_RAYS, 16u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_tie_rays, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_tie_rays_discrete_superrays, it_timer_setup,
                                        it_timer_teardown),
    };
    const it_buffers_t b = {&arena_a, &arena_b, &scratch, ARENA_BYTES, SCRATCH_BYTES};
    return it_run_tests("test_integrate_rays", tests, sizeof tests / sizeof tests[0], b);
}
