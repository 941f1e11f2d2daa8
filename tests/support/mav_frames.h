/* SPDX-License-Identifier: BSD-3-Clause */
/* mav_frames.h - MAVLink test fixtures shared by test_mavlink.c (the wire) and
 * test_mavlink_feed.c (the feed): exact float equality, a byte-wise parse and an ATTITUDE frame.
 * static inline, so a test that uses only some of them builds without warnings. */
#ifndef OCC_TEST_MAV_FRAMES_H_INCLUDED
#define OCC_TEST_MAV_FRAMES_H_INCLUDED

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "occmap/occ_mavlink.h"
#include "ardupilotmega/mavlink.h"

static inline bool feq(double a, double b)
{
    return !(a < b) && !(a > b);
}

static inline size_t parse_all(occ_mav_parser_t *p, const uint8_t *b, size_t n, occ_mav_result_t *last,
                        occ_mav_frame_t *fr)
{
    size_t frames = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_mav_result_t r = occ_mav_parser_push(p, b[i], fr);
        if (r != OCC_MAV_NONE && r != OCC_MAV_JUNK) {
            frames++;
            if (last != NULL) {
                *last = r;
            }
        }
    }
    return frames;
}

/* A valid MAVLink 2 ATTITUDE frame. */
static inline size_t attitude_frame(occ_mav_sender_t *tx, float yaw, uint8_t *buf)
{
    mavlink_attitude_t a;
    memset(&a, 0, sizeof a);
    a.time_boot_ms = 1000;
    a.yaw = yaw;
    a.roll = 0.1f;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_ATTITUDE, (const uint8_t *)&a, sizeof a, buf,
                            OCC_MAV_FRAME_MAX);
}

#endif
