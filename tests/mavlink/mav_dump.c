/* SPDX-License-Identifier: BSD-3-Clause */
/* mav_dump.c OUT.bin OUT.txt - frames from our C encoder for pymavlink to decode
 * (tools/mav_check_c_frames.py): OBSTACLE_DISTANCE with random fields, including payloads whose
 * trailing zeros MAVLink 2 trims, and HEARTBEATs. Expected values go to OUT.txt, one line each. */
#include <stdio.h>
#include <stdlib.h>

#include "occmap/occ_mavlink.h"

static uint32_t rng = 12345u;
static uint32_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: mav_dump OUT.bin OUT.txt\n");
        return 2;
    }
    FILE *fb = fopen(argv[1], "wb");
    FILE *ft = fopen(argv[2], "w");
    if (fb == NULL || ft == NULL) {
        perror("mav_dump");
        return 1;
    }
    occ_mav_sender_t tx = {1, OCC_MAV_COMP_ID_OBSTACLE_AVOIDANCE, 250};
    uint8_t buf[OCC_MAV_FRAME_MAX];
    for (int i = 0; i < 40; i++) {
        size_t n;
        if (i % 5 == 4) {
            occ_mav_heartbeat_t hb = {next(), 18, 8, (uint8_t)next(), 4, 3};
            const uint8_t seq = tx.seq;
            n = occ_mav_encode_heartbeat(&tx, &hb, buf, sizeof buf);
            fprintf(ft, "0 %u %u %u %u %u %u %u %u %u\n", tx.sysid, tx.compid, seq,
                    (unsigned)hb.custom_mode, hb.type, hb.autopilot, hb.base_mode,
                    hb.system_status, hb.mavlink_version);
        } else {
            occ_mav_obstacle_distance_t m;
            m.time_usec = ((uint64_t)next() << 32) | next();
            m.sensor_type = (uint8_t)(next() % 5u);
            m.increment = (uint8_t)(i % 3 == 0 ? 0 : next());
            m.min_distance = (uint16_t)next();
            m.max_distance = (uint16_t)next();
            m.increment_f = i % 3 == 2 ? 0.0f : (float)(next() % 1000u) / 100.0f;
            m.angle_offset = i % 3 == 2 ? 0.0f : (float)((int)(next() % 3600u) - 1800) / 10.0f;
            m.frame = (uint8_t)(i % 3 == 2 ? 0 : 12);
            for (int k = 0; k < 72; k++) {
                const uint32_t r = next() % 4u;
                m.distances[k] = (uint16_t)(r == 0 ? UINT16_MAX : (r == 1 ? 0 : next() % 3000u));
            }
            if (i % 6 == 1) { /* trim into the distances array */
                for (int k = 40; k < 72; k++) {
                    m.distances[k] = 0;
                }
                m.min_distance = m.max_distance = 0;
                m.increment = 0;
                m.sensor_type = 0;
                m.increment_f = m.angle_offset = 0.0f;
                m.frame = 0;
            }
            const uint8_t seq = tx.seq;
            n = occ_mav_encode_obstacle_distance(&tx, &m, buf, sizeof buf);
            fprintf(ft, "330 %u %u %u %llu %u %u %u %u %.9g %.9g %u", tx.sysid, tx.compid, seq,
                    (unsigned long long)m.time_usec, m.sensor_type, m.increment, m.min_distance,
                    m.max_distance, (double)m.increment_f, (double)m.angle_offset, m.frame);
            for (int k = 0; k < 72; k++) {
                fprintf(ft, " %u", m.distances[k]);
            }
            fprintf(ft, "\n");
        }
        if (n == 0 || fwrite(buf, 1, n, fb) != n) {
            fprintf(stderr, "mav_dump: encode/write failed\n");
            return 1;
        }
    }
    fclose(fb);
    fclose(ft);
    return 0;
}
