/* SPDX-License-Identifier: BSD-3-Clause */
/* test_depth_tum.c - occ_map_insert_depth() on the real TUM frames, voxel for voxel against
 * back-projection + occ_map_insert_cloud() (SIMPLE, DISCRETE, SUPER_RAYS) and against OctoMap's
 * insertPointCloud: the pioneer_slam2 frames with their association poses, and tum_fr1_rpy with
 * poses interpolated from its 100 Hz ground truth by occ_pose_history (the capture-gap frames
 * refused). Skips when ../shared is absent. */
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
#include "occmap/host/occ_tum.h"
#include "support/depth_fixture.h"
#include "support/oracle_io.h"

#define PIONEER_DIR "../shared/data/depth/tum_fr2_pioneer_slam2"
#define RPY_DIR "../shared/data/depth/tum_fr1_rpy"

/* ---- real frames ---------------------------------------------------------------------------- */
typedef struct {
    uint16_t *pix;
    uint32_t w, h;
    occ_pose_t pose; /* map_from_camera */
    char path[512];
} frame_t;

static bool load_png(const char *path, frame_t *f)
{
    char msg[256] = "";
    snprintf(f->path, sizeof f->path, "%s", path);
    if (occ_depth_read_png_image(path, &f->pix, &f->w, &f->h, msg, sizeof msg) != OCC_OK) {
        printf("SKIP: %s unreadable (%s; needs ../shared)\n", path, msg);
        return false;
    }
    return true;
}

static occ_depth_image_t tum_image(const frame_t *f)
{
    const occ_depth_image_t im = {f->pix, OCC_DEPTH_U16, f->w, f->h, (size_t)f->w * 2u,
                                  1.0f / 5000.0f};
    return im;
}

static occ_depth_params_t cam_params(const occ_depth_camera_t *cam, float min_m, float max_m,
                                     uint32_t step)
{
    const occ_depth_params_t p = {{cam->fx, cam->fy, cam->cx, cam->cy}, min_m, max_m, step};
    return p;
}

/* The test's own back-projection of the valid pixels, the header's arithmetic: *n points. */
static occ_vec3_t *back_project(const frame_t *f, const occ_depth_params_t *dp, size_t *n)
{
    occ_vec3_t *pts = malloc((size_t)f->w * f->h * sizeof *pts);
    assert_non_null(pts);
    const occ_pinhole_t *k = &dp->intrinsics;
    *n = 0;
    for (uint32_t v = 0; v < f->h; v += dp->pixel_step) {
        for (uint32_t u = 0; u < f->w; u += dp->pixel_step) {
            const uint16_t raw = f->pix[(size_t)v * f->w + u];
            const float d = (float)raw * (1.0f / 5000.0f);
            const occ_vec3_t c = {((float)u - k->cx) * d / k->fx, ((float)v - k->cy) * d / k->fy,
                                  d};
            if (raw != 0u && sqrtf(c.x * c.x + c.y * c.y + c.z * c.z) >= dp->min_range_m) {
                pts[(*n)++] = occ_pose_apply(&f->pose, c);
            }
        }
    }
    return pts;
}

/* insert_depth into map_a, back-projection + insert_cloud into map_b: the same map (digest of
 * every node and the pool counters) and the same insert counters. */
static void same_as_cloud(const frame_t *f, const occ_depth_params_t *dp,
                          const occ_insert_params_t *ip)
{
    const occ_depth_image_t im = tum_image(f);
    occ_depth_result_t r;
    assert_int_equal(occ_map_insert_depth(&map_a, &im, dp, &f->pose, ip, scratch, SCRATCH_BYTES,
                                          &r),
                     OCC_OK);
    size_t n = 0;
    occ_vec3_t *pts = back_project(f, dp, &n);
    occ_insert_params_t p = *ip;
    p.max_range_m = dp->max_range_m;
    occ_insert_result_t rc;
    assert_int_equal(occ_map_insert_cloud(&map_b, &f->pose.p, pts, n, &p, scratch, SCRATCH_BYTES,
                                          &rc),
                     OCC_OK);
    free(pts);
    assert_int_equal(r.points, n);
    assert_int_equal(r.pixels_sampled, OCC_DEPTH_PIXELS(f->w, f->h, dp->pixel_step));
    assert_int_equal(r.insert.voxels_updated, rc.voxels_updated);
    assert_int_equal(r.insert.voxels_occupied, rc.voxels_occupied);
    assert_int_equal(r.insert.rays_clipped, rc.rays_clipped);
    printf("  %zu pixels: %zu no reading, %zu too close, %zu beyond max\n", r.pixels_sampled,
           r.pixels_no_reading, r.pixels_too_close, r.pixels_beyond_max);
    assert_true(r.pixels_beyond_max > 0u && r.pixels_too_close > 0u);
    assert_true(iotest_map_digest(&map_a) == iotest_map_digest(&map_b));
}

/* The pioneer frames: poses and names from my_association.txt (occ_depth_read_tum_dir). */
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
        assert_true(load_png(path, &out[i]));
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

/* Our back-projection agrees with the host reader's (double precision, its own rotation
 * matrix) to float rounding: the formula and the pose convention are right. */
static void check_against_reader(const frame_t *f, const occ_depth_camera_t *cam)
{
    const occ_depth_params_t dp = cam_params(cam, 0.0f, 100.0f, 8u);
    size_t n = 0;
    occ_vec3_t *pts = back_project(f, &dp, &n);
    const float t[3] = {f->pose.p.x, f->pose.p.y, f->pose.p.z};
    const float q[4] = {f->pose.q.w, f->pose.q.x, f->pose.q.y, f->pose.q.z};
    occ_scan_frame_t ref;
    char msg[256];
    assert_int_equal(occ_depth_read_png(f->path, cam, t, q, 8u, &ref, msg, sizeof msg), OCC_OK);
    assert_int_equal(ref.n_points, n);
    float worst = 0.0f;
    for (size_t i = 0; i < n; i++) {
        worst = fmaxf(worst, fabsf(pts[i].x - ref.points[i].x) + fabsf(pts[i].y - ref.points[i].y) +
                                 fabsf(pts[i].z - ref.points[i].z));
    }
    assert_true(worst < 2e-5f);
    free(pts);
    free(ref.points);
}

static void test_pioneer_equals_cloud(void **state)
{
    (void)state;
    frame_t f[6];
    const size_t n = pioneer_frames(f, 6u);
    if (n == 0u) {
        skip();
    }
    assert_int_equal(n, 6);
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    check_against_reader(&f[0], &cam);
    const occ_insert_method_t methods[3] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                            OCC_INSERT_SUPER_RAYS};
    const occ_depth_params_t dp = cam_params(&cam, 1.5f, 4.0f, 4u);
    for (unsigned m = 0; m < 3u; m++) {
        init_maps(m == 2u ? 0.2f : 0.1f);
        occ_insert_params_t ip = occ_insert_params_default();
        ip.method = methods[m];
        for (size_t i = 0; i < n; i += 5u) {
            same_as_cloud(&f[i], &dp, &ip);
        }
    }
    free_frames(f, n);
}

/* insert_depth frame after frame into map_a and OctoMap's insertPointCloud of the test's own
 * back-projection (same max range; OctoMap has no min range: 0 here) into one tree: the same
 * leaves, values within 1/1024 per frame (our log-odds are 16-bit fixed point, OctoMap's float;
 * each update rounds to 1/1024). */
static void same_as_octomap(const frame_t *f, size_t n, const occ_depth_params_t *dp,
                            occ_insert_method_t method, float res)
{
    init_maps(res);
    oracle_io_t *t = oracle_io_new(ORACLE_OCTREE, (double)res);
    assert_non_null(t);
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = method;
    for (size_t i = 0; i < n; i++) {
        const occ_depth_image_t im = tum_image(&f[i]);
        occ_depth_result_t r;
        assert_int_equal(occ_map_insert_depth(&map_a, &im, dp, &f[i].pose, &ip, scratch,
                                              SCRATCH_BYTES, &r),
                         OCC_OK);
        size_t np = 0;
        occ_vec3_t *pts = back_project(&f[i], dp, &np);
        const float o[3] = {f[i].pose.p.x, f[i].pose.p.y, f[i].pose.p.z};
        oracle_io_insert_cloud(t, (const float *)(const void *)pts, np, o,
                               (double)dp->max_range_m, method == OCC_INSERT_DISCRETE);
        free(pts);
    }
    char why[256] = "";
    const bool eq = iotest_equivalent(&map_a, t, (float)n / 1024.0f + 1e-4f, why, sizeof why);
    if (!eq) {
        printf("differs from OctoMap (method %d, res %.2f): %s\n", (int)method, (double)res, why);
    }
    assert_true(eq);
    oracle_io_free(t);
}

static void test_pioneer_octomap(void **state)
{
    (void)state;
    frame_t f[10];
    const size_t n = pioneer_frames(f, 10u);
    if (n == 0u) {
        skip();
    }
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr2();
    const occ_depth_params_t dp = cam_params(&cam, 0.0f, 3.5f, 8u);
    const frame_t some[3] = {f[0], f[4], f[9]};
    same_as_octomap(some, 3u, &dp, OCC_INSERT_SIMPLE, 0.05f);
    same_as_octomap(some, 3u, &dp, OCC_INSERT_DISCRETE, 0.1f);
    free_frames(f, n);
}

/* ---- tum_fr1_rpy: poses interpolated from the 100 Hz ground truth -------------------------- */
typedef struct {
    occ_pose_sample_t *gt;
    size_t n_gt;
    occ_tum_depth_entry_t *list;
    size_t n_list;
    occ_pose_history_t h;
} rpy_t;

static bool load_rpy(rpy_t *r)
{
    char msg[256] = "";
    if (occ_tum_read_groundtruth(RPY_DIR "/groundtruth.txt", &r->gt, &r->n_gt, msg, sizeof msg) !=
            OCC_OK ||
        occ_tum_read_depth_list(RPY_DIR "/depth.txt", &r->list, &r->n_list, msg, sizeof msg) !=
            OCC_OK) {
        printf("SKIP: %s not available (%s; needs ../shared)\n", RPY_DIR, msg);
        return false;
    }
    const occ_pose_history_cfg_t cfg = {OCC_TUM_MAX_GAP_US, 0u};
    assert_int_equal(occ_pose_history_init(&r->h, r->gt, r->n_gt, &cfg), OCC_OK);
    assert_int_equal(occ_tum_history_fill(&r->h, r->gt, r->n_gt), OCC_OK);
    return true;
}

/* The position by hand: the bracketing samples, linear in time (double). */
static void check_interpolation(const rpy_t *r, uint64_t t_us, const occ_pose_t *got)
{
    size_t i = 0;
    while (i + 1u < r->n_gt && r->gt[i + 1u].t_us < t_us) {
        i++;
    }
    const occ_pose_sample_t *a = &r->gt[i], *b = &r->gt[i + 1u];
    assert_true(a->t_us <= t_us && t_us <= b->t_us);
    const double s = (double)(t_us - a->t_us) / (double)(b->t_us - a->t_us);
    const double want_x = (double)a->pose.p.x + s * (double)(b->pose.p.x - a->pose.p.x);
    const double want_z = (double)a->pose.p.z + s * (double)(b->pose.p.z - a->pose.p.z);
    assert_true(fabs((double)got->p.x - want_x) < 1e-5 && fabs((double)got->p.z - want_z) < 1e-5);
    /* slerp by hand (double): sin((1 - s) th) / sin th a + sin(s th) / sin th b, shortest arc */
    const double qa[4] = {a->pose.q.w, a->pose.q.x, a->pose.q.y, a->pose.q.z};
    double qb[4] = {b->pose.q.w, b->pose.q.x, b->pose.q.y, b->pose.q.z};
    double dot = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
    const double sign = dot < 0.0 ? -1.0 : 1.0;
    dot *= sign;
    const double th = acos(fmin(dot, 1.0));
    const double wa = th > 1e-9 ? sin((1.0 - s) * th) / sin(th) : 1.0 - s;
    const double wb = (th > 1e-9 ? sin(s * th) / sin(th) : s) * sign;
    const double qg[4] = {got->q.w, got->q.x, got->q.y, got->q.z};
    const double gs = qg[0] * (wa * qa[0] + wb * qb[0]) >= 0.0 ? 1.0 : -1.0; /* q = -q */
    for (unsigned c = 0; c < 4u; c++) {
        assert_true(fabs(gs * qg[c] - (wa * qa[c] + wb * qb[c])) < 1e-5);
    }
}

static void test_rpy_interpolated(void **state)
{
    (void)state;
    rpy_t r;
    if (!load_rpy(&r)) {
        skip();
    }
    assert_true(r.n_list >= 500u);
    /* Of the 500 frames here exactly the four in the capture gap (130 ms without a pose, after
     * the sample at .8129 s) have no pose: SOURCE.md's three plus .814094, 1.2 ms after the
     * last sample, which would have to be interpolated across the gap. */
    static const uint64_t gap[4] = {1305031244814094u, 1305031244841822u, 1305031244881801u,
                                    1305031244914908u};
    size_t refused = 0;
    for (size_t i = 0; i < 500u; i++) {
        occ_pose_t p;
        occ_pose_refusal_t why;
        if (occ_pose_history_at(&r.h, r.list[i].t_us, &p, &why) != OCC_OK) {
            assert_int_equal(why, OCC_POSE_GAP);
            assert_true(refused < 4u && r.list[i].t_us == gap[refused]);
            refused++;
        } else {
            check_interpolation(&r, r.list[i].t_us, &p);
        }
    }
    assert_int_equal(refused, 4);
    /* Three frames across the sequence, posed by the history, into occmap and OctoMap. */
    frame_t f[3];
    const size_t idx[3] = {0u, 250u, 499u};
    for (size_t i = 0; i < 3u; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", RPY_DIR, r.list[idx[i]].file);
        assert_true(load_png(path, &f[i]));
        assert_int_equal(occ_pose_history_at(&r.h, r.list[idx[i]].t_us, &f[i].pose, NULL), OCC_OK);
    }
    const occ_depth_camera_t cam = occ_depth_camera_tum_fr1();
    check_against_reader(&f[1], &cam);
    const occ_depth_params_t dp = cam_params(&cam, 0.0f, 3.0f, 6u);
    same_as_octomap(f, 3u, &dp, OCC_INSERT_SIMPLE, 0.05f);
    const occ_depth_params_t dp_close = cam_params(&cam, 1.0f, 3.0f, 4u);
    init_maps(0.1f);
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_SUPER_RAYS;
    for (size_t i = 0; i < 3u; i++) {
        same_as_cloud(&f[i], &dp_close, &ip);
    }
    free_frames(f, 3u);
    free(r.gt);
    free(r.list);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pioneer_equals_cloud),
        cmocka_unit_test(test_pioneer_octomap),
        cmocka_unit_test(test_rpy_interpolated),
    };
    return cmocka_run_group_tests(tests, depth_setup, depth_teardown);
}
