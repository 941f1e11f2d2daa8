/* SPDX-License-Identifier: BSD-3-Clause */
/* fuzz_mavlink.c - libFuzzer harness for the MAVLink frame parser and the decoders.
 * Invariants checked on every input: the parser never reads or writes outside its buffer
 * (ASan), every byte is accounted for in exactly one place, a frame handed out lies inside
 * the parser's buffer with a consistent length, and a good frame re-encodes to itself when it
 * is an unsigned MAVLink 2 frame whose payload has no trailing zero. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_mavlink.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static occ_mav_parser_t p;
    occ_mav_parser_init(&p);
    uint32_t results = 0;
    for (size_t i = 0; i < size; i++) {
        occ_mav_frame_t f;
        const occ_mav_result_t r = occ_mav_parser_push(&p, data[i], &f);
        if (r == OCC_MAV_NONE || r == OCC_MAV_JUNK) {
            continue;
        }
        results++;
        if (f.frame != p.priv.buf || f.frame_len > OCC_MAV_FRAME_MAX ||
            f.payload + f.len > f.frame + f.frame_len) {
            abort();
        }
        if (r != OCC_MAV_OK) {
            continue;
        }
        /* Decoders must accept any good frame of their id. */
        union {
            occ_mav_local_position_ned_t lp;
            occ_mav_attitude_t at;
            occ_mav_attitude_quaternion_t aq;
            occ_mav_odometry_t od;
            occ_mav_distance_sensor_t ds;
            occ_mav_heartbeat_t hb;
            occ_mav_obstacle_distance_t ob;
        } u;
        occ_err_t e = OCC_OK;
        switch (f.msgid) {
        case OCC_MAV_MSG_LOCAL_POSITION_NED: e = occ_mav_decode_local_position_ned(&f, &u.lp); break;
        case OCC_MAV_MSG_ATTITUDE: e = occ_mav_decode_attitude(&f, &u.at); break;
        case OCC_MAV_MSG_ATTITUDE_QUATERNION: e = occ_mav_decode_attitude_quaternion(&f, &u.aq); break;
        case OCC_MAV_MSG_ODOMETRY: e = occ_mav_decode_odometry(&f, &u.od); break;
        case OCC_MAV_MSG_DISTANCE_SENSOR: e = occ_mav_decode_distance_sensor(&f, &u.ds); break;
        case OCC_MAV_MSG_HEARTBEAT: e = occ_mav_decode_heartbeat(&f, &u.hb); break;
        case OCC_MAV_MSG_OBSTACLE_DISTANCE: e = occ_mav_decode_obstacle_distance(&f, &u.ob); break;
        default: break;
        }
        if (e != OCC_OK) {
            abort();
        }
        if (f.version == 2 && !f.is_signed && f.len > 0 && f.payload[f.len - 1] != 0 &&
            f.incompat_flags == 0 && f.compat_flags == 0) {
            occ_mav_sender_t tx = {f.sysid, f.compid, f.seq};
            uint8_t out[OCC_MAV_FRAME_MAX];
            uint8_t copy[OCC_MAV_FRAME_MAX];
            memcpy(copy, f.frame, f.frame_len);
            const size_t n = occ_mav_finalize(&tx, f.msgid, copy + 10, f.len, out, sizeof out);
            if (n != f.frame_len || memcmp(out, copy, n) != 0) {
                abort();
            }
        }
    }
    const occ_mav_counters_t *c = &p.counters;
    if (c->bytes != size ||
        c->frames_ok + c->bad_crc + c->bad_len + c->unknown_id + c->bad_flags != results) {
        abort();
    }
    return 0;
}
