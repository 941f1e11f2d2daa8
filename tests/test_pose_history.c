/* SPDX-License-Identifier: BSD-3-Clause */
/* test_pose_history.c - the timed pose history (occ_pose.h, src/sensors/pose_history.c) against
 * hand-computed values: init refusals, pushes out of order / duplicate / bad (counted, the
 * history unchanged), the ring dropping its oldest, exact sample times, interpolation between
 * the bracketing samples, every refusal with its counter and `why`, and extrapolation. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occ_pose.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define SAME_BITS(a, b) (memcmp(&(a), &(b), sizeof(a)) == 0)
/* A real clock: microseconds since 1970 (float fractions must come from differences). */
#define T0 1700000000000000ull

static void near(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) {
        fail_msg("%s: got %.9g, want %.9g (tol %g)", what, got, want, tol);
    }
}

/* A pose at (x, y, z) turned by yaw about z (map ENU). */
static occ_pose_t yaw_pose(double x, double y, double z, double yaw)
{
    occ_pose_t p;
    p.p.x = (float)x;
    p.p.y = (float)y;
    p.p.z = (float)z;
    p.q.w = (float)cos(0.5 * yaw);
    p.q.x = 0.0f;
    p.q.y = 0.0f;
    p.q.z = (float)sin(0.5 * yaw);
    return p;
}

static void pose_near(const occ_pose_t *got, double x, double y, double z, double yaw,
                      const char *what)
{
    near(got->p.x, x, 1e-5, what);
    near(got->p.y, y, 1e-5, what);
    near(got->p.z, z, 1e-5, what);
    near(occ_pose_yaw(got), yaw, 1e-6, what);
    assert_int_equal(occ_pose_check(got), OCC_OK);
}

static occ_pose_sample_t ring[8];
static occ_pose_history_t h;

static void init(size_t cap, uint64_t max_gap_us, uint64_t max_extrapolate_us)
{
    const occ_pose_history_cfg_t cfg = {max_gap_us, max_extrapolate_us};
    assert_int_equal(occ_pose_history_init(&h, ring, cap, &cfg), OCC_OK);
}

static void push(uint64_t t_us, double x, double yaw)
{
    const occ_pose_t p = yaw_pose(x, -2.0 * x, 0.5 * x, yaw);
    assert_int_equal(occ_pose_history_push(&h, t_us, &p), OCC_OK);
}

/* at() refuses with `want`: OCC_ERR_TIME, `why` set, its counter up by one, *out untouched. */
static void refused(uint64_t t_us, occ_pose_refusal_t want)
{
    const uint32_t before = h.refused[want];
    const occ_pose_t keep = yaw_pose(99, 99, 99, 1);
    occ_pose_t out = keep;
    occ_pose_refusal_t why = OCC_POSE_OK;
    assert_int_equal(occ_pose_history_at(&h, t_us, &out, &why), OCC_ERR_TIME);
    assert_int_equal(why, want);
    assert_int_equal(h.refused[want], before + 1u);
    assert_true(SAME_BITS(out, keep));
}

static occ_pose_t at(uint64_t t_us)
{
    occ_pose_t out;
    occ_pose_refusal_t why = OCC_POSE_EMPTY;
    assert_int_equal(occ_pose_history_at(&h, t_us, &out, &why), OCC_OK);
    assert_int_equal(why, OCC_POSE_OK);
    return out;
}

static void test_init_refusals(void **state)
{
    (void)state;
    const occ_pose_history_cfg_t ok = {1000u, 0u}, no_gap = {0u, 500u};
    assert_int_equal(occ_pose_history_init(NULL, ring, 8, &ok), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_init(&h, NULL, 8, &ok), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_init(&h, ring, 8, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_init(&h, ring, 0, &ok), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_init(&h, ring, 1, &ok), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_init(&h, ring, 8, &no_gap), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_init(&h, ring, 2, &ok), OCC_OK);
    assert_int_equal(occ_pose_history_count(&h), 0);
    assert_int_equal(occ_pose_history_count(NULL), 0);
    uint64_t a = 7, b = 7;
    assert_int_equal(occ_pose_history_span(&h, &a, &b), OCC_ERR_STATE);
    assert_true(a == 7u && b == 7u);
    assert_int_equal(occ_pose_history_span(NULL, &a, &b), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_span(&h, NULL, &b), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_span(&h, &a, NULL), OCC_ERR_ARG);
    /* Re-init clears counters and samples. */
    push(T0, 1, 0);
    assert_int_equal(occ_pose_history_init(&h, ring, 2, &ok), OCC_OK);
    assert_int_equal(occ_pose_history_count(&h), 0);
    assert_int_equal(h.pushed, 0);
}

static void test_push_refusals(void **state)
{
    (void)state;
    init(8, 1000000u, 0u);
    push(T0 + 100, 1, 0.1);
    push(T0 + 200, 2, 0.2);
    const occ_pose_t p = yaw_pose(5, 5, 5, 0.5);
    assert_int_equal(occ_pose_history_push(&h, T0 + 200, &p), OCC_ERR_TIME); /* duplicate */
    assert_int_equal(occ_pose_history_push(&h, T0 + 150, &p), OCC_ERR_TIME); /* out of order */
    assert_int_equal(occ_pose_history_push(&h, 0, &p), OCC_ERR_TIME);
    assert_int_equal(h.rejected_order, 3);
    occ_pose_t bad = p;
    bad.p.z = NAN;
    assert_int_equal(occ_pose_history_push(&h, T0 + 300, &bad), OCC_ERR_ARG);
    bad = p;
    bad.q.w = 2.0f; /* |q| = 2.03: not a rotation */
    assert_int_equal(occ_pose_history_push(&h, T0 + 300, &bad), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_push(&h, T0 + 300, NULL), OCC_ERR_ARG);
    assert_int_equal(h.rejected_bad, 3);
    assert_int_equal(occ_pose_history_push(NULL, T0 + 300, &p), OCC_ERR_ARG);
    /* Unchanged: two samples, the newest still the one at 200. */
    assert_int_equal(h.pushed, 2);
    assert_int_equal(h.rejected_order, 3);
    assert_int_equal(occ_pose_history_count(&h), 2);
    uint64_t a, b;
    assert_int_equal(occ_pose_history_span(&h, &a, &b), OCC_OK);
    assert_true(a == T0 + 100 && b == T0 + 200);
    const occ_pose_t newest = at(T0 + 200);
    pose_near(&newest, 2, -4, 1, 0.2, "newest unchanged");
    /* A bad pose is refused before its time is looked at. */
    assert_int_equal(occ_pose_history_push(&h, T0, NULL), OCC_ERR_ARG);
    assert_int_equal(h.rejected_bad, 4);
    assert_int_equal(h.rejected_order, 3);
}

static void test_ring_wrap(void **state)
{
    (void)state;
    init(4, 1000000u, 0u);
    for (unsigned i = 1; i <= 10; i++) {
        push(T0 + i * 1000u, (double)i, 0.1 * i);
        assert_int_equal(occ_pose_history_count(&h), i < 4u ? i : 4u);
    }
    assert_int_equal(h.pushed, 10);
    uint64_t a, b;
    assert_int_equal(occ_pose_history_span(&h, &a, &b), OCC_OK);
    assert_true(a == T0 + 7000 && b == T0 + 10000);
    refused(T0 + 6999, OCC_POSE_TOO_OLD); /* held once, dropped when the ring filled */
    refused(T0 + 1000, OCC_POSE_TOO_OLD);
    for (unsigned i = 7; i <= 10; i++) {
        const occ_pose_t p = at(T0 + i * 1000u);
        pose_near(&p, i, -2.0 * i, 0.5 * i, 0.1 * i, "kept sample");
    }
    const occ_pose_t mid = at(T0 + 8500);
    pose_near(&mid, 8.5, -17, 4.25, 0.85, "between wrapped samples");
}

static void test_exact_and_between(void **state)
{
    (void)state;
    init(8, 1000000u, 0u);
    occ_pose_t a = yaw_pose(0, 0, 0, 0), b = yaw_pose(10, -20, 5, PI / 2);
    assert_int_equal(occ_pose_history_push(&h, T0 + 1000, &a), OCC_OK);
    assert_int_equal(occ_pose_history_push(&h, T0 + 2000, &b), OCC_OK);
    push(T0 + 3000, 0, 0);
    const occ_pose_t e0 = at(T0 + 1000), e1 = at(T0 + 2000);
    assert_true(SAME_BITS(e0, a));
    assert_true(SAME_BITS(e1, b));
    const occ_pose_t q1 = at(T0 + 1250), q2 = at(T0 + 1500), q3 = at(T0 + 1999);
    pose_near(&q1, 2.5, -5, 1.25, 22.5 * DEG, "1/4");
    pose_near(&q2, 5, -10, 2.5, 45 * DEG, "1/2");
    pose_near(&q3, 9.99, -19.98, 4.995, 89.91 * DEG, "999/1000");
    /* Between 2000 and 3000, the second segment: back to 0. */
    const occ_pose_t q4 = at(T0 + 2750);
    pose_near(&q4, 2.5, -5, 1.25, 22.5 * DEG, "second segment, 3/4");
    /* The same rotation stored as -q: still the short way. */
    init(8, 1000000u, 0u);
    a = yaw_pose(0, 0, 0, 170 * DEG);
    b = yaw_pose(0, 0, 0, -170 * DEG);
    b.q.w = -b.q.w, b.q.z = -b.q.z;
    assert_int_equal(occ_pose_history_push(&h, T0, &a), OCC_OK);
    assert_int_equal(occ_pose_history_push(&h, T0 + 400, &b), OCC_OK);
    const occ_pose_t s = at(T0 + 100);
    near(occ_pose_yaw(&s), 175 * DEG, 1e-6, "shortest arc, q and -q");
}

static void test_refusals(void **state)
{
    (void)state;
    init(8, 5000u, 500u);
    refused(T0, OCC_POSE_EMPTY);
    refused(0, OCC_POSE_EMPTY);
    push(T0 + 1000, 1, 0);
    push(T0 + 2000, 2, 0);
    push(T0 + 10000, 3, 0); /* 8 ms after 2000: beyond max_gap_us */
    refused(T0 + 999, OCC_POSE_TOO_OLD);
    refused(T0 + 2001, OCC_POSE_GAP);
    refused(T0 + 9999, OCC_POSE_GAP);
    refused(T0 + 10501, OCC_POSE_TOO_NEW);
    refused(UINT64_MAX, OCC_POSE_TOO_NEW);
    /* Each counter counted its own refusals only. */
    assert_int_equal(h.refused[OCC_POSE_OK], 0);
    assert_int_equal(h.refused[OCC_POSE_EMPTY], 2);
    assert_int_equal(h.refused[OCC_POSE_TOO_OLD], 1);
    assert_int_equal(h.refused[OCC_POSE_GAP], 2);
    assert_int_equal(h.refused[OCC_POSE_TOO_NEW], 2);
    /* The samples at the gap's ends are exact, the gap's edges and 500 us past the newest too. */
    const occ_pose_t g0 = at(T0 + 2000), g1 = at(T0 + 10000), last = at(T0 + 10500);
    pose_near(&g0, 2, -4, 1, 0, "gap start");
    pose_near(&g1, 3, -6, 1.5, 0, "gap end");
    pose_near(&last, 3, -6, 1.5, 0, "extrapolation limit: the newest held (gap before it)");
    /* A gap exactly max_gap_us wide still interpolates. */
    push(T0 + 15000, 4, 0);
    const occ_pose_t m = at(T0 + 12500);
    pose_near(&m, 3.5, -7, 1.75, 0, "gap == max_gap_us");
    /* NULL h / out: OCC_ERR_ARG, nothing counted; why may be NULL. */
    occ_pose_t out;
    assert_int_equal(occ_pose_history_at(NULL, T0, &out, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_at(&h, T0 + 1000, NULL, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_pose_history_at(&h, T0 + 1000, &out, NULL), OCC_OK);
    assert_int_equal(occ_pose_history_at(&h, T0, &out, NULL), OCC_ERR_TIME);
    assert_int_equal(h.refused[OCC_POSE_TOO_OLD], 2);
}

static void test_extrapolation(void **state)
{
    (void)state;
    init(8, 5000u, 500u);
    push(T0 + 1000, 1, 0); /* one sample: held */
    const occ_pose_t one = at(T0 + 1400);
    pose_near(&one, 1, -2, 0.5, 0, "single sample held");
    push(T0 + 2000, 2, 10 * DEG);
    /* The last two samples' motion continued: +1 m and +10 deg per ms. */
    const occ_pose_t e = at(T0 + 2500);
    pose_near(&e, 2.5, -5, 1.25, 15 * DEG, "extrapolated half a step");
    const occ_pose_t e2 = at(T0 + 2100);
    pose_near(&e2, 2.1, -4.2, 1.05, 11 * DEG, "extrapolated a tenth");
    refused(T0 + 2501, OCC_POSE_TOO_NEW);
    /* No extrapolation allowed: exactly the newest time only. */
    init(8, 5000u, 0u);
    push(T0 + 1000, 1, 0);
    push(T0 + 2000, 2, 0);
    (void)at(T0 + 2000);
    refused(T0 + 2001, OCC_POSE_TOO_NEW);
    /* The last two a gap apart: the newest held. */
    init(8, 5000u, 500u);
    push(T0 + 1000, 1, 0);
    push(T0 + 7000, 7, 1.0);
    const occ_pose_t held = at(T0 + 7300);
    pose_near(&held, 7, -14, 3.5, 1.0, "newest held after a gap");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_refusals),
        cmocka_unit_test(test_push_refusals),
        cmocka_unit_test(test_ring_wrap),
        cmocka_unit_test(test_exact_and_between),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_extrapolation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
