/* SPDX-License-Identifier: BSD-3-Clause */
/* golden_dump.c - reads DroneCAN test cases (one per line, hex fields) from stdin and prints the
 * frames occmap's encoder makes for each, one line per case: "ID:DATA ID:DATA ...". Driven by
 * tests/can/golden.py, which compares them with pydronecan's frames byte for byte. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_dronecan.h"

typedef struct {
    occ_can_frame_t f[32];
    size_t n;
} sink_t;

static occ_err_t sink_tx(void *user, const occ_can_frame_t *fr)
{
    sink_t *s = user;
    if (s->n >= 32u) {
        return OCC_ERR_NOMEM;
    }
    s->f[s->n++] = *fr;
    return OCC_OK;
}

static float f_bits(unsigned long u)
{
    const uint32_t v = (uint32_t)u;
    float f;
    memcpy(&f, &v, sizeof f);
    return f;
}

static size_t hex_bytes(const char *s, uint8_t *out, size_t cap)
{
    if (strcmp(s, "-") == 0) {
        return 0;
    }
    size_t n = 0;
    while (s[0] != '\0' && s[1] != '\0' && n < cap) {
        unsigned v;
        if (sscanf(s, "%2x", &v) != 1) {
            break;
        }
        out[n++] = (uint8_t)v;
        s += 2;
    }
    return n;
}

static void print_frames(const sink_t *s)
{
    for (size_t i = 0; i < s->n; i++) {
        printf("%s%08" PRIX32 ":", i ? " " : "", s->f[i].id);
        for (size_t k = 0; k < s->f[i].len; k++) {
            printf("%02x", s->f[i].data[k]);
        }
    }
    printf("\n");
}

int main(void)
{
    char line[1024];
    while (fgets(line, sizeof line, stdin) != NULL) {
        sink_t sink;
        memset(&sink, 0, sizeof sink);
        const occ_can_iface_t iface = {sink_tx, NULL, &sink};
        unsigned prio, node, tid;
        occ_err_t e = OCC_ERR_FORMAT;
        if (line[0] == 'P') {
            unsigned sensor, type, flags;
            unsigned long yaw, pitch, dist;
            if (sscanf(line + 1, "%x %x %x %x %x %x %lx %lx %lx", &prio, &node, &tid, &sensor,
                       &type, &flags, &yaw, &pitch, &dist) == 9) {
                occ_dronecan_proximity_t m;
                m.sensor_id = (uint8_t)sensor;
                m.reading_type = (occ_prox_reading_t)type;
                m.flags = (uint8_t)flags;
                m.yaw_deg = f_bits(yaw);
                m.pitch_deg = f_bits(pitch);
                m.distance_m = f_bits(dist);
                uint8_t p[8];
                const size_t len = occ_dronecan_encode_proximity(&m, p);
                e = occ_dronecan_send_transfer(
                    &iface, occ_dronecan_msg_id((uint8_t)prio, OCC_DRONECAN_PROXIMITY_ID, (uint8_t)node),
                    OCC_DRONECAN_PROXIMITY_SIG, (uint8_t)tid, p, len, NULL);
            }
        } else if (line[0] == 'S') {
            unsigned long up;
            unsigned health, mode, sub, vendor;
            if (sscanf(line + 1, "%x %x %x %lx %x %x %x %x", &prio, &node, &tid, &up, &health,
                       &mode, &sub, &vendor) == 8) {
                occ_dronecan_node_status_t st;
                st.uptime_sec = (uint32_t)up;
                st.health = (uint8_t)health;
                st.mode = (uint8_t)mode;
                st.sub_mode = (uint8_t)sub;
                st.vendor_status = (uint16_t)vendor;
                uint8_t p[7];
                const size_t len = occ_dronecan_encode_node_status(&st, p);
                e = occ_dronecan_send_transfer(
                    &iface, occ_dronecan_msg_id((uint8_t)prio, OCC_DRONECAN_NODESTATUS_ID, (uint8_t)node),
                    OCC_DRONECAN_NODESTATUS_SIG, (uint8_t)tid, p, len, NULL);
            }
        } else if (line[0] == 'I') {
            unsigned dst, health, mode, sub, vendor, swmaj, swmin, swfl, hwmaj, hwmin;
            unsigned long up, vcs;
            unsigned long long crc;
            char uid_hex[64], name_hex[300];
            if (sscanf(line + 1, "%x %x %x %x %lx %x %x %x %x %x %x %x %lx %llx %x %x %63s %299s",
                       &prio, &dst, &node, &tid, &up, &health, &mode, &sub, &vendor, &swmaj,
                       &swmin, &swfl, &vcs, &crc, &hwmaj, &hwmin, uid_hex, name_hex) == 18) {
                occ_dronecan_node_info_t info;
                memset(&info, 0, sizeof info);
                info.status.uptime_sec = (uint32_t)up;
                info.status.health = (uint8_t)health;
                info.status.mode = (uint8_t)mode;
                info.status.sub_mode = (uint8_t)sub;
                info.status.vendor_status = (uint16_t)vendor;
                info.sw_major = (uint8_t)swmaj;
                info.sw_minor = (uint8_t)swmin;
                info.sw_optional_flags = (uint8_t)swfl;
                info.vcs_commit = (uint32_t)vcs;
                info.image_crc = (uint64_t)crc;
                info.hw_major = (uint8_t)hwmaj;
                info.hw_minor = (uint8_t)hwmin;
                (void)hex_bytes(uid_hex, info.unique_id, 16);
                char name[128];
                const size_t nl = hex_bytes(name_hex, (uint8_t *)name, sizeof name - 1u);
                name[nl] = '\0';
                info.name = name;
                uint8_t p[OCC_DRONECAN_MAX_PAYLOAD];
                const size_t len = occ_dronecan_encode_node_info(&info, p, sizeof p);
                e = occ_dronecan_send_transfer(
                    &iface, occ_dronecan_svc_id((uint8_t)prio, OCC_DRONECAN_GETNODEINFO_ID, false,
                                                (uint8_t)dst, (uint8_t)node),
                    OCC_DRONECAN_GETNODEINFO_SIG, (uint8_t)tid, p, len, NULL);
            }
        }
        if (e != OCC_OK) {
            fprintf(stderr, "golden_dump: bad case or send error %d: %s", (int)e, line);
            return 1;
        }
        print_frames(&sink);
    }
    return 0;
}
