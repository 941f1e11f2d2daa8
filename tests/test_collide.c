/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_collide.c - "is this volume safe?" for spheres, boxes, oriented boxes, capsules, frusta and
 * segments against the brute-force oracle (every voxel the shape touches, Eigen geometry), with
 * both unknown policies and volumes leaving the map; libccd (GJK and MPR) against the analytic
 * checks where both apply. Random seed printed, OCC_SEED to repeat.
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

#include "occmap/occmap.h"
#include "occmap/host/occ_collide_ccd.h"
#include "support/oracle_query.h"
#include "support/query_shapes.h"

#define ARENA_BYTES (4u << 20)
#define MAX_CELLS 300000u

static uint8_t arena[ARENA_BYTES];
static occ_map_t map;
static uint64_t rng;
static uint64_t codes[MAX_CELLS];
static uint8_t amb[MAX_CELLS];

static int setup(void **state)
{
    (void)state;
    rng = qs_seed("test_collide");
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.25f;
    cfg.depth_levels = 6;
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) return 1;
    return oracle_q_random_map(&map, qs_rand(&rng), 2500u) != OCC_OK;
}

static occ_err_t collide_by_kind(const occ_volume_t *v, occ_unknown_policy_t pol, occ_collision_t *out)
{
    switch (v->kind) {
    case OCC_VOL_SPHERE:
        return occ_collide_sphere(&map, v->u.sphere.c, v->u.sphere.r, pol, out);
    case OCC_VOL_AABB:
        return occ_collide_aabb(&map, v->bmin, v->bmax, pol, out);
    case OCC_VOL_OBB:
        return occ_collide_obb(&map, v->u.obb.c, v->u.obb.half, v->u.obb.axis, pol, out);
    case OCC_VOL_CAPSULE:
        return occ_collide_capsule(&map, v->u.capsule.a, v->u.capsule.b, v->u.capsule.r, pol, out);
    case OCC_VOL_FRUSTUM:
    case OCC_VOL_SEGMENT:
    default:
        return occ_collide_volume(&map, v, pol, out);
    }
}

static void test_against_oracle(void **state)
{
    (void)state;
    const double half = 8.0; /* 0.25 m * 32 */
    unsigned safe_n = 0, unsafe_n = 0, outside_n = 0, skipped = 0;
    for (unsigned i = 0; i < 600u; i++) {
        qs_shape_t s;
        const double reach = i % 8u == 7u ? 9.5 : 6.0;
        const double size = i % 2u ? 1.0 : 3.0;
        assert_true(qs_random_shape(&rng, &map, (int)(i % 6u), reach, size, &s));
        for (int p = 0; p < 2; p++) {
            const occ_unknown_policy_t pol = p ? OCC_UNKNOWN_SAFE : OCC_UNKNOWN_UNSAFE;
            occ_collision_t c;
            assert_int_equal(collide_by_kind(&s.vol, pol, &c), OCC_OK);
            double mn[3], mx[3];
            oracle_q_bounds(s.oracle, mn, mx);
            bool leaves = false;
            for (int k = 0; k < 3; k++) {
                leaves = leaves || mn[k] < -half || mx[k] >= half;
            }
            if (pol == OCC_UNKNOWN_UNSAFE && leaves) {
                assert_false(c.safe);
                assert_true(c.outside);
                outside_n++;
                continue;
            }
            assert_false(c.outside);
            const unsigned states = OCC_PRED_OCCUPIED | (pol == OCC_UNKNOWN_UNSAFE ? OCC_PRED_UNKNOWN : 0u);
            const size_t n = oracle_q_collect(&map, s.oracle, states, 0, codes, amb, MAX_CELLS);
            size_t definite = 0;
            for (size_t j = 0; j < n && j < MAX_CELLS; j++) {
                definite += amb[j] ? 0u : 1u;
            }
            if (definite > 0u) {
                if (c.safe) {
                    fail_msg("%s policy %d: safe, oracle finds %zu blocking voxels", s.desc, p, definite);
                }
                /* The reported blocker is a blocking node that touches the shape. */
                assert_true(c.node.state == OCC_STATE_OCCUPIED ||
                            (pol == OCC_UNKNOWN_UNSAFE && c.node.state == OCC_STATE_UNKNOWN));
                assert_int_not_equal(oracle_q_cell(s.oracle, &map, c.node.key, c.node.level), 0);
                /* ... and the first one in Morton order: the volume iterator's first node. */
                occ_query_iter_t it;
                occ_pred_t pred = {(uint8_t)states, 0u, 0u};
                occ_query_node_t first;
                assert_int_equal(occ_query_begin(&it, &map, &s.vol, pred), OCC_OK);
                assert_true(occ_query_next(&it, &first));
                assert_memory_equal(&first.key, &c.node.key, sizeof first.key);
                assert_int_equal(first.level, c.node.level);
                assert_int_equal(first.state, c.node.state);
                unsafe_n++;
            } else if (n == 0u) {
                if (!c.safe) {
                    fail_msg("%s policy %d: unsafe (node %u,%u,%u level %u), oracle finds none",
                             s.desc, p, c.node.key.k[0], c.node.key.k[1], c.node.key.k[2], c.node.level);
                }
                safe_n++;
            } else {
                skipped++;
            }
        }
        qs_free(&s);
    }
    printf("collide: %u safe, %u unsafe, %u off-map, %u ambiguous\n", safe_n, unsafe_n, outside_n, skipped);
    assert_true(safe_n > 50u && unsafe_n > 50u && outside_n > 10u);
}

/* ---- libccd ---------------------------------------------------------------------------------- */
typedef struct { occ_vec3_t c; float r; } sphere_t;
typedef struct { occ_vec3_t c; occ_vec3_t ax[3]; float h[3]; } obb_t;
typedef struct { occ_vec3_t a, b; float r; } capsule_t;

static float dot3(occ_vec3_t a, occ_vec3_t b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static void sphere_support(const void *shape, const occ_vec3_t *d, occ_vec3_t *out)
{
    const sphere_t *s = shape;
    const float n = sqrtf(dot3(*d, *d));
    out->x = s->c.x + s->r * d->x / n;
    out->y = s->c.y + s->r * d->y / n;
    out->z = s->c.z + s->r * d->z / n;
}

static void obb_support(const void *shape, const occ_vec3_t *d, occ_vec3_t *out)
{
    const obb_t *b = shape;
    *out = b->c;
    for (int i = 0; i < 3; i++) {
        const float sg = dot3(*d, b->ax[i]) >= 0 ? b->h[i] : -b->h[i];
        out->x += sg * b->ax[i].x;
        out->y += sg * b->ax[i].y;
        out->z += sg * b->ax[i].z;
    }
}

static void capsule_support(const void *shape, const occ_vec3_t *d, occ_vec3_t *out)
{
    const capsule_t *c = shape;
    const occ_vec3_t ab = {c->b.x - c->a.x, c->b.y - c->a.y, c->b.z - c->a.z};
    const occ_vec3_t p = dot3(*d, ab) >= 0 ? c->b : c->a;
    const float n = sqrtf(dot3(*d, *d));
    out->x = p.x + c->r * d->x / n;
    out->y = p.y + c->r * d->y / n;
    out->z = p.z + c->r * d->z / n;
}

static void test_ccd_vs_analytic(void **state)
{
    (void)state;
    const float delta = 2e-3f;
    unsigned agree = 0, checked = 0;
    for (unsigned i = 0; i < 900u; i++) {
        const occ_vec3_t c = {(float)qs_uniform(&rng, -7, 7), (float)qs_uniform(&rng, -7, 7),
                              (float)qs_uniform(&rng, -7, 7)};
        const float r = (float)qs_uniform(&rng, 0.1, 1.2);
        const occ_unknown_policy_t pol = (i & 1u) ? OCC_UNKNOWN_SAFE : OCC_UNKNOWN_UNSAFE;
        const occ_ccd_algo_t algo = (i & 2u) ? OCC_CCD_MPR : OCC_CCD_GJK;
        occ_convex_t cv;
        occ_collision_t ccd, lo, hi;
        sphere_t sp;
        obb_t ob;
        capsule_t ca;
        const unsigned kind = i % 3u;
        if (kind == 0u) {
            sp.c = c;
            sp.r = r;
            cv.shape = &sp;
            cv.support = sphere_support;
            assert_int_equal(occ_collide_sphere(&map, c, r - delta, pol, &lo), OCC_OK);
            assert_int_equal(occ_collide_sphere(&map, c, r + delta, pol, &hi), OCC_OK);
        } else if (kind == 1u) {
            float h[3], hl[3], hh[3];
            for (int k = 0; k < 3; k++) {
                h[k] = (float)qs_uniform(&rng, 0.1, 1.0);
                hl[k] = h[k] - delta;
                hh[k] = h[k] + delta;
            }
            occ_volume_t v;
            assert_int_equal(occ_volume_obb_yaw(&v, c, h, (float)qs_uniform(&rng, -3, 3)), OCC_OK);
            ob.c = c;
            for (int k = 0; k < 3; k++) {
                ob.ax[k] = v.u.obb.axis[k];
                ob.h[k] = h[k];
            }
            cv.shape = &ob;
            cv.support = obb_support;
            assert_int_equal(occ_collide_obb(&map, c, hl, ob.ax, pol, &lo), OCC_OK);
            assert_int_equal(occ_collide_obb(&map, c, hh, ob.ax, pol, &hi), OCC_OK);
        } else {
            ca.a = c;
            ca.b.x = c.x + (float)qs_uniform(&rng, -2, 2);
            ca.b.y = c.y + (float)qs_uniform(&rng, -2, 2);
            ca.b.z = c.z + (float)qs_uniform(&rng, -2, 2);
            ca.r = r;
            cv.shape = &ca;
            cv.support = capsule_support;
            assert_int_equal(occ_collide_capsule(&map, ca.a, ca.b, r - delta, pol, &lo), OCC_OK);
            assert_int_equal(occ_collide_capsule(&map, ca.a, ca.b, r + delta, pol, &hi), OCC_OK);
        }
        /* Bounds and centre from the support function itself. */
        const occ_vec3_t dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        occ_vec3_t e[6];
        for (int k = 0; k < 6; k++) cv.support(cv.shape, &dirs[k], &e[k]);
        cv.bmin = (occ_vec3_t){e[1].x, e[3].y, e[5].z};
        cv.bmax = (occ_vec3_t){e[0].x, e[2].y, e[4].z};
        cv.center = kind == 2u ? (occ_vec3_t){0.5f * (ca.a.x + ca.b.x), 0.5f * (ca.a.y + ca.b.y),
                                               0.5f * (ca.a.z + ca.b.z)}
                               : c;
        assert_int_equal(occ_collide_convex(&map, &cv, pol, algo, &ccd), OCC_OK);
        if (hi.safe) {
            assert_true(ccd.safe);
        }
        if (!lo.safe) {
            if (ccd.safe) {
                fail_msg("shape %u kind %u algo %d policy %d: ccd safe, analytic (shrunk) unsafe", i, kind, algo, pol);
            }
        }
        checked++;
        agree += (hi.safe == lo.safe) ? 1u : 0u;
    }
    printf("ccd: %u shapes, %u decided by the analytic bracket\n", checked, agree);
    assert_true(agree > checked / 2u);
    /* Bad input. */
    occ_convex_t bad = {0};
    occ_collision_t out;
    assert_int_equal(occ_collide_convex(&map, &bad, OCC_UNKNOWN_SAFE, OCC_CCD_GJK, &out), OCC_ERR_ARG);
}

/* Closed volumes: a face or a sphere exactly on a voxel's face touches it, a hair away does not.
 * Hand-built: one occupied voxel [-0.25, 0)^3 at 0.25 m (everything else unknown, safe here), so
 * that its upper faces lie on the borders of nodes of every level. */
static void test_faces_touch(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.25f;
    cfg.depth_levels = 6;
    static uint8_t small[1 << 16];
    occ_map_t m2;
    assert_int_equal(occ_map_init(&m2, &cfg, small, sizeof small), OCC_OK);
    const occ_vec3_t v = {-0.1f, -0.1f, -0.1f};
    assert_int_equal(occ_map_update(&m2, v, cfg.clamp_max), OCC_OK);
    assert_int_equal(occ_map_state_at(&m2, v), OCC_STATE_OCCUPIED);
    const float up = nextafterf(0.0f, 1.0f), in = -0.05f;
    occ_collision_t c;
    const struct {
        occ_vec3_t mn, mx;
        bool safe;
    } boxes[] = {
        {{0.0f, -0.2f, -0.2f}, {1.0f, in, in}, false}, /* lower x face on the voxel's upper */
        {{up, -0.2f, -0.2f}, {1.0f, in, in}, true},
        {{-1.0f, -0.2f, -0.2f}, {-0.25f, in, in}, false}, /* upper x face on its lower face */
        {{-1.0f, -0.2f, -0.2f}, {nextafterf(-0.25f, -1.0f), in, in}, true},
        {{-0.2f, 0.0f, 0.0f}, {in, 1.0f, 1.0f}, false}, /* along an edge */
        {{-0.2f, 0.0f, up}, {in, 1.0f, 1.0f}, true},
        {{0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}, false}, /* at a corner */
        {{up, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}, true},
    };
    for (size_t i = 0; i < sizeof boxes / sizeof boxes[0]; i++) {
        assert_int_equal(occ_collide_aabb(&m2, boxes[i].mn, boxes[i].mx, OCC_UNKNOWN_SAFE, &c), OCC_OK);
        if (c.safe != boxes[i].safe) {
            fail_msg("box %zu: safe %d, expected %d", i, c.safe, boxes[i].safe);
        }
    }
    /* A sphere 0.25 m beyond the middle of the voxel's upper x face. */
    const occ_vec3_t sc = {0.25f, -0.125f, -0.125f};
    assert_int_equal(occ_collide_sphere(&m2, sc, 0.25f, OCC_UNKNOWN_SAFE, &c), OCC_OK);
    assert_false(c.safe);
    assert_int_equal(occ_collide_sphere(&m2, sc, nextafterf(0.25f, 0.0f), OCC_UNKNOWN_SAFE, &c), OCC_OK);
    assert_true(c.safe);
}

static void test_bad_input(void **state)
{
    (void)state;
    occ_collision_t out;
    const occ_vec3_t z = {0, 0, 0}, n = {NAN, 0, 0};
    assert_int_equal(occ_collide_sphere(&map, z, -1.f, OCC_UNKNOWN_UNSAFE, &out), OCC_ERR_ARG);
    assert_int_equal(occ_collide_sphere(&map, n, 1.f, OCC_UNKNOWN_UNSAFE, &out), OCC_ERR_ARG);
    assert_int_equal(occ_collide_sphere(&map, z, 1.f, (occ_unknown_policy_t)3, &out), OCC_ERR_ARG);
    assert_int_equal(occ_collide_sphere(&map, z, 1.f, OCC_UNKNOWN_SAFE, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_collide_capsule(&map, z, n, 1.f, OCC_UNKNOWN_SAFE, &out), OCC_ERR_ARG);
    const float h[3] = {1, 1, 1};
    const occ_vec3_t degenerate[3] = {{1, 0, 0}, {1, 0, 0}, {0, 0, 1}};
    assert_int_equal(occ_collide_obb(&map, z, h, degenerate, OCC_UNKNOWN_SAFE, &out), OCC_ERR_ARG);
    assert_int_equal(occ_collide_aabb(&map, h[0] > 0 ? (occ_vec3_t){1, 1, 1} : z, z, OCC_UNKNOWN_SAFE, &out), OCC_ERR_ARG);
    /* A point-sized sphere in unknown space under each policy. */
    occ_map_config_t cfg = occ_map_config_default();
    static uint8_t small[1 << 16];
    occ_map_t m2;
    assert_int_equal(occ_map_init(&m2, &cfg, small, sizeof small), OCC_OK);
    assert_int_equal(occ_collide_sphere(&m2, z, 0.f, OCC_UNKNOWN_UNSAFE, &out), OCC_OK);
    assert_false(out.safe);
    assert_int_equal(occ_collide_sphere(&m2, z, 0.f, OCC_UNKNOWN_SAFE, &out), OCC_OK);
    assert_true(out.safe);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_faces_touch),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_against_oracle),
        cmocka_unit_test(test_ccd_vs_analytic),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
