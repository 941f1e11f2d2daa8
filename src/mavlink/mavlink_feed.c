/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_feed.c - poses in, OBSTACLE_DISTANCE + HEARTBEAT out, on the caller's clock. */
#include "occmap/occ_mavlink.h"
#include "occmap/occ_mavlink_run.h"

#include <math.h>
#include <string.h>

#define MAV_TYPE_ONBOARD_CONTROLLER_ 18u
#define MAV_AUTOPILOT_INVALID_ 8u
#define MAV_STATE_ACTIVE_ 4u

/* MAV_FRAME values whose positions are local NED-like: LOCAL_NED 1, VISION_NED 16,
 * ESTIM_NED 18, LOCAL_FRD 20 (north/east replaced by the autopilot's local axes). */
static bool odometry_frame_ok(uint8_t frame)
{
    return frame == 1u || frame == 16u || frame == 18u || frame == 20u;
}

occ_mav_feed_config_t occ_mav_feed_config_default(void)
{
    occ_mav_feed_config_t c;
    c.sysid = 1u;
    c.compid = OCC_MAV_COMP_ID_OBSTACLE_AVOIDANCE;
    c.period_us = 100000u;
    c.heartbeat_period_us = 1000000u;
    c.pose_timeout_us = 300000u;
    c.autopilot = OCC_AUTOPILOT_ARDUPILOT;
    c.map_frame = OCC_MAP_FRAME_ENU;
    c.sensor_type = 0u;
    c.autopilot_sysid = 0u;
    c.autopilot_compid = OCC_MAV_COMP_ID_AUTOPILOT1;
    c.pose_interval_us = 50000u;
    c.request_period_us = 1000000u;
    c.sectors = occ_sectors_config_default();
    c.sectors.angle_offset_deg = OCC_MAV_ANGLE_OFFSET_DEFAULT_DEG;
    return c;
}

occ_err_t occ_mav_feed_init(occ_mav_feed_t *f, const occ_mav_feed_config_t *cfg)
{
    if (f == NULL || cfg == NULL || cfg->period_us == 0u || cfg->heartbeat_period_us == 0u ||
        cfg->pose_timeout_us == 0u || occ_sectors_config_check(&cfg->sectors) != OCC_OK ||
        (cfg->pose_interval_us > 0u && cfg->request_period_us == 0u)) {
        return OCC_ERR_ARG;
    }
    if (cfg->autopilot != OCC_AUTOPILOT_ARDUPILOT && cfg->autopilot != OCC_AUTOPILOT_PX4) {
        return OCC_ERR_ARG;
    }
    if (cfg->map_frame != OCC_MAP_FRAME_ENU && cfg->map_frame != OCC_MAP_FRAME_NED) {
        return OCC_ERR_ARG;
    }
    if (cfg->autopilot == OCC_AUTOPILOT_PX4 &&
        (float)cfg->sectors.n_sectors * cfg->sectors.increment_deg < 360.0f - 1e-3f) {
        return OCC_ERR_ARG;
    }
    memset(f, 0, sizeof *f);
    f->cfg = *cfg;
    f->cfg.sectors.map_ned = cfg->map_frame == OCC_MAP_FRAME_NED;
    occ_mav_parser_init(&f->parser);
    f->priv.tx.sysid = cfg->sysid;
    f->priv.tx.compid = cfg->compid;
    f->priv.tx.seq = 0;
    f->have_autopilot = cfg->autopilot_sysid != 0u;
    f->ap_sysid = cfg->autopilot_sysid;
    f->ap_compid = cfg->autopilot_compid;
    f->priv.system_status = MAV_STATE_ACTIVE_;
    return OCC_OK;
}

void occ_mav_feed_set_status(occ_mav_feed_t *f, uint8_t system_status)
{
    if (f != NULL && f->priv.system_status != system_status) {
        f->priv.system_status = system_status;
        /* A change is told at once, not up to a heartbeat period later: the autopilot (and
         * a GCS) should see BOOT -> ACTIVE -> CRITICAL as it happens. */
        if (f->priv.started) {
            f->priv.next_heartbeat_us = 0;
        }
    }
}

static bool is_pose_message(uint32_t msgid)
{
    return msgid == OCC_MAV_MSG_LOCAL_POSITION_NED || msgid == OCC_MAV_MSG_ATTITUDE ||
           msgid == OCC_MAV_MSG_ATTITUDE_QUATERNION || msgid == OCC_MAV_MSG_ODOMETRY;
}

static bool from_autopilot(const occ_mav_feed_t *f, const occ_mav_frame_t *fr)
{
    return f->have_autopilot && fr->sysid == f->ap_sysid && fr->compid == f->ap_compid;
}

/* The first autopilot HEARTBEAT names the system whose poses we take (unless configured). */
static void take_heartbeat(occ_mav_feed_t *f, const occ_mav_frame_t *fr)
{
    occ_mav_heartbeat_t hb;
    if (!f->have_autopilot && occ_mav_decode_heartbeat(fr, &hb) == OCC_OK &&
        hb.autopilot != OCC_MAV_AUTOPILOT_INVALID && hb.type != OCC_MAV_TYPE_GCS) {
        f->have_autopilot = true;
        f->ap_sysid = fr->sysid;
    }
}

static void take_ack(occ_mav_feed_t *f, const occ_mav_frame_t *fr)
{
    occ_mav_command_ack_t ack;
    if (!from_autopilot(f, fr) || occ_mav_decode_command_ack(fr, &ack) != OCC_OK ||
        ack.command != OCC_MAV_CMD_SET_MESSAGE_INTERVAL) {
        f->counters.ignored_rx++;
        return;
    }
    if (ack.result == OCC_MAV_RESULT_ACCEPTED) {
        f->counters.request_acks++;
    } else {
        f->counters.request_refusals++;
        f->counters.last_refusal_result = ack.result;
    }
}

static occ_quat_t quat_of(const float q[4])
{
    const occ_quat_t r = {q[0], q[1], q[2], q[3]};
    return r;
}

/* Here, not in the codec (mavlink.c builds alone for the fuzzer): it is the pose module's. */
float occ_mav_quat_yaw(const float q[4], float *roll, float *pitch)
{
    float yaw = 0.0f;
    occ_quat_to_euler(quat_of(q), roll, pitch, &yaw);
    return yaw;
}

/* A finite local NED position (false, nothing taken, otherwise). */
static bool set_position(occ_mav_feed_t *f, float north, float east, float down, uint64_t now_us)
{
    if (!isfinite(north) || !isfinite(east) || !isfinite(down)) {
        return false;
    }
    f->priv.ned_m.x = north;
    f->priv.ned_m.y = east;
    f->priv.ned_m.z = down;
    f->priv.pos_us = now_us;
    f->priv.have_pos = true;
    f->counters.positions_rx++;
    return true;
}

/* An attitude NED <- FRD, kept unit; NaN, Inf or a zero quaternion is not taken. */
static bool set_attitude(occ_mav_feed_t *f, occ_quat_t ned_from_frd, uint64_t now_us)
{
    if (occ_quat_normalize(ned_from_frd, &f->priv.ned_from_frd) != OCC_OK) {
        return false;
    }
    f->priv.att_us = now_us;
    f->priv.have_att = true;
    f->counters.attitudes_rx++;
    return true;
}

/* Each take_* below: true when the message was taken (it decoded, and what it says is finite
 * and in a frame we use). */
static bool take_position(occ_mav_feed_t *f, const occ_mav_frame_t *fr, uint64_t now_us)
{
    occ_mav_local_position_ned_t m;
    return occ_mav_decode_local_position_ned(fr, &m) == OCC_OK &&
           set_position(f, m.x, m.y, m.z, now_us);
}

static bool take_attitude(occ_mav_feed_t *f, const occ_mav_frame_t *fr, uint64_t now_us)
{
    occ_mav_attitude_t m;
    return occ_mav_decode_attitude(fr, &m) == OCC_OK &&
           set_attitude(f, occ_quat_from_euler(m.roll, m.pitch, m.yaw), now_us);
}

static bool take_quaternion(occ_mav_feed_t *f, const occ_mav_frame_t *fr, uint64_t now_us)
{
    occ_mav_attitude_quaternion_t m;
    return occ_mav_decode_attitude_quaternion(fr, &m) == OCC_OK &&
           set_attitude(f, quat_of(m.q), now_us);
}

static bool take_odometry(occ_mav_feed_t *f, const occ_mav_frame_t *fr, uint64_t now_us)
{
    occ_mav_odometry_t m;
    if (occ_mav_decode_odometry(fr, &m) != OCC_OK || !odometry_frame_ok(m.frame_id) ||
        !isfinite(m.x) || !isfinite(m.y) || !isfinite(m.z) ||
        !set_attitude(f, quat_of(m.q), now_us)) {
        return false;
    }
    return set_position(f, m.x, m.y, m.z, now_us); /* finite: checked above */
}

static bool take_pose(occ_mav_feed_t *f, const occ_mav_frame_t *fr, uint64_t now_us)
{
    switch (fr->msgid) {
    case OCC_MAV_MSG_LOCAL_POSITION_NED:
        return take_position(f, fr, now_us);
    case OCC_MAV_MSG_ATTITUDE:
        return take_attitude(f, fr, now_us);
    case OCC_MAV_MSG_ATTITUDE_QUATERNION:
        return take_quaternion(f, fr, now_us);
    case OCC_MAV_MSG_ODOMETRY:
        return take_odometry(f, fr, now_us);
    default:
        return false;
    }
}

static void take_frame(occ_mav_feed_t *f, const occ_mav_frame_t *fr, uint64_t now_us)
{
    if (fr->sysid == f->cfg.sysid && fr->compid == f->cfg.compid) {
        f->counters.ignored_rx++;
        return;
    }
    if (fr->msgid == OCC_MAV_MSG_HEARTBEAT) {
        take_heartbeat(f, fr);
        f->counters.ignored_rx++; /* not a pose */
        return;
    }
    if (fr->msgid == OCC_MAV_MSG_COMMAND_ACK) {
        take_ack(f, fr);
        return;
    }
    if (is_pose_message(fr->msgid) && !from_autopilot(f, fr)) {
        f->counters.foreign_rx++;
        f->counters.ignored_rx++;
        return;
    }
    if (!take_pose(f, fr, now_us)) {
        f->counters.ignored_rx++;
    }
}

void occ_mav_feed_rx(occ_mav_feed_t *f, const uint8_t *data, size_t n, uint64_t now_us)
{
    if (f == NULL || data == NULL) {
        return;
    }
    for (size_t i = 0; i < n; i++) {
        occ_mav_frame_t fr;
        if (occ_mav_parser_push(&f->parser, data[i], &fr) == OCC_MAV_OK) {
            take_frame(f, &fr, now_us);
        }
    }
}

static bool fresh_at(const occ_mav_feed_t *f, bool have, uint64_t at_us, uint64_t now_us)
{
    return have && now_us >= at_us && now_us - at_us <= f->cfg.pose_timeout_us;
}

bool occ_mav_feed_pose(const occ_mav_feed_t *f, uint64_t now_us, occ_pose_t *pose)
{
    if (f == NULL || !f->priv.have_pos || !f->priv.have_att) {
        return false;
    }
    const bool fresh = fresh_at(f, f->priv.have_pos, f->priv.pos_us, now_us) &&
                       fresh_at(f, f->priv.have_att, f->priv.att_us, now_us);
    if (pose == NULL) {
        return fresh;
    }
    if (f->cfg.map_frame == OCC_MAP_FRAME_NED) {
        pose->p = f->priv.ned_m;
        pose->q = f->priv.ned_from_frd;
        return fresh;
    }
    /* Both parts were checked when taken: this cannot fail, but never reads as fresh if it does. */
    return occ_pose_from_ned(f->priv.ned_m, f->priv.ned_from_frd, pose) == OCC_OK && fresh;
}

uint64_t occ_mav_feed_next_due(const occ_mav_feed_t *f)
{
    if (f == NULL || !f->priv.started) {
        return 0;
    }
    uint64_t due = f->priv.next_obstacle_us < f->priv.next_heartbeat_us ? f->priv.next_obstacle_us
                                                               : f->priv.next_heartbeat_us;
    if (f->have_autopilot && f->cfg.pose_interval_us > 0u && f->priv.next_request_us < due) {
        due = f->priv.next_request_us;
    }
    return due;
}

/* Advance a deadline past now by whole periods. */
static uint64_t advance(uint64_t due, uint32_t period, uint64_t now_us)
{
    due += period;
    if (due <= now_us) {
        due = now_us + period - ((now_us - due) % period);
    }
    return due;
}

/* One SET_MESSAGE_INTERVAL per call while a request round has streams left: a round starts
 * every request_period_us and asks for each stream that is not fresh. */
static size_t poll_request(occ_mav_feed_t *f, uint64_t now_us, uint8_t *out, size_t cap)
{
    if (!f->have_autopilot || f->cfg.pose_interval_us == 0u) {
        return 0;
    }
    if (f->priv.request_mask == 0u && now_us >= f->priv.next_request_us) {
        f->priv.next_request_us = now_us + f->cfg.request_period_us;
        f->priv.request_mask = (uint8_t)((fresh_at(f, f->priv.have_pos, f->priv.pos_us, now_us) ? 0u : 1u) |
                                    (fresh_at(f, f->priv.have_att, f->priv.att_us, now_us) ? 0u : 2u));
    }
    if (f->priv.request_mask == 0u) {
        return 0;
    }
    const bool pos = (f->priv.request_mask & 1u) != 0u;
    f->priv.request_mask = (uint8_t)(f->priv.request_mask & (pos ? ~1u : ~2u));
    occ_mav_command_long_t c;
    memset(&c, 0, sizeof c);
    c.target_system = f->ap_sysid;
    c.target_component = f->ap_compid;
    c.command = OCC_MAV_CMD_SET_MESSAGE_INTERVAL;
    c.param[0] = (float)(pos ? OCC_MAV_MSG_LOCAL_POSITION_NED : OCC_MAV_MSG_ATTITUDE);
    c.param[1] = (float)f->cfg.pose_interval_us;
    const size_t n = occ_mav_encode_command_long(&f->priv.tx, &c, out, cap);
    if (n > 0u) {
        f->counters.requests_tx++;
    }
    return n;
}

/* The OBSTACLE_DISTANCE of the sectors just computed. Out of line: its 72-distance message
 * would otherwise sit on the stack under occ_sectors_compute (make cross, issue 24). */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static size_t encode_obstacle(occ_mav_feed_t *f, uint64_t now_us, uint8_t *out, size_t cap)
{
    const occ_sectors_config_t *const sc = &f->cfg.sectors;
    occ_mav_obstacle_distance_t m;
    m.time_usec = now_us;
    m.sensor_type = f->cfg.sensor_type;
    for (unsigned i = 0; i < 72u; i++) {
        m.distances[i] = i < f->priv.sectors.n ? f->priv.sectors.distance_cm[i] : UINT16_MAX;
    }
    const float inc = sc->increment_deg;
    m.increment = 0;
    if (f->cfg.autopilot == OCC_AUTOPILOT_ARDUPILOT && inc >= 1.0f && inc <= 255.0f) {
        m.increment = (uint8_t)(inc + 0.5f);
    }
    m.min_distance = sc->min_distance_cm;
    m.max_distance = sc->max_distance_cm;
    m.increment_f = inc;
    m.angle_offset = sc->angle_offset_deg;
    m.frame = OCC_MAV_FRAME_BODY_FRD;
    const size_t n = occ_mav_encode_obstacle_distance(&f->priv.tx, &m, out, cap);
    if (n > 0u) {
        f->counters.obstacle_tx++;
    }
    return n;
}

size_t occ_mav_feed_poll(occ_mav_feed_t *f, const occ_map_t *map, uint64_t now_us, uint8_t *out,
                         size_t cap)
{
    if (f == NULL || out == NULL || cap < OCC_MAV_FRAME_MAX) {
        return 0;
    }
    if (!f->priv.started) {
        f->priv.started = true;
        f->priv.next_heartbeat_us = now_us;
        f->priv.next_obstacle_us = now_us;
    }
    if (now_us >= f->priv.next_heartbeat_us) {
        const uint32_t hb_period = f->cfg.heartbeat_period_us;
        /* 0 = made due by a status change: the period restarts from now */
        f->priv.next_heartbeat_us = f->priv.next_heartbeat_us == 0u
                                        ? now_us + hb_period
                                        : advance(f->priv.next_heartbeat_us, hb_period, now_us);
        occ_mav_heartbeat_t hb;
        hb.custom_mode = 0;
        hb.type = MAV_TYPE_ONBOARD_CONTROLLER_;
        hb.autopilot = MAV_AUTOPILOT_INVALID_;
        hb.base_mode = 0;
        hb.system_status = f->priv.system_status;
        hb.mavlink_version = 3;
        const size_t n = occ_mav_encode_heartbeat(&f->priv.tx, &hb, out, cap);
        if (n > 0u) {
            f->counters.heartbeat_tx++;
        }
        return n;
    }
    const size_t nr = poll_request(f, now_us, out, cap);
    if (nr > 0u) {
        return nr;
    }
    if (now_us < f->priv.next_obstacle_us) {
        return 0;
    }
    f->priv.next_obstacle_us = advance(f->priv.next_obstacle_us, f->cfg.period_us, now_us);
    occ_pose_t pose;
    if (map == NULL || !occ_mav_feed_pose(f, now_us, &pose)) {
        f->counters.stale_skips++;
        return 0;
    }
    const occ_sectors_config_t *const sc = &f->cfg.sectors;
    if (occ_sectors_compute(map, &pose, sc, &f->priv.sectors) != OCC_OK) {
        f->counters.sector_errors++;
        return 0;
    }
    return encode_obstacle(f, now_us, out, cap);
}
