/* SPDX-License-Identifier: BSD-3-Clause */
/* test_run_mavlink.c - the MAVLink parts of `occmap run` (occ_mavlink_run.h): the TIMESYNC
 * offset against hand-computed values (min-RTT sample of the window, refusals), the codecs
 * through the parser, and the pose receiver's filter (another system or component ignored,
 * pairing tolerance, stamps on the autopilot's clock, not-newer and bad poses refused). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occ_mavlink_run.h"
#include "ardupilotmega/mavlink.h"

/* Parse one whole frame (as built by finalize / an encoder) into f; the parser is static so the
 * payload pointer stays valid until the next call. */
static occ_mav_frame_t parse(const uint8_t *buf, size_t n)
{
    static occ_mav_parser_t p;
    occ_mav_frame_t f;
    occ_mav_parser_init(&p);
    occ_mav_result_t r = OCC_MAV_NONE;
    for (size_t i = 0; i < n; i++) {
        r = occ_mav_parser_push(&p, buf[i], &f);
    }
    assert_int_equal(r, OCC_MAV_OK);
    return f;
}

/* A reply to a request sent at local `sent_us`, stamped remote_us by the autopilot. */
static occ_mav_timesync_t reply(uint64_t sent_us, int64_t remote_us)
{
    occ_mav_timesync_t m = occ_timesync_request(sent_us);
    m.tc1 = remote_us * 1000;
    return m;
}

static void test_timesync_offset(void **state)
{
    (void)state;
    occ_timesync_t ts;
    assert_int_equal(occ_timesync_init(&ts, 500000u), OCC_OK);
    assert_false(ts.valid);
    /* sent 1.000 s, answered 5.000 s, back 1.010 s: offset 5.000 - 1.005 = 3.995 s, rtt 10 ms */
    occ_mav_timesync_t m = reply(1000000u, 5000000);
    assert_int_equal(occ_timesync_take(&ts, &m, 1010000u), OCC_OK);
    assert_true(ts.valid);
    assert_true(ts.offset_us == 3995000);
    assert_int_equal(ts.rtt_us, 10000u);
    /* a slower round trip (40 ms, offset 6.030 - 2.020 = 4.010 s) does not replace it */
    m = reply(2000000u, 6030000);
    assert_int_equal(occ_timesync_take(&ts, &m, 2040000u), OCC_OK);
    assert_true(ts.offset_us == 3995000);
    /* a faster one (4 ms: 6.9975 - 3.002 = 3.9955 s) does */
    m = reply(3000000u, 6997500);
    assert_int_equal(occ_timesync_take(&ts, &m, 3004000u), OCC_OK);
    assert_true(ts.offset_us == 3995500);
    assert_int_equal(ts.rtt_us, 4000u);
    assert_int_equal(ts.accepted, 3u);
    /* refused, offset unchanged: not a reply (tc1 0), from the future, older than max rtt */
    m = occ_timesync_request(3100000u);
    assert_int_equal(occ_timesync_take(&ts, &m, 3100000u), OCC_ERR_TIME);
    m = reply(9000000u, 7000000);
    assert_int_equal(occ_timesync_take(&ts, &m, 3100000u), OCC_ERR_TIME);
    m = reply(100000u, 7000000);
    assert_int_equal(occ_timesync_take(&ts, &m, 3100000u), OCC_ERR_TIME);
    assert_int_equal(ts.refused, 3u);
    assert_true(ts.offset_us == 3995500);
    /* eight 20 ms replies push the 4 ms sample out of the window: 10.020 - 4.010 = 6.010 s */
    for (unsigned i = 0; i < OCC_TIMESYNC_WINDOW; i++) {
        const uint64_t sent = 4000000u + 100000u * i;
        m = reply(sent, (int64_t)sent + 6010000 + 10000);
        assert_int_equal(occ_timesync_take(&ts, &m, sent + 20000u), OCC_OK);
    }
    assert_true(ts.offset_us == 6010000);
    assert_int_equal(ts.rtt_us, 20000u);
    assert_int_equal(occ_timesync_take(NULL, &m, 0), OCC_ERR_ARG);
    assert_int_equal(occ_timesync_init(&ts, 0), OCC_ERR_ARG);
}

static void test_codecs(void **state)
{
    (void)state;
    occ_mav_sender_t tx = {1, 196, 0};
    uint8_t buf[OCC_MAV_FRAME_MAX];
    const occ_mav_timesync_t q = {-5, 1234567890123};
    size_t n = occ_mav_encode_timesync(&tx, &q, buf, sizeof buf);
    assert_true(n > 0u);
    occ_mav_frame_t f = parse(buf, n);
    occ_mav_timesync_t d;
    assert_int_equal(occ_mav_decode_timesync(&f, &d), OCC_OK);
    assert_true(d.tc1 == -5 && d.ts1 == 1234567890123);
    assert_int_equal(f.sysid, 1u);
    assert_int_equal(f.compid, 196u);
    /* STATUSTEXT: severity, text cut at 50 bytes */
    const char *const long_text = "occmap: pose stale, obstacle data stopped 0123456789ABCDEF";
    n = occ_mav_encode_statustext(&tx, OCC_MAV_SEVERITY_WARNING, long_text, buf, sizeof buf);
    f = parse(buf, n);
    assert_int_equal(f.msgid, OCC_MAV_MSG_STATUSTEXT);
    mavlink_statustext_t s;
    memset(&s, 0, sizeof s);
    memcpy(&s, f.payload, f.len);
    assert_int_equal(s.severity, 4u);
    assert_memory_equal(s.text, long_text, 50);
    assert_int_equal(occ_mav_decode_timesync(&f, &d), OCC_ERR_ARG); /* another message */
    assert_int_equal(occ_mav_encode_statustext(&tx, 4u, NULL, buf, sizeof buf), 0u);
}

static occ_mav_sender_t ap = {1, 1, 0};

static occ_mav_frame_t pos_frame(uint8_t sysid, uint8_t compid, uint32_t ms, float n, float e,
                                 float d, uint8_t *buf)
{
    mavlink_local_position_ned_t lp;
    memset(&lp, 0, sizeof lp);
    lp.time_boot_ms = ms;
    lp.x = n, lp.y = e, lp.z = d;
    occ_mav_sender_t tx = {sysid, compid, 0};
    const size_t len = occ_mav_finalize(&tx, MAVLINK_MSG_ID_LOCAL_POSITION_NED,
                                        (const uint8_t *)&lp, sizeof lp, buf, OCC_MAV_FRAME_MAX);
    return parse(buf, len);
}

static occ_mav_frame_t att_frame(uint8_t sysid, uint8_t compid, uint32_t ms, float yaw,
                                 uint8_t *buf)
{
    mavlink_attitude_t a;
    memset(&a, 0, sizeof a);
    a.time_boot_ms = ms;
    a.yaw = yaw;
    occ_mav_sender_t tx = {sysid, compid, 0};
    const size_t len = occ_mav_finalize(&tx, MAVLINK_MSG_ID_ATTITUDE, (const uint8_t *)&a,
                                        sizeof a, buf, OCC_MAV_FRAME_MAX);
    return parse(buf, len);
}

/* ATTITUDE_QUATERNION of the autopilot: q = w, x, y, z (body FRD -> local NED). */
static occ_mav_frame_t attq_frame(uint32_t ms, const float q[4], uint8_t *buf)
{
    mavlink_attitude_quaternion_t a;
    memset(&a, 0, sizeof a);
    a.time_boot_ms = ms;
    a.q1 = q[0], a.q2 = q[1], a.q3 = q[2], a.q4 = q[3];
    const size_t len = occ_mav_finalize(&ap, MAVLINK_MSG_ID_ATTITUDE_QUATERNION,
                                        (const uint8_t *)&a, MAVLINK_MSG_ID_ATTITUDE_QUATERNION_LEN,
                                        buf, OCC_MAV_FRAME_MAX);
    return parse(buf, len);
}

/* ODOMETRY of the autopilot in MAV_FRAME_LOCAL_NED (1): position NED, q body FRD -> NED. */
static occ_mav_frame_t odom_frame(uint64_t usec, float n, float e, float d, const float q[4],
                                  uint8_t *buf)
{
    mavlink_odometry_t o;
    memset(&o, 0, sizeof o);
    o.time_usec = usec;
    o.frame_id = 1;
    o.x = n, o.y = e, o.z = d;
    memcpy(o.q, q, sizeof o.q);
    const size_t len = occ_mav_finalize(&ap, MAVLINK_MSG_ID_ODOMETRY, (const uint8_t *)&o,
                                        MAVLINK_MSG_ID_ODOMETRY_LEN, buf, OCC_MAV_FRAME_MAX);
    return parse(buf, len);
}

static void test_pose_filter(void **state)
{
    (void)state;
    (void)ap;
    occ_mav_pose_rx_t rx;
    occ_mav_pose_rx_config_t cfg = occ_mav_pose_rx_config_default();
    assert_int_equal(occ_mav_pose_rx_init(&rx, &cfg), OCC_OK);
    uint8_t buf[OCC_MAV_FRAME_MAX];
    occ_pose_sample_t s;
    /* another system's position and attitude, then another component of ours: ignored */
    occ_mav_frame_t f = pos_frame(2, 1, 1000, 9.0f, 9.0f, 9.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    f = att_frame(2, 1, 1000, 1.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    f = pos_frame(1, 2, 1000, 9.0f, 9.0f, 9.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    assert_int_equal(rx.counters.foreign, 3u);
    assert_int_equal(rx.counters.positions, 0u);
    /* the autopilot: NED (1, 2, -3) at 1.000 s, heading north level at 1.010 s -> one pose at
     * 1.010 s: ENU (2, 1, 3), body x along north = ENU yaw +90 deg: q = (cos 45, 0, 0, sin 45) */
    f = pos_frame(1, 1, 1000, 1.0f, 2.0f, -3.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    f = att_frame(1, 1, 1010, 0.0f, buf);
    assert_true(occ_mav_pose_rx_take(&rx, &f, &s));
    assert_true(s.t_us == 1010000u);
    assert_float_equal(s.pose.p.x, 2.0f, 1e-6f);
    assert_float_equal(s.pose.p.y, 1.0f, 1e-6f);
    assert_float_equal(s.pose.p.z, 3.0f, 1e-6f);
    const float sg = s.pose.q.w < 0.0f ? -1.0f : 1.0f; /* q and -q: the same rotation */
    assert_float_equal(sg * s.pose.q.w, 0.70710678f, 1e-6f);
    assert_float_equal(sg * s.pose.q.x, 0.0f, 1e-6f);
    assert_float_equal(sg * s.pose.q.y, 0.0f, 1e-6f);
    assert_float_equal(sg * s.pose.q.z, 0.70710678f, 1e-6f);
    /* the foreign position sent meanwhile did not replace ours (next pose keeps 2, 1, 3) */
    f = pos_frame(2, 1, 1020, 50.0f, 50.0f, 50.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    /* an attitude whose position is in the last pose already waits for its own position */
    f = att_frame(1, 1, 1015, 0.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    f = pos_frame(1, 1, 1020, 1.0f, 2.0f, -3.0f, buf);
    assert_true(occ_mav_pose_rx_take(&rx, &f, &s));
    assert_true(s.t_us == 1020000u);
    assert_float_equal(s.pose.p.x, 2.0f, 1e-6f);
    f = att_frame(1, 1, 1020, 0.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s)); /* its position is in that pose */
    f = pos_frame(1, 1, 1030, 1.0f, 2.0f, -3.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    f = att_frame(1, 1, 1030, 0.0f, buf);
    assert_true(occ_mav_pose_rx_take(&rx, &f, &s));
    assert_true(s.t_us == 1030000u);
    assert_float_equal(s.pose.p.x, 2.0f, 1e-6f);
    /* the same stamp again: not newer; an attitude 100 ms from the position: no pose. Replaced
     * without ever making a pose (unpaired): the 1020 attitude (by 1030's) and the repeated
     * 1030 one (by 1130's); 1130's itself counts only once something replaces it */
    f = att_frame(1, 1, 1030, 0.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    f = att_frame(1, 1, 1130, 0.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    assert_int_equal(rx.counters.unpaired, 2u);
    /* a NaN position is refused and does not become the position */
    f = pos_frame(1, 1, 1130, NAN, 0.0f, 0.0f, buf);
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    assert_int_equal(rx.counters.bad, 1u);
    assert_int_equal(rx.counters.poses, 3u);
    assert_int_equal(rx.counters.positions, 3u);
    assert_int_equal(rx.counters.attitudes, 6u);
}

/* Take one frame of the autopilot; true when it completed a pose (its stamp in *t_us). */
static bool take(occ_mav_pose_rx_t *rx, occ_mav_frame_t f, uint64_t *t_us)
{
    occ_pose_sample_t s;
    const bool got = occ_mav_pose_rx_take(rx, &f, &s);
    *t_us = got ? s.t_us : 0u;
    return got;
}

/* unpaired counts a position or attitude replaced by a newer one without ever having made a
 * pose: a 33 ms stream (beyond the 25 ms tolerance from the previous partner) whose position
 * comes before its attitude, or the other way round, pairs a moment later and is not counted. */
static void test_pose_unpaired(void **state)
{
    (void)state;
    occ_mav_pose_rx_t rx;
    const occ_mav_pose_rx_config_t cfg = occ_mav_pose_rx_config_default();
    assert_int_equal(occ_mav_pose_rx_init(&rx, &cfg), OCC_OK);
    uint8_t buf[OCC_MAV_FRAME_MAX];
    uint64_t t = 0;
    const float level[4] = {1.0f, 0.0f, 0.0f, 0.0f};
    /* position first, then attitude, every 33 ms: three poses, nothing unpaired */
    for (uint32_t ms = 1000; ms <= 1066; ms += 33) {
        assert_false(take(&rx, pos_frame(1, 1, ms, 0.0f, 0.0f, 0.0f, buf), &t));
        assert_true(take(&rx, att_frame(1, 1, ms, 0.0f, buf), &t));
        assert_true(t == (uint64_t)ms * 1000u);
    }
    /* attitude first (34 ms after the last position), then its position: a pose */
    assert_false(take(&rx, att_frame(1, 1, 1100, 0.0f, buf), &t));
    assert_true(take(&rx, pos_frame(1, 1, 1100, 0.0f, 0.0f, 0.0f, buf), &t));
    assert_int_equal(rx.counters.unpaired, 0u);
    /* a position that never pairs (replaced 33 ms later): one */
    assert_false(take(&rx, pos_frame(1, 1, 1200, 0.0f, 0.0f, 0.0f, buf), &t));
    assert_false(take(&rx, pos_frame(1, 1, 1233, 0.0f, 0.0f, 0.0f, buf), &t));
    assert_int_equal(rx.counters.unpaired, 1u);
    assert_true(take(&rx, attq_frame(1233, level, buf), &t));
    /* an attitude that never pairs (replaced by the next): two */
    assert_false(take(&rx, attq_frame(1300, level, buf), &t));
    assert_false(take(&rx, attq_frame(1400, level, buf), &t));
    assert_true(take(&rx, pos_frame(1, 1, 1400, 0.0f, 0.0f, 0.0f, buf), &t));
    assert_int_equal(rx.counters.unpaired, 2u);
    /* ODOMETRY replaces both parts: the lone position before it counts, the paired attitude
     * does not; ODOMETRY itself is a pose */
    assert_false(take(&rx, pos_frame(1, 1, 1500, 0.0f, 0.0f, 0.0f, buf), &t));
    assert_true(take(&rx, odom_frame(1600000u, 0.0f, 0.0f, 0.0f, level, buf), &t));
    assert_true(t == 1600000u);
    assert_int_equal(rx.counters.unpaired, 3u);
    assert_int_equal(rx.counters.poses, 7u);
}

/* A pose completed by the receiver, pushed into the history (as `occmap run` does). */
static void take_push(occ_mav_pose_rx_t *rx, occ_pose_history_t *h, occ_mav_frame_t f,
                      uint64_t want_t_us)
{
    occ_pose_sample_t s;
    assert_true(occ_mav_pose_rx_take(rx, &f, &s));
    assert_true(s.t_us == want_t_us);
    assert_int_equal(occ_pose_history_push(h, s.t_us, &s.pose), OCC_OK);
}

/* The history's pose at t: position, and where the body's forward (FLU x) and left (y) axes
 * point in the ENU map. */
static void expect_at(occ_pose_history_t *h, uint64_t t_us, occ_vec3_t p, occ_vec3_t fwd,
                      occ_vec3_t left)
{
    occ_pose_t pose;
    assert_int_equal(occ_pose_history_at(h, t_us, &pose, NULL), OCC_OK);
    const occ_vec3_t f = occ_pose_rotate(&pose, (occ_vec3_t){1.0f, 0.0f, 0.0f});
    const occ_vec3_t l = occ_pose_rotate(&pose, (occ_vec3_t){0.0f, 1.0f, 0.0f});
    const float got[9] = {pose.p.x, pose.p.y, pose.p.z, f.x, f.y, f.z, l.x, l.y, l.z};
    const float want[9] = {p.x, p.y, p.z, fwd.x, fwd.y, fwd.z, left.x, left.y, left.z};
    for (unsigned i = 0; i < 9u; i++) {
        assert_float_equal(got[i], want[i], 1e-5f);
    }
}

/* ATTITUDE_QUATERNION (+ LOCAL_POSITION_NED) and ODOMETRY through the receiver into a pose
 * history, read back at and between the samples against hand-computed poses. NED heading h
 * is ENU yaw 90 deg - h; NED (n, e, d) is ENU (e, n, -d). */
static void test_pose_history_feed(void **state)
{
    (void)state;
    occ_mav_pose_rx_t rx;
    const occ_mav_pose_rx_config_t cfg = occ_mav_pose_rx_config_default();
    assert_int_equal(occ_mav_pose_rx_init(&rx, &cfg), OCC_OK);
    occ_pose_sample_t ring[8];
    const occ_pose_history_cfg_t hc = {100000u, 0u};
    occ_pose_history_t h;
    assert_int_equal(occ_pose_history_init(&h, ring, 8, &hc), OCC_OK);
    uint8_t buf[OCC_MAV_FRAME_MAX];
    const float c15 = 0.96592583f, s15 = 0.25881905f, c45 = 0.70710678f;
    const float c30 = 0.86602540f;
    /* 1.000 s: NED (1, 2, -3), heading 30 deg (q = cos 15, 0, 0, sin 15) -> ENU (2, 1, 3),
     * yaw 60 deg: forward (cos 60, sin 60, 0), left (-sin 60, cos 60, 0) */
    occ_mav_frame_t f = pos_frame(1, 1, 1000, 1.0f, 2.0f, -3.0f, buf);
    occ_pose_sample_t s;
    assert_false(occ_mav_pose_rx_take(&rx, &f, &s));
    const float qa[4] = {c15, 0.0f, 0.0f, s15};
    take_push(&rx, &h, attq_frame(1000, qa, buf), 1000000u);
    /* 1.080 s, ODOMETRY: NED (1, 4, -3), heading 90 deg (east) -> ENU (4, 1, 3), yaw 0 */
    const float qb[4] = {c45, 0.0f, 0.0f, c45};
    take_push(&rx, &h, odom_frame(1080000u, 1.0f, 4.0f, -3.0f, qb, buf), 1080000u);
    /* 1.160 s, ODOMETRY: the same place and heading, rolled 30 deg right (right wing down):
     * q = qz(90) qx(30); the left wing points north and up (0, cos 30, sin 30) */
    const float qc[4] = {c45 * c15, c45 * s15, c45 * s15, c45 * c15};
    take_push(&rx, &h, odom_frame(1160000u, 1.0f, 4.0f, -3.0f, qc, buf), 1160000u);
    expect_at(&h, 1000000u, (occ_vec3_t){2.0f, 1.0f, 3.0f}, (occ_vec3_t){0.5f, c30, 0.0f},
              (occ_vec3_t){-c30, 0.5f, 0.0f});
    /* halfway to the first ODOMETRY: (3, 1, 3), yaw 30 deg */
    expect_at(&h, 1040000u, (occ_vec3_t){3.0f, 1.0f, 3.0f}, (occ_vec3_t){c30, 0.5f, 0.0f},
              (occ_vec3_t){-0.5f, c30, 0.0f});
    expect_at(&h, 1080000u, (occ_vec3_t){4.0f, 1.0f, 3.0f}, (occ_vec3_t){1.0f, 0.0f, 0.0f},
              (occ_vec3_t){0.0f, 1.0f, 0.0f});
    /* a quarter of the way through the roll: 7.5 deg, left (0, cos 7.5, sin 7.5) */
    expect_at(&h, 1100000u, (occ_vec3_t){4.0f, 1.0f, 3.0f}, (occ_vec3_t){1.0f, 0.0f, 0.0f},
              (occ_vec3_t){0.0f, 0.99144486f, 0.13052619f});
    expect_at(&h, 1160000u, (occ_vec3_t){4.0f, 1.0f, 3.0f}, (occ_vec3_t){1.0f, 0.0f, 0.0f},
              (occ_vec3_t){0.0f, c30, 0.5f});
    assert_int_equal(rx.counters.poses, 3u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_timesync_offset),
        cmocka_unit_test(test_codecs),
        cmocka_unit_test(test_pose_filter),
        cmocka_unit_test(test_pose_unpaired),
        cmocka_unit_test(test_pose_history_feed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
