/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_geometry.c - one voxel geometry for every call (issue 16, section 1).
 *
 * Write-then-query on voxel borders: points whose coordinates are decimal multiples of 0.1,
 * 0.05, 0.2, 0.08, 0.02, 0.15 m (both signs, each axis), maps of several resolutions at depth 16
 * and 21. occ_map_update(p, +hit) on a map that is otherwise free, then every call must name the
 * same voxel: occ_map_key, occ_map_read / read_key / state_at, the lookup cursor, occ_cast_ray
 * from p and towards p, occ_line_of_sight from p, sphere and box collision at p, the volume
 * iterator, nearest obstacle, integration (a ray ending at p), the sectors of a pose next to it,
 * and eviction around p keeping it. And occ_map_key equals OctoMap's
 * OcTree(decimal).coordToKeyChecked on all those points (tests/support/oracle_geom.cpp).
 *
 * Built twice: with the host's double key arithmetic (keys equal OctoMap's exactly), and with
 * -DOCC_RAY_DOUBLE=0 (tests/geometry.mk, the firmware's float arithmetic), where a key may
 * differ from OctoMap's within ~1e-7 relative of a border but all occmap calls still agree.
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
#include "occmap/occ_evict.h"
#include "occmap/occ_sectors.h"
#include "occmap/occ_integrate.h"
#include "occmap/occ_query.h"
#include "support/oracle_geom.h"
#if OCC_RAY_DOUBLE
#include <stdlib.h>
#include <unistd.h>
#include "occmap/host/occ_scan.h"
#include "support/oracle_rays.h"
#endif

#define ARENA_BYTES (1u << 20)
#define SCRATCH_BYTES (4u << 20)

static uint8_t arena[ARENA_BYTES];
static uint8_t scratch[SCRATCH_BYTES];
static occ_map_t map;
static occ_nearest_entry_t heap[512];
static occ_sectors_t sectors;

static const float resolutions[] = {0.1f, 0.05f, 0.2f, 0.08f, 0.02f, 0.15f,
                                    0.04f, 0.25f, 0.3f, 0.07f, 0.5f, 0.01f};
static const float steps[] = {0.1f, 0.05f, 0.2f, 0.08f, 0.02f, 0.15f};
static const int multiples[] = {1, 2, 3, 5, 7, 10, 13, 29};

/* Where the point is and which call disagreed, for the failure message. */
typedef struct {
    float res;
    unsigned depth;
    occ_vec3_t p;
} where_t;

#define CHECK(cond, w, what)                                                                     \
    do {                                                                                          \
        if (!(cond)) {                                                                            \
            fail_msg("res %g depth %u p (%.9g, %.9g, %.9g): %s", (double)(w)->res, (w)->depth,    \
                     (double)(w)->p.x, (double)(w)->p.y, (double)(w)->p.z, what);                 \
        }                                                                                         \
    } while (0)

/* Bit-for-bit equality of two floats or doubles (-Wfloat-equal forbids ==). */
static bool feq(double a, double b)
{
    return !(a < b) && !(a > b);
}

static bool key_eq(occ_key_t a, occ_key_t b)
{
    return a.k[0] == b.k[0] && a.k[1] == b.k[1] && a.k[2] == b.k[2];
}

static occ_vec3_t v3(float x, float y, float z)
{
    const occ_vec3_t v = {x, y, z};
    return v;
}

static void init_free_map(float res, unsigned depth)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    cfg.depth_levels = (uint8_t)depth;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const occ_key_t any = {{0u, 0u, 0u}};
    /* Everything free (the root uniform), so walks and sectors see only the written voxel. */
    assert_int_equal(occ_map_set_key(&map, any, depth, -1.0f), OCC_OK);
}

#if !OCC_RAY_DOUBLE
static float axis_of(occ_vec3_t v, unsigned a)
{
    return a == 0u ? v.x : (a == 1u ? v.y : v.z);
}

/* A float within 1e-6 relative of a voxel border of the decimal resolution (the float build
 * may put such a point in OctoMap's neighbour voxel). */
static bool near_border(float c, float res)
{
    const double q = (double)c / oracle_geom_user_res((double)res);
    const double d = fabs(q - floor(q + 0.5));
    return d <= 1e-6 * (fabs(q) > 1.0 ? fabs(q) : 1.0);
}
#endif

static unsigned octomap_key_diffs;

/* occ_map_key against OcTree(decimal).coordToKeyChecked (depth 16; at depth 21 the same floor,
 * shifted by 2^20 - 2^15). */
static void check_octomap_key(const where_t *w, occ_key_t k)
{
    uint32_t ok[3];
    CHECK(oracle_geom_key(w->res, w->p.x, w->p.y, w->p.z, ok) == 1, w, "OctoMap: off the map");
    const uint32_t shift = (1u << (w->depth - 1u)) - (1u << 15);
    for (unsigned a = 0; a < 3u; a++) {
        if (k.k[a] != ok[a] + shift) {
#if OCC_RAY_DOUBLE
            CHECK(false, w, "occ_map_key differs from OcTree(decimal).coordToKeyChecked");
#else
            CHECK(near_border(axis_of(w->p, a), w->res), w,
                  "float build: key differs from OctoMap's away from a border");
            octomap_key_diffs++;
#endif
        }
    }
    if (w->depth == 16u) {
        /* And the centre is keyToCoord's. */
        float oc[3];
        oracle_geom_center(w->res, k.k, 0u, oc);
        const occ_vec3_t c = occ_map_key_center(&map, k, 0u);
#if OCC_RAY_DOUBLE
        CHECK(feq((double)c.x, (double)oc[0]) && feq((double)c.y, (double)oc[1]) &&
                  feq((double)c.z, (double)oc[2]),
              w, "centre differs from keyToCoord");
#else
        CHECK(fabsf(c.x - oc[0]) <= 1e-6f * (1.0f + fabsf(oc[0])) &&
                  fabsf(c.y - oc[1]) <= 1e-6f * (1.0f + fabsf(oc[1])) &&
                  fabsf(c.z - oc[2]) <= 1e-6f * (1.0f + fabsf(oc[2])),
              w, "float build: centre far from keyToCoord");
#endif
    }
}

static void check_reads(const where_t *w, occ_key_t k)
{
    occ_node_info_t info;
    CHECK(occ_map_read_key(&map, k, 0u, &info) == OCC_OK && info.state == OCC_STATE_OCCUPIED &&
              info.level == 0u,
          w, "occ_map_read_key(key) is not the occupied voxel");
    CHECK(occ_map_read(&map, w->p, 0u, &info) == OCC_OK && info.state == OCC_STATE_OCCUPIED &&
              info.level == 0u,
          w, "occ_map_read(p) is not the occupied voxel");
    CHECK(occ_map_state_at(&map, w->p) == OCC_STATE_OCCUPIED, w, "occ_map_state_at(p)");
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    CHECK(occ_lookup_state(&lk, w->p) == OCC_STATE_OCCUPIED, w, "lookup cursor at p");
}

static void check_rays(const where_t *w, occ_key_t k)
{
    const float res = w->res;
    const occ_vec3_t dirs[6] = {v3(1, 0, 0), v3(-1, 0, 0), v3(0, 1, 0),
                                v3(0, -1, 0), v3(0, 0, 1),  v3(0.6f, -0.48f, 0.64f)};
    for (unsigned d = 0; d < 6u; d++) {
        occ_ray_result_t r;
        CHECK(occ_cast_ray(&map, w->p, dirs[d], false, -1.0f, &r) == OCC_OK && r.hit &&
                  r.stop == OCC_RAY_HIT && key_eq(r.key, k),
              w, "occ_cast_ray from p does not stop in p's voxel");
        /* From 2.5 voxels before p, towards it: the walk enters p's voxel and stops there. */
        const occ_vec3_t o = v3(w->p.x - 2.5f * res * dirs[d].x, w->p.y - 2.5f * res * dirs[d].y,
                                w->p.z - 2.5f * res * dirs[d].z);
        /* (Along an axis only: a slanted ray through a corner may pass the neighbour.) */
        CHECK(d == 5u || (occ_cast_ray(&map, o, dirs[d], false, -1.0f, &r) == OCC_OK && r.hit &&
                          key_eq(r.key, k)),
              w, "occ_cast_ray towards p does not stop in p's voxel");
        bool visible = true;
        occ_ray_result_t blocker;
        const float eps = 0.3f * res;
        const occ_vec3_t b = v3(w->p.x + eps * dirs[d].x, w->p.y + eps * dirs[d].y,
                                w->p.z + eps * dirs[d].z);
        CHECK(occ_line_of_sight(&map, w->p, b, OCC_UNKNOWN_SAFE, &visible, &blocker) == OCC_OK &&
                  !visible && blocker.hit && key_eq(blocker.key, k),
              w, "occ_line_of_sight(p, p + eps) visible or blocked elsewhere");
        CHECK(occ_line_of_sight(&map, o, w->p, OCC_UNKNOWN_SAFE, &visible, &blocker) == OCC_OK &&
                  !visible && key_eq(blocker.key, k),
              w, "occ_line_of_sight(o, p) visible or blocked elsewhere");
    }
}

static void check_volumes(const where_t *w, occ_key_t k)
{
    const float res = w->res;
    occ_collision_t col;
    CHECK(occ_collide_sphere(&map, w->p, 0.01f * res, OCC_UNKNOWN_SAFE, &col) == OCC_OK &&
              !col.safe && col.node.level == 0u && key_eq(col.node.key, k),
          w, "sphere at p does not collide with p's voxel");
    const float h = 0.01f * res;
    const occ_vec3_t lo = v3(w->p.x - h, w->p.y - h, w->p.z - h);
    const occ_vec3_t hi = v3(w->p.x + h, w->p.y + h, w->p.z + h);
    CHECK(occ_collide_aabb(&map, lo, hi, OCC_UNKNOWN_SAFE, &col) == OCC_OK && !col.safe &&
              key_eq(col.node.key, k),
          w, "box at p does not collide with p's voxel");
    /* The iterator over a box of two voxels around p reports exactly p's voxel as occupied. */
    occ_volume_t vol;
    const occ_vec3_t blo = v3(w->p.x - 2.0f * res, w->p.y - 2.0f * res, w->p.z - 2.0f * res);
    const occ_vec3_t bhi = v3(w->p.x + 2.0f * res, w->p.y + 2.0f * res, w->p.z + 2.0f * res);
    assert_int_equal(occ_volume_aabb(&vol, blo, bhi), OCC_OK);
    const occ_pred_t pred = {(uint8_t)OCC_PRED_OCCUPIED, 0u, 0u};
    occ_query_iter_t it;
    assert_int_equal(occ_query_begin(&it, &map, &vol, pred), OCC_OK);
    occ_query_node_t node;
    unsigned n = 0;
    bool same = true;
    while (occ_query_next(&it, &node)) {
        n++;
        same = same && node.level == 0u && key_eq(node.key, k);
    }
    CHECK(n == 1u && same, w, "volume iterator: not exactly p's voxel occupied");
    /* Nearest obstacle: p's voxel, at distance 0 (node boxes are float centre +- half edge:
     * a face may round a few float steps off the decimal one). */
    const float tiny = 1e-6f;
    float dist = -1.0f;
    occ_obstacle_t outcome = OCC_OBSTACLE_UNDECIDED;
    CHECK(occ_distance_to_obstacle(&map, w->p, 1.0f, OCC_UNKNOWN_SAFE, heap,
                                   sizeof heap / sizeof heap[0], &dist, &outcome) == OCC_OK &&
              outcome == OCC_OBSTACLE_FOUND && dist <= tiny,
          w, "occ_distance_to_obstacle(p) is not 0");
    occ_nearest_t nn;
    assert_int_equal(occ_nearest_begin(&nn, &map, w->p, 1.0f, pred, heap,
                                       sizeof heap / sizeof heap[0]),
                     OCC_OK);
    bool found = false;
    CHECK(occ_nearest_next(&nn, &node, &dist, &found) == OCC_OK && found && dist <= tiny &&
              key_eq(node.key, k),
          w, "nearest iterator: first node is not p's voxel at 0");
}

/* The pose 2.5 voxels from p along -x (or +x): the sector looking at the voxel reads the
 * horizontal distance to the voxel's box, the box of key k (float rounding aside). */
static void check_sectors(const where_t *w, occ_key_t k)
{
    const float res = w->res;
    const float dx = w->p.x > 0.0f ? -2.5f * res : 2.5f * res;
    const occ_pose_t pose = {{w->p.x + dx, w->p.y, w->p.z}, {1.0f, 0.0f, 0.0f, 0.0f}};
    const occ_sectors_config_t cfg = occ_sectors_config_default();
    CHECK(occ_sectors_compute(&map, &pose, &cfg, &sectors) == OCC_OK, w, "occ_sectors_compute");
    float best = OCC_SECTORS_FAR;
    for (unsigned s = 0; s < sectors.n; s++) {
        best = sectors.d_occ_m[s] < best ? sectors.d_occ_m[s] : best;
    }
    const occ_vec3_t c = occ_map_key_center(&map, k, 0u);
    const double half = 0.5 * (double)res;
    const double gx = fmax(fabs((double)pose.p.x - (double)c.x) - half, 0.0);
    const double gy = fmax(fabs((double)pose.p.y - (double)c.y) - half, 0.0);
    const double want = sqrt(gx * gx + gy * gy);
    CHECK(fabs((double)best - want) < 1e-3 * (double)res, w,
          "sectors: nearest obstacle is not p's voxel box");
}

static void check_evict(const where_t *w)
{
    occ_evict_policy_t pol = occ_evict_policy_default();
    pol.keep_radius_m = 0.0f;
    occ_evict_out_t ev;
    occ_evict_out_init(&ev);
    CHECK(occ_map_evict(&map, &w->p, &pol, UINT32_MAX / 4u, &ev) == OCC_OK, w, "occ_map_evict");
    CHECK(occ_map_state_at(&map, w->p) == OCC_STATE_OCCUPIED, w,
          "eviction around p (keep radius 0) lost p's voxel");
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* A ray that ends at p (from a point off the borders) marks p's voxel occupied. */
static void check_integration(const where_t *w, occ_key_t k, occ_insert_method_t method)
{
    occ_map_config_t cfg = map.cfg;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const float res = w->res;
    const occ_vec3_t o = v3(w->p.x + 3.37f * res, w->p.y - 2.29f * res, w->p.z + 1.23f * res);
    occ_insert_params_t par = occ_insert_params_default();
    par.method = method;
    occ_insert_result_t r;
    CHECK(occ_map_insert_cloud(&map, &o, &w->p, 1u, &par, scratch, sizeof scratch, &r) == OCC_OK,
          w, "occ_map_insert_cloud");
    occ_node_info_t info;
    CHECK(occ_map_read_key(&map, k, 0u, &info) == OCC_OK && info.state == OCC_STATE_OCCUPIED,
          w, "integration: the ray ending at p did not mark p's voxel");
    CHECK(r.voxels_occupied == 1u, w, "integration: more than one hit voxel");
}

static void check_point(float res, unsigned depth, occ_vec3_t p)
{
    const where_t w = {res, depth, p};
    init_free_map(res, depth);
    occ_key_t k;
    CHECK(occ_map_key(&map, p, &k) == OCC_OK, &w, "occ_map_key");
    check_octomap_key(&w, k);
    CHECK(occ_map_update(&map, p, 3.0f) == OCC_OK, &w, "occ_map_update");
    check_reads(&w, k);
    check_rays(&w, k);
    check_volumes(&w, k);
    check_sectors(&w, k);
    check_evict(&w);
    check_integration(&w, k, OCC_INSERT_SIMPLE);
    check_integration(&w, k, OCC_INSERT_DISCRETE);
}

/* The border values of one step: +-n * step for the multiples. */
static unsigned border_values(float step, float out[])
{
    unsigned n = 0;
    for (size_t m = 0; m < sizeof multiples / sizeof multiples[0]; m++) {
        const float v = (float)((double)multiples[m] * (double)step);
        out[n++] = v;
        out[n++] = -v;
    }
    return n;
}

static void run_depth(unsigned depth)
{
    unsigned checked = 0;
    octomap_key_diffs = 0;
    for (size_t r = 0; r < sizeof resolutions / sizeof resolutions[0]; r++) {
        for (size_t s = 0; s < sizeof steps / sizeof steps[0]; s++) {
            float vals[2u * sizeof multiples / sizeof multiples[0]];
            const unsigned nv = border_values(steps[s], vals);
            for (unsigned i = 0; i < nv; i++) {
                for (unsigned a = 0; a < 3u; a++) {
                    /* The border value on axis a, other border values of the same step on the
                     * other axes (so every point lies on a border on all three). */
                    float c[3];
                    c[a] = vals[i];
                    c[(a + 1u) % 3u] = vals[(i + 3u) % nv];
                    c[(a + 2u) % 3u] = vals[(i + 6u) % nv];
                    check_point(resolutions[r], depth, v3(c[0], c[1], c[2]));
                    checked++;
                }
            }
        }
    }
    printf("depth %u: %u border points, every call names the same voxel (OCC_RAY_DOUBLE %d, "
           "%u key differences from OctoMap next to a border)\n",
           depth, checked, (int)OCC_RAY_DOUBLE, octomap_key_diffs);
#if OCC_RAY_DOUBLE
    assert_int_equal(octomap_key_diffs, 0u);
#endif
}

static void test_border_points_depth16(void **state)
{
    (void)state;
    run_depth(16u);
}

static void test_border_points_depth21(void **state)
{
    (void)state;
    run_depth(21u);
}

/* The issue's case by hand: at 0.1 m, x = 1.0 is the low face of voxel 10 (OcTree(0.1): 1.0f *
 * 10.0 = 10 exactly), not voxel 9 (as 1.0 / (double)0.1f = 9.99999985 made it). */
static void test_issue_case(void **state)
{
    (void)state;
    init_free_map(0.1f, 16u);
    const occ_vec3_t p = v3(1.0f, 0.05f, 0.05f);
    occ_key_t k;
    assert_int_equal(occ_map_key(&map, p, &k), OCC_OK);
    assert_int_equal(k.k[0], 32768u + 10u);
    assert_int_equal(k.k[1], 32768u);
    assert_int_equal(occ_map_update(&map, p, 3.0f), OCC_OK);
    bool visible = true;
    const occ_vec3_t b = v3(1.03f, 0.05f, 0.05f);
    assert_int_equal(occ_line_of_sight(&map, p, b, OCC_UNKNOWN_SAFE, &visible, NULL), OCC_OK);
    assert_false(visible);
    occ_ray_result_t r;
    assert_int_equal(occ_cast_ray(&map, p, v3(1, 0, 0), false, -1.0f, &r), OCC_OK);
    assert_true(r.hit);
    assert_int_equal(r.key.k[0], 32768u + 10u);
    /* The decimal resolution the map holds: 0.1, 0.08 (shortest decimals of the floats). */
#if OCC_RAY_DOUBLE
    assert_true(feq(map.priv.geo_res, 0.1));
    init_free_map(0.08f, 16u);
    assert_true(feq(map.priv.geo_res, 0.08));
    init_free_map(0.15f, 16u);
    assert_true(feq(map.priv.geo_res, 0.15));
#endif
}

/* Key ranges (occ_map_key_range, what the sectors use): the keys of the ends, clamped. */
static void test_key_range(void **state)
{
    (void)state;
    init_free_map(0.1f, 16u);
    uint32_t lo = 0;
    uint32_t hi = 0;
    assert_int_equal(occ_map_key_range(&map, 1.0f, 1.2f, &lo, &hi), OCC_OK);
    assert_int_equal(lo, 32768u + 10u);
    assert_int_equal(hi, 32768u + 12u);
    assert_int_equal(occ_map_key_range(&map, -1e9f, 1e9f, &lo, &hi), OCC_OK);
    assert_int_equal(lo, 0u);
    assert_int_equal(hi, 65535u);
    assert_int_equal(occ_map_key_range(&map, 1e9f, 2e9f, &lo, &hi), OCC_ERR_RANGE);
    assert_int_equal(occ_map_key_range(&map, 2.0f, 1.0f, &lo, &hi), OCC_ERR_ARG);
    assert_int_equal(occ_map_key_range(&map, NAN, 1.0f, &lo, &hi), OCC_ERR_ARG);
    assert_int_equal(occ_map_key_range(NULL, 0.0f, 1.0f, &lo, &hi), OCC_ERR_ARG);
}

/* A level above the depth (also >= 32, an undefined shift before) reads as the root. */
static void test_level_saturates(void **state)
{
    (void)state;
    init_free_map(0.1f, 16u);
    const occ_key_t k = {{12345u, 40000u, 7u}};
    const unsigned levels[] = {17u, 32u, 40u, UINT32_MAX};
    for (size_t i = 0; i < sizeof levels / sizeof levels[0]; i++) {
        const occ_vec3_t c = occ_map_key_center(&map, k, levels[i]);
        assert_true(feq((double)c.x, 0.0) && feq((double)c.y, 0.0) && feq((double)c.z, 0.0));
        assert_true(feq((double)occ_map_node_size(&map, levels[i]),
                        (double)occ_map_node_size(&map, 16u)));
    }
}

/* Fail closed: a caller that ignores the error code reads "blocked". */
static void test_fail_closed_rays(void **state)
{
    (void)state;
    init_free_map(0.1f, 16u);
    const occ_vec3_t off = v3(1e9f, 0.0f, 0.0f);
    const occ_vec3_t p = v3(0.05f, 0.05f, 0.05f);
    bool visible = true;
    occ_ray_result_t r;
    memset(&r, 0, sizeof r);
    assert_int_equal(occ_line_of_sight(&map, p, off, OCC_UNKNOWN_SAFE, &visible, &r), OCC_ERR_RANGE);
    assert_false(visible);
    assert_true(r.hit);
    visible = true;
    assert_int_equal(occ_line_of_sight(NULL, p, p, OCC_UNKNOWN_SAFE, &visible, NULL), OCC_ERR_ARG);
    assert_false(visible);
    visible = true;
    assert_int_equal(occ_line_of_sight(&map, p, p, (occ_unknown_policy_t)7, &visible, NULL),
                     OCC_ERR_ARG);
    assert_false(visible);
    visible = true;
    const occ_vec3_t nan = v3(NAN, 0.0f, 0.0f);
    assert_int_equal(occ_line_of_sight(&map, nan, p, OCC_UNKNOWN_SAFE, &visible, NULL), OCC_ERR_ARG);
    assert_false(visible);
    /* Visible: the blocker says no hit. */
    assert_int_equal(occ_line_of_sight(&map, p, v3(0.5f, 0.05f, 0.05f), OCC_UNKNOWN_SAFE, &visible,
                                       &r),
                     OCC_OK);
    assert_true(visible);
    assert_false(r.hit);
    /* occ_cast_ray: an obstacle at the origin, in no voxel. */
    memset(&r, 0, sizeof r);
    assert_int_equal(occ_cast_ray(&map, off, v3(1, 0, 0), false, -1.0f, &r), OCC_ERR_RANGE);
    assert_true(r.hit);
    assert_int_equal(r.stop, OCC_RAY_HIT);
    assert_int_equal(r.key.k[0], OCC_NONE);
    assert_true(feq((double)r.end.x, (double)off.x));
    memset(&r, 0, sizeof r);
    assert_int_equal(occ_cast_ray(&map, p, v3(0, 0, 0), false, -1.0f, &r), OCC_ERR_ARG);
    assert_true(r.hit);
    memset(&r, 0, sizeof r);
    assert_int_equal(occ_cast_ray(NULL, p, v3(1, 0, 0), false, -1.0f, &r), OCC_ERR_ARG);
    assert_true(r.hit);
    memset(&r, 0, sizeof r);
    assert_int_equal(occ_cast_ray(&map, p, v3(1, 0, 0), false, NAN, &r), OCC_ERR_ARG);
    assert_true(r.hit);
}

#if OCC_RAY_DOUBLE
/* OctoMap's occupied and free volume (m3) of the leaves of an oracle tree at res (decimal). */
static void octomap_volumes(void *t, double res, double *occ_m3, double *free_m3)
{
    const size_t cap = 1u << 21;
    uint32_t *keys = malloc(3u * cap * sizeof *keys);
    uint8_t *levels = malloc(cap);
    float *lo = malloc(cap * sizeof *lo);
    assert_non_null(keys);
    assert_non_null(levels);
    assert_non_null(lo);
    const size_t n = oracle_ins_leaves(t, keys, levels, lo, cap);
    assert_true(n <= cap);
    *occ_m3 = 0.0;
    *free_m3 = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double edge = res * (double)(1u << levels[i]);
        *(lo[i] >= 0.0f ? occ_m3 : free_m3) += edge * edge * edge; /* isNodeOccupied: >= */
    }
    free(keys);
    free(levels);
    free(lo);
}

/* A number after `"key": ` in a JSON line; -1 when missing. */
static double json_number(const char *json, const char *key)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *at = strstr(json, pat);
    return at == NULL ? -1.0 : strtod(at + strlen(pat), NULL);
}

/* `occmap build` on OctoMap's real scan prints OcTree(0.1)'s and OcTree(0.2)'s occupied and
 * free volumes (to its 3 printed decimals): the same voxels, not OcTree((double)0.1f)'s. */
static void test_cli_volumes_vs_octomap(void **state)
{
    (void)state;
    occ_vec3_t *pts = NULL;
    size_t n = 0;
    char msg[256] = "";
    if (access("build/occmap", X_OK) != 0 ||
        occ_scan_read_xyz("build/data/scan.dat", &pts, &n, msg, sizeof msg) != OCC_OK) {
        printf("SKIP: build/occmap or build/data/scan.dat missing (make test-build)\n");
        skip();
    }
    const float res_f[2] = {0.1f, 0.2f};
    for (unsigned r = 0; r < 2u; r++) {
        void *t = oracle_ins_new((double)res_f[r]); /* builds OcTree(0.1), OcTree(0.2) */
        const float o[3] = {0.0f, 0.0f, 0.0f};
        oracle_ins_cloud(t, (const float *)(const void *)pts, n, o, -1.0, 0);
        double occ_m3 = 0.0;
        double free_m3 = 0.0;
        octomap_volumes(t, oracle_geom_user_res((double)res_f[r]), &occ_m3, &free_m3);
        oracle_ins_delete(t);
        char cmd[256];
        snprintf(cmd, sizeof cmd, "build/occmap build --scan build/data/scan.dat --res %g --json",
                 (double)res_f[r]);
        FILE *const pipe = popen(cmd, "r");
        assert_non_null(pipe);
        static char out[8192];
        const size_t got = fread(out, 1, sizeof out - 1u, pipe);
        out[got] = '\0';
        assert_int_equal(pclose(pipe), 0);
        const double cli_occ = json_number(out, "occupied_volume_m3");
        const double cli_free = json_number(out, "free_volume_m3");
        printf("scan.dat at %g m: occmap build %.3f / %.3f m3 occupied / free, OcTree(%g) %.6f / "
               "%.6f\n", (double)res_f[r], cli_occ, cli_free, oracle_geom_user_res((double)res_f[r]),
               occ_m3, free_m3);
        char a[32];
        char b[32];
        snprintf(a, sizeof a, "%.3f %.3f", cli_occ, cli_free);
        snprintf(b, sizeof b, "%.3f %.3f", occ_m3, free_m3);
        assert_string_equal(a, b);
    }
    free(pts);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_issue_case),
        cmocka_unit_test(test_key_range),
        cmocka_unit_test(test_fail_closed_rays),
        cmocka_unit_test(test_level_saturates),
        cmocka_unit_test(test_border_points_depth16),
        cmocka_unit_test(test_border_points_depth21),
#if OCC_RAY_DOUBLE
        cmocka_unit_test(test_cli_volumes_vs_octomap),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
