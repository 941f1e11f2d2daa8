/* SPDX-License-Identifier: BSD-3-Clause */
/* test_mavlink_pose.c - the MAVLink feed's pose is the library's occ_pose_t: LOCAL_POSITION_NED
 * with ATTITUDE (roll, pitch, yaw) or ATTITUDE_QUATERNION gives occ_pose_from_ned() of the
 * autopilot's NED pose (ENU map) or the NED <- FRD pose itself (NED map); an attitude with NaN
 * or a zero quaternion is not taken. Frames are built with the generated MAVLink C headers. */
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
static occ_mav_sender_t ap = {7, 1, 0}; /* the autopilot: system 7, component 1 */

static void start(occ_map_frame_t frame)
{
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    cfg.autopilot_sysid = 7;
    cfg.map_frame = frame;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
}

static void rx(uint32_t msgid, const void *payload, size_t len)
{
    uint8_t buf[OCC_MAV_FRAME_MAX];
    const size_t n = occ_mav_finalize(&ap, msgid, (const uint8_t *)payload, len, buf, sizeof buf);
    assert_true(n > 0u);
    occ_mav_feed_rx(&feed, buf, n, 1000000u);
}

static void position(float north, float east, float down)
{
    mavlink_local_position_ned_t lp;
    memset(&lp, 0, sizeof lp);
    lp.x = north, lp.y = east, lp.z = down; /* local NED, metres */
    rx(MAVLINK_MSG_ID_LOCAL_POSITION_NED, &lp, sizeof lp);
}

static void attitude(float roll, float pitch, float yaw)
{
    mavlink_attitude_t a;
    memset(&a, 0, sizeof a);
    a.roll = roll;
    a.pitch = pitch;
    a.yaw = yaw;
    rx(MAVLINK_MSG_ID_ATTITUDE, &a, sizeof a);
}

static void attitude_quaternion(occ_quat_t q)
{
    mavlink_attitude_quaternion_t a;
    memset(&a, 0, sizeof a);
    a.q1 = q.w;
    a.q2 = q.x;
    a.q3 = q.y;
    a.q4 = q.z;
    rx(MAVLINK_MSG_ID_ATTITUDE_QUATERNION, &a, sizeof a);
}

static void pose_equal(const occ_pose_t *got, const occ_pose_t *want)
{
    assert_true(fabsf(got->p.x - want->p.x) < 1e-6f && fabsf(got->p.y - want->p.y) < 1e-6f &&
                fabsf(got->p.z - want->p.z) < 1e-6f);
    const float d = got->q.w * want->q.w + got->q.x * want->q.x + got->q.y * want->q.y +
                    got->q.z * want->q.z;
    assert_true(fabsf(fabsf(d) - 1.0f) < 1e-6f);
}

static void test_attitude_enu(void **state)
{
    (void)state;
    start(OCC_MAP_FRAME_ENU);
    occ_pose_t got;
    assert_false(occ_mav_feed_pose(&feed, 1000000u, &got));
    position(1.0f, 2.0f, -3.0f);
    attitude(0.3f, -0.2f, 1.0f);
    assert_true(occ_mav_feed_pose(&feed, 1000000u, &got));
    occ_pose_t want;
    const occ_vec3_t ned = {1.0f, 2.0f, -3.0f};
    assert_int_equal(occ_pose_from_ned(ned, occ_quat_from_euler(0.3f, -0.2f, 1.0f), &want),
                     OCC_OK);
    pose_equal(&got, &want);
    /* By hand: map (east, north, up) = (2, 1, 3); heading 90 deg - 1 rad from east. */
    assert_true(fabsf(got.p.x - 2.0f) < 1e-6f && fabsf(got.p.z - 3.0f) < 1e-6f);
    assert_true(fabsf(occ_pose_yaw(&got) - (1.5707963f - 1.0f)) < 1e-5f);
    /* The same attitude as ATTITUDE_QUATERNION (here scaled by 2: normalised when taken). */
    const occ_quat_t q = occ_quat_from_euler(0.3f, -0.2f, 1.0f);
    const occ_quat_t q2 = {2.0f * q.w, 2.0f * q.x, 2.0f * q.y, 2.0f * q.z};
    attitude(0.0f, 0.0f, 0.0f);
    attitude_quaternion(q2);
    assert_true(occ_mav_feed_pose(&feed, 1000000u, &got));
    pose_equal(&got, &want);
    assert_int_equal(occ_pose_check(&got), OCC_OK);
    assert_int_equal(feed.counters.attitudes_rx, 3);
}

static void test_attitude_ned_map(void **state)
{
    (void)state;
    start(OCC_MAP_FRAME_NED);
    position(1.0f, 2.0f, -3.0f);
    attitude(0.3f, -0.2f, 1.0f);
    occ_pose_t got;
    assert_true(occ_mav_feed_pose(&feed, 1000000u, &got));
    const occ_pose_t want = {{1.0f, 2.0f, -3.0f}, occ_quat_from_euler(0.3f, -0.2f, 1.0f)};
    pose_equal(&got, &want);
    assert_true(fabsf(occ_pose_yaw(&got) - 1.0f) < 1e-5f); /* NED heading, from north */
}

static void test_bad_attitude_not_taken(void **state)
{
    (void)state;
    start(OCC_MAP_FRAME_ENU);
    position(0.0f, 0.0f, 0.0f);
    attitude(0.0f, 0.0f, 0.5f);
    occ_pose_t before, after;
    assert_true(occ_mav_feed_pose(&feed, 1000000u, &before));
    const uint32_t ignored = feed.counters.ignored_rx;
    attitude(NAN, 0.0f, 0.0f);     /* a NaN roll: not a rotation */
    attitude(0.0f, 0.0f, INFINITY);
    const occ_quat_t zero = {0.0f, 0.0f, 0.0f, 0.0f};
    attitude_quaternion(zero);
    const occ_quat_t nanq = {NAN, 0.0f, 0.0f, 1.0f};
    attitude_quaternion(nanq);
    assert_int_equal(feed.counters.ignored_rx, ignored + 4u);
    assert_int_equal(feed.counters.attitudes_rx, 1);
    assert_true(occ_mav_feed_pose(&feed, 1000000u, &after));
    assert_memory_equal(&before, &after, sizeof before);
    position(NAN, 0.0f, 0.0f);
    assert_int_equal(feed.counters.ignored_rx, ignored + 5u);
    assert_int_equal(feed.counters.positions_rx, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_attitude_enu),
        cmocka_unit_test(test_attitude_ned_map),
        cmocka_unit_test(test_bad_attitude_not_taken),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
