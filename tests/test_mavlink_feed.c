/* SPDX-License-Identifier: BSD-3-Clause */
/* test_mavlink_feed.c - the MAVLink feed state machine (occ_mav_feed_*): what it sends for a
 * pose and a map, as ArduPilot reads it (faces, arming, unknown space), whose poses it takes and
 * the stream requests it makes. The wire itself: test_mavlink.c. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_mavlink.h"
#include "occmap/occ_mavlink_run.h"
#include "ardupilotmega/mavlink.h"
#include "support/mav_frames.h"

/* ---- the feed state machine ---------------------------------------------------------------------- */

static uint8_t arena[1u << 20];

static size_t pose_frames(occ_mav_sender_t *ap, float n, float e, float d, float yaw, uint8_t *buf)
{
    mavlink_local_position_ned_t lp;
    memset(&lp, 0, sizeof lp);
    lp.x = n;
    lp.y = e;
    lp.z = d;
    size_t len = occ_mav_finalize(ap, MAVLINK_MSG_ID_LOCAL_POSITION_NED, (const uint8_t *)&lp,
                                  sizeof lp, buf, OCC_MAV_FRAME_MAX);
    len += attitude_frame(ap, yaw, buf + len);
    return len;
}

/* A HEARTBEAT as `tx` (type, autopilot: 2, 3 = an ArduPilot quad; 6, 8 = a GCS). */
static size_t heartbeat_frame(occ_mav_sender_t *tx, uint8_t type, uint8_t autopilot, uint8_t *buf)
{
    const occ_mav_heartbeat_t hb = {0, type, autopilot, 0, 4, 3};
    return occ_mav_encode_heartbeat(tx, &hb, buf, OCC_MAV_FRAME_MAX);
}

static size_t ack_frame(occ_mav_sender_t *tx, uint8_t result, uint8_t *buf)
{
    occ_mav_command_ack_t a;
    memset(&a, 0, sizeof a);
    a.command = OCC_MAV_CMD_SET_MESSAGE_INTERVAL;
    a.result = result;
    a.target_system = 1;
    a.target_component = 196;
    return occ_mav_encode_command_ack(tx, &a, buf, OCC_MAV_FRAME_MAX);
}

typedef struct {
    unsigned hb, obst, req;
    occ_mav_obstacle_distance_t last;
    occ_mav_command_long_t reqs[16]; /* the first 16 SET_MESSAGE_INTERVAL commands */
} sink_t;

static void drain(occ_mav_feed_t *f, const occ_map_t *map, uint64_t now, sink_t *s)
{
    uint8_t out[OCC_MAV_FRAME_MAX];
    size_t n;
    while ((n = occ_mav_feed_poll(f, map, now, out, sizeof out)) > 0) {
        occ_mav_parser_t p;
        occ_mav_parser_init(&p);
        occ_mav_result_t r = OCC_MAV_NONE;
        occ_mav_frame_t fr;
        assert_int_equal(parse_all(&p, out, n, &r, &fr), 1);
        assert_int_equal(r, OCC_MAV_OK);
        assert_int_equal(fr.sysid, 1);
        assert_int_equal(fr.compid, 196);
        if (fr.msgid == 0) {
            occ_mav_heartbeat_t hb;
            assert_int_equal(occ_mav_decode_heartbeat(&fr, &hb), OCC_OK);
            assert_int_equal(hb.type, 18);
            assert_int_equal(hb.autopilot, 8);
            s->hb++;
        } else if (fr.msgid == OCC_MAV_MSG_COMMAND_LONG) {
            occ_mav_command_long_t c;
            assert_int_equal(occ_mav_decode_command_long(&fr, &c), OCC_OK);
            assert_int_equal(c.command, OCC_MAV_CMD_SET_MESSAGE_INTERVAL);
            if (s->req < 16u) {
                s->reqs[s->req] = c;
            }
            s->req++;
        } else {
            assert_int_equal(fr.msgid, 330);
            assert_int_equal(occ_mav_decode_obstacle_distance(&fr, &s->last), OCC_OK);
            s->obst++;
        }
    }
}

static void test_feed(void **state)
{
    (void)state;
    occ_map_t map;
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &mc, arena, sizeof arena), OCC_OK);
    /* Free space around the origin with a wall 1.5 m north (ENU y in [1.5, 1.6)). */
    for (int i = 0; i < 8; i++) {
        occ_vec3_t v = {(i & 1) ? 0.05f : -0.05f, (i & 2) ? 0.05f : -0.05f,
                        (i & 4) ? 0.05f : -0.05f};
        occ_key_t k;
        assert_int_equal(occ_map_key(&map, v, &k), OCC_OK);
        assert_int_equal(occ_map_set_key(&map, k, 8, -2.0f), OCC_OK);
    }
    for (float x = -3.0f; x < 3.0f; x += 0.1f) {
        for (float z = -0.6f; z < 0.6f; z += 0.1f) {
            occ_vec3_t v = {x, 1.55f, z};
            assert_int_equal(occ_map_update(&map, v, 2.0f), OCC_OK);
        }
    }
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t ap = {1, 1, 0};
    uint8_t in[2 * OCC_MAV_FRAME_MAX];
    sink_t s;
    memset(&s, 0, sizeof s);
    /* No pose yet: heartbeats only. */
    uint64_t t = 1000000;
    for (int i = 0; i < 25; i++, t += 50000) {
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.obst, 0);
    assert_int_equal(s.hb, 2); /* t = 1.0 s and 2.0 s */
    assert_int_equal(s.req, 0); /* no autopilot yet */
    assert_true(feed.counters.stale_skips >= 10);
    /* Poses before the autopilot's HEARTBEAT are not taken; after it they are. */
    size_t nin = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, nin, t);
    assert_int_equal(feed.counters.positions_rx, 0);
    assert_int_equal(feed.counters.foreign_rx, 2);
    nin = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, nin, t);
    assert_true(feed.have_autopilot && feed.ap_sysid == 1 && feed.ap_compid == 1);
    /* Poses at 20 Hz for 2 s: 10 Hz obstacle messages. Facing north (NED yaw 0). */
    const unsigned hb0 = s.hb;
    for (int i = 0; i < 40; i++, t += 50000) {
        const size_t n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_true(s.obst >= 19 && s.obst <= 21);
    assert_int_equal(s.hb - hb0, 2);
    assert_int_equal(s.last.frame, 12);
    assert_true(feq((double)s.last.increment_f, 5.0));
    assert_int_equal(s.last.increment, 5);
    assert_int_equal(s.last.min_distance, 20);
    assert_int_equal(s.last.max_distance, 2000);
    assert_true(feq((double)s.last.angle_offset, -20.0)); /* element 4 looks straight ahead */
    /* Wall 1.5 m straight ahead. */
    assert_int_equal(s.last.distances[4], 150);
    assert_int_equal(s.last.distances[40], 2001); /* observed free behind: max + 1 */
    /* The same numbers as occ_sectors_compute for the same pose. */
    static occ_sectors_t ref;
    occ_pose_t pose;
    const occ_vec3_t origin = {0.0f, 0.0f, 0.0f};
    assert_int_equal(occ_pose_from_ned(origin, occ_quat_identity(), &pose), OCC_OK); /* north */
    assert_int_equal(occ_sectors_compute(&map, &pose, &cfg.sectors, &ref), OCC_OK);
    assert_memory_equal(ref.distance_cm, s.last.distances, 72 * sizeof(uint16_t));
    /* Facing east (NED yaw +90 deg): the wall is on the left, body 270 deg = element 58. */
    for (int i = 0; i < 4; i++, t += 50000) {
        const size_t n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, (float)(M_PI / 2.0), in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.last.distances[58], 150);
    /* Poses stop: messages stop within the 300 ms timeout, heartbeats go on. */
    const uint64_t t_last_pose = t - 50000;
    const unsigned ob = s.obst, hb1 = s.hb;
    unsigned after = 0;
    for (int i = 0; i < 60; i++, t += 50000) {
        const unsigned before = s.obst;
        drain(&feed, &map, t, &s);
        if (s.obst > before) {
            assert_true(t - t_last_pose <= 300000);
            after++;
        }
    }
    assert_true(after <= 3);
    assert_true(s.obst - ob <= 3);
    assert_true(s.hb - hb1 >= 2);
    /* Our own frames echoed back are ignored; ODOMETRY revives the feed. */
    occ_mav_sender_t self = {1, 196, 0};
    size_t n = pose_frames(&self, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, n, t);
    const unsigned ob2 = s.obst;
    drain(&feed, &map, t, &s);
    t += 100000;
    drain(&feed, &map, t, &s);
    assert_int_equal(s.obst, ob2);
    mavlink_odometry_t od;
    memset(&od, 0, sizeof od);
    od.frame_id = 1;
    od.q[0] = cosf(0.25f * (float)M_PI); /* yaw 90 deg about down: facing east */
    od.q[3] = sinf(0.25f * (float)M_PI);
    n = occ_mav_finalize(&ap, MAVLINK_MSG_ID_ODOMETRY, (const uint8_t *)&od, MAVLINK_MSG_ID_ODOMETRY_LEN, in,
                         sizeof in);
    occ_mav_feed_rx(&feed, in, n, t);
    t += 100000;
    drain(&feed, &map, t, &s);
    assert_int_equal(s.obst, ob2 + 1);
    assert_int_equal(s.last.distances[58], 150);
    /* The ODOMETRY pose in the map frame: NED heading east = ENU yaw 0. */
    occ_pose_t pz;
    assert_true(occ_mav_feed_pose(&feed, t, &pz));
    assert_true(fabsf(occ_pose_yaw(&pz)) < 1e-5f);
    /* PX4 needs all 72 elements covered. */
    occ_mav_feed_config_t c2 = cfg;
    c2.autopilot = OCC_AUTOPILOT_PX4;
    c2.sectors.n_sectors = 8;
    c2.sectors.increment_deg = 10.0f;
    assert_int_equal(occ_mav_feed_init(&feed, &c2), OCC_ERR_ARG);
    c2.sectors.n_sectors = 72;
    c2.sectors.increment_deg = 5.0f;
    assert_int_equal(occ_mav_feed_init(&feed, &c2), OCC_OK);
    c2.period_us = 0;
    assert_int_equal(occ_mav_feed_init(&feed, &c2), OCC_ERR_ARG);
    printf("feed: %u heartbeats, %u OBSTACLE_DISTANCE\n", s.hb, s.obst);
}

/* ---- the feed as ArduPilot reads it ---------------------------------------------------------------- */

/* ArduPilot's OBSTACLE_DISTANCE handler as documented (AP_Proximity_MAV, PRX1_TYPE = 2): reset
 * the 8 faces of 45 deg centred on 0, 45, ..., 315; walk the elements in order, skipping 0,
 * UINT16_MAX, < min and > max; keep the nearest valid element of the current face and write
 * the face each time a valid element's face differs from the previous one. face_m < 0: no
 * obstacle. */
static void ardupilot_faces(const occ_mav_obstacle_distance_t *m, double face_m[8])
{
    for (int f = 0; f < 8; f++) {
        face_m[f] = -1.0;
    }
    const double inc = m->increment_f > 0.0f ? (double)m->increment_f : (double)m->increment;
    int prev = -1;
    double best = 0.0;
    for (int i = 0; i < 72; i++) {
        const uint16_t d = m->distances[i];
        if (d == 0u || d == UINT16_MAX || d < m->min_distance || d > m->max_distance) {
            continue;
        }
        const double angle = fmod(fmod((double)i * inc + (double)m->angle_offset, 360.0) + 360.0,
                                  360.0);
        const int face = (int)(fmod(angle + 22.5, 360.0) / 45.0) % 8;
        if (prev >= 0 && face != prev) {
            face_m[prev] = best;
            prev = -1;
        }
        const double dm = (double)d * 0.01;
        if (prev < 0 || dm < best) {
            best = dm;
        }
        prev = face;
    }
    if (prev >= 0) {
        face_m[prev] = best;
    }
}

/* A map of free space (the eight level-8 nodes around the origin, 25.6 m cubes). */
static void free_map(occ_map_t *map)
{
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(map, &mc, arena, sizeof arena), OCC_OK);
    for (int i = 0; i < 8; i++) {
        occ_vec3_t v = {(i & 1) ? 0.05f : -0.05f, (i & 2) ? 0.05f : -0.05f,
                        (i & 4) ? 0.05f : -0.05f};
        occ_key_t k;
        assert_int_equal(occ_map_key(map, v, &k), OCC_OK);
        assert_int_equal(occ_map_set_key(map, k, 8, -2.0f), OCC_OK);
    }
}

/* A post (one voxel column, z -0.45..0.45) at body angle b_deg, range r_m from a vehicle at the
 * origin facing north; returns its distance, worked out from the voxel's square in double. */
static double post(occ_map_t *map, double b_deg, double r_m)
{
    const double res = (double)map->cfg.resolution_m;
    const double x = r_m * sin(b_deg * M_PI / 180.0), y = r_m * cos(b_deg * M_PI / 180.0);
    for (double z = -0.45; z < 0.5; z += 0.1) {
        const occ_vec3_t v = {(float)x, (float)y, (float)z};
        assert_int_equal(occ_map_update(map, v, 2.0f), OCC_OK);
    }
    const double x0 = floor(x / res) * res, y0 = floor(y / res) * res;
    const double qx = x0 > 0.0 ? x0 : (x0 + res < 0.0 ? x0 + res : 0.0);
    const double qy = y0 > 0.0 ? y0 : (y0 + res < 0.0 ? y0 + res : 0.0);
    return sqrt(qx * qx + qy * qy);
}

/* One OBSTACLE_DISTANCE of a feed with `cfg` for the autopilot (1, 1) at NED (n, e, d, yaw). */
static occ_mav_obstacle_distance_t feed_once(const occ_mav_feed_config_t *cfg,
                                             const occ_map_t *map, float n, float e, float d,
                                             float yaw)
{
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, cfg), OCC_OK);
    occ_mav_sender_t ap = {1, 1, 0};
    uint8_t in[3 * OCC_MAV_FRAME_MAX];
    size_t len = heartbeat_frame(&ap, 2, 3, in);
    len += pose_frames(&ap, n, e, d, yaw, in + len);
    occ_mav_feed_rx(&feed, in, len, 1000000);
    sink_t s;
    memset(&s, 0, sizeof s);
    drain(&feed, map, 1000000, &s);
    assert_int_equal(s.obst, 1);
    return s.last;
}

/* Every face ArduPilot computes from our message is the nearest obstacle in its 45 degrees;
 * faces without one read "no obstacle" (free elements are max + 1, dropped by its range check).
 * The forward face holds two posts, the near one at 10 deg, a far one at 345 deg: with
 * angle_offset 0 (the old default) ArduPilot's forward face is the far one (elements 68-71
 * overwrite 0-4), the 1.96 m instead of 1.16 m. */
static void test_feed_ardupilot_faces(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    const double near0 = post(&map, 10.0, 1.2), far0 = post(&map, 345.0, 2.0);
    const double d2 = post(&map, 100.0, 1.5), d5 = post(&map, 225.0, 0.8);
    assert_true(near0 < far0 - 0.5);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    assert_true(feq((double)cfg.sectors.angle_offset_deg, -20.0));
    cfg.sectors.max_distance_cm = 500;
    const occ_mav_obstacle_distance_t m = feed_once(&cfg, &map, 0.0f, 0.0f, 0.0f, 0.0f);
    double face[8];
    ardupilot_faces(&m, face);
    const double want[8] = {near0, -1.0, d2, -1.0, -1.0, d5, -1.0, -1.0};
    for (int f = 0; f < 8; f++) {
        printf("face %d: ardupilot %.2f m, nearest in the map %.3f m\n", f, face[f], want[f]);
        if (want[f] < 0.0) {
            assert_true(face[f] < 0.0);
        } else {
            assert_true(fabs(face[f] - want[f]) <= 0.011);
        }
    }
    unsigned free_elems = 0;
    for (int i = 0; i < 72; i++) {
        free_elems += m.distances[i] == 501u ? 1u : 0u;
        assert_true(m.distances[i] != 0u && m.distances[i] != 500u);
    }
    assert_true(free_elems > 50u);
    /* The old offset: ArduPilot's forward face reads the far post. */
    cfg.sectors.angle_offset_deg = 0.0f;
    const occ_mav_obstacle_distance_t m0 = feed_once(&cfg, &map, 0.0f, 0.0f, 0.0f, 0.0f);
    ardupilot_faces(&m0, face);
    assert_true(fabs(face[0] - far0) <= 0.011);
    /* Free as max_distance (the old encoding) would be an obstacle at 5 m in every face. */
    occ_mav_obstacle_distance_t old = m;
    for (int i = 0; i < 72; i++) {
        old.distances[i] = old.distances[i] == 501u ? 500u : old.distances[i];
    }
    ardupilot_faces(&old, face);
    assert_true(fabs(face[1] - 5.0) < 1e-9);
}

/* The vehicle standing on a floor can arm: no face nearer than 0.6 m (ArduPilot's arming check). */
static void test_feed_floor_arming(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    for (float x = -4.95f; x < 5.0f; x += 0.1f) {
        for (float y = -4.95f; y < 5.0f; y += 0.1f) {
            const occ_vec3_t v = {x, y, -0.05f}; /* floor voxels z -0.1..0 */
            assert_int_equal(occ_map_update(&map, v, 2.0f), OCC_OK);
        }
    }
    const double d_post = post(&map, 45.0, 2.0);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    cfg.sectors.max_distance_cm = 400;
    /* Standing 5 cm above the floor (NED down -0.05), heading 30 deg. */
    occ_mav_obstacle_distance_t m = feed_once(&cfg, &map, 0.0f, 0.0f, -0.05f, 0.0f);
    double face[8];
    ardupilot_faces(&m, face);
    for (int f = 0; f < 8; f++) {
        assert_true(face[f] < 0.0 || face[f] > 0.6);
    }
    assert_true(fabs(face[1] - d_post) <= 0.011);
    /* Hovering 0.4 m over it: the same. */
    m = feed_once(&cfg, &map, 0.0f, 0.0f, -0.4f, 0.0f);
    ardupilot_faces(&m, face);
    for (int f = 0; f < 8; f++) {
        assert_true(face[f] < 0.0 || face[f] > 0.6);
    }
    /* Without the ground rule the floor is at 0.2 m (min_distance) in every face. */
    cfg.sectors.ignore_ground = false;
    m = feed_once(&cfg, &map, 0.0f, 0.0f, -0.05f, 0.0f);
    ardupilot_faces(&m, face);
    for (int f = 0; f < 8; f++) {
        assert_true(fabs(face[f] - 0.2) < 1e-9);
    }
}

/* Unknown space: UINT16_MAX by default (ArduPilot: a face of only unknown = no obstacle); with
 * unknown_as_distance its distance (an obstacle both autopilots respect). */
static void test_feed_unknown_encoding(void **state)
{
    (void)state;
    occ_map_t map;
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &mc, arena, sizeof arena), OCC_OK);
    /* Free only north of the vehicle (y >= 0): the south half is never observed. */
    for (float x = -2.95f; x < 3.0f; x += 0.1f) {
        for (float y = -0.05f; y < 3.0f; y += 0.1f) {
            for (float z = -0.45f; z < 0.5f; z += 0.1f) {
                const occ_vec3_t v = {x, y, z};
                assert_int_equal(occ_map_update(&map, v, -2.0f), OCC_OK);
            }
        }
    }
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    cfg.sectors.max_distance_cm = 250;
    occ_mav_obstacle_distance_t m = feed_once(&cfg, &map, 0.05f, 0.05f, 0.0f, 0.0f);
    double face[8];
    ardupilot_faces(&m, face);
    assert_int_equal(m.distances[40], UINT16_MAX); /* behind: unknown 10 cm away */
    assert_true(face[4] < 0.0);                     /* ArduPilot: no obstacle behind */
    assert_true(face[0] < 0.0);                     /* ahead: observed free */
    cfg.sectors.unknown_as_distance = true;
    m = feed_once(&cfg, &map, 0.05f, 0.05f, 0.0f, 0.0f);
    ardupilot_faces(&m, face);
    assert_int_equal(m.distances[40], 20); /* 0.1 m, clamped to min_distance */
    assert_true(fabs(face[4] - 0.2) < 1e-9);
    assert_true(face[0] < 0.0);
}

/* The autopilot: named by its HEARTBEAT (not a GCS's, not a companion's) or by the config;
 * poses from other systems or components are ignored. */
static void test_feed_sysid(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t gcs = {255, 190, 0}, companion = {7, 197, 0}, ap = {7, 1, 0};
    occ_mav_sender_t other = {2, 1, 0}, ap_other_comp = {7, 2, 0};
    uint8_t in[3 * OCC_MAV_FRAME_MAX];
    size_t n = heartbeat_frame(&gcs, 6, 8, in);
    n += heartbeat_frame(&companion, 18, 8, in + n);
    occ_mav_feed_rx(&feed, in, n, 1000000);
    assert_false(feed.have_autopilot);
    n = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, n, 1000000);
    assert_true(feed.have_autopilot && feed.ap_sysid == 7 && feed.ap_compid == 1);
    n = heartbeat_frame(&other, 2, 12, in); /* a second autopilot does not take over */
    occ_mav_feed_rx(&feed, in, n, 1000000);
    assert_int_equal(feed.ap_sysid, 7);
    sink_t s;
    memset(&s, 0, sizeof s);
    uint64_t t = 1000000;
    for (int i = 0; i < 10; i++, t += 50000) {
        n = pose_frames(&other, 0.0f, 0.0f, 0.0f, 0.0f, in);
        n += pose_frames(&ap_other_comp, 0.0f, 0.0f, 0.0f, 0.0f, in + n);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.obst, 0);
    assert_int_equal(feed.counters.positions_rx + feed.counters.attitudes_rx, 0);
    assert_int_equal(feed.counters.foreign_rx, 40);
    n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, n, t);
    drain(&feed, &map, t, &s);
    assert_int_equal(s.obst, 1);
    /* Given sysid and compid: no HEARTBEAT needed, others' ignored. */
    cfg.autopilot_sysid = 9;
    cfg.autopilot_compid = 3;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t ap9 = {9, 3, 0};
    n = heartbeat_frame(&ap, 2, 3, in);
    n += pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in + n);
    occ_mav_feed_rx(&feed, in, n, t);
    assert_int_equal(feed.ap_sysid, 9);
    assert_int_equal(feed.counters.positions_rx, 0);
    n = pose_frames(&ap9, 0.0f, 0.0f, 0.0f, 0.0f, in);
    occ_mav_feed_rx(&feed, in, n, t);
    assert_int_equal(feed.counters.positions_rx, 1);
    assert_int_equal(feed.counters.attitudes_rx, 1);
}

static bool is_request(const occ_mav_command_long_t *c, uint32_t msgid)
{
    return c->target_system == 7u && c->target_component == 1u &&
           c->command == OCC_MAV_CMD_SET_MESSAGE_INTERVAL &&
           feq((double)c->param[0], (double)msgid) && feq((double)c->param[1], 50000.0);
}

/* SET_MESSAGE_INTERVAL for LOCAL_POSITION_NED and ATTITUDE: sent once the autopilot is known,
 * every second until the streams arrive, again when they stop; refusals counted. */
/* A status change is told at once: one HEARTBEAT with the new MAV_STATE at the next poll, then
 * the 1 Hz period restarts from there (a 0.3 s window of BOOT must not end unseen). */
static void test_feed_status_change(void **state)
{
    (void)state;
    occ_map_t map;
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &mc, arena, sizeof arena), OCC_OK);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_feed_set_status(&feed, 0); /* before the first poll: no effect on the schedule */
    uint8_t out[OCC_MAV_FRAME_MAX];
    uint8_t seen[8];
    unsigned n_seen = 0;
    static const uint64_t t_set[3] = {1300000, 1500000, 1500000};
    static const uint8_t st_set[3] = {3 /* STANDBY */, 4 /* ACTIVE */, 4 /* unchanged */};
    for (uint64_t t = 1000000; t <= 3000000; t += 100000) {
        for (unsigned i = 0; i < 3; i++) {
            if (t == t_set[i]) {
                occ_mav_feed_set_status(&feed, st_set[i]);
            }
        }
        size_t n;
        while ((n = occ_mav_feed_poll(&feed, &map, t, out, sizeof out)) > 0) {
            occ_mav_parser_t p;
            occ_mav_parser_init(&p);
            occ_mav_result_t r = OCC_MAV_NONE;
            occ_mav_frame_t fr;
            assert_int_equal(parse_all(&p, out, n, &r, &fr), 1);
            occ_mav_heartbeat_t hb;
            if (fr.msgid == 0 && occ_mav_decode_heartbeat(&fr, &hb) == OCC_OK && n_seen < 8u) {
                seen[n_seen++] = (uint8_t)(hb.system_status | (uint8_t)((t / 100000u) << 4));
            }
        }
    }
    /* t=1.0 s (status 0), 1.3 s STANDBY at once, 1.5 s ACTIVE at once, 2.5 s, period from 1.5 s */
    assert_int_equal(n_seen, 4);
    assert_int_equal(seen[0] & 15, 0);
    assert_int_equal(seen[1], (uint8_t)(3 | (13 << 4)));
    assert_int_equal(seen[2], (uint8_t)(4 | (15 << 4)));
    assert_int_equal(seen[3], (uint8_t)(4 | (25 << 4)));
}

static void test_feed_requests(void **state)
{
    (void)state;
    occ_map_t map;
    free_map(&map);
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    static occ_mav_feed_t feed;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    occ_mav_sender_t ap = {7, 1, 0}, other = {2, 1, 0};
    uint8_t in[3 * OCC_MAV_FRAME_MAX];
    sink_t s;
    memset(&s, 0, sizeof s);
    uint64_t t = 1000000;
    drain(&feed, &map, t, &s);
    assert_int_equal(s.req, 0); /* nobody to ask yet */
    size_t n = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, n, t);
    drain(&feed, &map, t, &s);
    assert_int_equal(s.req, 2);
    assert_true(is_request(&s.reqs[0], 32) && is_request(&s.reqs[1], 30));
    /* Refused, then accepted; an ACK from another system is not ours. */
    n = ack_frame(&ap, 2, in);
    n += ack_frame(&other, 4, in + n);
    n += ack_frame(&ap, 0, in + n);
    occ_mav_feed_rx(&feed, in, n, t);
    assert_int_equal(feed.counters.request_refusals, 1);
    assert_int_equal(feed.counters.last_refusal_result, 2);
    assert_int_equal(feed.counters.request_acks, 1);
    /* Nothing arrives: asked again every second. */
    for (int i = 0; i < 20; i++) {
        t += 50000;
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.req, 4);
    assert_true(is_request(&s.reqs[2], 32) && is_request(&s.reqs[3], 30));
    /* Poses at 20 Hz for 3 s: no more requests. */
    for (int i = 0; i < 60; i++) {
        t += 50000;
        n = pose_frames(&ap, 0.0f, 0.0f, 0.0f, 0.0f, in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.req, 4);
    assert_true(s.obst >= 28);
    /* Only the attitude stops: only ATTITUDE is asked for. */
    mavlink_local_position_ned_t lp;
    memset(&lp, 0, sizeof lp);
    for (int i = 0; i < 30; i++) {
        t += 50000;
        n = occ_mav_finalize(&ap, MAVLINK_MSG_ID_LOCAL_POSITION_NED, (const uint8_t *)&lp,
                             sizeof lp, in, sizeof in);
        occ_mav_feed_rx(&feed, in, n, t);
        drain(&feed, &map, t, &s);
    }
    assert_true(s.req >= 5 && s.req <= 6);
    assert_true(is_request(&s.reqs[4], 30));
    /* Everything stops (the autopilot rebooted): both asked for again, every second. */
    const unsigned r0 = s.req;
    for (int i = 0; i < 40; i++) {
        t += 50000;
        drain(&feed, &map, t, &s);
    }
    assert_true(s.req >= r0 + 2);
    assert_true(is_request(&s.reqs[s.req - 2], 32) && is_request(&s.reqs[s.req - 1], 30));
    assert_int_equal(feed.counters.requests_tx, s.req);
    /* pose_interval_us 0: never asks. */
    cfg.pose_interval_us = 0;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_OK);
    memset(&s, 0, sizeof s);
    n = heartbeat_frame(&ap, 2, 3, in);
    occ_mav_feed_rx(&feed, in, n, t);
    for (int i = 0; i < 40; i++) {
        t += 50000;
        drain(&feed, &map, t, &s);
    }
    assert_int_equal(s.req, 0);
    cfg.pose_interval_us = 50000;
    cfg.request_period_us = 0;
    assert_int_equal(occ_mav_feed_init(&feed, &cfg), OCC_ERR_ARG);
}

/* The termios serial link over a pseudo-terminal: frames both ways, non-blocking reads. */

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_feed),
        cmocka_unit_test(test_feed_ardupilot_faces),
        cmocka_unit_test(test_feed_floor_arming),
        cmocka_unit_test(test_feed_unknown_encoding),
        cmocka_unit_test(test_feed_sysid),
        cmocka_unit_test(test_feed_requests),
        cmocka_unit_test(test_feed_status_change),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
