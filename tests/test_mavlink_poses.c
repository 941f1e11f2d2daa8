/* SPDX-License-Identifier: BSD-3-Clause */
/* test_mavlink_poses.c - which pose messages the MAVLink feed takes, message by message: each of
 * LOCAL_POSITION_NED, ATTITUDE, ATTITUDE_QUATERNION and ODOMETRY sets exactly its part of the
 * pose (read back through occ_mav_feed_pose in a NED map frame) and its counters; a message that
 * decodes but says something non-finite, or ODOMETRY in a frame that is not local, is ignored:
 * counted in ignored_rx, pose unchanged. Routing (whose poses): test_mavlink_feed.c. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occ_mavlink.h"
#include "ardupilotmega/mavlink.h"
#include "support/mav_frames.h"

static occ_mav_feed_t feed;
static occ_mav_sender_t ap = {1, 1, 0}; /* the configured autopilot */

static void feed_init(void)
{
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    cfg.autopilot_sysid = 1;
    cfg.autopilot_compid = 1;
    cfg.map_frame = OCC_MAP_FRAME_NED; /* the pose reads back as the autopilot sent it */
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
}

static void rx(uint32_t msgid, const void *payload, size_t len, uint64_t now_us)
{
    uint8_t buf[OCC_MAV_FRAME_MAX];
    const size_t n = occ_mav_finalize(&ap, msgid, (const uint8_t *)payload, len, buf, sizeof buf);
    assert_true(n > 0u);
    occ_mav_feed_rx(&feed, buf, n, now_us);
}

static void position(float n, float e, float d, uint64_t now_us)
{
    mavlink_local_position_ned_t m;
    memset(&m, 0, sizeof m);
    m.x = n;
    m.y = e;
    m.z = d;
    rx(MAVLINK_MSG_ID_LOCAL_POSITION_NED, &m, sizeof m, now_us);
}

static void attitude(float roll, float pitch, float yaw, uint64_t now_us)
{
    mavlink_attitude_t m;
    memset(&m, 0, sizeof m);
    m.roll = roll;
    m.pitch = pitch;
    m.yaw = yaw;
    rx(MAVLINK_MSG_ID_ATTITUDE, &m, sizeof m, now_us);
}

static void odometry(uint8_t frame, float n, float e, float d, const float q[4], uint64_t now_us)
{
    mavlink_odometry_t m;
    memset(&m, 0, sizeof m);
    m.frame_id = frame;
    m.x = n;
    m.y = e;
    m.z = d;
    memcpy(m.q, q, sizeof m.q);
    rx(MAVLINK_MSG_ID_ODOMETRY, &m, MAVLINK_MSG_ID_ODOMETRY_LEN, now_us); /* sizeof m has padding */
}

/* w, x, y, z of roll, pitch, yaw (ZYX, as MAVLink's attitude quaternions). */
static void quat_of(float roll, float pitch, float yaw, float q[4])
{
    const float cr = cosf(roll / 2), sr = sinf(roll / 2), cp = cosf(pitch / 2);
    const float sp = sinf(pitch / 2), cy = cosf(yaw / 2), sy = sinf(yaw / 2);
    q[0] = cr * cp * cy + sr * sp * sy;
    q[1] = sr * cp * cy - cr * sp * sy;
    q[2] = cr * sp * cy + sr * cp * sy;
    q[3] = cr * cp * sy - sr * sp * cy;
}

static void expect_pose(float n, float e, float d, float roll, float pitch, float yaw)
{
    occ_pose_t p;
    memset(&p, 0, sizeof p);
    assert_true(occ_mav_feed_pose(&feed, 1000000, &p)); /* NED map: NED <- FRD as sent */
    assert_true(feq(p.p.x, n) && feq(p.p.y, e) && feq(p.p.z, d));
    float r = 0.0f, pt = 0.0f, y = 0.0f;
    occ_quat_to_euler(p.q, &r, &pt, &y);
    /* the attitude went through a quaternion: equal to float rounding */
    assert_true(fabsf(r - roll) < 2e-6f && fabsf(pt - pitch) < 2e-6f && fabsf(y - yaw) < 2e-6f);
}

static void expect_counts(uint32_t pos, uint32_t att, uint32_t ignored)
{
    assert_int_equal(feed.counters.positions_rx, pos);
    assert_int_equal(feed.counters.attitudes_rx, att);
    assert_int_equal(feed.counters.ignored_rx, ignored);
    assert_int_equal(feed.counters.foreign_rx, 0);
}

/* Position and attitude each from their own message; non-finite ones are ignored. */
static void test_position_and_attitude(void **state)
{
    (void)state;
    feed_init();
    position(1.0f, 2.0f, -3.0f, 1000000);
    assert_false(occ_mav_feed_pose(&feed, 1000000, NULL)); /* no attitude yet */
    expect_counts(1, 0, 0);
    attitude(0.1f, -0.2f, 0.5f, 1000000);
    expect_pose(1.0f, 2.0f, -3.0f, 0.1f, -0.2f, 0.5f);
    expect_counts(1, 1, 0);
    position(NAN, 2.5f, -3.5f, 1000000);
    position(4.0f, INFINITY, -3.5f, 1000000);
    position(4.0f, 2.5f, -INFINITY, 1000000);
    attitude(0.3f, 0.3f, NAN, 1000000);
    expect_pose(1.0f, 2.0f, -3.0f, 0.1f, -0.2f, 0.5f);
    expect_counts(1, 1, 4);
    /* A NaN roll or pitch makes no rotation either: not taken (fail closed). */
    attitude(NAN, 0.0f, -1.0f, 1000000);
    attitude(0.0f, NAN, -1.0f, 1000000);
    expect_pose(1.0f, 2.0f, -3.0f, 0.1f, -0.2f, 0.5f);
    expect_counts(1, 1, 6);
}

/* ATTITUDE_QUATERNION: yaw, roll and pitch from the quaternion (occ_mav_quat_yaw). */
static void test_quaternion(void **state)
{
    (void)state;
    feed_init();
    position(0.0f, 0.0f, 0.0f, 1000000);
    float q[4];
    quat_of(0.2f, -0.1f, 1.0f, q);
    mavlink_attitude_quaternion_t m;
    memset(&m, 0, sizeof m);
    m.q1 = q[0];
    m.q2 = q[1];
    m.q3 = q[2];
    m.q4 = q[3];
    rx(MAVLINK_MSG_ID_ATTITUDE_QUATERNION, &m, sizeof m, 1000000);
    float roll = 0.0f, pitch = 0.0f;
    const float yaw = occ_mav_quat_yaw(q, &roll, &pitch);
    assert_true(fabsf(yaw - 1.0f) < 1e-5f && fabsf(roll - 0.2f) < 1e-5f &&
                fabsf(pitch + 0.1f) < 1e-5f);
    expect_pose(0.0f, 0.0f, 0.0f, roll, pitch, yaw);
    expect_counts(1, 1, 0);
}

/* ODOMETRY: position and attitude at once, in a local frame only (LOCAL_NED 1, VISION_NED 16,
 * ESTIM_NED 18, LOCAL_FRD 20); anything else leaves the pose as it was. */
static void test_odometry(void **state)
{
    (void)state;
    feed_init();
    float q[4];
    quat_of(0.05f, 0.1f, -2.0f, q);
    float roll = 0.0f, pitch = 0.0f;
    const float yaw = occ_mav_quat_yaw(q, &roll, &pitch);
    const uint8_t local[] = {1u, 16u, 18u, 20u};
    for (size_t i = 0; i < sizeof local; i++) {
        odometry(local[i], 5.0f + (float)i, 6.0f, -7.0f, q, 1000000);
        expect_pose(5.0f + (float)i, 6.0f, -7.0f, roll, pitch, yaw);
        expect_counts((uint32_t)i + 1u, (uint32_t)i + 1u, 0);
    }
    float q2[4];
    quat_of(0.0f, 0.0f, 0.7f, q2);
    const uint8_t other[] = {0u, 8u, 12u, 21u};
    for (size_t i = 0; i < sizeof other; i++) {
        odometry(other[i], 9.0f, 9.0f, 9.0f, q2, 1000000);
    }
    odometry(1u, 9.0f, NAN, 9.0f, q2, 1000000);
    const float bad_q[4] = {NAN, 0.0f, 0.0f, 0.0f};
    odometry(1u, 9.0f, 9.0f, 9.0f, bad_q, 1000000);
    expect_pose(8.0f, 6.0f, -7.0f, roll, pitch, yaw);
    expect_counts(4, 4, 6);
}

/* A good frame of a message the feed does not use: ignored, nothing else changes. */
static void test_other_messages(void **state)
{
    (void)state;
    feed_init();
    mavlink_sys_status_t m;
    memset(&m, 0, sizeof m);
    rx(MAVLINK_MSG_ID_SYS_STATUS, &m, sizeof m, 1000000);
    expect_counts(0, 0, 1);
    assert_false(occ_mav_feed_pose(&feed, 1000000, NULL));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_position_and_attitude),
        cmocka_unit_test(test_quaternion),
        cmocka_unit_test(test_odometry),
        cmocka_unit_test(test_other_messages),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
