/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_pose_rx.c - poses from one autopilot, stamped on its clock (occ_mavlink_run.h). */
#include "occmap/occ_mavlink_run.h"

#include <math.h>
#include <string.h>

occ_mav_pose_rx_config_t occ_mav_pose_rx_config_default(void)
{
    occ_mav_pose_rx_config_t c;
    c.sysid = 1u;
    c.compid = OCC_MAV_COMP_ID_AUTOPILOT1;
    c.pair_tol_us = 25000u;
    return c;
}

occ_err_t occ_mav_pose_rx_init(occ_mav_pose_rx_t *rx, const occ_mav_pose_rx_config_t *cfg)
{
    if (rx == NULL || cfg == NULL) {
        return OCC_ERR_ARG;
    }
    memset(rx, 0, sizeof *rx);
    rx->cfg = *cfg;
    return OCC_OK;
}

bool occ_mav_is_pose_msg(uint32_t msgid)
{
    return msgid == OCC_MAV_MSG_LOCAL_POSITION_NED || msgid == OCC_MAV_MSG_ATTITUDE ||
           msgid == OCC_MAV_MSG_ATTITUDE_QUATERNION || msgid == OCC_MAV_MSG_ODOMETRY;
}

/* The pose of the stored parts at t_us, if it is newer than the last one handed out. */
static bool emit(occ_mav_pose_rx_t *rx, uint64_t t_us, occ_pose_sample_t *out)
{
    occ_pose_sample_t s;
    if (rx->priv.have_out && t_us <= rx->priv.out_us) {
        return false;
    }
    if (occ_pose_from_ned(rx->priv.ned, rx->priv.q, &s.pose) != OCC_OK) {
        rx->counters.bad++;
        return false;
    }
    s.t_us = t_us;
    rx->priv.pos_paired = rx->priv.att_paired = true;
    rx->priv.have_out = true;
    rx->priv.out_us = t_us;
    rx->counters.poses++;
    *out = s;
    return true;
}

/* A position or attitude just stored at t_us: a pose when its partner is close in time. */
static bool pair(occ_mav_pose_rx_t *rx, bool have_other, uint64_t other_us, uint64_t t_us,
                 occ_pose_sample_t *out)
{
    if (!have_other) {
        return false;
    }
    const uint64_t d = t_us > other_us ? t_us - other_us : other_us - t_us;
    if (d > rx->cfg.pair_tol_us) {
        return false; /* its own partner may still come: counted only if it never does */
    }
    if (rx->priv.have_out && other_us <= rx->priv.out_us) {
        return false; /* the partner is in the last pose already: wait for its own partner */
    }
    return emit(rx, t_us > other_us ? t_us : other_us, out);
}

/* A part about to be replaced: unpaired if it never made a pose. */
static void replace_part(occ_mav_pose_rx_t *rx, bool have, bool paired)
{
    if (have && !paired) {
        rx->counters.unpaired++;
    }
}

static bool take_position(occ_mav_pose_rx_t *rx, const occ_mav_frame_t *f, occ_pose_sample_t *out)
{
    occ_mav_local_position_ned_t m;
    if (occ_mav_decode_local_position_ned(f, &m) != OCC_OK || !isfinite(m.x) ||
        !isfinite(m.y) || !isfinite(m.z)) {
        rx->counters.bad++;
        return false;
    }
    rx->counters.positions++;
    replace_part(rx, rx->priv.have_pos, rx->priv.pos_paired);
    rx->priv.ned.x = m.x;
    rx->priv.ned.y = m.y;
    rx->priv.ned.z = m.z;
    rx->priv.pos_us = (uint64_t)m.time_boot_ms * 1000u;
    rx->priv.have_pos = true;
    rx->priv.pos_paired = false;
    return pair(rx, rx->priv.have_att, rx->priv.att_us, rx->priv.pos_us, out);
}

static bool take_attitude(occ_mav_pose_rx_t *rx, occ_quat_t q, uint32_t time_boot_ms,
                          occ_pose_sample_t *out)
{
    occ_quat_t u;
    if (occ_quat_normalize(q, &u) != OCC_OK) {
        rx->counters.bad++;
        return false;
    }
    rx->counters.attitudes++;
    replace_part(rx, rx->priv.have_att, rx->priv.att_paired);
    rx->priv.q = u;
    rx->priv.att_us = (uint64_t)time_boot_ms * 1000u;
    rx->priv.have_att = true;
    rx->priv.att_paired = false;
    return pair(rx, rx->priv.have_pos, rx->priv.pos_us, rx->priv.att_us, out);
}

static bool take_odometry(occ_mav_pose_rx_t *rx, const occ_mav_frame_t *f, occ_pose_sample_t *out)
{
    occ_mav_odometry_t m;
    occ_quat_t u;
    const bool frame_ok = occ_mav_decode_odometry(f, &m) == OCC_OK &&
                          (m.frame_id == 1u || m.frame_id == 16u || m.frame_id == 18u ||
                           m.frame_id == 20u);
    const occ_quat_t q = {m.q[0], m.q[1], m.q[2], m.q[3]};
    if (!frame_ok || !isfinite(m.x) || !isfinite(m.y) || !isfinite(m.z) ||
        occ_quat_normalize(q, &u) != OCC_OK) {
        rx->counters.bad++;
        return false;
    }
    rx->counters.positions++;
    rx->counters.attitudes++;
    replace_part(rx, rx->priv.have_pos, rx->priv.pos_paired);
    replace_part(rx, rx->priv.have_att, rx->priv.att_paired);
    rx->priv.pos_paired = rx->priv.att_paired = false;
    rx->priv.ned.x = m.x;
    rx->priv.ned.y = m.y;
    rx->priv.ned.z = m.z;
    rx->priv.q = u;
    rx->priv.pos_us = rx->priv.att_us = m.time_usec;
    rx->priv.have_pos = rx->priv.have_att = true;
    return emit(rx, m.time_usec, out);
}

bool occ_mav_pose_rx_take(occ_mav_pose_rx_t *rx, const occ_mav_frame_t *f, occ_pose_sample_t *out)
{
    if (rx == NULL || f == NULL || out == NULL || !occ_mav_is_pose_msg(f->msgid)) {
        return false;
    }
    if (f->sysid != rx->cfg.sysid || f->compid != rx->cfg.compid) {
        rx->counters.foreign++;
        return false;
    }
    switch (f->msgid) {
    case OCC_MAV_MSG_LOCAL_POSITION_NED:
        return take_position(rx, f, out);
    case OCC_MAV_MSG_ATTITUDE: {
        occ_mav_attitude_t m;
        if (occ_mav_decode_attitude(f, &m) != OCC_OK) {
            rx->counters.bad++;
            return false;
        }
        return take_attitude(rx, occ_quat_from_euler(m.roll, m.pitch, m.yaw), m.time_boot_ms, out);
    }
    case OCC_MAV_MSG_ATTITUDE_QUATERNION: {
        occ_mav_attitude_quaternion_t m;
        if (occ_mav_decode_attitude_quaternion(f, &m) != OCC_OK) {
            rx->counters.bad++;
            return false;
        }
        const occ_quat_t q = {m.q[0], m.q[1], m.q[2], m.q[3]};
        return take_attitude(rx, q, m.time_boot_ms, out);
    }
    default:
        return take_odometry(rx, f, out);
    }
}
