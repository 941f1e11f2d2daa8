/* SPDX-License-Identifier: BSD-3-Clause */
/* test_projective.c - OCC_INSERT_PROJECTIVE (occ_map_insert_projective and
 * occ_map_insert_depth with that method): voxel for voxel against the brute-force oracle of the
 * header's rule (tests/support/projective_ref.c) on the real TUM pioneer frames at 0.2, 0.1 and
 * 0.05 m, end points never free, an 8x8 time-of-flight array by hand and by the oracle, and the
 * errors (NaN / Inf / bad intrinsics, rotation, short scratch, full pool) with the map
 * unchanged. The TUM cases skip when ../shared is absent. */
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
#include "occmap/occ_depth.h"
#include "occmap/host/occ_scan.h"
#include "support/iotest.h"
#include "support/leak_check.h"
#include "support/oracle_io.h"
#include "support/projective_ref.h"

#define PIONEER_DIR "../shared/data/depth/tum_fr2_pioneer_slam2"
#define BIG_ARENA ((size_t)96 << 20)
#define BIG_SCRATCH ((size_t)16 << 20)

static uint8_t *arena_a, *arena_b, *scratch;
static occ_map_t map_a, map_b;

static int setup(void **state)
{
    (void)state;
    arena_a = malloc(BIG_ARENA);
    arena_b = malloc(BIG_ARENA);
    scratch = malloc(BIG_SCRATCH);
    return arena_a != NULL && arena_b != NULL && scratch != NULL ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    free(arena_a);
    free(arena_b);
    free(scratch);
    return 0;
}

static void init_maps(float res, size_t arena_bytes)
{
    occ_map_config_t c = iotest_octomap_cfg();
    c.resolution_m = res;
    assert_int_equal(occ_map_init(&map_a, &c, arena_a, arena_bytes), OCC_OK);
    assert_int_equal(occ_map_init(&map_b, &c, arena_b, arena_bytes), OCC_OK);
}

/* The camera as occ_map_insert_depth builds it for step 1: rotation columns from the pose. */
static occ_proj_camera_t camera_of(const occ_pose_t *pose, float fx, float fy, float cx, float cy,
                                   float min_m, float max_m)
{
    occ_proj_camera_t k;
    memset(&k, 0, sizeof k);
    k.fx = fx;
    k.fy = fy;
    k.cx = cx;
    k.cy = cy;
    projref_rotation_of(pose, k.r);
    k.t = pose->p;
    k.min_range_m = min_m;
    k.max_range_m = max_m;
    return k;
}

/* map_a through insert_depth (PROJECTIVE), map_b through the oracle's codes: equal maps. */
static void frame_equals_oracle(const occ_depth_image_t *im, const occ_depth_params_t *dp,
                                const occ_pose_t *pose, occ_depth_result_t *r)
{
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_PROJECTIVE;
    assert_int_equal(occ_map_insert_depth(&map_a, im, dp, pose, &ip, scratch, BIG_SCRATCH, r),
                     OCC_OK);
    const occ_proj_image_t pim = {im->data, im->format == OCC_DEPTH_U16 ? OCC_PROJ_U16
                                                                         : OCC_PROJ_F32,
                                  im->width, im->height, im->row_stride_bytes,
                                  im->format == OCC_DEPTH_U16 ? 2u : 4u, im->depth_scale_m};
    const occ_pinhole_t *k = &dp->intrinsics;
    const occ_proj_camera_t cam =
        camera_of(pose, k->fx, k->fy, k->cx, k->cy, dp->min_range_m, dp->max_range_m);
    occ_code_t *codes = NULL;
    size_t hits = 0;
    const size_t n = projref_codes(&map_b, &pim, &cam, &codes, &hits);
    size_t changed = 0;
    assert_int_equal(occ_map_observe_codes(&map_b, codes, n, &changed), OCC_OK);
    free(codes);
    printf("  oracle %zu updates (%zu hits); walk %zu voxel updates + %zu whole nodes, %zu nodes "
           "tested\n",
           n, hits, r->insert.voxels_updated, r->insert.coarse_updated,
           r->insert.voxel_visits);
    assert_int_equal(r->insert.voxels_occupied, hits);
    assert_true(r->insert.voxels_updated <= n);
    assert_true(iotest_map_digest(&map_a) == iotest_map_digest(&map_b));
    assert_int_equal(occ_map_check(&map_a), OCC_OK);
}

/* ---- the TUM pioneer frames ------------------------------------------------------------------ */
typedef struct {
    uint16_t *pix;
    uint32_t w, h;
    occ_pose_t pose;
} frame_t;

static size_t pioneer_frames(frame_t *out, size_t max)
{
    occ_scan_frame_t *fr = NULL;
    size_t n = 0;
    char msg[256] = "";
    if (occ_depth_read_tum_dir(PIONEER_DIR, 64u, max, &fr, &n, msg, sizeof msg) != OCC_OK) {
        printf("SKIP: %s not available (%s; needs ../shared)\n", PIONEER_DIR, msg);
        return 0;
    }
    for (size_t i = 0; i < n; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/depth/%s", PIONEER_DIR, fr[i].name);
        assert_int_equal(occ_depth_read_png_image(path, &out[i].pix, &out[i].w, &out[i].h, msg,
                                                  sizeof msg),
                         OCC_OK);
        out[i].pose.p = (occ_vec3_t){fr[i].pose_t[0], fr[i].pose_t[1], fr[i].pose_t[2]};
        const occ_quat_t q = {fr[i].pose_q[0], fr[i].pose_q[1], fr[i].pose_q[2], fr[i].pose_q[3]};
        assert_int_equal(occ_quat_normalize(q, &out[i].pose.q), OCC_OK);
    }
    occ_scan_frames_free(fr, n);
    return n;
}

static void free_frames(frame_t *f, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        free(f[i].pix);
    }
}

static occ_depth_image_t tum_image(const frame_t *f)
{
    const occ_depth_image_t im = {f->pix, OCC_DEPTH_U16, f->w, f->h, (size_t)f->w * 2u,
                                  1.0f / 5000.0f};
    return im;
}

/* Frames first..first+count (every `every`-th) at resolution res, accumulated: after each frame
 * the map equals the oracle's. */
static void pioneer_at(const frame_t *f, size_t n, float res, size_t every, float max_m)
{
    init_maps(res, BIG_ARENA);
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    const occ_depth_params_t dp = {{cam.fx, cam.fy, cam.cx, cam.cy}, 0.3f, max_m, 1u};
    printf("res %.2f m, max range %.1f m\n", (double)res, (double)max_m);
    for (size_t i = 0; i < n; i += every) {
        const occ_depth_image_t im = tum_image(&f[i]);
        occ_depth_result_t r;
        frame_equals_oracle(&im, &dp, &f[i].pose, &r);
        assert_true(r.pixels_beyond_max > 0u && r.pixels_no_reading > 0u);
    }
    assert_int_equal(occ_map_check(&map_a), OCC_OK);
}

static void test_pioneer_equals_oracle(void **state)
{
    (void)state;
    frame_t f[10];
    const size_t n = pioneer_frames(f, 10u);
    if (n == 0u) {
        skip();
    }
    assert_int_equal(n, 10);
    pioneer_at(f, n, 0.2f, 3u, 4.0f);
    pioneer_at(f, n, 0.1f, 5u, 4.0f);
    pioneer_at(f, n, 0.05f, 9u, 3.0f);
    free_frames(f, n);
}

/* A fresh map per frame: every end point's voxel reads occupied (never free), and the pixels
 * beyond max range marked nothing. */
static void test_end_points_never_free(void **state)
{
    (void)state;
    frame_t f[10];
    const size_t n = pioneer_frames(f, 10u);
    if (n == 0u) {
        skip();
    }
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    const float res[2] = {0.1f, 0.05f};
    for (size_t i = 0; i < n; i += 4u) {
        init_maps(res[i % 2u], BIG_ARENA);
        const occ_depth_params_t dp = {{cam.fx, cam.fy, cam.cx, cam.cy}, 0.3f, 5.0f, 1u};
        const occ_depth_image_t im = tum_image(&f[i]);
        occ_insert_params_t ip = occ_insert_params_default();
        ip.method = OCC_INSERT_PROJECTIVE;
        occ_depth_result_t r;
        assert_int_equal(occ_map_insert_depth(&map_a, &im, &dp, &f[i].pose, &ip, scratch,
                                              BIG_SCRATCH, &r),
                         OCC_OK);
        const occ_proj_image_t pim = {f[i].pix, OCC_PROJ_U16, f[i].w, f[i].h, (size_t)f[i].w * 2u,
                                      2u, 1.0f / 5000.0f};
        const occ_proj_camera_t k = camera_of(&f[i].pose, cam.fx, cam.fy, cam.cx, cam.cy, 0.3f,
                                              5.0f);
        occ_key_t *pts = NULL;
        const size_t np = projref_end_keys(&map_a, &pim, &k, &pts);
        size_t bad = 0;
        for (size_t p = 0; p < np; p++) {
            const occ_vec3_t c = occ_map_key_center(&map_a, pts[p], 0u);
            bad += occ_map_state_at(&map_a, c) != OCC_STATE_OCCUPIED ? 1u : 0u;
        }
        free(pts);
        printf("  frame %zu: %zu end points, %zu not occupied, %zu free voxels, %zu whole nodes\n",
               i, np, bad, r.insert.voxels_free, r.insert.coarse_updated);
        assert_true(np > 100000u);
        assert_int_equal(bad, 0);
        assert_true(r.insert.voxels_free > 0u && r.insert.coarse_updated > 0u);
    }
    free_frames(f, n);
}

/* Against OctoMap's insertPointCloud of the same frames (every valid pixel, the same max
 * range): weighted by voxels, OctoMap's known space as seen here. Loose bounds: projection
 * decides by voxel centres, so voxels crossed by a ray but whose centre's pixel reads nearer
 * stay unknown here (bench/projective.cpp reports the full agreement). */
typedef struct {
    const occ_map_t *map;
    double known, opposite, unknown_here;
} vs_octo_t;

static void vs_octo_leaf(void *ctx, const uint32_t key[3], unsigned level, float logodds)
{
    vs_octo_t *v = ctx;
    const occ_key_t k = {{key[0], key[1], key[2]}};
    const occ_state_t ours = occ_map_state_at(v->map, occ_map_key_center(v->map, k, level));
    const occ_state_t theirs = logodds >= 0.0f ? OCC_STATE_OCCUPIED : OCC_STATE_FREE;
    const double w = (double)((uint64_t)1 << (3u * level));
    v->known += w;
    v->unknown_here += ours == OCC_STATE_UNKNOWN ? w : 0.0;
    v->opposite += ours != OCC_STATE_UNKNOWN && ours != theirs ? w : 0.0;
}

static void test_pioneer_vs_octomap(void **state)
{
    (void)state;
    frame_t f[10];
    const size_t n = pioneer_frames(f, 10u);
    if (n == 0u) {
        skip();
    }
    init_maps(0.1f, BIG_ARENA);
    oracle_io_t *t = oracle_io_new(ORACLE_OCTREE, 0.1);
    assert_non_null(t);
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    const occ_depth_params_t dp = {{cam.fx, cam.fy, cam.cx, cam.cy}, 0.0f, 4.0f, 1u};
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_PROJECTIVE;
    for (size_t i = 0; i < n; i += 4u) {
        const occ_depth_image_t im = tum_image(&f[i]);
        occ_depth_result_t r;
        assert_int_equal(occ_map_insert_depth(&map_a, &im, &dp, &f[i].pose, &ip, scratch,
                                              BIG_SCRATCH, &r),
                         OCC_OK);
        const occ_proj_image_t pim = {f[i].pix, OCC_PROJ_U16, f[i].w, f[i].h, (size_t)f[i].w * 2u,
                                      2u, 1.0f / 5000.0f};
        const occ_proj_camera_t all = camera_of(&f[i].pose, cam.fx, cam.fy, cam.cx, cam.cy, 0.0f,
                                                1e6f); /* every valid pixel, beyond max too */
        occ_vec3_t *pts = NULL;
        const size_t np = projref_end_points(&pim, &all, &pts);
        const float o[3] = {f[i].pose.p.x, f[i].pose.p.y, f[i].pose.p.z};
        oracle_io_insert_cloud(t, (const float *)(const void *)pts, np, o, 4.0, false);
        free(pts);
    }
    vs_octo_t v = {&map_a, 0.0, 0.0, 0.0};
    (void)oracle_io_for_each_leaf(t, vs_octo_leaf, &v);
    oracle_io_free(t);
    printf("  OctoMap's known voxels: %.0f; opposite state here %.3f%%, unknown here %.2f%%\n",
           v.known, 100.0 * v.opposite / v.known, 100.0 * v.unknown_here / v.known);
    assert_true(v.known > 2e4);
    assert_true(v.opposite < 0.01 * v.known);
    assert_true(v.unknown_here < 0.25 * v.known);
    free_frames(f, n);
}

/* ---- an 8x8 time-of-flight array ------------------------------------------------------------- */
/* VL53L5CX-like: f = 4 / tan(22.5 deg), cx = cy = 3.5, a wall 2 m ahead (camera looking along
 * map +x), one zone with no reading, one beyond max range. */
static float tof[8][8];
static const occ_depth_params_t tof_dp = {{9.656854f, 9.656854f, 3.5f, 3.5f}, 0.05f, 3.0f, 1u};

static occ_pose_t tof_pose(void)
{
    /* optical z = map x, optical x = map -y, optical y = map -z */
    occ_pose_t p = {{0.31f, 0.12f, 1.03f}, {0.5f, -0.5f, 0.5f, -0.5f}};
    return p;
}

static void fill_tof(void)
{
    for (unsigned v = 0; v < 8u; v++) {
        for (unsigned u = 0; u < 8u; u++) {
            tof[v][u] = 2.0f;
        }
    }
    for (unsigned v = 1; v <= 3u; v++) { /* a 3 x 3 block without readings around zone (5, 2) */
        for (unsigned u = 4; u <= 6u; u++) {
            tof[v][u] = NAN;
        }
    }
    tof[5][6] = NAN;       /* an isolated zone without a reading: its neighbours' depth frees */
    tof[6][1] = INFINITY;  /* no return within range */
}

static void test_tof_8x8(void **state)
{
    (void)state;
    fill_tof();
    const occ_depth_image_t im = {tof, OCC_DEPTH_F32, 8u, 8u, sizeof tof[0], 1.0f};
    const occ_pose_t pose = tof_pose();
    const float res[3] = {0.2f, 0.1f, 0.05f};
    for (unsigned i = 0; i < 3u; i++) {
        init_maps(res[i], (size_t)8 << 20);
        occ_depth_result_t r;
        frame_equals_oracle(&im, &tof_dp, &pose, &r);
        assert_int_equal(r.pixels_sampled, 64);
        assert_int_equal(r.pixels_no_reading, 10);
        assert_int_equal(r.pixels_beyond_max, 1);
        /* By hand: straight ahead at 1 m is free, the wall at 2 m occupied, behind it unknown. */
        const occ_vec3_t ahead = {pose.p.x + 1.0f, pose.p.y, pose.p.z};
        const float off = 0.5f * 2.0f / 9.656854f; /* zone (3, 3)'s end point */
        const occ_vec3_t wall = {pose.p.x + 2.0f, pose.p.y + off, pose.p.z + off};
        const occ_vec3_t behind = {pose.p.x + 2.5f, pose.p.y, pose.p.z};
        assert_int_equal(occ_map_state_at(&map_a, ahead), OCC_STATE_FREE);
        assert_int_equal(occ_map_state_at(&map_a, wall), OCC_STATE_OCCUPIED);
        assert_int_equal(occ_map_state_at(&map_a, behind), OCC_STATE_UNKNOWN);
        /* Zone (5, 2) and its four neighbours have no reading: its centre ray at 1 m stays
         * unknown; zone (6, 5) has none but its neighbours read 2 m: free at 1 m (the zone is
         * 0.1 m wide there: checked where a voxel is smaller). */
        const float zx = (5.0f - 3.5f) / 9.656854f, zy = (2.0f - 3.5f) / 9.656854f;
        const occ_vec3_t nz = {pose.p.x + 1.0f, pose.p.y - zx, pose.p.z - zy};
        const float fx_ = (6.0f - 3.5f) / 9.656854f, fy_ = (5.0f - 3.5f) / 9.656854f;
        const occ_vec3_t filled = {pose.p.x + 1.0f, pose.p.y - fx_, pose.p.z - fy_};
        if (res[i] < 0.06f) {
            assert_int_equal(occ_map_state_at(&map_a, nz), OCC_STATE_UNKNOWN);
            assert_int_equal(occ_map_state_at(&map_a, filled), OCC_STATE_FREE);
        }
        /* Behind the camera: unknown. The camera's own voxel: free (the near rays start there,
         * as OctoMap's rays do); beside the camera, outside the field of view: unknown. */
        const occ_vec3_t back = {pose.p.x - 0.5f, pose.p.y, pose.p.z};
        assert_int_equal(occ_map_state_at(&map_a, back), OCC_STATE_UNKNOWN);
        assert_int_equal(occ_map_state_at(&map_a, pose.p), OCC_STATE_FREE);
        const occ_vec3_t side = {pose.p.x, pose.p.y + 0.5f, pose.p.z};
        assert_int_equal(occ_map_state_at(&map_a, side), OCC_STATE_UNKNOWN);
        assert_int_equal(leak_check(&map_a), 0);
        assert_int_equal(leak_check(&map_b), 0);
    }
}

/* Maps of one to four levels (a root of level 1 or 2 takes the walk's bricks directly): the
 * ToF frame twice, the second time onto the first's voxels, equal to the oracle's. The camera
 * sits near the map's -x face looking along +x, so that voxels of every map are in view. */
static void test_tof_shallow_maps(void **state)
{
    (void)state;
    fill_tof();
    const occ_depth_image_t im = {tof, OCC_DEPTH_F32, 8u, 8u, sizeof tof[0], 1.0f};
    occ_pose_t pose = tof_pose();
    for (unsigned depth = 1; depth <= 4u; depth++) {
        occ_map_config_t c = iotest_octomap_cfg();
        c.resolution_m = 2.0f / (float)(1u << depth); /* the map spans [-1, 1) m */
        c.depth_levels = (uint8_t)depth;
        pose.p = (occ_vec3_t){-0.9f, 0.01f, 0.02f};
        assert_int_equal(occ_map_init(&map_a, &c, arena_a, (size_t)1 << 20), OCC_OK);
        assert_int_equal(occ_map_init(&map_b, &c, arena_b, (size_t)1 << 20), OCC_OK);
        printf("depth %u, res %.3f m\n", depth, (double)c.resolution_m);
        for (unsigned twice = 0; twice < 2u; twice++) {
            occ_depth_result_t r;
            frame_equals_oracle(&im, &tof_dp, &pose, &r);
            assert_true(r.insert.voxels_updated + r.insert.coarse_updated > 0u);
        }
    }
}

/* ---- errors: the map unchanged --------------------------------------------------------------- */
static occ_err_t tof_insert(const occ_depth_params_t *dp, const occ_pose_t *pose, size_t bytes,
                            occ_depth_result_t *r)
{
    const occ_depth_image_t im = {tof, OCC_DEPTH_F32, 8u, 8u, sizeof tof[0], 1.0f};
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_PROJECTIVE;
    return occ_map_insert_depth(&map_a, &im, dp, pose, &ip, scratch, bytes, r);
}

static void test_errors_leave_map(void **state)
{
    (void)state;
    fill_tof();
    init_maps(0.1f, (size_t)8 << 20);
    const occ_pose_t pose = tof_pose();
    occ_depth_result_t r;
    assert_int_equal(tof_insert(&tof_dp, &pose, BIG_SCRATCH, &r), OCC_OK);
    const uint64_t before = iotest_map_digest(&map_a);
    occ_depth_params_t bad = tof_dp;
    bad.intrinsics.fx = NAN;
    assert_int_equal(tof_insert(&bad, &pose, BIG_SCRATCH, &r), OCC_ERR_ARG);
    bad = tof_dp;
    bad.intrinsics.cy = INFINITY;
    assert_int_equal(tof_insert(&bad, &pose, BIG_SCRATCH, &r), OCC_ERR_ARG);
    bad = tof_dp;
    bad.intrinsics.fy = -1.0f;
    assert_int_equal(tof_insert(&bad, &pose, BIG_SCRATCH, &r), OCC_ERR_ARG);
    bad = tof_dp;
    bad.max_range_m = INFINITY;
    assert_int_equal(tof_insert(&bad, &pose, BIG_SCRATCH, &r), OCC_ERR_ARG);
    occ_pose_t bp = pose;
    bp.p.x = NAN;
    assert_int_equal(tof_insert(&tof_dp, &bp, BIG_SCRATCH, &r), OCC_ERR_ARG);
    bp = pose;
    bp.p.x = 1e9f;
    assert_int_equal(tof_insert(&tof_dp, &bp, BIG_SCRATCH, &r), OCC_ERR_RANGE);
    /* The direct call: a rotation that is not one, noise out of range, no scratch. */
    const occ_proj_image_t pim = {tof, OCC_PROJ_F32, 8u, 8u, sizeof tof[0], 4u, 1.0f};
    occ_proj_camera_t k = camera_of(&pose, 9.656854f, 9.656854f, 3.5f, 3.5f, 0.05f, 3.0f);
    occ_proj_result_t pr;
    for (unsigned b = 0; b < 3u; b++) {
        k.r[0][b] *= 1.1f; /* not orthonormal */
    }
    assert_int_equal(occ_map_insert_projective(&map_a, &pim, &k, scratch, BIG_SCRATCH, &pr),
                     OCC_ERR_ARG);
    k = camera_of(&pose, 9.656854f, 9.656854f, 3.5f, 3.5f, 0.05f, 3.0f);
    k.noise_rel = 0.6f;
    assert_int_equal(occ_map_insert_projective(&map_a, &pim, &k, scratch, BIG_SCRATCH, &pr),
                     OCC_ERR_ARG);
    k.noise_rel = 0.01f;
    assert_int_equal(occ_map_insert_projective(&map_a, &pim, &k, NULL, 0, &pr), OCC_ERR_SCRATCH);
    const occ_proj_image_t bad_stride = {tof, OCC_PROJ_F32, 8u, 8u, 16u, 4u, 1.0f};
    assert_int_equal(occ_map_insert_projective(&map_a, &bad_stride, &k, scratch, BIG_SCRATCH, &pr),
                     OCC_ERR_ARG);
    /* insert_cloud refuses the method (it has no image). */
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_PROJECTIVE;
    const occ_vec3_t pt = {1, 1, 1};
    assert_int_equal(occ_map_insert_cloud(&map_a, &pose.p, &pt, 1, &ip, scratch, BIG_SCRATCH,
                                          NULL),
                     OCC_ERR_ARG);
    /* Short scratch: every size below what the frame used is refused, the formula suffices. */
    occ_map_clear(&map_b);
    assert_int_equal(tof_insert(&tof_dp, &pose, BIG_SCRATCH, &r), OCC_OK);
    const size_t used = r.insert.scratch_used;
    const uint64_t after_ok = iotest_map_digest(&map_a);
    for (size_t b = 0; b + 7u < used; b += 97u) {
        assert_int_equal(tof_insert(&tof_dp, &pose, b, &r), OCC_ERR_SCRATCH);
    }
    assert_int_equal(iotest_map_digest(&map_a), after_ok);
    assert_true(used <= OCC_PROJ_SCRATCH_BYTES(8, 8, OCC_PROJ_OUT_DEFAULT(8, 8)));
    /* occ_depth_scratch_bytes with the method is that formula, and it is enough. */
    ip.method = OCC_INSERT_PROJECTIVE;
    const size_t need = occ_depth_scratch_bytes(&map_a, 8u, 8u, 1u, 3.0f, &ip);
    assert_int_equal(need, OCC_PROJ_SCRATCH_BYTES(8, 8, OCC_PROJ_OUT_DEFAULT(8, 8)));
    assert_int_equal(tof_insert(&tof_dp, &pose, need, &r), OCC_OK);
    assert_true(after_ok != before); /* the accepted inserts above changed the map */
    assert_int_equal(leak_check(&map_a), 0);
    assert_int_equal(leak_check(&map_b), 0);
}

/* A pool too small for the frame: OCC_ERR_NOMEM at every small arena size, the map unchanged
 * (digest and pool counters), oom_count bumped; a big enough one works. */
static void test_full_pool(void **state)
{
    (void)state;
    fill_tof();
    const occ_pose_t pose = tof_pose();
    occ_map_config_t c = iotest_octomap_cfg();
    c.resolution_m = 0.05f;
    bool fitted = false;
    for (size_t bytes = 4096; bytes <= ((size_t)1 << 20) && !fitted; bytes += bytes / 4u) {
        assert_int_equal(occ_map_init(&map_a, &c, arena_a, bytes), OCC_OK);
        /* something already in the map, so that "unchanged" means something */
        const occ_vec3_t p = {pose.p.x - 1.0f, pose.p.y, pose.p.z};
        if (occ_map_update(&map_a, p, c.hit) != OCC_OK) {
            continue;
        }
        const uint64_t d0 = iotest_map_digest(&map_a);
        const uint32_t used_in = map_a.inner.used, used_lf = map_a.leaf.used;
        const uint32_t oom = map_a.oom_count;
        occ_depth_result_t r;
        const occ_err_t e = tof_insert(&tof_dp, &pose, BIG_SCRATCH, &r);
        if (e == OCC_OK) {
            fitted = true;
            assert_true(iotest_map_digest(&map_a) != d0);
        } else {
            assert_int_equal(e, OCC_ERR_NOMEM);
            assert_int_equal(iotest_map_digest(&map_a), d0);
            assert_int_equal(map_a.inner.used, used_in);
            assert_int_equal(map_a.leaf.used, used_lf);
            assert_int_equal(map_a.oom_count, oom + 1u);
        }
        assert_int_equal(leak_check(&map_a), 0);
    }
    assert_true(fitted);
}

/* The header's scratch formula covers the call's fixed parts for every small image shape at
 * every alignment of the scratch: an image without readings needs no output slot, so what the
 * call uses then is its fixed part, which must not exceed OCC_PROJ_SCRATCH_BYTES(w, h, 0), and
 * OCC_PROJ_SCRATCH_BYTES(w, h, 1) bytes of a malloc'd block (ASan catches a write past them)
 * must do. A frame with readings in OCC_PROJ_OUT_DEFAULT slots works too. */
static void test_scratch_formula_every_shape(void **state)
{
    (void)state;
    init_maps(0.1f, (size_t)8 << 20);
    float none[3 * 33], some[3 * 33];
    for (size_t i = 0; i < 3u * 33u; i++) {
        none[i] = NAN;
        some[i] = (i % 7u) == 3u ? NAN : 1.0f + 0.05f * (float)(i % 5u); /* a few holes */
    }
    const occ_pose_t pose = tof_pose();
    for (uint32_t w = 1; w <= 33u; w++) {
        for (uint32_t h = 1; h <= 3u; h++) {
            const occ_proj_camera_t k = camera_of(&pose, 8.0f, 8.0f, 0.5f * (float)w,
                                                  0.5f * (float)h, 0.05f, 3.0f);
            const occ_proj_image_t empty = {none, OCC_PROJ_F32, w, h, 33u * 4u, 4u, 1.0f};
            const occ_proj_image_t frame = {some, OCC_PROJ_F32, w, h, 33u * 4u, 4u, 1.0f};
            const size_t fixed = OCC_PROJ_SCRATCH_BYTES(w, h, 0);
            const size_t full = OCC_PROJ_SCRATCH_BYTES(w, h, OCC_PROJ_OUT_DEFAULT(w, h));
            for (size_t off = 0; off < 16u; off += 3u) {
                unsigned char *const block = malloc(off + full);
                occ_proj_result_t r;
                assert_int_equal(occ_map_insert_projective(&map_a, &empty, &k, block + off,
                                                           fixed + 8u, &r),
                                 OCC_OK);
                assert_true(r.insert.scratch_used <= fixed);
                assert_int_equal(occ_map_insert_projective(&map_a, &frame, &k, block + off, full,
                                                           &r),
                                 OCC_OK);
                free(block);
            }
        }
    }
    assert_int_equal(occ_map_check(&map_a), OCC_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tof_8x8),
        cmocka_unit_test(test_tof_shallow_maps),
        cmocka_unit_test(test_errors_leave_map),
        cmocka_unit_test(test_full_pool),
        cmocka_unit_test(test_pioneer_equals_oracle),
        cmocka_unit_test(test_end_points_never_free),
        cmocka_unit_test(test_pioneer_vs_octomap),
        cmocka_unit_test(test_scratch_formula_every_shape),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
