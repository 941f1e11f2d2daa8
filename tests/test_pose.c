/* SPDX-License-Identifier: BSD-3-Clause */
/* test_pose.c - the pose algebra (occ_pose.h, src/sensors/pose.c) against hand-computed values:
 * compose / invert / apply / rotate, Euler angles (gimbal lock, yaw wrap), axis-angle, the
 * refusals, NED/FRD <-> ENU/FLU (where body forward / left / up go in the map), the yaw of a
 * rolled and pitched pose, and interpolation (slerp, shortest arc, extrapolation).
 * The timed history is in test_pose_history.c. Random cases print their seed (OCC_SEED). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_pose.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static unsigned seed_rng(void)
{
    const char *const s = getenv("OCC_SEED");
    const unsigned seed = s != NULL ? (unsigned)strtoul(s, NULL, 10) : 20261202u;
    printf("test_pose: seed %u (OCC_SEED)\n", seed);
    srand(seed);
    return seed;
}

static double urand(double lo, double hi)
{
    return lo + (hi - lo) * (double)rand() / (double)RAND_MAX;
}

static void near(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) {
        fail_msg("%s: got %.9g, want %.9g (tol %g)", what, got, want, tol);
    }
}

/* Angles equal modulo 2 pi. */
static void near_angle(double got, double want, double tol, const char *what)
{
    double d = fmod(got - want, 2.0 * PI);
    d = d > PI ? d - 2.0 * PI : (d < -PI ? d + 2.0 * PI : d);
    if (!(fabs(d) <= tol)) {
        fail_msg("%s: got %.9g, want %.9g (mod 2 pi, tol %g)", what, got, want, tol);
    }
}

static void near3(occ_vec3_t v, double x, double y, double z, double tol, const char *what)
{
    near(v.x, x, tol, what);
    near(v.y, y, tol, what);
    near(v.z, z, tol, what);
}

/* Same rotation: q = +-r. */
static void same_rot(occ_quat_t q, occ_quat_t r, double tol, const char *what)
{
    const double d = (double)q.w * (double)r.w + (double)q.x * (double)r.x +
                     (double)q.y * (double)r.y + (double)q.z * (double)r.z;
    if (!(fabs(fabs(d) - 1.0) <= tol)) {
        fail_msg("%s: (%g %g %g %g) vs (%g %g %g %g), |dot| %.9g", what, (double)q.w, (double)q.x,
                 (double)q.y, (double)q.z, (double)r.w, (double)r.x, (double)r.y, (double)r.z,
                 fabs(d));
    }
}

/* Bit-for-bit equal: "untouched" and exact results. */
#define SAME_BITS(a, b) (memcmp(&(a), &(b), sizeof(a)) == 0)

static occ_vec3_t v3(double x, double y, double z)
{
    const occ_vec3_t v = {(float)x, (float)y, (float)z};
    return v;
}

static occ_quat_t qyaw(double yaw)
{
    const occ_quat_t q = {(float)cos(0.5 * yaw), 0.0f, 0.0f, (float)sin(0.5 * yaw)};
    return q;
}

static occ_pose_t pose(double x, double y, double z, occ_quat_t q)
{
    occ_pose_t p;
    p.p = v3(x, y, z);
    p.q = q;
    return p;
}

static occ_pose_t random_pose(void)
{
    const occ_quat_t q = occ_quat_from_euler((float)urand(-PI, PI), (float)urand(-1.5, 1.5),
                                             (float)urand(-PI, PI));
    return pose(urand(-50, 50), urand(-50, 50), urand(-10, 10), q);
}

static void test_apply_rotate(void **state)
{
    (void)state;
    const occ_pose_t id = occ_pose_identity();
    near3(occ_pose_apply(&id, v3(1, -2, 3)), 1, -2, 3, 0, "identity apply");
    /* 90 deg about z, at (1, 2, 3): x -> y, y -> -x. */
    const occ_pose_t a = pose(1, 2, 3, qyaw(PI / 2));
    near3(occ_pose_apply(&a, v3(1, 0, 0)), 1, 3, 3, 1e-6, "apply x");
    near3(occ_pose_apply(&a, v3(0, 1, 0)), 0, 2, 3, 1e-6, "apply y");
    near3(occ_pose_rotate(&a, v3(1, 0, 0)), 0, 1, 0, 1e-6, "rotate x");
    near3(occ_pose_rotate(&a, v3(0, 0, 2)), 0, 0, 2, 1e-6, "rotate z");
    /* 120 deg about (1, 1, 1): the axes cycle x -> y -> z -> x. */
    const occ_quat_t c = {0.5f, 0.5f, 0.5f, 0.5f};
    const occ_pose_t b = pose(0, 0, 0, c);
    near3(occ_pose_rotate(&b, v3(1, 0, 0)), 0, 1, 0, 1e-6, "cycle x");
    near3(occ_pose_rotate(&b, v3(0, 1, 0)), 0, 0, 1, 1e-6, "cycle y");
    near3(occ_pose_rotate(&b, v3(0, 0, 1)), 1, 0, 0, 1e-6, "cycle z");
}

static void test_compose_invert_hand(void **state)
{
    (void)state;
    /* a: 1 m east, facing north; b in a's frame: 1 m ahead, turned 90 deg more. */
    const occ_pose_t a = pose(1, 0, 0, qyaw(PI / 2));
    const occ_pose_t ab = occ_pose_compose(&a, &a);
    near3(ab.p, 1, 1, 0, 1e-6, "compose p");
    same_rot(ab.q, qyaw(PI), 1e-6, "compose q");
    /* invert of (1, 2, 3) yaw 90: yaw -90, p = -R(-90)(1, 2, 3) = (-2, 1, -3). */
    const occ_pose_t b = pose(1, 2, 3, qyaw(PI / 2));
    const occ_pose_t bi = occ_pose_invert(&b);
    near3(bi.p, -2, 1, -3, 1e-6, "invert p");
    same_rot(bi.q, qyaw(-PI / 2), 1e-6, "invert q");
    near3(occ_pose_apply(&bi, v3(1, 2, 3)), 0, 0, 0, 1e-6, "invert maps b's origin to 0");
}

static void test_compose_invert_random(void **state)
{
    (void)state;
    (void)seed_rng();
    for (int i = 0; i < 200; i++) {
        const occ_pose_t a = random_pose(), b = random_pose(), c = random_pose();
        const occ_pose_t ai = occ_pose_invert(&a);
        const occ_pose_t e1 = occ_pose_compose(&a, &ai), e2 = occ_pose_compose(&ai, &a);
        near3(e1.p, 0, 0, 0, 1e-4, "a o a^-1 p");
        near3(e2.p, 0, 0, 0, 1e-4, "a^-1 o a p");
        same_rot(e1.q, occ_quat_identity(), 1e-6, "a o a^-1 q");
        same_rot(e2.q, occ_quat_identity(), 1e-6, "a^-1 o a q");
        const occ_pose_t ab = occ_pose_compose(&a, &b), bc = occ_pose_compose(&b, &c);
        const occ_pose_t l = occ_pose_compose(&ab, &c), r = occ_pose_compose(&a, &bc);
        near3(l.p, r.p.x, r.p.y, r.p.z, 1e-4, "associativity p");
        same_rot(l.q, r.q, 1e-6, "associativity q");
        const occ_vec3_t v = v3(urand(-5, 5), urand(-5, 5), urand(-5, 5));
        const occ_vec3_t bv = occ_pose_apply(&b, v), abv = occ_pose_apply(&ab, v);
        const occ_vec3_t want = occ_pose_apply(&a, bv);
        near3(abv, want.x, want.y, want.z, 1e-4, "compose applies b then a");
        assert_int_equal(occ_pose_check(&l), OCC_OK);
        assert_int_equal(occ_pose_check(&ai), OCC_OK);
    }
}

static void test_euler_hand(void **state)
{
    (void)state;
    const occ_quat_t y = occ_quat_from_euler(0.0f, 0.0f, (float)(PI / 3));
    same_rot(y, qyaw(PI / 3), 1e-7, "yaw only");
    const occ_quat_t r = occ_quat_from_euler((float)(PI / 2), 0.0f, 0.0f);
    const occ_pose_t pr = pose(0, 0, 0, r);
    near3(occ_pose_rotate(&pr, v3(0, 1, 0)), 0, 0, 1, 1e-6, "roll 90: y -> z");
    const occ_quat_t p = occ_quat_from_euler(0.0f, (float)(PI / 2), 0.0f);
    const occ_pose_t pp = pose(0, 0, 0, p);
    near3(occ_pose_rotate(&pp, v3(1, 0, 0)), 0, 0, -1, 1e-6, "pitch 90: x -> -z");
    /* R = Rz(0) Ry(90) Rx(90): roll first, in the body. x -> -z, y -> x, z -> -y. */
    const occ_pose_t rp = pose(0, 0, 0, occ_quat_from_euler((float)(PI / 2), (float)(PI / 2), 0));
    near3(occ_pose_rotate(&rp, v3(1, 0, 0)), 0, 0, -1, 1e-6, "ZYX x");
    near3(occ_pose_rotate(&rp, v3(0, 1, 0)), 1, 0, 0, 1e-6, "ZYX y");
    near3(occ_pose_rotate(&rp, v3(0, 0, 1)), 0, -1, 0, 1e-6, "ZYX z");
    /* Yaw 90 after pitch 90: the nose still points down, the left wing goes from +y to -x. */
    const occ_pose_t yp = pose(0, 0, 0, occ_quat_from_euler(0, (float)(PI / 2), (float)(PI / 2)));
    near3(occ_pose_rotate(&yp, v3(0, 1, 0)), -1, 0, 0, 1e-6, "yaw after pitch");
    float ro = 9, pi = 9, ya = 9;
    occ_quat_to_euler(occ_quat_from_euler(0.1f, -0.2f, 0.3f), &ro, &pi, &ya);
    near(ro, 0.1, 1e-6, "roll back");
    near(pi, -0.2, 1e-6, "pitch back");
    near(ya, 0.3, 1e-6, "yaw back");
    occ_quat_to_euler(y, NULL, NULL, NULL); /* every output may be NULL */
    const occ_quat_t n = occ_quat_from_euler(NAN, 0.0f, 0.0f);
    const occ_pose_t np = pose(0, 0, 0, n);
    assert_int_equal(occ_pose_check(&np), OCC_ERR_ARG);
}

static void test_euler_round_trip(void **state)
{
    (void)state;
    (void)seed_rng();
    for (int i = 0; i < 500; i++) {
        const double r = urand(-3.14, 3.14), p = urand(-1.55, 1.55), y = urand(-3.14, 3.14);
        const occ_quat_t q = occ_quat_from_euler((float)r, (float)p, (float)y);
        near(sqrt((double)(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z)), 1.0, 1e-6, "unit");
        float r2, p2, y2;
        occ_quat_to_euler(q, &r2, &p2, &y2);
        near(r2, r, 2e-4, "roll");
        near(p2, p, 2e-4, "pitch");
        near(y2, y, 2e-4, "yaw");
    }
}

/* At +-90 deg pitch roll and yaw turn about the same axis: roll 0, yaw takes the difference
 * (pitch up) or the sum (pitch down), and the rotation is the same. */
static void test_euler_gimbal(void **state)
{
    (void)state;
    const double signs[2] = {1.0, -1.0};
    for (int i = 0; i < 2; i++) {
        const occ_quat_t q = occ_quat_from_euler(0.3f, (float)(signs[i] * PI / 2), 0.8f);
        float r, p, y;
        occ_quat_to_euler(q, &r, &p, &y);
        near(p, signs[i] * PI / 2, 1e-6, "gimbal pitch");
        near(r, 0.0, 0.0, "gimbal roll");
        near_angle(y, 0.8 - signs[i] * 0.3, 1e-5, "gimbal yaw");
        same_rot(occ_quat_from_euler(r, p, y), q, 1e-6, "gimbal same rotation");
    }
    /* -3 + -1 wraps: pitch down, roll 2, yaw 2.5 -> yaw 4.5 = 4.5 - 2 pi. */
    float r, p, y;
    occ_quat_to_euler(occ_quat_from_euler(2.0f, (float)(-PI / 2), 2.5f), &r, &p, &y);
    near(y, 4.5 - 2 * PI, 1e-5, "gimbal yaw wrapped");
}

static void test_euler_yaw_wrap(void **state)
{
    (void)state;
    float y;
    occ_quat_to_euler(occ_quat_from_euler(0, 0, (float)(1.5 * PI)), NULL, NULL, &y);
    near(y, -PI / 2, 1e-6, "3pi/2 -> -pi/2");
    occ_quat_to_euler(occ_quat_from_euler(0, 0, (float)(-1.5 * PI)), NULL, NULL, &y);
    near(y, PI / 2, 1e-6, "-3pi/2 -> pi/2");
    occ_quat_to_euler(occ_quat_from_euler(0, 0, (float)(2 * PI + 0.1)), NULL, NULL, &y);
    near(y, 0.1, 1e-6, "2pi + 0.1 -> 0.1");
    /* A half turn is +pi, never -pi: also for a quaternion with signed zeros. */
    const occ_quat_t half = {0.0f, 0.0f, 0.0f, 1.0f};
    occ_quat_to_euler(half, NULL, NULL, &y);
    near(y, PI, 1e-6, "half turn");
    const occ_quat_t half_neg0 = {-0.0f, 0.0f, -0.0f, 1.0f};
    occ_quat_to_euler(half_neg0, NULL, NULL, &y);
    assert_true(y > 0.0f);
    near(y, PI, 1e-6, "half turn from -0");
    const occ_pose_t hp = pose(0, 0, 0, half_neg0);
    assert_true(occ_pose_yaw(&hp) > 0.0f);
}

static void test_axis_angle(void **state)
{
    (void)state;
    occ_quat_t q;
    assert_int_equal(occ_quat_from_axis_angle(v3(0, 0, 2), (float)(PI / 2), &q), OCC_OK);
    same_rot(q, qyaw(PI / 2), 1e-7, "z axis, not unit");
    assert_true(q.w > 0.0f && q.z > 0.0f);
    assert_int_equal(occ_quat_from_axis_angle(v3(1, 1, 1), (float)(2 * PI / 3), &q), OCC_OK);
    const occ_quat_t cyc = {0.5f, 0.5f, 0.5f, 0.5f};
    same_rot(q, cyc, 1e-6, "(1,1,1) 120 deg");
    assert_int_equal(occ_quat_from_axis_angle(v3(1, 0, 0), (float)(PI / 3), &q), OCC_OK);
    same_rot(q, occ_quat_from_euler((float)(PI / 3), 0, 0), 1e-7, "x axis = roll");
    assert_int_equal(occ_quat_from_axis_angle(v3(0, 3, 0), 0.0f, &q), OCC_OK);
    same_rot(q, occ_quat_identity(), 0.0, "angle 0");
    const occ_quat_t keep = {9.0f, 9.0f, 9.0f, 9.0f};
    const occ_vec3_t bad_axes[4] = {v3(0, 0, 0), v3(NAN, 0, 1), v3(0, INFINITY, 0),
                                    v3(1e-30, 0, 0)};
    for (int i = 0; i < 4; i++) {
        q = keep;
        assert_int_equal(occ_quat_from_axis_angle(bad_axes[i], 1.0f, &q), OCC_ERR_ARG);
        assert_true(SAME_BITS(q, keep));
    }
    assert_int_equal(occ_quat_from_axis_angle(v3(0, 0, 1), NAN, &q), OCC_ERR_ARG);
    assert_int_equal(occ_quat_from_axis_angle(v3(0, 0, 1), INFINITY, &q), OCC_ERR_ARG);
    assert_true(SAME_BITS(q, keep));
    assert_int_equal(occ_quat_from_axis_angle(v3(0, 0, 1), 1.0f, NULL), OCC_ERR_ARG);
}

static void test_normalize(void **state)
{
    (void)state;
    occ_quat_t out;
    const occ_quat_t two = {2.0f, 0.0f, 0.0f, 0.0f}, ones = {1.0f, 1.0f, 1.0f, 1.0f};
    assert_int_equal(occ_quat_normalize(two, &out), OCC_OK);
    const occ_quat_t unit_w = {1.0f, 0.0f, 0.0f, 0.0f};
    assert_true(SAME_BITS(out, unit_w));
    assert_int_equal(occ_quat_normalize(ones, &out), OCC_OK);
    near(out.w, 0.5, 1e-7, "w");
    near(out.z, 0.5, 1e-7, "z");
    const occ_quat_t bad[5] = {{0, 0, 0, 0}, {NAN, 0, 0, 1}, {1, INFINITY, 0, 0},
                               {1e-7f, 0, 0, 0}, {0, 0, -INFINITY, 0}};
    for (int i = 0; i < 5; i++) {
        const occ_quat_t keep = {7.0f, 7.0f, 7.0f, 7.0f};
        out = keep;
        assert_int_equal(occ_quat_normalize(bad[i], &out), OCC_ERR_ARG);
        assert_true(SAME_BITS(out, keep));
    }
    assert_int_equal(occ_quat_normalize(two, NULL), OCC_ERR_ARG);
}

static void test_pose_check(void **state)
{
    (void)state;
    occ_pose_t p = occ_pose_identity();
    assert_int_equal(occ_pose_check(&p), OCC_OK);
    assert_int_equal(occ_pose_check(NULL), OCC_ERR_ARG);
    const float nonfinite[3] = {NAN, INFINITY, -INFINITY};
    for (int i = 0; i < 3; i++) {
        p = occ_pose_identity();
        p.p.y = nonfinite[i];
        assert_int_equal(occ_pose_check(&p), OCC_ERR_ARG);
        p = occ_pose_identity();
        p.q.z = nonfinite[i];
        assert_int_equal(occ_pose_check(&p), OCC_ERR_ARG);
    }
    /* |q| within OCC_POSE_QUAT_NORM_TOL of 1 passes, beyond it is refused. */
    p = occ_pose_identity();
    p.q.w = 1.0f + 0.9f * OCC_POSE_QUAT_NORM_TOL;
    assert_int_equal(occ_pose_check(&p), OCC_OK);
    p.q.w = 1.0f - 0.9f * OCC_POSE_QUAT_NORM_TOL;
    assert_int_equal(occ_pose_check(&p), OCC_OK);
    p.q.w = 1.0f + 1.1f * OCC_POSE_QUAT_NORM_TOL;
    assert_int_equal(occ_pose_check(&p), OCC_ERR_ARG);
    p.q.w = 1.0f - 1.1f * OCC_POSE_QUAT_NORM_TOL;
    assert_int_equal(occ_pose_check(&p), OCC_ERR_ARG);
    p.q.w = 0.0f;
    assert_int_equal(occ_pose_check(&p), OCC_ERR_ARG);
    p = pose(1e6, -1e6, 3, qyaw(2.0));
    assert_int_equal(occ_pose_check(&p), OCC_OK);
}

/* Where body forward (x), left (y) and up (z) point in the ENU map. */
static void body_axes(const occ_pose_t *p, const double fwd[3], const double left[3],
                      const double up[3], const char *what)
{
    near3(occ_pose_rotate(p, v3(1, 0, 0)), fwd[0], fwd[1], fwd[2], 1e-6, what);
    near3(occ_pose_rotate(p, v3(0, 1, 0)), left[0], left[1], left[2], 1e-6, what);
    near3(occ_pose_rotate(p, v3(0, 0, 1)), up[0], up[1], up[2], 1e-6, what);
}

static void test_ned_headings(void **state)
{
    (void)state;
    struct {
        double heading_deg, fwd[3], left[3], yaw;
    } const cases[4] = {
        {0, {0, 1, 0}, {-1, 0, 0}, PI / 2},   /* north: forward +y, left west */
        {90, {1, 0, 0}, {0, 1, 0}, 0},        /* east */
        {180, {0, -1, 0}, {1, 0, 0}, -PI / 2}, /* south */
        {270, {-1, 0, 0}, {0, -1, 0}, PI},    /* west */
    };
    const double up[3] = {0, 0, 1};
    for (int i = 0; i < 4; i++) {
        occ_pose_t p;
        const occ_quat_t q = occ_quat_from_euler(0, 0, (float)(cases[i].heading_deg * DEG));
        assert_int_equal(occ_pose_from_ned(v3(1, 2, 3), q, &p), OCC_OK);
        near3(p.p, 2, 1, -3, 0, "NED (1, 2, 3) -> ENU (2, 1, -3)");
        body_axes(&p, cases[i].fwd, cases[i].left, up, "heading");
        near_angle(occ_pose_yaw(&p), cases[i].yaw, 1e-6, "ENU yaw");
    }
}

/* NED pitch positive is nose up, roll positive is the right wing down. */
static void test_ned_pitch_roll(void **state)
{
    (void)state;
    const double c = cos(30 * DEG), s = sin(30 * DEG);
    occ_pose_t p;
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0), occ_quat_from_euler(0, (float)(30 * DEG), 0),
                                       &p), OCC_OK);
    const double pf[3] = {0, c, s}, pl[3] = {-1, 0, 0}, pu[3] = {0, -s, c};
    body_axes(&p, pf, pl, pu, "pitch up 30, heading north");
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0), occ_quat_from_euler((float)(30 * DEG), 0, 0),
                                       &p), OCC_OK);
    const double rf[3] = {0, 1, 0}, rl[3] = {-c, 0, s}, ru[3] = {s, 0, c};
    body_axes(&p, rf, rl, ru, "roll right 30, heading north");
    /* heading east, pitch up 30: forward east and up. */
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0),
                                       occ_quat_from_euler(0, (float)(30 * DEG), (float)(90 * DEG)),
                                       &p), OCC_OK);
    near3(occ_pose_rotate(&p, v3(1, 0, 0)), c, 0, s, 1e-6, "east, pitch up");
}

static void test_ned_round_trip_refusals(void **state)
{
    (void)state;
    (void)seed_rng();
    for (int i = 0; i < 100; i++) {
        const occ_vec3_t ned = v3(urand(-9, 9), urand(-9, 9), urand(-9, 9));
        const occ_quat_t q = occ_quat_from_euler((float)urand(-3, 3), (float)urand(-1.5, 1.5),
                                                 (float)urand(-3, 3));
        occ_pose_t p;
        occ_vec3_t ned2;
        occ_quat_t q2;
        assert_int_equal(occ_pose_from_ned(ned, q, &p), OCC_OK);
        assert_int_equal(occ_pose_check(&p), OCC_OK);
        assert_int_equal(occ_pose_to_ned(&p, &ned2, &q2), OCC_OK);
        near3(ned2, ned.x, ned.y, ned.z, 0, "NED position round trip");
        same_rot(q2, q, 1e-6, "NED attitude round trip");
    }
    occ_pose_t p = occ_pose_identity();
    const occ_quat_t scaled = {2.0f, 0.0f, 0.0f, 0.0f}; /* normalised on the way in */
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0), scaled, &p), OCC_OK);
    assert_int_equal(occ_pose_check(&p), OCC_OK);
    const occ_pose_t keep = pose(5, 5, 5, qyaw(1));
    const occ_quat_t zero = {0, 0, 0, 0}, nanq = {NAN, 0, 0, 1};
    p = keep;
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0), zero, &p), OCC_ERR_ARG);
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0), nanq, &p), OCC_ERR_ARG);
    assert_int_equal(occ_pose_from_ned(v3(NAN, 0, 0), scaled, &p), OCC_ERR_ARG);
    assert_int_equal(occ_pose_from_ned(v3(0, INFINITY, 0), scaled, &p), OCC_ERR_ARG);
    assert_true(SAME_BITS(p, keep));
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0), scaled, NULL), OCC_ERR_ARG);
    occ_vec3_t n;
    occ_quat_t q;
    assert_int_equal(occ_pose_to_ned(NULL, &n, &q), OCC_ERR_ARG);
    assert_int_equal(occ_pose_to_ned(&keep, NULL, &q), OCC_ERR_ARG);
    assert_int_equal(occ_pose_to_ned(&keep, &n, NULL), OCC_ERR_ARG);
    occ_pose_t bad = keep;
    bad.q.w = 3.0f;
    assert_int_equal(occ_pose_to_ned(&bad, &n, &q), OCC_ERR_ARG);
}

/* The yaw is the heading of the body x axis: roll and pitch do not change it. */
static void test_yaw_with_roll_pitch(void **state)
{
    (void)state;
    const double rolls[4] = {0, 0.4, -1.2, 2.9}, pitches[4] = {0, 0.3, -0.7, 1.4};
    const double yaws[4] = {0, 1.0, -2.5, 3.1};
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j < 4; j++) {
            for (int k = 0; k < 4; k++) {
                const occ_pose_t p = pose(0, 0, 0, occ_quat_from_euler((float)rolls[i],
                                                                       (float)pitches[j],
                                                                       (float)yaws[k]));
                near_angle(occ_pose_yaw(&p), yaws[k], 2e-6, "yaw of rolled / pitched pose");
                const occ_vec3_t f = occ_pose_rotate(&p, v3(1, 0, 0));
                near_angle(occ_pose_yaw(&p), atan2(f.y, f.x), 2e-6, "heading of body x");
            }
        }
    }
    occ_pose_t p;
    assert_int_equal(occ_pose_from_ned(v3(0, 0, 0),
                                       occ_quat_from_euler((float)(20 * DEG), (float)(10 * DEG),
                                                           (float)(45 * DEG)), &p), OCC_OK);
    near(occ_pose_yaw(&p), 45 * DEG, 1e-6, "NED heading 45, rolled and pitched -> ENU 45");
}

static void test_interpolate_hand(void **state)
{
    (void)state;
    const occ_pose_t a = pose(0, 0, 0, occ_quat_identity());
    const occ_pose_t b = pose(4, 8, -4, qyaw(PI / 2));
    const double s[5] = {0, 0.25, 0.5, 1, 1.5};
    for (int i = 0; i < 5; i++) {
        const occ_pose_t r = occ_pose_interpolate(&a, &b, (float)s[i]);
        near3(r.p, 4 * s[i], 8 * s[i], -4 * s[i], 1e-6, "lerp position");
        same_rot(r.q, qyaw(s[i] * PI / 2), 1e-7, "slerp yaw");
        assert_int_equal(occ_pose_check(&r), OCC_OK);
    }
    /* b given as -q: the same rotation, the same (short) path. */
    occ_pose_t bn = b;
    bn.q.w = -b.q.w, bn.q.z = -b.q.z;
    same_rot(occ_pose_interpolate(&a, &bn, 0.5f).q, qyaw(PI / 4), 1e-7, "slerp from -q");
    /* 170 deg to -170 deg: through 180 (20 deg), not through 0 (340 deg). */
    const occ_pose_t c = pose(0, 0, 0, qyaw(170 * DEG)), d = pose(0, 0, 0, qyaw(-170 * DEG));
    near_angle(occ_pose_yaw(&(occ_pose_t){c.p, occ_pose_interpolate(&c, &d, 0.5f).q}), PI, 1e-6,
               "shortest arc across +-180");
    near_angle(occ_pose_yaw(&(occ_pose_t){c.p, occ_pose_interpolate(&c, &d, 0.25f).q}),
               175 * DEG, 1e-6, "shortest arc, quarter");
    /* About another axis, from a non-identity start: roll 10 -> 70 at 1/4 is roll 25. */
    const occ_pose_t e = pose(0, 0, 0, occ_quat_from_euler((float)(10 * DEG), 0, 0));
    const occ_pose_t f = pose(0, 0, 0, occ_quat_from_euler((float)(70 * DEG), 0, 0));
    same_rot(occ_pose_interpolate(&e, &f, 0.25f).q, occ_quat_from_euler((float)(25 * DEG), 0, 0),
             1e-7, "roll slerp");
    /* Extrapolating a small turn far: 1 deg per step, 30 steps = 30 deg. */
    const occ_pose_t g = pose(0, 0, 0, qyaw(1 * DEG));
    same_rot(occ_pose_interpolate(&a, &g, 30.0f).q, qyaw(30 * DEG), 1e-7, "extrapolate small turn");
    same_rot(occ_pose_interpolate(&a, &a, 0.7f).q, occ_quat_identity(), 0.0, "equal rotations");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_apply_rotate),
        cmocka_unit_test(test_compose_invert_hand),
        cmocka_unit_test(test_compose_invert_random),
        cmocka_unit_test(test_euler_hand),
        cmocka_unit_test(test_euler_round_trip),
        cmocka_unit_test(test_euler_gimbal),
        cmocka_unit_test(test_euler_yaw_wrap),
        cmocka_unit_test(test_axis_angle),
        cmocka_unit_test(test_normalize),
        cmocka_unit_test(test_pose_check),
        cmocka_unit_test(test_ned_headings),
        cmocka_unit_test(test_ned_pitch_roll),
        cmocka_unit_test(test_ned_round_trip_refusals),
        cmocka_unit_test(test_yaw_with_roll_pitch),
        cmocka_unit_test(test_interpolate_hand),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
