/* SPDX-License-Identifier: BSD-3-Clause */
/* test_depth.c - occ_map_insert_depth() on synthetic frames: an 8x8 time-of-flight frame worked
 * out by hand (uint16 and float), rays that overflow float, every bad input (error, map
 * unchanged), pools short at every small arena size, the scratch formula on a static buffer.
 * The real TUM frames: test_depth_tum.c. */
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
#include "support/depth_fixture.h"

/* ---- the 8x8 time-of-flight frame ---------------------------------------------------------- */
/* VL53L5CX-like: 8x8 zones over a 45 degree square field of view: f = 4 / tan(22.5 deg),
 * zone centres at pixel indices 0..7, principal point 3.5. Depth in mm (scale 0.001). */
#define TOF_F 9.65685425f
static const occ_pinhole_t TOF_K = {TOF_F, TOF_F, 3.5f, 3.5f};

/* A wall 0.5 m ahead, zone (0,0) without reading, zone (7,0) at 20 mm (closer than min
 * 0.05 m), zone (7,3) at 4 m (beyond max 2 m). */
static void tof_frame(uint16_t mm[64])
{
    for (unsigned i = 0; i < 64u; i++) {
        mm[i] = 500u;
    }
    mm[0] = 0u;
    mm[7] = 20u;
    mm[3 * 8 + 7] = 4000u;
}

static occ_depth_image_t tof_image(const uint16_t *mm)
{
    const occ_depth_image_t im = {mm, OCC_DEPTH_U16, 8u, 8u, 16u, 0.001f};
    return im;
}

static occ_depth_params_t tof_params(void)
{
    const occ_depth_params_t p = {TOF_K, 0.05f, 2.0f, 1u};
    return p;
}

/* Camera at the centre of voxel (0, 0, 0) at 0.1 m, optical axis = map z (identity pose). */
static occ_pose_t tof_pose(void)
{
    occ_pose_t p = occ_pose_identity();
    p.p = (occ_vec3_t){0.05f, 0.05f, 0.05f};
    return p;
}

/* State of the voxel with index (i, j, k) (its centre at (i + 0.5) res ...): 0 unknown, 1 free,
 * 2 occupied. */
static int voxel_state(const occ_map_t *m, int i, int j, int k)
{
    const float r = m->cfg.resolution_m;
    const occ_vec3_t c = {((float)i + 0.5f) * r, ((float)j + 0.5f) * r, ((float)k + 0.5f) * r};
    occ_node_info_t info;
    assert_int_equal(occ_map_read(m, c, 0u, &info), OCC_OK);
    return !info.observed ? 0 : info.logodds >= 0.0f ? 2 : 1;
}

static int point_state(const occ_map_t *m, occ_vec3_t p)
{
    const float r = m->cfg.resolution_m;
    return voxel_state(m, (int)floorf(p.x / r), (int)floorf(p.y / r), (int)floorf(p.z / r));
}

/* Hand computation (res 0.1): zone u ends at x = 0.05 + (u - 3.5) 0.5 / f = 0.05 + (u - 3.5)
 * 0.05178, voxel index -2 -1 -1 0 0 1 1 2 for u = 0..7 (the same in y with v), z = 0.55:
 * index 5. The 25 end columns minus (-2,-2) (only zone (0,0), no reading) and (2,-2) (only
 * zone (7,0), too close) are hit: 23 voxels. The four central zones' rays stay in column
 * (0,0): free from k = 0 to 4. Zone (7,3) runs along (0.34035, -0.04862, 0.93904) and stops
 * at 2 m: 1.5 m along it is (0.5605, -0.0229, 1.4586), voxel (5,-1,14), free; 1.95 m along is
 * (0.7137, -0.0448, 1.8811), voxel (7,-1,18), free; the clipped end (0.7307, -0.0472, 1.9281)
 * lies in voxel (7,-1,19), which stays unknown (no hit; computeRayKeys excludes the end voxel),
 * as does (9,-1,23), 2.5 m along. Behind the wall (k = 6) only that ray's voxel (2,0,6) is
 * known. */
static void check_tof_map(const occ_map_t *m)
{
    for (int i = -2; i <= 2; i++) {
        for (int j = -2; j <= 2; j++) {
            const bool lone = (i == -2 && j == -2) || (i == 2 && j == -2);
            assert_int_equal(voxel_state(m, i, j, 5), lone ? 0 : 2);
            /* behind the wall: unknown, but where zone (7,3)'s ray passes (z 0.6..0.7 at
             * x 0.249..0.286, y 0.016..0.022) */
            assert_int_equal(voxel_state(m, i, j, 6), i == 2 && j == 0 ? 1 : 0);
        }
    }
    for (int k = 0; k <= 4; k++) {
        assert_int_equal(voxel_state(m, 0, 0, k), 1);
    }
    assert_int_equal(voxel_state(m, 5, -1, 14), 1);
    assert_int_equal(voxel_state(m, 7, -1, 18), 1);
    assert_int_equal(voxel_state(m, 7, -1, 19), 0);
    assert_int_equal(voxel_state(m, 9, -1, 23), 0);
    assert_int_equal(voxel_state(m, -2, -2, 4), 0);
}

static void check_tof_counts(const occ_depth_result_t *r)
{
    assert_int_equal(r->pixels_sampled, 64);
    assert_int_equal(r->pixels_no_reading, 1);
    assert_int_equal(r->pixels_too_close, 1);
    assert_int_equal(r->pixels_beyond_max, 1);
    assert_int_equal(r->points, 62);
    assert_int_equal(r->insert.points_integrated, 62);
    assert_int_equal(r->insert.rays_clipped, 1);
    assert_int_equal(r->insert.voxels_occupied, 23);
}

static void test_tof_8x8(void **state)
{
    (void)state;
    init_maps(0.1f);
    uint16_t mm[64];
    tof_frame(mm);
    const occ_depth_image_t im = tof_image(mm);
    const occ_depth_params_t dp = tof_params();
    const occ_pose_t pose = tof_pose();
    const occ_insert_params_t ip = occ_insert_params_default();
    occ_depth_result_t r;
    assert_int_equal(occ_map_insert_depth(&map_a, &im, &dp, &pose, &ip, scratch, SCRATCH_BYTES,
                                          &r),
                     OCC_OK);
    check_tof_counts(&r);
    check_tof_map(&map_a);
    assert_int_equal(point_state(&map_a, (occ_vec3_t){0.5605f, -0.0229f, 1.4586f}), 1);

    /* The same scene as float metres: NaN = no reading, +Inf = no return (placed at 2 x max
     * = 4 m, the U16 frame's 4000 mm): the same map. */
    float m[64];
    for (unsigned i = 0; i < 64u; i++) {
        m[i] = (float)mm[i] * 0.001f;
    }
    m[0] = NAN;
    m[3 * 8 + 7] = INFINITY;
    const occ_depth_image_t imf = {m, OCC_DEPTH_F32, 8u, 8u, 32u, 0.0f};
    occ_depth_result_t rf;
    assert_int_equal(occ_map_insert_depth(&map_b, &imf, &dp, &pose, &ip, scratch, SCRATCH_BYTES,
                                          &rf),
                     OCC_OK);
    check_tof_counts(&rf);
    assert_true(iotest_map_digest(&map_a) == iotest_map_digest(&map_b));
    /* A finite depth too far for float arithmetic is placed like +Inf: the same map again. */
    m[3 * 8 + 7] = 1e30f;
    occ_map_clear(&map_b);
    assert_int_equal(occ_map_insert_depth(&map_b, &imf, &dp, &pose, &ip, scratch, SCRATCH_BYTES,
                                          &rf),
                     OCC_OK);
    check_tof_counts(&rf);
    assert_true(iotest_map_digest(&map_a) == iotest_map_digest(&map_b));
    check_tof_map(&map_b);
}

/* Intrinsics so extreme that every ray overflows float: nothing integrated, no error, the map
 * unchanged (never an Inf point handed on). */
static void test_overflowing_rays(void **state)
{
    (void)state;
    init_maps(0.1f);
    float m[64];
    for (unsigned i = 0; i < 64u; i++) {
        m[i] = 0.5f;
    }
    const occ_depth_image_t imf = {m, OCC_DEPTH_F32, 8u, 8u, 32u, 0.0f};
    occ_depth_params_t dp = tof_params();
    dp.intrinsics.fx = 1e-38f;
    dp.intrinsics.fy = 1e-38f;
    const occ_pose_t pose = tof_pose();
    const occ_insert_params_t ip = occ_insert_params_default();
    const uint64_t d = iotest_map_digest(&map_a);
    occ_depth_result_t r;
    assert_int_equal(occ_map_insert_depth(&map_a, &imf, &dp, &pose, &ip, scratch, SCRATCH_BYTES,
                                          &r),
                     OCC_OK);
    assert_int_equal(r.pixels_no_reading, 64);
    assert_int_equal(r.points, 0);
    assert_true(iotest_map_digest(&map_a) == d);
}

/* ---- bad input: a clear error and the map unchanged ---------------------------------------- */
typedef struct {
    occ_depth_image_t im;
    occ_depth_params_t dp;
    occ_pose_t pose;
    occ_insert_params_t ip;
    size_t scratch_bytes;
} call_t;

static call_t tof_call(const uint16_t *mm)
{
    call_t c;
    c.im = tof_image(mm);
    c.dp = tof_params();
    c.pose = tof_pose();
    c.ip = occ_insert_params_default();
    c.scratch_bytes = SCRATCH_BYTES;
    return c;
}

static occ_err_t run_call(const call_t *c)
{
    occ_depth_result_t r;
    return occ_map_insert_depth(&map_a, &c->im, &c->dp, &c->pose, &c->ip, scratch,
                                c->scratch_bytes, &r);
}

/* One field broken per case; `what` names it in a failure. */
static void expect_refused(const call_t *c, occ_err_t want, uint64_t digest, const char *what)
{
    const occ_err_t e = run_call(c);
    if (e != want || iotest_map_digest(&map_a) != digest) {
        printf("case '%s': %s, map %s\n", what, occ_err_str(e),
               iotest_map_digest(&map_a) == digest ? "unchanged" : "CHANGED");
    }
    assert_int_equal(e, want);
    assert_true(iotest_map_digest(&map_a) == digest);
}

static void bad_image_cases(const call_t *ok, uint64_t d)
{
    call_t c = *ok;
    c.im.data = NULL;
    expect_refused(&c, OCC_ERR_ARG, d, "data NULL");
    const uint32_t sides[3] = {0u, OCC_DEPTH_MAX_SIDE + 1u, 0u};
    for (unsigned i = 0; i < 2u; i++) {
        c = *ok;
        c.im.width = sides[i];
        expect_refused(&c, OCC_ERR_ARG, d, "width");
        c = *ok;
        c.im.height = sides[i];
        expect_refused(&c, OCC_ERR_ARG, d, "height");
    }
    c = *ok;
    c.im.row_stride_bytes = 15u;
    expect_refused(&c, OCC_ERR_ARG, d, "stride < width * 2");
    c = *ok;
    c.im.format = OCC_DEPTH_F32;
    c.im.row_stride_bytes = 31u;
    expect_refused(&c, OCC_ERR_ARG, d, "float stride < width * 4");
    c = *ok;
    c.im.format = (occ_depth_format_t)7;
    expect_refused(&c, OCC_ERR_ARG, d, "format");
    const float bad_scale[4] = {0.0f, -1.0f, NAN, INFINITY};
    for (unsigned i = 0; i < 4u; i++) {
        c = *ok;
        c.im.depth_scale_m = bad_scale[i];
        expect_refused(&c, OCC_ERR_ARG, d, "depth scale");
    }
}

static void bad_params_cases(const call_t *ok, uint64_t d)
{
    const float bad_f[4] = {0.0f, -5.0f, NAN, INFINITY};
    for (unsigned i = 0; i < 4u; i++) {
        call_t c = *ok;
        c.dp.intrinsics.fx = bad_f[i];
        expect_refused(&c, OCC_ERR_ARG, d, "fx");
        c = *ok;
        c.dp.intrinsics.fy = bad_f[i];
        expect_refused(&c, OCC_ERR_ARG, d, "fy");
    }
    call_t c = *ok;
    c.dp.intrinsics.cx = NAN;
    expect_refused(&c, OCC_ERR_ARG, d, "cx NaN");
    c = *ok;
    c.dp.intrinsics.cy = -INFINITY;
    expect_refused(&c, OCC_ERR_ARG, d, "cy Inf");
    const float ranges[6][2] = {{NAN, 2.0f}, {-0.1f, 2.0f}, {0.05f, NAN},
                                {0.05f, INFINITY}, {2.0f, 2.0f}, {3.0f, 2.0f}};
    for (unsigned i = 0; i < 6u; i++) {
        c = *ok;
        c.dp.min_range_m = ranges[i][0];
        c.dp.max_range_m = ranges[i][1];
        expect_refused(&c, OCC_ERR_ARG, d, "min / max range");
    }
    c = *ok;
    c.dp.pixel_step = 0u;
    expect_refused(&c, OCC_ERR_ARG, d, "step 0");
}

static void bad_pose_cases(const call_t *ok, uint64_t d)
{
    call_t c = *ok;
    c.pose.p.y = NAN;
    expect_refused(&c, OCC_ERR_ARG, d, "pose NaN");
    c = *ok;
    c.pose.q = (occ_quat_t){0.0f, 0.0f, 0.0f, 0.0f};
    expect_refused(&c, OCC_ERR_ARG, d, "zero quaternion");
    c = *ok;
    c.pose.q = (occ_quat_t){1.01f, 0.0f, 0.0f, 0.0f};
    expect_refused(&c, OCC_ERR_ARG, d, "quaternion not unit");
    c = *ok;
    c.pose.p.x = 1e7f;
    expect_refused(&c, OCC_ERR_RANGE, d, "camera outside the map");
    c = *ok;
    c.ip.method = (occ_insert_method_t)99;
    expect_refused(&c, OCC_ERR_ARG, d, "insert method");
    c = *ok;
    c.scratch_bytes = 3u + 12u * 61u; /* one point short */
    expect_refused(&c, OCC_ERR_SCRATCH, d, "scratch for 61 of 62 points");
    c = *ok;
    c.scratch_bytes = 3u + 12u * 62u; /* the points, nothing for insert_cloud */
    expect_refused(&c, OCC_ERR_SCRATCH, d, "no scratch left for insert_cloud");
}

static void test_bad_input(void **state)
{
    (void)state;
    init_maps(0.1f);
    uint16_t mm[64];
    tof_frame(mm);
    call_t ok = tof_call(mm);
    ok.pose.p.z = 0.35f; /* a map that already holds something */
    assert_int_equal(run_call(&ok), OCC_OK);
    ok.pose.p.z = 0.05f;
    const uint64_t d = iotest_map_digest(&map_a);
    occ_depth_result_t r;
    assert_int_equal(occ_map_insert_depth(NULL, &ok.im, &ok.dp, &ok.pose, &ok.ip, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_ERR_ARG);
    assert_int_equal(occ_map_insert_depth(&map_a, NULL, &ok.dp, &ok.pose, &ok.ip, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_ERR_ARG);
    assert_int_equal(occ_map_insert_depth(&map_a, &ok.im, NULL, &ok.pose, &ok.ip, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_ERR_ARG);
    assert_int_equal(occ_map_insert_depth(&map_a, &ok.im, &ok.dp, NULL, &ok.ip, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_ERR_ARG);
    assert_int_equal(occ_map_insert_depth(&map_a, &ok.im, &ok.dp, &ok.pose, NULL, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_ERR_ARG);
    assert_int_equal(occ_map_insert_depth(&map_a, &ok.im, &ok.dp, &ok.pose, &ok.ip, NULL,
                                          SCRATCH_BYTES, &r),
                     OCC_ERR_SCRATCH);
    assert_true(iotest_map_digest(&map_a) == d);
    bad_image_cases(&ok, d);
    bad_params_cases(&ok, d);
    bad_pose_cases(&ok, d);
    assert_int_equal(run_call(&ok), OCC_OK); /* and the good call still works */
    assert_true(iotest_map_digest(&map_a) != d);
}

/* Maps whose pools cannot hold the frame, at every small arena size: OCC_ERR_NOMEM, the map
 * unchanged and still valid. */
static void test_pools_short(void **state)
{
    (void)state;
    static uint8_t small[65536];
    occ_map_config_t cfg = iotest_octomap_cfg();
    cfg.resolution_m = 0.1f;
    uint16_t mm[64];
    tof_frame(mm);
    const call_t c = tof_call(mm);
    size_t refused = 0, fitted = 0;
    for (size_t bytes = 1024u; bytes <= sizeof small; bytes += 1024u) {
        occ_map_t m;
        if (occ_map_init(&m, &cfg, small, bytes) != OCC_OK) {
            continue;
        }
        const uint64_t d = iotest_map_digest(&m);
        occ_depth_result_t r;
        const occ_err_t e = occ_map_insert_depth(&m, &c.im, &c.dp, &c.pose, &c.ip, scratch,
                                                 SCRATCH_BYTES, &r);
        assert_true(e == OCC_OK || e == OCC_ERR_NOMEM);
        if (e == OCC_ERR_NOMEM) {
            refused++;
            assert_true(iotest_map_digest(&m) == d);
        } else {
            fitted++;
            check_tof_map(&m);
        }
        assert_int_equal(occ_map_check(&m), OCC_OK);
    }
    assert_true(refused > 0u && fitted > 0u);
}

/* The compile-time formula sizes a static buffer that is enough, and equals the function. */
#define TOF_RAY_VOXELS 22u /* ceil(2 m / 0.1 m) + 2 */
static union {
    uint8_t b[OCC_DEPTH_SCRATCH_BYTES(8, 8, 1, TOF_RAY_VOXELS)];
    uint32_t align; /* b 4-aligned: b + 1 needs 3 bytes to align the points */
} tof_scratch;

static void test_scratch_formula(void **state)
{
    (void)state;
    init_maps(0.1f);
    const occ_insert_params_t ip = occ_insert_params_default();
    assert_int_equal(occ_depth_scratch_bytes(&map_a, 8u, 8u, 1u, 2.0f, &ip), sizeof tof_scratch.b);
    assert_int_equal(OCC_DEPTH_PIXELS(640, 480, 8), 80u * 60u);
    assert_int_equal(OCC_DEPTH_PIXELS(641, 479, 8), 81u * 60u);
    assert_true(OCC_DEPTH_SCRATCH_FITS(640, 480, 1, 100));
    /* the largest image saturates instead of wrapping (a 32-bit size_t) */
    const size_t big = occ_depth_scratch_bytes(&map_a, OCC_DEPTH_MAX_SIDE, OCC_DEPTH_MAX_SIDE, 1u,
                                               100.0f, &ip);
    assert_true(big == SIZE_MAX || big / 12u >= (size_t)OCC_DEPTH_MAX_SIDE * OCC_DEPTH_MAX_SIDE);
    assert_int_equal(occ_depth_scratch_bytes(&map_a, 0u, 8u, 1u, 2.0f, &ip), 0);
    assert_int_equal(occ_depth_scratch_bytes(&map_a, 8u, 8u, 0u, 2.0f, &ip), 0);
    assert_int_equal(occ_depth_scratch_bytes(&map_a, 8u, 8u, 1u, INFINITY, &ip), 0);
    uint16_t mm[64];
    tof_frame(mm);
    call_t c = tof_call(mm);
    const occ_insert_method_t methods[3] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                            OCC_INSERT_SUPER_RAYS};
    for (unsigned i = 0; i < 3u; i++) {
        c.ip.method = methods[i];
        occ_depth_result_t r;
        /* off by one byte from the buffer's start: the alignment term is needed */
        assert_int_equal(occ_map_insert_depth(&map_a, &c.im, &c.dp, &c.pose, &c.ip,
                                              tof_scratch.b + 1, sizeof tof_scratch.b - 1u, &r),
                         OCC_OK);
        assert_int_equal(r.scratch_points, 3u + 12u * 62u);
        assert_true(r.scratch_points + r.insert.scratch_used <= sizeof tof_scratch.b);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tof_8x8),
        cmocka_unit_test(test_overflowing_rays),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_pools_short),
        cmocka_unit_test(test_scratch_formula),
    };
    return cmocka_run_group_tests(tests, depth_setup, depth_teardown);
}
