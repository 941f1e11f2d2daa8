/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink.c - MAVLink frame parser, encoders and pose decoders (see occ_mavlink.h).
 * Message definitions come from the mavgen-generated headers (build/gen/mavlink, -isystem). */
#include "occmap/occ_mavlink.h"
#include "mavlink_internal.h"

#include <math.h>
#include <string.h>

#include "ardupilotmega/mavlink.h"

#if MAVLINK_NEED_BYTE_SWAP
#error "occ_mavlink decodes by copying payloads into the generated structs: little-endian only"
#endif

#define STX_V1 0xFEu
#define STX_V2 0xFDu
#define HDR_V1 6u
#define HDR_V2 10u
#define SIG_LEN 13u

static const mavlink_msg_entry_t msg_table[] = MAVLINK_MESSAGE_CRCS;
#define MSG_TABLE_N (sizeof msg_table / sizeof msg_table[0])

/* The generated table is sorted by id: binary search. */
static const mavlink_msg_entry_t *find_msg(uint32_t msgid)
{
    size_t lo = 0;
    size_t hi = MSG_TABLE_N;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2u;
        if (msg_table[mid].msgid < msgid) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return (lo < MSG_TABLE_N && msg_table[lo].msgid == msgid) ? &msg_table[lo] : NULL;
}

bool occ_mav_msg_info(uint32_t msgid, uint8_t *crc_extra, uint8_t *min_len, uint8_t *max_len)
{
    const mavlink_msg_entry_t *const e = find_msg(msgid);
    if (e == NULL) {
        return false;
    }
    if (crc_extra != NULL) {
        *crc_extra = e->crc_extra;
    }
    if (min_len != NULL) {
        *min_len = e->min_msg_len;
    }
    if (max_len != NULL) {
        *max_len = e->max_msg_len;
    }
    return true;
}

static uint16_t crc_bytes(uint16_t crc, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        crc_accumulate(p[i], &crc);
    }
    return crc;
}

void occ_mav_parser_init(occ_mav_parser_t *p)
{
    if (p != NULL) {
        memset(p, 0, sizeof *p);
    }
}

static occ_mav_result_t finish(occ_mav_parser_t *p, occ_mav_frame_t *frame)
{
    const uint8_t *const b = p->priv.buf;
    occ_mav_frame_t f;
    const bool v2 = b[0] == STX_V2;
    const uint16_t hdr = v2 ? HDR_V2 : HDR_V1;
    f.version = v2 ? 2u : 1u;
    f.len = b[1];
    f.incompat_flags = v2 ? b[2] : 0u;
    f.compat_flags = v2 ? b[3] : 0u;
    f.seq = v2 ? b[4] : b[2];
    f.sysid = v2 ? b[5] : b[3];
    f.compid = v2 ? b[6] : b[4];
    f.msgid = v2 ? ((uint32_t)b[7] | ((uint32_t)b[8] << 8) | ((uint32_t)b[9] << 16)) : b[5];
    f.is_signed = v2 && (f.incompat_flags & MAVLINK_IFLAG_SIGNED) != 0u;
    f.payload = b + hdr;
    f.frame = b;
    f.frame_len = p->priv.pos;
    p->priv.pos = 0;
    p->priv.need = 0;
    if (frame != NULL) {
        *frame = f;
    }
    if (v2 && (f.incompat_flags & (uint8_t)~MAVLINK_IFLAG_SIGNED) != 0u) {
        p->counters.bad_flags++;
        return OCC_MAV_BAD_FLAGS;
    }
    const mavlink_msg_entry_t *const e = find_msg(f.msgid);
    if (e == NULL) {
        p->counters.unknown_id++;
        return OCC_MAV_UNKNOWN;
    }
    uint16_t crc = 0xFFFFu;
    crc = crc_bytes(crc, b + 1, (size_t)hdr - 1u + f.len);
    crc_accumulate(e->crc_extra, &crc);
    const uint16_t wire = (uint16_t)((uint16_t)b[hdr + f.len] | (uint16_t)(b[hdr + f.len + 1u] << 8));
    if (crc != wire) {
        p->counters.bad_crc++;
        return OCC_MAV_BAD_CRC;
    }
    if ((v2 && f.len > e->max_msg_len) || (!v2 && f.len != e->min_msg_len)) {
        p->counters.bad_len++;
        return OCC_MAV_BAD_LEN;
    }
    p->counters.frames_ok++;
    return OCC_MAV_OK;
}

occ_mav_result_t occ_mav_parser_push(occ_mav_parser_t *p, uint8_t byte, occ_mav_frame_t *frame)
{
    if (p == NULL) {
        return OCC_MAV_NONE;
    }
    p->counters.bytes++;
    if (p->priv.pos == 0u) {
        if (byte != STX_V1 && byte != STX_V2) {
            p->counters.junk_bytes++;
            return OCC_MAV_JUNK;
        }
        p->priv.buf[0] = byte;
        p->priv.pos = 1;
        p->priv.need = 0;
        return OCC_MAV_NONE;
    }
    if (p->priv.pos >= OCC_MAV_FRAME_MAX) { /* cannot happen: need <= OCC_MAV_FRAME_MAX */
        p->priv.pos = 0;
        p->counters.junk_bytes++;
        return OCC_MAV_JUNK;
    }
    p->priv.buf[p->priv.pos++] = byte;
    if (p->priv.need == 0u) {
        const bool v2 = p->priv.buf[0] == STX_V2;
        if (!v2 && p->priv.pos == 2u) {
            p->priv.need = (uint16_t)(HDR_V1 + p->priv.buf[1] + 2u);
        } else if (v2 && p->priv.pos == 3u) {
            p->priv.need = (uint16_t)(HDR_V2 + p->priv.buf[1] + 2u +
                                 (((p->priv.buf[2] & MAVLINK_IFLAG_SIGNED) != 0u) ? SIG_LEN : 0u));
        }
        return OCC_MAV_NONE;
    }
    if (p->priv.pos < p->priv.need) {
        return OCC_MAV_NONE;
    }
    return finish(p, frame);
}

/* ---- encoding ------------------------------------------------------------------------------ */

size_t occ_mav_finalize(occ_mav_sender_t *tx, uint32_t msgid, const uint8_t *payload, size_t len,
                        uint8_t *out, size_t cap)
{
    const mavlink_msg_entry_t *const e = find_msg(msgid);
    if (tx == NULL || payload == NULL || out == NULL || e == NULL || len > e->max_msg_len) {
        return 0;
    }
    size_t n = len;
    while (n > 1u && payload[n - 1u] == 0u) {
        n--;
    }
    const size_t total = HDR_V2 + n + 2u;
    if (cap < total) {
        return 0;
    }
    out[0] = STX_V2;
    out[1] = (uint8_t)n;
    out[2] = 0;
    out[3] = 0;
    out[4] = tx->seq;
    out[5] = tx->sysid;
    out[6] = tx->compid;
    out[7] = (uint8_t)(msgid & 0xFFu);
    out[8] = (uint8_t)((msgid >> 8) & 0xFFu);
    out[9] = (uint8_t)((msgid >> 16) & 0xFFu);
    memcpy(out + HDR_V2, payload, n);
    uint16_t crc = crc_bytes(0xFFFFu, out + 1, HDR_V2 - 1u + n);
    crc_accumulate(e->crc_extra, &crc);
    out[HDR_V2 + n] = (uint8_t)(crc & 0xFFu);
    out[HDR_V2 + n + 1u] = (uint8_t)(crc >> 8);
    tx->seq++;
    return total;
}

size_t occ_mav_encode_obstacle_distance(occ_mav_sender_t *tx, const occ_mav_obstacle_distance_t *m,
                                        uint8_t *out, size_t cap)
{
    if (m == NULL) {
        return 0;
    }
    mavlink_obstacle_distance_t s;
    memset(&s, 0, sizeof s);
    s.time_usec = m->time_usec;
    for (unsigned i = 0; i < 72u; i++) {
        s.distances[i] = m->distances[i];
    }
    s.min_distance = m->min_distance;
    s.max_distance = m->max_distance;
    s.sensor_type = m->sensor_type;
    s.increment = m->increment;
    s.increment_f = m->increment_f;
    s.angle_offset = m->angle_offset;
    s.frame = m->frame;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_OBSTACLE_DISTANCE, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_OBSTACLE_DISTANCE_LEN, out, cap);
}

size_t occ_mav_encode_heartbeat(occ_mav_sender_t *tx, const occ_mav_heartbeat_t *m, uint8_t *out,
                                size_t cap)
{
    if (m == NULL) {
        return 0;
    }
    mavlink_heartbeat_t s;
    memset(&s, 0, sizeof s);
    s.custom_mode = m->custom_mode;
    s.type = m->type;
    s.autopilot = m->autopilot;
    s.base_mode = m->base_mode;
    s.system_status = m->system_status;
    s.mavlink_version = m->mavlink_version;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_HEARTBEAT, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_HEARTBEAT_LEN, out, cap);
}

size_t occ_mav_encode_command_long(occ_mav_sender_t *tx, const occ_mav_command_long_t *m,
                                   uint8_t *out, size_t cap)
{
    if (m == NULL) {
        return 0;
    }
    mavlink_command_long_t s;
    memset(&s, 0, sizeof s);
    s.target_system = m->target_system;
    s.target_component = m->target_component;
    s.command = m->command;
    s.confirmation = m->confirmation;
    s.param1 = m->param[0];
    s.param2 = m->param[1];
    s.param3 = m->param[2];
    s.param4 = m->param[3];
    s.param5 = m->param[4];
    s.param6 = m->param[5];
    s.param7 = m->param[6];
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_COMMAND_LONG, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_COMMAND_LONG_LEN, out, cap);
}

size_t occ_mav_encode_command_ack(occ_mav_sender_t *tx, const occ_mav_command_ack_t *m,
                                  uint8_t *out, size_t cap)
{
    if (m == NULL) {
        return 0;
    }
    mavlink_command_ack_t s;
    memset(&s, 0, sizeof s);
    s.command = m->command;
    s.result = m->result;
    s.progress = m->progress;
    s.result_param2 = m->result_param2;
    s.target_system = m->target_system;
    s.target_component = m->target_component;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_COMMAND_ACK, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_COMMAND_ACK_LEN, out, cap);
}

/* ---- decoding -------------------------------------------------------------------------------- */

bool occi_mav_load(const occ_mav_frame_t *f, uint32_t msgid, void *dst, size_t size)
{
    if (f == NULL || f->payload == NULL || f->msgid != msgid) {
        return false;
    }
    memset(dst, 0, size);
    memcpy(dst, f->payload, f->len < size ? f->len : size);
    return true;
}

occ_err_t occ_mav_decode_local_position_ned(const occ_mav_frame_t *f, occ_mav_local_position_ned_t *out)
{
    mavlink_local_position_ned_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_LOCAL_POSITION_NED, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->time_boot_ms = s.time_boot_ms;
    out->x = s.x;
    out->y = s.y;
    out->z = s.z;
    out->vx = s.vx;
    out->vy = s.vy;
    out->vz = s.vz;
    return OCC_OK;
}

occ_err_t occ_mav_decode_attitude(const occ_mav_frame_t *f, occ_mav_attitude_t *out)
{
    mavlink_attitude_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_ATTITUDE, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->time_boot_ms = s.time_boot_ms;
    out->roll = s.roll;
    out->pitch = s.pitch;
    out->yaw = s.yaw;
    out->rollspeed = s.rollspeed;
    out->pitchspeed = s.pitchspeed;
    out->yawspeed = s.yawspeed;
    return OCC_OK;
}

occ_err_t occ_mav_decode_attitude_quaternion(const occ_mav_frame_t *f,
                                             occ_mav_attitude_quaternion_t *out)
{
    mavlink_attitude_quaternion_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_ATTITUDE_QUATERNION, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->time_boot_ms = s.time_boot_ms;
    out->q[0] = s.q1;
    out->q[1] = s.q2;
    out->q[2] = s.q3;
    out->q[3] = s.q4;
    out->rollspeed = s.rollspeed;
    out->pitchspeed = s.pitchspeed;
    out->yawspeed = s.yawspeed;
    return OCC_OK;
}

occ_err_t occ_mav_decode_odometry(const occ_mav_frame_t *f, occ_mav_odometry_t *out)
{
    mavlink_odometry_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_ODOMETRY, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->time_usec = s.time_usec;
    out->frame_id = s.frame_id;
    out->child_frame_id = s.child_frame_id;
    out->x = s.x;
    out->y = s.y;
    out->z = s.z;
    for (unsigned i = 0; i < 4u; i++) {
        out->q[i] = s.q[i];
    }
    out->vx = s.vx;
    out->vy = s.vy;
    out->vz = s.vz;
    return OCC_OK;
}

occ_err_t occ_mav_decode_distance_sensor(const occ_mav_frame_t *f, occ_mav_distance_sensor_t *out)
{
    mavlink_distance_sensor_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_DISTANCE_SENSOR, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->time_boot_ms = s.time_boot_ms;
    out->min_distance = s.min_distance;
    out->max_distance = s.max_distance;
    out->current_distance = s.current_distance;
    out->type = s.type;
    out->id = s.id;
    out->orientation = s.orientation;
    out->covariance = s.covariance;
    out->horizontal_fov = s.horizontal_fov;
    out->vertical_fov = s.vertical_fov;
    for (unsigned i = 0; i < 4u; i++) {
        out->quaternion[i] = s.quaternion[i];
    }
    out->signal_quality = s.signal_quality;
    return OCC_OK;
}

occ_err_t occ_mav_decode_heartbeat(const occ_mav_frame_t *f, occ_mav_heartbeat_t *out)
{
    mavlink_heartbeat_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_HEARTBEAT, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->custom_mode = s.custom_mode;
    out->type = s.type;
    out->autopilot = s.autopilot;
    out->base_mode = s.base_mode;
    out->system_status = s.system_status;
    out->mavlink_version = s.mavlink_version;
    return OCC_OK;
}

occ_err_t occ_mav_decode_obstacle_distance(const occ_mav_frame_t *f, occ_mav_obstacle_distance_t *out)
{
    mavlink_obstacle_distance_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_OBSTACLE_DISTANCE, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->time_usec = s.time_usec;
    out->sensor_type = s.sensor_type;
    for (unsigned i = 0; i < 72u; i++) {
        out->distances[i] = s.distances[i];
    }
    out->increment = s.increment;
    out->min_distance = s.min_distance;
    out->max_distance = s.max_distance;
    out->increment_f = s.increment_f;
    out->angle_offset = s.angle_offset;
    out->frame = s.frame;
    return OCC_OK;
}

occ_err_t occ_mav_decode_command_long(const occ_mav_frame_t *f, occ_mav_command_long_t *out)
{
    mavlink_command_long_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_COMMAND_LONG, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->target_system = s.target_system;
    out->target_component = s.target_component;
    out->command = s.command;
    out->confirmation = s.confirmation;
    out->param[0] = s.param1;
    out->param[1] = s.param2;
    out->param[2] = s.param3;
    out->param[3] = s.param4;
    out->param[4] = s.param5;
    out->param[5] = s.param6;
    out->param[6] = s.param7;
    return OCC_OK;
}

occ_err_t occ_mav_decode_command_ack(const occ_mav_frame_t *f, occ_mav_command_ack_t *out)
{
    mavlink_command_ack_t s;
    if (out == NULL || !occi_mav_load(f, MAVLINK_MSG_ID_COMMAND_ACK, &s, sizeof s)) {
        return OCC_ERR_ARG;
    }
    out->command = s.command;
    out->result = s.result;
    out->progress = s.progress;
    out->result_param2 = s.result_param2;
    out->target_system = s.target_system;
    out->target_component = s.target_component;
    return OCC_OK;
}
