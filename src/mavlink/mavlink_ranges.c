/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_ranges.c - DISTANCE_SENSOR, OBSTACLE_DISTANCE and OBSTACLE_DISTANCE_3D as range beams
 * (see occ_mavlink_ranges.h). Public headers only, plus the generated dialect for 11037. */
#include "occmap/occ_mavlink_ranges.h"

#include <math.h>
#include <string.h>

#include "ardupilotmega/mavlink.h"
#include "mavlink_internal.h"

#define DEG_TO_RAD 0.017453292519943295f
#define PI_F 3.14159265358979f
#define CM_TO_M 0.01f
#define UNKNOWN_ELEMENT 0xFFFFu

/* MAV_SENSOR_ORIENTATION 0..40: roll, pitch, yaw in degrees (common.xml's descriptions). 38 is
 * what ArduPilot really applies (its rotations.h: "actually roll 90, pitch 68.8, yaw 293.3"). */
static const float rotation_deg[41][3] = {
    {0, 0, 0},     {0, 0, 45},    {0, 0, 90},    {0, 0, 135},   {0, 0, 180},   {0, 0, 225},
    {0, 0, 270},   {0, 0, 315},   {180, 0, 0},   {180, 0, 45},  {180, 0, 90},  {180, 0, 135},
    {0, 180, 0},   {180, 0, 225}, {180, 0, 270}, {180, 0, 315}, {90, 0, 0},    {90, 0, 45},
    {90, 0, 90},   {90, 0, 135},  {270, 0, 0},   {270, 0, 45},  {270, 0, 90},  {270, 0, 135},
    {0, 90, 0},    {0, 270, 0},   {0, 180, 90},  {0, 180, 270}, {90, 90, 0},   {180, 90, 0},
    {270, 90, 0},  {90, 180, 0},  {270, 180, 0}, {90, 270, 0},  {180, 270, 0}, {270, 270, 0},
    {90, 180, 90}, {90, 0, 270},  {90, 68.8f, 293.3f}, {0, 315, 0}, {90, 315, 0},
};

/* A rotation of body FRD as the same rotation of body FLU: FLU = Rx(pi) FRD, and conjugating by
 * Rx(pi) flips the y and z parts of the quaternion. */
static occ_quat_t frd_to_flu(occ_quat_t q)
{
    const occ_quat_t r = {q.w, q.x, -q.y, -q.z};
    return r;
}

/* A direction of FRD (body or NED world's horizontal) in FLU. */
static occ_vec3_t vec_frd_to_flu(float x, float y, float z)
{
    const occ_vec3_t v = {x, -y, -z};
    return v;
}

occ_err_t occ_mav_sensor_mount(uint8_t orientation, const float custom_q[4],
                               occ_pose_t *body_from_sensor)
{
    if (body_from_sensor == NULL) {
        return OCC_ERR_ARG;
    }
    occ_quat_t q_frd;
    if (orientation == OCC_MAV_SENSOR_ROTATION_CUSTOM) {
        if (custom_q == NULL) {
            return OCC_ERR_ARG;
        }
        const occ_quat_t raw = {custom_q[0], custom_q[1], custom_q[2], custom_q[3]};
        if (occ_quat_normalize(raw, &q_frd) != OCC_OK) {
            return OCC_ERR_FORMAT;
        }
    } else if (orientation < sizeof rotation_deg / sizeof rotation_deg[0]) {
        const float *const rpy = rotation_deg[orientation];
        q_frd = occ_quat_from_euler(rpy[0] * DEG_TO_RAD, rpy[1] * DEG_TO_RAD, rpy[2] * DEG_TO_RAD);
    } else {
        return OCC_ERR_UNSUPPORTED;
    }
    body_from_sensor->p.x = 0.0f;
    body_from_sensor->p.y = 0.0f;
    body_from_sensor->p.z = 0.0f;
    body_from_sensor->q = frd_to_flu(q_frd);
    return OCC_OK;
}

/* The wire's inclusive [min, max] cm as a beam interval (see the header). */
static bool set_limits_cm(occ_range_beam_t *b, uint16_t min_cm, uint16_t max_cm)
{
    if (min_cm >= max_cm) {
        return false;
    }
    b->min_m = (float)min_cm * CM_TO_M;
    b->max_m = ((float)max_cm + 0.5f) * CM_TO_M;
    return true;
}

/* Half the smaller known field of view; false for NaN, negative or >= pi. */
static bool cone_from_fov(float hfov, float vfov, float *half)
{
    if (!(hfov >= 0.0f && hfov < PI_F) || !(vfov >= 0.0f && vfov < PI_F)) {
        return false;
    }
    float fov = hfov > 0.0f ? hfov : vfov;
    if (vfov > 0.0f && vfov < fov) {
        fov = vfov;
    }
    *half = 0.5f * fov;
    return true;
}

static occ_err_t from_distance_sensor(occ_mav_ranges_t *rx, const occ_mav_frame_t *f,
                                      occ_mav_beams_t *out)
{
    occ_mav_distance_sensor_t m;
    if (occ_mav_decode_distance_sensor(f, &m) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    occ_range_beam_t *const b = &out->beam[0];
    if (m.signal_quality > 100u || !set_limits_cm(b, m.min_distance, m.max_distance) ||
        !cone_from_fov(m.horizontal_fov, m.vertical_fov, &b->cone_half_rad)) {
        return OCC_ERR_FORMAT;
    }
    const occ_err_t e = occ_mav_sensor_mount(m.orientation, m.quaternion, &out->mount);
    if (e != OCC_OK) {
        return e;
    }
    b->dir.x = 1.0f;
    b->dir.y = 0.0f;
    b->dir.z = 0.0f;
    b->distance_m = (float)m.current_distance * CM_TO_M;
    b->valid = m.signal_quality != 1u;
    if (!b->valid) {
        rx->counters.invalid_readings++;
    }
    out->n = 1;
    out->sensor_id = m.id;
    out->time_us = (uint64_t)m.time_boot_ms * 1000u;
    return OCC_OK;
}

/* increment_f "non-zero" without -Wfloat-equal's == (NaN is refused before). */
static bool is_zero(float v)
{
    return !(v < 0.0f) && !(v > 0.0f);
}

/* Element j's bearing in radians (clockwise from forward or north). */
static float element_bearing(const occ_mav_obstacle_distance_t *m, unsigned j)
{
    const float inc = !is_zero(m->increment_f) ? m->increment_f : (float)m->increment;
    return (m->angle_offset + (float)j * inc) * DEG_TO_RAD;
}

static occ_err_t from_obstacle_distance(occ_mav_ranges_t *rx, const occ_mav_frame_t *f,
                                        occ_mav_beams_t *out)
{
    occ_mav_obstacle_distance_t m;
    if (occ_mav_decode_obstacle_distance(f, &m) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    occ_range_beam_t limits;
    if (!isfinite(m.increment_f) || !isfinite(m.angle_offset) ||
        (is_zero(m.increment_f) && m.increment == 0u) ||
        !set_limits_cm(&limits, m.min_distance, m.max_distance)) {
        return OCC_ERR_FORMAT;
    }
    if (m.frame == OCC_MAV_FRAME_BODY_FRD) {
        out->frame = OCC_MAV_BEAMS_BODY;
    } else if (m.frame == OCC_MAV_FRAME_GLOBAL || m.frame == OCC_MAV_FRAME_LOCAL_NED) {
        out->frame = OCC_MAV_BEAMS_NORTH;
    } else {
        return OCC_ERR_UNSUPPORTED;
    }
    for (unsigned j = 0; j < OCC_MAV_OBSTACLE_ELEMENTS; j++) {
        if (m.distances[j] == UNKNOWN_ELEMENT) {
            out->unknown_elements++;
            continue;
        }
        const float a = element_bearing(&m, j);
        occ_range_beam_t *const b = &out->beam[out->n++];
        *b = limits;
        /* Clockwise bearing in a FRD / NED horizontal plane: (cos a, sin a, 0) there. */
        b->dir = vec_frd_to_flu(cosf(a), sinf(a), 0.0f);
        if (out->frame == OCC_MAV_BEAMS_NORTH) {
            b->dir.x = sinf(a); /* ENU: east = sin a, north = cos a */
            b->dir.y = cosf(a);
        }
        b->distance_m = (float)m.distances[j] * CM_TO_M;
        b->cone_half_rad = 0.0f;
        b->valid = true;
    }
    rx->counters.unknown_elements += out->unknown_elements;
    out->time_us = m.time_usec;
    return OCC_OK;
}

static occ_err_t from_obstacle_3d(const occ_mav_frame_t *f, occ_mav_beams_t *out)
{
    mavlink_obstacle_distance_3d_t m;
    if (!occi_mav_load(f, MAVLINK_MSG_ID_OBSTACLE_DISTANCE_3D, &m, sizeof m)) {
        return OCC_ERR_ARG;
    }
    if (m.frame != OCC_MAV_FRAME_BODY_FRD) {
        return OCC_ERR_UNSUPPORTED;
    }
    const occ_vec3_t p = vec_frd_to_flu(m.x, m.y, m.z);
    const float d = sqrtf(p.x * p.x + p.y * p.y + p.z * p.z);
    if (!isfinite(d) || !(d > 0.0f) || !(m.min_distance >= 0.0f) ||
        !(m.max_distance > m.min_distance) || !isfinite(m.max_distance)) {
        return OCC_ERR_FORMAT;
    }
    occ_range_beam_t *const b = &out->beam[0];
    b->dir.x = p.x / d;
    b->dir.y = p.y / d;
    b->dir.z = p.z / d;
    b->distance_m = d;
    b->min_m = m.min_distance;
    b->max_m = m.max_distance;
    b->cone_half_rad = 0.0f;
    b->valid = true;
    out->n = 1;
    out->time_us = (uint64_t)m.time_boot_ms * 1000u;
    return OCC_OK;
}

occ_err_t occ_mav_ranges_init(occ_mav_ranges_t *rx, uint8_t own_sysid, uint8_t own_compid)
{
    if (rx == NULL) {
        return OCC_ERR_ARG;
    }
    memset(rx, 0, sizeof *rx);
    rx->own_sysid = own_sysid;
    rx->own_compid = own_compid;
    return OCC_OK;
}

static occ_err_t translate(occ_mav_ranges_t *rx, const occ_mav_frame_t *f, occ_mav_beams_t *out)
{
    switch (f->msgid) {
    case OCC_MAV_MSG_DISTANCE_SENSOR:
        return from_distance_sensor(rx, f, out);
    case OCC_MAV_MSG_OBSTACLE_DISTANCE:
        return from_obstacle_distance(rx, f, out);
    case OCC_MAV_MSG_OBSTACLE_DISTANCE_3D:
        return from_obstacle_3d(f, out);
    default:
        return OCC_ERR_UNSUPPORTED;
    }
}

static bool is_range_msg(uint32_t msgid)
{
    return msgid == OCC_MAV_MSG_DISTANCE_SENSOR || msgid == OCC_MAV_MSG_OBSTACLE_DISTANCE ||
           msgid == OCC_MAV_MSG_OBSTACLE_DISTANCE_3D;
}

occ_err_t occ_mav_ranges_decode(occ_mav_ranges_t *rx, const occ_mav_frame_t *f,
                                occ_mav_beams_t *out)
{
    if (rx == NULL || f == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    if (!is_range_msg(f->msgid)) {
        rx->counters.other_msgs++;
        return OCC_ERR_UNSUPPORTED;
    }
    if (f->sysid == rx->own_sysid && f->compid == rx->own_compid) {
        rx->counters.own_refused++;
        return OCC_ERR_ARG;
    }
    memset(out, 0, sizeof *out);
    out->msgid = f->msgid;
    out->sysid = f->sysid;
    out->compid = f->compid;
    out->frame = OCC_MAV_BEAMS_BODY;
    out->mount = occ_pose_identity();
    const occ_err_t e = translate(rx, f, out);
    if (e == OCC_OK) {
        rx->counters.translated++;
    } else if (e == OCC_ERR_FORMAT) {
        rx->counters.malformed++;
    } else if (e == OCC_ERR_UNSUPPORTED) {
        rx->counters.unsupported++;
    }
    return e;
}

occ_err_t occ_mav_beams_sensor_pose(const occ_mav_beams_t *beams, const occ_pose_t *map_from_body,
                                    occ_pose_t *map_from_sensor)
{
    if (beams == NULL || map_from_sensor == NULL || occ_pose_check(map_from_body) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    if (beams->frame == OCC_MAV_BEAMS_NORTH) {
        map_from_sensor->p = map_from_body->p;
        map_from_sensor->q = occ_quat_identity();
    } else {
        *map_from_sensor = occ_pose_compose(map_from_body, &beams->mount);
    }
    return OCC_OK;
}
