/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_failclosed.c - issue 16, "fail closed": a caller that ignores an error code reads
 * "unsafe", never "clear". Every collision entry point answers unsafe on bad input; the obstacle
 * distance has three outcomes (found, none within range, undecided); public levels >= 32 are
 * saturated or refused, never an undefined shift, and keys off the map never overflow (UBSan
 * watches). Stale handles: test_stale_handles.c. Expected values are worked out by hand in the
 * comments.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_collide_ccd.h"
#include "occmap/occ_evict.h"
#include "support/query_shapes.h"
#include "support/failclosed_map.h"

#define ARENA_BYTES OCC_ARENA_BYTES(4096, 4096)
static uint8_t arena[ARENA_BYTES];
static occ_map_t map;

/* a == b without -Wfloat-equal's complaint (exact values worked out by hand). */
static bool feq(float a, float b)
{
    return !(a < b) && !(a > b);
}

static void make_map(void)
{
    fc_make_map(&map, arena, sizeof arena);
}

static occ_key_t key_of(occ_vec3_t p)
{
    return fc_key_of(&map, p);
}

static int teardown(void **state)
{
    (void)state;
    return fc_forget_all(&map);
}

/* ---- collision checks: unsafe on every error --------------------------------------------------- */

/* What a previous successful call could have left: safe, and a FREE node. */
static void poison(occ_collision_t *c)
{
    memset(c, 0, sizeof *c);
    c->safe = true;
    c->outside = true;
    c->node.observed = true;
    c->node.state = OCC_STATE_FREE;
}

static void assert_unsafe(const occ_collision_t *c, const char *what)
{
    if (c->safe || c->outside || c->node.state != OCC_STATE_UNKNOWN || c->node.observed) {
        fail_msg("%s: safe %d outside %d node state %d observed %d", what, c->safe, c->outside,
                 c->node.state, c->node.observed);
    }
}

#define EXPECT_UNSAFE(call, err)              \
    do {                                      \
        poison(&col);                         \
        assert_int_equal((call), (err));      \
        assert_unsafe(&col, #call);           \
    } while (0)

static void sphere_support(const void *shape, const occ_vec3_t *d, occ_vec3_t *out)
{
    const float *const s = (const float *)shape; /* x, y, z, r */
    const float n = sqrtf(d->x * d->x + d->y * d->y + d->z * d->z);
    out->x = s[0] + s[3] * d->x / n;
    out->y = s[1] + s[3] * d->y / n;
    out->z = s[2] + s[3] * d->z / n;
}

static occ_convex_t convex_sphere(const float *s)
{
    occ_convex_t cv;
    cv.shape = s;
    cv.support = sphere_support;
    cv.center = v3(s[0], s[1], s[2]);
    cv.bmin = v3(s[0] - s[3], s[1] - s[3], s[2] - s[3]);
    cv.bmax = v3(s[0] + s[3], s[1] + s[3], s[2] + s[3]);
    return cv;
}

static void test_collision_errors_read_unsafe(void **state)
{
    (void)state;
    make_map();
    occ_collision_t col;
    occ_volume_t v;
    const occ_vec3_t nan3 = v3(NAN, 0.f, 0.f), inf3 = v3(0.f, INFINITY, 0.f);
    const occ_unknown_policy_t bad_policy = (occ_unknown_policy_t)7;
    const float half[3] = {0.1f, 0.1f, 0.1f}, neg_half[3] = {0.1f, -0.1f, 0.1f};
    const occ_vec3_t axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const occ_vec3_t skew[3] = {{1, 0, 0}, {0.7071f, 0.7071f, 0}, {0, 0, 1}};
    assert_int_equal(occ_volume_sphere(&v, P_FREE, 0.01f), OCC_OK);

    EXPECT_UNSAFE(occ_collide_volume(NULL, &v, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_volume(&map, NULL, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_volume(&map, &v, bad_policy, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_sphere(NULL, P_FREE, 0.01f, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_sphere(&map, nan3, 0.01f, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_sphere(&map, P_FREE, -0.01f, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_sphere(&map, P_FREE, NAN, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_sphere(&map, P_FREE, 0.01f, bad_policy, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_aabb(&map, v3(0.1f, 0.f, 0.f), v3(0.f, 0.1f, 0.1f),
                                   OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG); /* min > max */
    EXPECT_UNSAFE(occ_collide_aabb(&map, inf3, P_FREE, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_obb(&map, P_FREE, neg_half, axes, OCC_UNKNOWN_SAFE, &col),
                  OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_obb(&map, P_FREE, half, skew, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_obb(&map, P_FREE, NULL, axes, OCC_UNKNOWN_SAFE, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_capsule(&map, P_FREE, nan3, 0.01f, OCC_UNKNOWN_SAFE, &col),
                  OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_capsule(&map, P_FREE, P_FREE, -1.f, OCC_UNKNOWN_SAFE, &col),
                  OCC_ERR_ARG);

    const float ball[4] = {0.05f, 0.05f, 0.05f, 0.01f};
    occ_convex_t cv = convex_sphere(ball);
    EXPECT_UNSAFE(occ_collide_convex(NULL, &cv, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_convex(&map, NULL, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_convex(&map, &cv, bad_policy, OCC_CCD_GJK, &col), OCC_ERR_ARG);
    EXPECT_UNSAFE(occ_collide_convex(&map, &cv, OCC_UNKNOWN_SAFE, (occ_ccd_algo_t)9, &col),
                  OCC_ERR_ARG);
    cv.bmin.x = cv.bmax.x + 1.f; /* a bounding box inside out */
    EXPECT_UNSAFE(occ_collide_convex(&map, &cv, OCC_UNKNOWN_SAFE, OCC_CCD_MPR, &col), OCC_ERR_ARG);
    cv = convex_sphere(ball);
    cv.support = NULL;
    EXPECT_UNSAFE(occ_collide_convex(&map, &cv, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &col), OCC_ERR_ARG);
    cv = convex_sphere(ball);
    cv.center = nan3;
    EXPECT_UNSAFE(occ_collide_convex(&map, &cv, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &col), OCC_ERR_ARG);

    /* NULL out: the error alone, no crash. */
    assert_int_equal(occ_collide_volume(&map, &v, OCC_UNKNOWN_SAFE, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_collide_sphere(&map, nan3, 1.f, OCC_UNKNOWN_SAFE, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_collide_convex(&map, &cv, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, NULL),
                     OCC_ERR_ARG);
}

/* The same calls with good arguments still answer safe where it is (inside the free slab), and
 * name the occupied voxel where it is not: unsafe-first did not make everything unsafe. */
static void test_collision_answers_after_errors(void **state)
{
    (void)state;
    make_map();
    occ_collision_t col;
    const float half[3] = {0.02f, 0.02f, 0.02f};
    const occ_vec3_t axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const float ball[4] = {0.05f, 0.05f, 0.05f, 0.02f};
    const occ_convex_t cv = convex_sphere(ball);
    for (int round = 0; round < 2; round++) { /* each after a refused call on the same out */
        poison(&col);
        assert_int_equal(occ_collide_sphere(&map, P_FREE, NAN, OCC_UNKNOWN_SAFE, &col),
                         OCC_ERR_ARG);
        switch (round) {
        case 0:
            assert_int_equal(occ_collide_sphere(&map, P_FREE, 0.02f, OCC_UNKNOWN_UNSAFE, &col),
                             OCC_OK);
            break;
        default:
            assert_int_equal(occ_collide_convex(&map, &cv, OCC_UNKNOWN_UNSAFE, OCC_CCD_GJK, &col),
                             OCC_OK);
            break;
        }
        assert_true(col.safe);
    }
    assert_int_equal(occ_collide_obb(&map, P_FREE, half, axes, OCC_UNKNOWN_UNSAFE, &col), OCC_OK);
    assert_true(col.safe);
    assert_int_equal(occ_collide_capsule(&map, P_FREE, v3(0.3f, 0.05f, 0.05f), 0.02f,
                                         OCC_UNKNOWN_UNSAFE, &col), OCC_OK);
    assert_true(col.safe);
    /* A capsule from the slab to x = 1.2 touches the occupied voxel (its only blocker with
     * unknown counted free). */
    assert_int_equal(occ_collide_capsule(&map, P_FREE, v3(1.2f, 0.05f, 0.05f), 0.02f,
                                         OCC_UNKNOWN_SAFE, &col), OCC_OK);
    assert_false(col.safe);
    assert_false(col.outside);
    assert_int_equal(col.node.state, OCC_STATE_OCCUPIED);
    const occ_key_t kocc = key_of(P_OCC);
    assert_int_equal(col.node.level, 0u);
    assert_memory_equal(&col.node.key, &kocc, sizeof kocc);
    /* Off the map under OCC_UNKNOWN_UNSAFE: unsafe and outside. */
    assert_int_equal(occ_collide_sphere(&map, v3(3276.7f, 0.f, 0.f), 1.f, OCC_UNKNOWN_UNSAFE,
                                        &col), OCC_OK);
    assert_false(col.safe);
    assert_true(col.outside);
}

/* A support function that writes the map on its first call: the walk over the box cannot
 * finish on the old tree, so the answer is OCC_ERR_STATE and unsafe, not "safe". */
typedef struct {
    float s[4];
    int calls;
} writing_shape_t;

static void writing_support(const void *shape, const occ_vec3_t *d, occ_vec3_t *out)
{
    writing_shape_t *const w = (writing_shape_t *)(uintptr_t)shape;
    if (w->calls++ == 0) {
        assert_int_equal(occ_map_update(&map, v3(-20.05f, 0.05f, 0.05f), 1.0f), OCC_OK);
    }
    sphere_support(w->s, d, out);
}

static void test_convex_map_written_during_check(void **state)
{
    (void)state;
    make_map();
    /* A ball at x = 0.85, r = 0.1 reaches x = 0.95, short of the occupied voxel at 1.0; its
     * box is widened to x = 1.2, so the walk meets that voxel, tests it (no hit) and goes on. */
    writing_shape_t w = {{0.85f, 0.05f, 0.05f, 0.1f}, 0};
    occ_convex_t cv = convex_sphere(w.s);
    cv.shape = &w;
    cv.support = writing_support;
    cv.bmax.x = 1.2f;
    occ_collision_t col;
    poison(&col);
    assert_int_equal(occ_collide_convex(&map, &cv, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &col),
                     OCC_ERR_STATE);
    assert_true(w.calls > 0);
    assert_unsafe(&col, "convex check with a map write inside");
    /* Without the write the same shape is safe. */
    const occ_convex_t plain = convex_sphere(w.s);
    occ_convex_t wide = plain;
    wide.bmax.x = 1.2f;
    assert_int_equal(occ_collide_convex(&map, &wide, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &col), OCC_OK);
    assert_true(col.safe);
}

/* ---- the obstacle distance: found, none within range, undecided --------------------------------- */

static void test_distance_three_outcomes(void **state)
{
    (void)state;
    make_map();
    static occ_nearest_entry_t buf[512];
    float d = -1.f;
    occ_obstacle_t r = OCC_OBSTACLE_UNDECIDED;
    /* Found: from (0.05, 0.05, 0.05) to the voxel face at x = 1.0: 0.95 m (unknown is free). */
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 2.f, OCC_UNKNOWN_SAFE, buf, 512, &d, &r),
                     OCC_OK);
    assert_int_equal(r, OCC_OBSTACLE_FOUND);
    assert_true(fabsf(d - 0.95f) < 1e-5f);
    /* None within 0.5 m: the distance reads max_dist, a bound that holds. */
    d = -1.f;
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 0.5f, OCC_UNKNOWN_SAFE, buf, 512, &d, &r),
                     OCC_OK);
    assert_int_equal(r, OCC_OBSTACLE_NONE);
    assert_true(feq(d, 0.5f));
    /* Unknown blocks: the unknown voxel on top of P_FREE's (z from 0.1) is 0.05 m away. */
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 2.f, OCC_UNKNOWN_UNSAFE, buf, 512, &d,
                                              &r), OCC_OK);
    assert_int_equal(r, OCC_OBSTACLE_FOUND);
    assert_true(fabsf(d - 0.05f) < 1e-6f);
    /* One heap entry: with unknown blocking, all 8 children of the root are candidates, so the
     * heap overflows. That is "undecided", an obstacle right here, never "none". */
    d = 7.f;
    r = OCC_OBSTACLE_NONE;
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 2.f, OCC_UNKNOWN_UNSAFE, buf, 1, &d, &r),
                     OCC_ERR_NOMEM);
    assert_int_equal(r, OCC_OBSTACLE_UNDECIDED);
    assert_true(feq(d, 0.f));
    /* With unknown free only one branch holds the occupied voxel: one entry suffices. */
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 2.f, OCC_UNKNOWN_SAFE, buf, 1, &d, &r),
                     OCC_OK);
    assert_int_equal(r, OCC_OBSTACLE_FOUND);
    assert_true(fabsf(d - 0.95f) < 1e-5f);
}

static void test_distance_errors_undecided(void **state)
{
    (void)state;
    make_map();
    occ_nearest_entry_t buf[64];
    float d;
    occ_obstacle_t r;
    const occ_vec3_t nan3 = v3(0.f, NAN, 0.f);
#define EXPECT_UNDECIDED(call)                          \
    do {                                                \
        d = 5.f;                                        \
        r = OCC_OBSTACLE_NONE;                          \
        assert_int_equal((call), OCC_ERR_ARG);          \
        assert_int_equal(r, OCC_OBSTACLE_UNDECIDED);    \
        assert_true(feq(d, 0.f));          \
    } while (0)
    EXPECT_UNDECIDED(occ_distance_to_obstacle(NULL, P_FREE, 1.f, OCC_UNKNOWN_SAFE, buf, 64, &d, &r));
    EXPECT_UNDECIDED(occ_distance_to_obstacle(&map, nan3, 1.f, OCC_UNKNOWN_SAFE, buf, 64, &d, &r));
    EXPECT_UNDECIDED(occ_distance_to_obstacle(&map, P_FREE, -1.f, OCC_UNKNOWN_SAFE, buf, 64, &d, &r));
    EXPECT_UNDECIDED(occ_distance_to_obstacle(&map, P_FREE, NAN, OCC_UNKNOWN_SAFE, buf, 64, &d, &r));
    EXPECT_UNDECIDED(occ_distance_to_obstacle(&map, P_FREE, 1.f, OCC_UNKNOWN_SAFE, NULL, 64, &d, &r));
    EXPECT_UNDECIDED(occ_distance_to_obstacle(&map, P_FREE, 1.f, OCC_UNKNOWN_SAFE, buf, 0, &d, &r));
    EXPECT_UNDECIDED(occ_distance_to_obstacle(&map, P_FREE, 1.f, (occ_unknown_policy_t)3, buf, 64,
                                              &d, &r));
#undef EXPECT_UNDECIDED
    d = 5.f;
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 1.f, OCC_UNKNOWN_SAFE, buf, 64, &d,
                                              NULL), OCC_ERR_ARG);
    assert_true(feq(d, 0.f));
    r = OCC_OBSTACLE_NONE;
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 1.f, OCC_UNKNOWN_SAFE, buf, 64, NULL,
                                              &r), OCC_ERR_ARG);
    assert_int_equal(r, OCC_OBSTACLE_UNDECIDED);
}

/* ---- levels a caller passes: saturated or refused, no shift by 32 or more ----------------------- */

static void test_levels_saturate(void **state)
{
    (void)state;
    const unsigned depths[2] = {16u, 21u};
    for (unsigned di = 0; di < 2u; di++) {
        occ_map_config_t cfg = occ_map_config_default();
        cfg.depth_levels = (uint8_t)depths[di];
        assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
        assert_int_equal(occ_map_update(&map, P_OCC, 3.f), OCC_OK);
        const unsigned depth = depths[di];
        /* The root's edge: 0.1 m * 2^depth (6553.6 m at depth 16, 209715.2 m at 21). */
        const float root = occ_map_node_size(&map, depth);
        assert_true(fabsf(root - 0.1f * (float)(1u << depth)) <= 1e-3f * root);
        const unsigned levels[5] = {depth + 1u, 31u, 32u, 33u, 255u};
        const occ_key_t k = key_of(P_OCC);
        for (unsigned li = 0; li < 5u; li++) {
            const unsigned l = levels[li];
            const float size = occ_map_node_size(&map, l);
            assert_true(feq(size, root));
            /* The root's centre is the map origin. */
            const occ_vec3_t c = occ_map_key_center(&map, k, l);
            assert_true(feq(c.x, 0.f) && feq(c.y, 0.f) && feq(c.z, 0.f));
            const occ_key_t base = occ_key_at_level(k, l);
            assert_int_equal(base.k[0] | base.k[1] | base.k[2], 0u);
            occ_node_info_t info;
            assert_int_equal(occ_map_read_key(&map, k, l, &info), OCC_ERR_ARG);
            assert_int_equal(occ_map_set_key(&map, k, l, 1.f), OCC_ERR_ARG);
            assert_int_equal(occ_map_forget_key(&map, k, l), OCC_ERR_ARG);
            occ_volume_t v;
            assert_int_equal(occ_volume_sphere(&v, P_OCC, 1.f), OCC_OK);
            occ_info_gain_t g = {99u, 9.f}; /* what an earlier call could have left */
            assert_int_equal(occ_info_gain(&map, &v, l, 0u, &g), OCC_ERR_ARG);
            assert_true(g.unknown_cells == 0u && !(g.entropy_bits > 0.f));
            occ_query_iter_t it;
            const occ_pred_t pred = {0u, (uint8_t)(l > 255u ? 255u : l), 0u};
            assert_int_equal(occ_query_begin(&it, &map, &v, pred), OCC_ERR_ARG);
            occ_nearest_t nit;
            occ_nearest_entry_t buf[8];
            assert_int_equal(occ_nearest_begin(&nit, &map, P_OCC, 1.f, pred, buf, 8), OCC_ERR_ARG);
            /* A node handle with a level no node has. */
            occ_node_t root_node, out;
            occ_map_node_root(&map, &root_node);
            root_node.level = (uint8_t)l;
            assert_int_equal(occ_map_node_child(&map, &root_node, 0u, &out), OCC_ERR_ARG);
            fc_assert_unknown_node(&out);
        }
        /* Level 31 keeps bit 31 of a key, 32 and above keep nothing. */
        const occ_key_t high = {{0x80000001u, 0xC0000000u, 0x7FFFFFFFu}};
        const occ_key_t b31 = occ_key_at_level(high, 31u);
        assert_int_equal(b31.k[0], 0x80000000u);
        assert_int_equal(b31.k[1], 0x80000000u);
        assert_int_equal(b31.k[2], 0u);
        const occ_key_t b32 = occ_key_at_level(high, 32u);
        assert_int_equal(b32.k[0] | b32.k[1] | b32.k[2], 0u);
        /* Levels in range are exact: level 3 is 0.8 m, the voxel 0.1 m. */
        assert_true(fabsf(occ_map_node_size(&map, 3u) - 0.8f) < 1e-6f);
        assert_true(fabsf(occ_map_node_size(&map, 0u) - 0.1f) < 1e-9f);
    }
    assert_true(feq(occ_map_node_size(NULL, 3u), 0.f));
}

/* Keys no voxel has (>= 2^depth, up to 2^32 - 1): the centre they would have, outside the map,
 * and no signed overflow (UBSan). Depth 16 at 0.1 m: the map spans +-3276.8 m. */
static void test_key_center_off_map(void **state)
{
    (void)state;
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const occ_key_t k = {{0x80000000u, 0xFFFFFFFFu, 1u << 16}};
    const occ_vec3_t c = occ_map_key_center(&map, k, 0u);
    /* x: (2^31 - 2^15) * 0.1 + 0.05 = 214745088.05; y: (2^32 - 1 - 2^15) * 0.1 + 0.05 =
     * 429493452.8; z: 2^15 * 0.1 + 0.05 = 3276.85 (float rounding: relative 1e-7). */
    assert_true(fabs((double)c.x - 214745088.05) < 30.0);
    assert_true(fabs((double)c.y - 429493452.8) < 60.0);
    assert_true(fabs((double)c.z - 3276.85) < 1e-3);
    /* The last voxel of the map, for comparison: 3276.75. */
    const occ_key_t last = {{0xFFFFu, 0xFFFFu, 0xFFFFu}};
    assert_true(fabs((double)occ_map_key_center(&map, last, 0u).x - 3276.75) < 1e-3);
}

/* A point read that fails leaves no stale answer behind: out reads an unobserved UNKNOWN node
 * (first filled with an OCCUPIED read, then the failing call). */
static void test_point_read_errors_read_unknown(void **state)
{
    (void)state;
    make_map();
    occ_node_info_t info;
    const occ_vec3_t off_map = v3(1.0e6f, 0.0f, 0.0f);
    const occ_vec3_t nan_p = v3(NAN, 0.0f, 0.0f);
    const occ_err_t want[3] = {OCC_ERR_RANGE, OCC_ERR_ARG, OCC_ERR_ARG};
    for (unsigned c = 0; c < 3u; c++) {
        assert_int_equal(occ_map_read(&map, P_OCC, 0u, &info), OCC_OK);
        assert_int_equal(info.state, OCC_STATE_OCCUPIED);
        occ_err_t e;
        if (c == 0u) {
            e = occ_map_read(&map, off_map, 0u, &info);
        } else if (c == 1u) {
            e = occ_map_read(&map, nan_p, 0u, &info);
        } else {
            e = occ_map_read_key(&map, key_of(P_OCC), 17u, &info); /* level above depth 16 */
        }
        assert_int_equal(e, want[c]);
        assert_int_equal(info.state, OCC_STATE_UNKNOWN);
        assert_false(info.observed);
        assert_true((info.flags & OCC_NODE_HAS_UNKNOWN) != 0u);
        assert_true((info.flags & OCC_NODE_HAS_OCCUPIED) == 0u);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_collision_errors_read_unsafe, teardown),
        cmocka_unit_test_teardown(test_collision_answers_after_errors, teardown),
        cmocka_unit_test_teardown(test_convex_map_written_during_check, teardown),
        cmocka_unit_test_teardown(test_distance_three_outcomes, teardown),
        cmocka_unit_test_teardown(test_distance_errors_undecided, teardown),
        cmocka_unit_test_teardown(test_levels_saturate, teardown),
        cmocka_unit_test_teardown(test_key_center_off_map, teardown),
        cmocka_unit_test_teardown(test_point_read_errors_read_unknown, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
