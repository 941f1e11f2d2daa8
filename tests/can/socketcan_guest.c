/* SPDX-License-Identifier: BSD-3-Clause */
/* socketcan_guest.c - the SocketCAN port and the DroneCAN node against a real kernel CAN stack.
 * Runs inside the qemu guest (tests/can/qemu_socketcan.sh) on vcan0; prints one line per check
 * and "OCC-SOCKETCAN checks=N failed=M", exits 0 only if nothing failed. Linked statically. */
#include <stdio.h>
#include <string.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>

#include "occmap/occ_dronecan.h"
#include "occmap/host/occ_socketcan.h"

static int checks, failed;

static void check(bool ok, const char *what)
{
    checks++;
    if (!ok) {
        failed++;
    }
    printf("%s %s\n", ok ? "ok  " : "FAIL", what);
    fflush(stdout);
}

static occ_can_frame_t frame(uint32_t id, uint8_t flags, uint8_t len, uint8_t seed)
{
    occ_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.flags = flags;
    f.len = len;
    for (unsigned i = 0; i < len; i++) {
        f.data[i] = (uint8_t)(seed + 3u * i);
    }
    return f;
}

static bool same(const occ_can_frame_t *a, const occ_can_frame_t *b)
{
    return a->id == b->id && a->flags == b->flags && a->len == b->len &&
           memcmp(a->data, b->data, a->len) == 0;
}

/* Receive one frame within 200 ms. */
static bool rx1(occ_socketcan_t *s, occ_can_frame_t *f)
{
    bool got = false;
    return occ_socketcan_recv(s, f, 200, &got) == OCC_OK && got;
}

static bool rx_none(occ_socketcan_t *s)
{
    occ_can_frame_t f;
    bool got = true;
    return occ_socketcan_recv(s, &f, 50, &got) == OCC_OK && !got;
}

static void drain(occ_socketcan_t *s)
{
    occ_can_frame_t f;
    bool got = true;
    while (got && occ_socketcan_recv(s, &f, 0, &got) == OCC_OK) {
    }
}

int main(int argc, char **argv)
{
    const char *ifname = argc > 1 ? argv[1] : "vcan0";
    char msg[160] = "";
    occ_socketcan_t a, b, c, d;
    if (occ_socketcan_open(&a, ifname, false, msg, sizeof msg) != OCC_OK) {
        printf("FAIL open %s: %s\nOCC-SOCKETCAN checks=1 failed=1\n", ifname, msg);
        return 1;
    }
    check(occ_socketcan_open(&b, ifname, true, msg, sizeof msg) == OCC_OK, "open FD socket B");
    check(occ_socketcan_open(&c, ifname, false, msg, sizeof msg) == OCC_OK, "open classic socket C");
    check(occ_socketcan_open(&d, ifname, true, msg, sizeof msg) == OCC_OK, "open FD socket D");
    occ_socketcan_t bad;
    check(occ_socketcan_open(&bad, "nosuch0", false, msg, sizeof msg) == OCC_ERR_IO,
          "open of a missing interface fails with OCC_ERR_IO");

    /* Classic frames, 29- and 11-bit ids, RTR. */
    const occ_can_frame_t f1 = frame(0x1F559664u, OCC_CAN_FLAG_EXT, 8, 1);
    const occ_can_frame_t f2 = frame(0x123u, 0, 3, 9);
    const occ_can_frame_t f3 = frame(0x7FFu, OCC_CAN_FLAG_RTR, 0, 0);
    occ_can_frame_t r;
    check(occ_socketcan_send(&a, &f1) == OCC_OK, "send classic EXT frame");
    check(rx1(&c, &r) && same(&r, &f1), "classic EXT frame round trip (C)");
    check(rx1(&b, &r) && same(&r, &f1), "classic frame read on an FD socket stays classic (B)");
    check(occ_socketcan_send(&a, &f2) == OCC_OK && rx1(&c, &r) && same(&r, &f2),
          "11-bit frame round trip");
    check(occ_socketcan_send(&a, &f3) == OCC_OK && rx1(&c, &r) && same(&r, &f3), "RTR round trip");
    check(rx_none(&a), "no echo of own frames");
    drain(&b);
    drain(&d);

    /* Receive filters. */
    const occ_can_filter_t std155 = {0x155u, 0x7FFu, false};
    check(occ_socketcan_set_filters(&c, &std155, 1) == OCC_OK, "set 11-bit filter");
    const occ_can_frame_t g1 = frame(0x1F015564u, OCC_CAN_FLAG_EXT, 8, 2);
    const occ_can_frame_t g2 = frame(0x155u, 0, 8, 3);
    const occ_can_frame_t g3 = frame(0x156u, 0, 8, 4);
    (void)occ_socketcan_send(&a, &g1);
    (void)occ_socketcan_send(&a, &g2);
    (void)occ_socketcan_send(&a, &g3);
    check(rx1(&c, &r) && same(&r, &g2) && rx_none(&c), "11-bit filter passes only 0x155");
    const occ_can_filter_t prox = {(uint32_t)OCC_DRONECAN_PROXIMITY_ID << 8, 0xFFFF80u, true};
    check(occ_socketcan_set_filters(&c, &prox, 1) == OCC_OK, "set 29-bit data type filter");
    (void)occ_socketcan_send(&a, &g1);
    (void)occ_socketcan_send(&a, &f1);
    (void)occ_socketcan_send(&a, &g2);
    check(rx1(&c, &r) && same(&r, &f1) && rx_none(&c), "29-bit filter passes only Proximity");
    check(occ_socketcan_set_filters(&c, NULL, 0) == OCC_OK, "clear filters");
    (void)occ_socketcan_send(&a, &f1);
    check(rx_none(&c), "no filters: nothing received");
    check(occ_socketcan_set_filters(&c, &(occ_can_filter_t){0, 0, true}, 1) == OCC_OK,
          "accept all 29-bit");
    drain(&b);
    drain(&d);

    /* CAN FD. */
    const occ_can_frame_t fd64 = frame(0x10AB1234u, OCC_CAN_FLAG_EXT | OCC_CAN_FLAG_FD | OCC_CAN_FLAG_BRS,
                                       64, 7);
    check(occ_socketcan_send(&b, &fd64) == OCC_OK, "send 64-byte FD frame with BRS");
    check(rx1(&d, &r) && same(&r, &fd64), "FD frame round trip with BRS flag");
    check(rx_none(&c), "classic socket does not see FD frames");
    check(occ_socketcan_send(&a, &fd64) == OCC_ERR_ARG, "FD frame on a classic socket refused");
    occ_can_frame_t fd13 = fd64;
    fd13.len = 13;
    check(occ_socketcan_send(&b, &fd13) == OCC_ERR_ARG, "invalid FD length refused");
    occ_can_frame_t long_classic = f1;
    long_classic.len = 9;
    check(occ_socketcan_send(&a, &long_classic) == OCC_ERR_ARG, "classic frame > 8 bytes refused");
    drain(&a);

    /* Error frames: a raw socket reports bus-off the way a controller driver does. */
    {
        const int e = socket(PF_CAN, SOCK_RAW, CAN_RAW);
        struct can_frame ef;
        memset(&ef, 0, sizeof ef);
        ef.can_id = CAN_ERR_FLAG | 0x40u; /* CAN_ERR_BUSOFF */
        ef.can_dlc = 8;
        struct sockaddr_can addr;
        memset(&addr, 0, sizeof addr);
        addr.can_family = AF_CAN;
        addr.can_ifindex = 0;
        bool sent = false;
        if (e >= 0) {
            /* bound to all interfaces (index 0); sendto names the interface */
            if (bind(e, (struct sockaddr *)&addr, sizeof addr) == 0) {
                addr.can_ifindex = (int)if_nametoindex(ifname);
                sent = sendto(e, &ef, sizeof ef, 0, (struct sockaddr *)&addr, sizeof addr) ==
                       (ssize_t)sizeof ef;
            }
            close(e);
        }
        bool got = false;
        bool seen = false;
        for (int i = 0; i < 4 && !seen; i++) {
            if (occ_socketcan_recv(&a, &r, 100, &got) == OCC_OK && got &&
                (r.flags & OCC_CAN_FLAG_ERR) != 0u) {
                seen = (r.id & OCC_CAN_ERR_BUS_OFF) != 0u;
            }
        }
        check(sent && seen && a.rx_errors >= 1u, "bus-off error frame reported as OCC_CAN_FLAG_ERR");
        drain(&c);
        drain(&b);
        drain(&d);
    }

    /* The DroneCAN node on socket A; C listens like an autopilot. */
    occ_dronecan_config_t cfg = occ_dronecan_config_default();
    cfg.node_id = 100;
    cfg.sensor_id = 1;
    cfg.priority = 31;
    cfg.unique_id[0] = 0x0C;
    const occ_can_iface_t iface = occ_socketcan_iface(&a);
    occ_dronecan_node_t node;
    check(occ_dronecan_init(&node, &cfg, &iface) == OCC_OK, "node init");
    occ_sectors_config_t sc;
    memset(&sc, 0, sizeof sc);
    sc.n_sectors = 8;
    sc.increment_deg = 45.0f;
    sc.min_distance_cm = 20;
    sc.max_distance_cm = 2000;
    occ_sectors_t s;
    memset(&s, 0, sizeof s);
    s.n = 8;
    for (unsigned i = 0; i < 8; i++) {
        s.distance_cm[i] = 2000;
    }
    s.distance_cm[1] = 350;   /* yaw 45, 3.5 m: the note's golden frame */
    s.distance_cm[4] = 1000;  /* yaw 180 */
    s.distance_cm[7] = 80;    /* yaw -45 */
    const occ_dronecan_view_t good = {true, true, &s, &sc};
    const occ_dronecan_view_t stale = {true, false, NULL, NULL};
    const occ_dronecan_view_t nomap = {false, false, NULL, NULL};
    const uint64_t t0 = 5000000u;
    occ_err_t pe = OCC_OK;
    for (unsigned k = 0; k < 3; k++) {
        pe = occ_dronecan_poll(&node, t0 + 100000u * k, &good);
    }
    check(pe == OCC_OK && node.stats.proximity_sent == 9u, "node sent 3 rounds x 3 obstacles");
    (void)occ_dronecan_poll(&node, t0 + 300000u, &stale);
    (void)occ_dronecan_poll(&node, t0 + 1000000u, &nomap);
    unsigned prox_frames = 0, status_frames = 0, other = 0;
    bool got = true;
    while (got && occ_socketcan_recv(&c, &r, 50, &got) == OCC_OK && got) {
        const uint32_t dt = (r.id >> 8) & 0xFFFFu;
        if ((r.id & 0x80u) == 0u && dt == OCC_DRONECAN_PROXIMITY_ID) {
            prox_frames++;
        } else if ((r.id & 0x80u) == 0u && dt == OCC_DRONECAN_NODESTATUS_ID) {
            status_frames++;
        } else {
            other++;
        }
    }
    printf("info proximity frames %u, status frames %u, other %u\n", prox_frames, status_frames,
           other);
    check(prox_frames == 2u * 11u && status_frames == 2u && other == 0u,
          "reader saw 11 Proximity transfers (9 GOOD, NO_DATA, NOT_CONNECTED) and 2 NodeStatus");

    /* GetNodeInfo: C (as node 10) asks, the node answers through A. */
    const occ_can_frame_t req = {occ_dronecan_svc_id(30, 1, true, 100, 10), 1, OCC_CAN_FLAG_EXT,
                                 {0xC5}};
    check(occ_socketcan_send(&c, &req) == OCC_OK, "GetNodeInfo request sent");
    bool answered = false;
    for (int i = 0; i < 5 && !answered; i++) {
        if (occ_socketcan_recv(&a, &r, 100, &got) == OCC_OK && got) {
            (void)occ_dronecan_ingest(&node, &r, t0 + 1100000u);
            answered = node.stats.node_info_answered == 1u;
        }
    }
    check(answered, "node answered GetNodeInfo");
    uint8_t stream[160];
    size_t sl = 0, nf = 0;
    bool ended = false;
    while (!ended && rx1(&c, &r)) {
        if (r.id != occ_dronecan_svc_id(30, 1, false, 10, 100) || r.len == 0u || sl + r.len > sizeof stream) {
            continue;
        }
        memcpy(stream + sl, r.data, r.len - 1u);
        sl += r.len - 1u;
        nf++;
        ended = (r.data[r.len - 1u] & OCC_DRONECAN_TAIL_END) != 0u &&
                (r.data[r.len - 1u] & OCC_DRONECAN_TAIL_TID) == 5u;
    }
    const char *name = "org.occmap.obstacles";
    const size_t plen = 41u + strlen(name);
    check(ended && sl == plen + 2u &&
              (uint16_t)(stream[0] | (stream[1] << 8)) ==
                  occ_dronecan_crc16(occ_dronecan_crc_seed(OCC_DRONECAN_GETNODEINFO_SIG),
                                     stream + 2, plen) &&
              memcmp(stream + 2 + 41, name, strlen(name)) == 0,
          "GetNodeInfo response reassembled, CRC and name right");
    printf("info GetNodeInfo response: %zu frames\n", nf);

    occ_socketcan_close(&a);
    occ_socketcan_close(&b);
    occ_socketcan_close(&c);
    occ_socketcan_close(&d);
    printf("OCC-SOCKETCAN checks=%d failed=%d\n", checks, failed);
    return failed == 0 ? 0 : 1;
}
