/* SPDX-License-Identifier: BSD-3-Clause */
/* range_rx.c - uavcan.equipment.range_sensor.Measurement in: transfer reassembly (tail bytes,
 * toggles, CRC seeded by the signature), the DSDL decode, and the beam with its mount. */
#include <math.h>
#include <string.h>

#include "occmap/occ_dronecan.h"

/* Bit offsets of the fields (DSDL v0, 120 bits). */
#define BIT_TIMESTAMP 0u
#define BIT_SENSOR_ID 56u
#define BIT_ORIENT 64u   /* int5[3] then bool orientation_defined */
#define BIT_FOV 80u
#define BIT_SENSOR_TYPE 96u
#define BIT_READING 101u
#define BIT_RANGE 104u
#define MAX_FRAME_DATA 64u

static int8_t int5(const uint64_t v)
{
    return (int8_t)((v & 0x10u) != 0u ? (int)v - 32 : (int)v);
}

occ_err_t occ_dronecan_decode_range(const uint8_t *const payload, const size_t len,
                                    occ_dronecan_range_t *const out)
{
    if (payload == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    if (len != OCC_DRONECAN_RANGE_BYTES) {
        return OCC_ERR_FORMAT;
    }
    occ_dronecan_range_t m;
    m.timestamp_us = occ_dronecan_get_bits(payload, BIT_TIMESTAMP, 56);
    m.sensor_id = (uint8_t)occ_dronecan_get_bits(payload, BIT_SENSOR_ID, 8);
    for (unsigned a = 0; a < 3u; a++) {
        m.orientation_rpy[a] = int5(occ_dronecan_get_bits(payload, BIT_ORIENT + 5u * a, 5));
    }
    m.orientation_defined = occ_dronecan_get_bits(payload, BIT_ORIENT + 15u, 1) != 0u;
    m.field_of_view_rad = occ_float16_to_float((uint16_t)occ_dronecan_get_bits(payload, BIT_FOV, 16));
    m.sensor_type = (uint8_t)occ_dronecan_get_bits(payload, BIT_SENSOR_TYPE, 5);
    m.reading_type = (uint8_t)occ_dronecan_get_bits(payload, BIT_READING, 3);
    m.range_m = occ_float16_to_float((uint16_t)occ_dronecan_get_bits(payload, BIT_RANGE, 16));
    *out = m;
    return OCC_OK;
}

occ_err_t occ_dronecan_range_beam(const occ_dronecan_range_t *const msg,
                                  const occ_dronecan_range_mount_t *const mounts,
                                  const size_t n_mounts, occ_range_beam_t *const beam,
                                  const occ_dronecan_range_mount_t **const mount)
{
    if (msg == NULL || (mounts == NULL && n_mounts > 0u) || beam == NULL || mount == NULL) {
        return OCC_ERR_ARG;
    }
    const occ_dronecan_range_mount_t *found = NULL;
    for (size_t i = 0; i < n_mounts && found == NULL; i++) {
        found = mounts[i].sensor_id == msg->sensor_id ? &mounts[i] : NULL;
    }
    if (found == NULL) {
        return OCC_ERR_UNSUPPORTED;
    }
    occ_range_beam_t b;
    memset(&b, 0, sizeof b);
    b.dir.x = 1.0f;
    b.min_m = found->min_m;
    b.max_m = found->max_m;
    b.distance_m = msg->reading_type == OCC_DRONECAN_RANGE_TOO_FAR ? found->max_m : msg->range_m;
    const float fov = msg->field_of_view_rad;
    const bool fov_ok = isfinite(fov) && fov >= 0.0f && fov <= 2.0f * OCC_RANGES_CONE_MAX_RAD;
    b.cone_half_rad = fov_ok ? 0.5f * fov : 0.0f;
    b.valid = fov_ok && (msg->reading_type == OCC_DRONECAN_RANGE_VALID ||
                         msg->reading_type == OCC_DRONECAN_RANGE_TOO_FAR);
    *beam = b;
    *mount = found;
    return OCC_OK;
}

occ_err_t occ_dronecan_range_rx_init(occ_dronecan_range_rx_t *const rx,
                                     const occ_dronecan_range_mount_t *const mounts,
                                     const size_t n_mounts)
{
    if (rx == NULL || (mounts == NULL && n_mounts > 0u)) {
        return OCC_ERR_ARG;
    }
    for (size_t i = 0; i < n_mounts; i++) {
        const occ_dronecan_range_mount_t *const m = &mounts[i];
        if (occ_pose_check(&m->body_from_sensor) != OCC_OK || !isfinite(m->min_m) ||
            !isfinite(m->max_m) || m->min_m < 0.0f || !(m->min_m < m->max_m)) {
            return OCC_ERR_ARG;
        }
        for (size_t j = 0; j < i; j++) {
            if (mounts[j].sensor_id == m->sensor_id) {
                return OCC_ERR_ARG;
            }
        }
    }
    memset(rx, 0, sizeof *rx);
    rx->mounts_ = mounts;
    rx->n_mounts_ = n_mounts;
    return OCC_OK;
}

/* The slot of source `src`, or (start frames only) a free or the oldest one; NULL if none. */
static size_t slot_for(const occ_dronecan_range_rx_t *const rx, const uint8_t src,
                       const bool start)
{
    size_t pick = OCC_DRONECAN_RANGE_RX_SLOTS;
    for (size_t i = 0; i < OCC_DRONECAN_RANGE_RX_SLOTS; i++) {
        if (rx->slot_[i].busy_ && rx->slot_[i].src_ == src) {
            return i;
        }
    }
    if (!start) {
        return pick;
    }
    for (size_t i = 0; i < OCC_DRONECAN_RANGE_RX_SLOTS; i++) {
        if (!rx->slot_[i].busy_) {
            return i;
        }
        if (pick == OCC_DRONECAN_RANGE_RX_SLOTS ||
            rx->slot_[i].start_us_ < rx->slot_[pick].start_us_) {
            pick = i;
        }
    }
    return pick;
}

/* The completed payload of a transfer into a reading (CRC checked for multi-frame ones). */
static bool finish(occ_dronecan_range_rx_t *const rx, const uint8_t src, const uint8_t *const p,
                   const size_t len, const bool multi, occ_dronecan_range_reading_t *const out)
{
    const uint8_t *payload = p;
    size_t n = len;
    if (multi) {
        const uint16_t crc = (uint16_t)(p[0] | (uint16_t)(p[1] << 8));
        payload = p + 2;
        n = len - 2u;
        if (occ_dronecan_crc16(occ_dronecan_crc_seed(OCC_DRONECAN_RANGE_SIG), payload, n) != crc) {
            rx->crc_errors++;
            return false;
        }
    }
    occ_dronecan_range_reading_t r;
    if (occ_dronecan_decode_range(payload, n, &r.msg) != OCC_OK) {
        rx->bad_payload++;
        return false;
    }
    if (occ_dronecan_range_beam(&r.msg, rx->mounts_, rx->n_mounts_, &r.beam, &r.mount) != OCC_OK) {
        rx->unknown_sensor++;
        return false;
    }
    r.src_node = src;
    *out = r;
    rx->readings++;
    return true;
}

/* A Measurement message frame: extended, not RTR/error, not a service, not anonymous. */
static bool is_measurement(const occ_can_frame_t *const f)
{
    return (f->flags & (OCC_CAN_FLAG_EXT | OCC_CAN_FLAG_RTR | OCC_CAN_FLAG_ERR)) ==
               OCC_CAN_FLAG_EXT &&
           f->len > 0u && f->len <= MAX_FRAME_DATA && (f->id & 0x80u) == 0u &&
           (f->id & 0x7Fu) != 0u && ((f->id >> 8) & 0xFFFFu) == OCC_DRONECAN_RANGE_ID;
}

occ_err_t occ_dronecan_range_rx_frame(occ_dronecan_range_rx_t *const rx,
                                      const occ_can_frame_t *const frame, const uint64_t now_us,
                                      occ_dronecan_range_reading_t *const out, bool *const got)
{
    if (got != NULL) {
        *got = false;
    }
    if (rx == NULL || frame == NULL || out == NULL || got == NULL) {
        return OCC_ERR_ARG;
    }
    if (!is_measurement(frame)) {
        return OCC_OK;
    }
    rx->frames++;
    const uint8_t src = (uint8_t)(frame->id & 0x7Fu);
    const uint8_t tail = frame->data[frame->len - 1u];
    const bool start = (tail & OCC_DRONECAN_TAIL_START) != 0u;
    const bool end = (tail & OCC_DRONECAN_TAIL_END) != 0u;
    const uint8_t toggle = (tail & OCC_DRONECAN_TAIL_TOGGLE) != 0u ? 1u : 0u;
    const uint8_t tid = (uint8_t)(tail & OCC_DRONECAN_TAIL_TID);
    const size_t n = frame->len - 1u;
    if (start && end) {
        *got = toggle == 0u && finish(rx, src, frame->data, n, false, out);
        rx->sequence_errors += toggle != 0u ? 1u : 0u;
        return OCC_OK;
    }
    const size_t i = slot_for(rx, src, start);
    if (i == OCC_DRONECAN_RANGE_RX_SLOTS) {
        rx->sequence_errors++; /* a middle or end frame of no transfer we follow */
        return OCC_OK;
    }
    occ_dronecan_range_slot_t *const s = &rx->slot_[i];
    if (start) {
        s->busy_ = true; /* a new transfer replaces whatever the slot held */
        s->src_ = src;
        s->tid_ = tid;
        s->toggle_ = 0;
        s->len_ = 0;
        s->start_us_ = now_us;
    }
    const bool in_sequence = toggle == s->toggle_ && tid == s->tid_ &&
                             now_us - s->start_us_ <= OCC_DRONECAN_RANGE_RX_TIMEOUT_US &&
                             n <= sizeof s->buf_ - s->len_;
    if (!in_sequence) {
        s->busy_ = false;
        rx->sequence_errors++;
        return OCC_OK;
    }
    memcpy(s->buf_ + s->len_, frame->data, n);
    s->len_ = (uint8_t)(s->len_ + n);
    s->toggle_ ^= 1u;
    if (end) {
        s->busy_ = false;
        *got = s->len_ >= 2u && finish(rx, src, s->buf_, s->len_, true, out);
        rx->bad_payload += s->len_ < 2u ? 1u : 0u;
    }
    return OCC_OK;
}
