/* SPDX-License-Identifier: BSD-3-Clause */
/* test_dronecan_node.c - the DroneCAN node (occ_dronecan_*): init, transfer ids and toggles,
 * a full queue, GetNodeInfo, the publication schedule, sectors, and the node fed from a real
 * map. The transfer layer and messages: test_dronecan.c. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occ_dronecan.h"
#include "support/can_capture.h"

/* ---- The node -------------------------------------------------------------------------------- */
static occ_dronecan_node_t node;

static void make_node(uint8_t node_id)
{
    occ_dronecan_config_t cfg = occ_dronecan_config_default();
    cfg.node_id = node_id;
    cfg.sensor_id = 3;
    cfg.priority = 31;
    cfg.unique_id[0] = 0xAA;
    cfg.unique_id[15] = 0x55;
    const occ_can_iface_t iface = cap_iface();
    assert_int_equal(occ_dronecan_init(&node, &cfg, &iface), OCC_OK);
}

static void test_init_args(void **state)
{
    (void)state;
    occ_dronecan_config_t cfg = occ_dronecan_config_default();
    const occ_can_iface_t iface = cap_iface();
    assert_int_equal(occ_dronecan_init(&node, &cfg, &iface), OCC_ERR_ARG); /* node id 0 */
    cfg.node_id = 128;
    assert_int_equal(occ_dronecan_init(&node, &cfg, &iface), OCC_ERR_ARG);
    cfg.node_id = 5;
    cfg.priority = 32;
    assert_int_equal(occ_dronecan_init(&node, &cfg, &iface), OCC_ERR_ARG);
    cfg.priority = 0;
    cfg.status_period_us = 2000000u;
    assert_int_equal(occ_dronecan_init(&node, &cfg, &iface), OCC_ERR_ARG);
    cfg.status_period_us = 1000000u;
    const occ_can_iface_t none = {NULL, NULL, NULL};
    assert_int_equal(occ_dronecan_init(&node, &cfg, &none), OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_init(&node, &cfg, &iface), OCC_OK);
}

static void test_tid_and_toggle_wrap(void **state)
{
    (void)state;
    make_node(100);
    const occ_dronecan_proximity_t m = {1, OCC_PROX_GOOD, 0, 45.0f, 0.0f, 3.5f};
    for (unsigned i = 0; i < 70; i++) {
        assert_int_equal(occ_dronecan_publish_proximity(&node, &m), OCC_OK);
    }
    assert_int_equal(cap.n, 140);
    for (unsigned i = 0; i < 70; i++) {
        const uint8_t t0 = cap.frames[2 * i].data[7];
        const uint8_t t1 = cap.frames[2 * i + 1].data[3];
        assert_int_equal(t0, 0x80u | (i % 32u));        /* start, toggle 0 */
        assert_int_equal(t1, 0x60u | (i % 32u));        /* end, toggle 1 */
    }
    /* NodeStatus has its own transfer id. */
    assert_int_equal(occ_dronecan_publish_status(&node, 0), OCC_OK);
    assert_int_equal(cap.frames[140].data[7], 0xC0u);
    assert_int_equal(node.stats.proximity_sent, 70);
    assert_int_equal(node.stats.tx_frames, 141);
}

static void test_queue_full_counted(void **state)
{
    (void)state;
    make_node(100);
    const occ_dronecan_proximity_t m = {1, OCC_PROX_GOOD, 0, 45.0f, 0.0f, 3.5f};
    /* Without tx_space: the hook takes 3 frames, the second transfer breaks after one frame. */
    cap.limit = 3;
    assert_int_equal(occ_dronecan_publish_proximity(&node, &m), OCC_OK);
    assert_int_equal(occ_dronecan_publish_proximity(&node, &m), OCC_ERR_NOMEM);
    assert_int_equal(occ_dronecan_publish_proximity(&node, &m), OCC_ERR_NOMEM);
    assert_int_equal(node.stats.tx_full, 2);
    assert_int_equal(node.stats.tx_transfers, 1);
    assert_int_equal(node.stats.tx_frames, 3);
    /* The partial transfer used id 1; the next one that starts is id 2. */
    assert_int_equal(node.priv.tid_proximity, 2);

    /* With tx_space: all or nothing, and the transfer id is not spent. */
    memset(&cap, 0, sizeof cap);
    cap.limit = 1;
    cap.report_space = true;
    make_node(100);
    assert_int_equal(occ_dronecan_publish_proximity(&node, &m), OCC_ERR_NOMEM);
    assert_int_equal(cap.n, 0);
    assert_int_equal(node.priv.tid_proximity, 0);
    assert_int_equal(node.stats.tx_full, 1);
    /* A single-frame NodeStatus still fits. */
    assert_int_equal(occ_dronecan_publish_status(&node, 0), OCC_OK);
    assert_int_equal(cap.n, 1);

    /* A driver error is reported as such. */
    memset(&cap, 0, sizeof cap);
    cap.limit = CAP_MAX;
    cap.fail_io = true;
    make_node(100);
    assert_int_equal(occ_dronecan_publish_status(&node, 0), OCC_ERR_IO);
    assert_int_equal(node.stats.tx_errors, 1);
}

static void test_get_node_info(void **state)
{
    (void)state;
    make_node(100);
    /* A request from node 10 with priority 30, transfer id 7: empty payload, tail only. */
    occ_can_frame_t req;
    memset(&req, 0, sizeof req);
    req.id = occ_dronecan_svc_id(30, 1, true, 100, 10);
    req.flags = OCC_CAN_FLAG_EXT;
    req.len = 1;
    req.data[0] = 0xC7;
    assert_int_equal(occ_dronecan_ingest(&node, &req, 2500000u), OCC_OK);
    assert_int_equal(node.stats.node_info_answered, 1);
    const size_t name_len = strlen("org.occmap.obstacles");
    const size_t plen = 41u + name_len;
    const size_t nf = occ_dronecan_frame_count(plen);
    assert_int_equal(cap.n, nf);
    uint8_t stream[160];
    size_t sl = 0;
    for (size_t i = 0; i < nf; i++) {
        assert_int_equal(cap.frames[i].id, 0x1E010AE4u);
        const uint8_t tail = cap.frames[i].data[cap.frames[i].len - 1u];
        assert_int_equal(tail & 0x1Fu, 7);
        memcpy(stream + sl, cap.frames[i].data, cap.frames[i].len - 1u);
        sl += cap.frames[i].len - 1u;
    }
    assert_int_equal(sl, plen + 2u);
    const uint8_t *p = stream + 2;
    assert_int_equal(stream[0] | (stream[1] << 8),
                     occ_dronecan_crc16(occ_dronecan_crc_seed(OCC_DRONECAN_GETNODEINFO_SIG), p, plen));
    /* status: not started yet -> uptime 0, health ERROR (no poll yet), mode INITIALIZATION */
    const uint8_t st[7] = {0, 0, 0, 0, (2u << 6) | (1u << 3), 0, 0};
    assert_memory_equal(p, st, 7);
    assert_int_equal(p[7], 0);   /* sw major */
    assert_int_equal(p[8], 1);   /* sw minor */
    assert_int_equal(p[9], 0);   /* optional flags */
    assert_int_equal(p[22], 0);  /* hw major */
    assert_int_equal(p[24], 0xAA);
    assert_int_equal(p[39], 0x55);
    assert_int_equal(p[40], 0);  /* empty certificate */
    assert_memory_equal(p + 41, "org.occmap.obstacles", name_len);

    /* Not for us / not a request / other service / multi-frame: ignored. */
    cap.n = 0;
    req.id = occ_dronecan_svc_id(30, 1, true, 99, 10);
    assert_int_equal(occ_dronecan_ingest(&node, &req, 0), OCC_OK);
    req.id = occ_dronecan_svc_id(30, 1, false, 100, 10);
    assert_int_equal(occ_dronecan_ingest(&node, &req, 0), OCC_OK);
    req.id = occ_dronecan_svc_id(30, 5, true, 100, 10);
    assert_int_equal(occ_dronecan_ingest(&node, &req, 0), OCC_OK);
    req.id = occ_dronecan_svc_id(30, 1, true, 100, 10);
    req.data[0] = 0x87;
    assert_int_equal(occ_dronecan_ingest(&node, &req, 0), OCC_OK);
    req.data[0] = 0xC7;
    req.flags = 0;
    assert_int_equal(occ_dronecan_ingest(&node, &req, 0), OCC_OK);
    assert_int_equal(cap.n, 0);
    assert_int_equal(node.stats.rx_ignored, 5);
    /* Error reports are counted. */
    occ_can_frame_t err;
    memset(&err, 0, sizeof err);
    err.flags = OCC_CAN_FLAG_ERR;
    err.id = OCC_CAN_ERR_BUS_OFF;
    assert_int_equal(occ_dronecan_ingest(&node, &err, 0), OCC_OK);
    assert_int_equal(node.stats.bus_off, 1);
    assert_int_equal(node.stats.rx_bus_errors, 1);
}

static void test_name_truncated(void **state)
{
    (void)state;
    char name[100];
    memset(name, 'x', sizeof name);
    name[99] = '\0';
    occ_dronecan_node_info_t info;
    memset(&info, 0, sizeof info);
    info.name = name;
    uint8_t out[OCC_DRONECAN_MAX_PAYLOAD];
    assert_int_equal(occ_dronecan_encode_node_info(&info, out, sizeof out), 41u + 80u);
    assert_int_equal(occ_dronecan_encode_node_info(&info, out, 10), 0);
}

static occ_sectors_config_t sector_cfg8(void)
{
    occ_sectors_config_t c;
    memset(&c, 0, sizeof c);
    c.n_sectors = 8;
    c.increment_deg = 45.0f;
    c.angle_offset_deg = 0.0f;
    c.min_distance_cm = 20;
    c.max_distance_cm = 2000;
    return c;
}

/* Decode a 2-frame Proximity transfer from cap.frames[i], [i+1]. */
static occ_dronecan_proximity_t decode_prox(size_t i)
{
    uint8_t p[8];
    memcpy(p, cap.frames[i].data + 2, 5);
    memcpy(p + 5, cap.frames[i + 1].data, 3);
    occ_dronecan_proximity_t m;
    m.sensor_id = p[0];
    m.reading_type = (occ_prox_reading_t)occ_dronecan_get_bits(p, 8, 3);
    m.flags = (uint8_t)occ_dronecan_get_bits(p, 11, 5);
    m.yaw_deg = occ_float16_to_float((uint16_t)occ_dronecan_get_bits(p, 16, 16));
    m.pitch_deg = occ_float16_to_float((uint16_t)occ_dronecan_get_bits(p, 32, 16));
    m.distance_m = occ_float16_to_float((uint16_t)occ_dronecan_get_bits(p, 48, 16));
    return m;
}

static void test_poll_schedule_and_states(void **state)
{
    (void)state;
    make_node(42);
    const occ_sectors_config_t sc = sector_cfg8();
    occ_sectors_t s;
    memset(&s, 0, sizeof s);
    s.n = 8;
    for (unsigned i = 0; i < 8; i++) {
        s.distance_cm[i] = 2000; /* observed free */
    }
    s.distance_cm[1] = 350;     /* 45 deg */
    s.distance_cm[5] = 120;     /* 225 deg -> -135 */
    s.distance_cm[6] = UINT16_MAX; /* unknown: not sent */
    const occ_dronecan_view_t good = {true, true, &s, &sc};
    const uint64_t t0 = 1000000000u;
    assert_int_equal(occ_dronecan_poll(&node, t0, &good), OCC_OK);
    /* First poll: two Proximity transfers (2 frames each) and one NodeStatus. */
    assert_int_equal(cap.n, 5);
    occ_dronecan_proximity_t a = decode_prox(0), b = decode_prox(2);
    assert_int_equal(a.sensor_id, 3);
    assert_int_equal(a.reading_type, OCC_PROX_GOOD);
    assert_true(same_float(a.yaw_deg, 45.0f));
    assert_true(fabsf(a.distance_m - 3.5f) < 0.002f);
    assert_true(same_float(b.yaw_deg, -135.0f));
    assert_true(fabsf(b.distance_m - 1.2f) < 0.001f);
    assert_int_equal(cap.frames[4].id, occ_dronecan_msg_id(31, 341, 42));
    assert_int_equal(cap.frames[4].data[4], 0); /* health OK, mode OPERATIONAL */
    assert_int_equal(cap.frames[4].data[5], 2); /* vendor status: 2 obstacles */

    /* 50 ms later: nothing due. At 100 ms: proximity again, no status. */
    cap.n = 0;
    assert_int_equal(occ_dronecan_poll(&node, t0 + 50000u, &good), OCC_OK);
    assert_int_equal(cap.n, 0);
    assert_int_equal(occ_dronecan_poll(&node, t0 + 100000u, &good), OCC_OK);
    assert_int_equal(cap.n, 4);
    /* One simulated second at 1 kHz polling: 10 proximity rounds, 1 status. */
    cap.n = 0;
    for (uint64_t t = t0 + 101000u; t <= t0 + 1100000u; t += 1000u) {
        assert_int_equal(occ_dronecan_poll(&node, t, &good), OCC_OK);
    }
    assert_int_equal(cap.n, 10u * 4u + 1u);

    /* Stale: one NO_DATA reading per period, health WARNING. */
    cap.n = 0;
    const occ_dronecan_view_t stale = {true, false, NULL, NULL};
    assert_int_equal(occ_dronecan_poll(&node, t0 + 1200000u, &stale), OCC_OK);
    assert_int_equal(cap.n, 2);
    a = decode_prox(0);
    assert_int_equal(a.reading_type, OCC_PROX_NO_DATA);
    assert_true(same_float(a.distance_m, 0.0f));
    assert_int_equal(node.health, OCC_NODE_HEALTH_WARNING);
    /* No map: NOT_CONNECTED and the status says ERROR / INITIALIZATION. */
    cap.n = 0;
    const occ_dronecan_view_t nomap = {false, false, NULL, NULL};
    assert_int_equal(occ_dronecan_poll(&node, t0 + 2200000u, &nomap), OCC_OK);
    assert_int_equal(cap.n, 3);
    a = decode_prox(0);
    assert_int_equal(a.reading_type, OCC_PROX_NOT_CONNECTED);
    assert_int_equal(cap.frames[2].data[4], (2u << 6) | (1u << 3));
    assert_int_equal(cap.frames[2].data[0], 2); /* uptime 2 s */
    /* A good view without sectors is a caller mistake. */
    const occ_dronecan_view_t bad = {true, true, NULL, NULL};
    assert_int_equal(occ_dronecan_poll(&node, t0 + 3200000u, &bad), OCC_ERR_ARG);
}

static void test_sector_yaw_wrap(void **state)
{
    (void)state;
    make_node(42);
    occ_sectors_config_t sc = sector_cfg8();
    sc.n_sectors = 72;
    sc.increment_deg = 5.0f;
    sc.angle_offset_deg = -2.5f;
    occ_sectors_t s;
    s.n = 72;
    for (unsigned i = 0; i < 72; i++) {
        s.distance_cm[i] = (uint16_t)(100u + i);
    }
    size_t sent = 0;
    assert_int_equal(occ_dronecan_publish_sectors(&node, &s, &sc, &sent), OCC_OK);
    assert_int_equal(sent, 72);
    for (unsigned i = 0; i < 72; i++) {
        const occ_dronecan_proximity_t m = decode_prox(2u * i);
        float want = -2.5f + 5.0f * (float)i;
        if (want > 180.0f) {
            want -= 360.0f;
        }
        assert_true(m.yaw_deg > -180.0f && m.yaw_deg <= 180.0f);
        assert_true(fabsf(m.yaw_deg - want) < 0.07f);
        assert_true(fabsf(m.distance_m - (float)(100u + i) / 100.0f) < 0.001f);
    }
}

/* ---- The node fed from a real map through the sector module -------------------------------------- */
static uint8_t map_arena[4u << 20];

static void test_poll_map(void **state)
{
    (void)state;
    static occ_map_t map;
    occ_map_config_t mc = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &mc, map_arena, sizeof map_arena), OCC_OK);
    /* Free disc of radius 4 m in the layer z in [0, 0.1), a wall 3 m north (map +y), x in
     * [-1.5, 1.5). */
    for (int y = -40; y < 40; y++) {
        for (int x = -40; x < 40; x++) {
            const occ_vec3_t q = {((float)x + 0.5f) * 0.1f, ((float)y + 0.5f) * 0.1f, 0.05f};
            const bool wall = y == 30 && x >= -15 && x < 15;
            if (wall || q.x * q.x + q.y * q.y < 16.0f) {
                assert_int_equal(occ_map_update(&map, q, wall ? 3.0f : -3.0f), OCC_OK);
            }
        }
    }
    make_node(7);
    occ_sectors_config_t sc = occ_sectors_config_default();
    sc.band_below_m = 0.04f;
    sc.band_above_m = 0.04f;
    /* Heading east (NED yaw 90): the wall is to the left, body yaw -90. */
    occ_pose_t pose;
    const occ_vec3_t up5cm = {0.0f, 0.0f, -0.05f};
    assert_int_equal(occ_pose_from_ned(up5cm, occ_quat_from_euler(0.0f, 0.0f, 1.57079633f), &pose),
                     OCC_OK);
    const uint64_t t0 = 10000000u;
    assert_int_equal(occ_dronecan_poll_map(&node, t0, &map, t0, &pose, t0, &sc), OCC_OK);
    const size_t n_prox = (cap.n - 1u) / 2u; /* + one NodeStatus */
    assert_int_equal(n_prox, 11); /* the wall spans +-26.6 degrees: 5-degree sectors -25..25 */
    bool seen_left = false;
    for (size_t i = 0; i < n_prox; i++) {
        const occ_dronecan_proximity_t m = decode_prox(2u * i);
        assert_int_equal(m.reading_type, OCC_PROX_GOOD);
        assert_true(m.yaw_deg > -120.0f && m.yaw_deg < -60.0f);
        /* Every reading lies on the wall: 3 m along the wall's normal (body -90). */
        const float along = m.distance_m * cosf((m.yaw_deg + 90.0f) * 0.0174532925f);
        assert_true(along > 2.85f && along < 3.05f);
        if (fabsf(m.yaw_deg + 90.0f) < 0.01f) {
            seen_left = true;
            assert_true(fabsf(m.distance_m - 3.0f) < 0.02f);
        }
    }
    assert_true(seen_left);
    assert_int_equal(node.health, OCC_NODE_HEALTH_OK);
    /* A pose 0.6 s old: NO_DATA. */
    cap.n = 0;
    assert_int_equal(occ_dronecan_poll_map(&node, t0 + 100000u, &map, t0 + 100000u, &pose,
                                           t0 - 500000u, &sc), OCC_OK);
    assert_int_equal(cap.n, 2);
    assert_int_equal(decode_prox(0).reading_type, OCC_PROX_NO_DATA);
    /* No map: NOT_CONNECTED. */
    cap.n = 0;
    assert_int_equal(occ_dronecan_poll_map(&node, t0 + 200000u, NULL, 0, &pose, t0 + 200000u, &sc),
                     OCC_OK);
    assert_int_equal(decode_prox(0).reading_type, OCC_PROX_NOT_CONNECTED);
    /* The vehicle off the map: the sector error comes back, the node still says NO_DATA and its
     * NodeStatus goes out on time. */
    cap.n = 0;
    occ_pose_t far;
    const occ_vec3_t far_ned = {1e7f, 0.0f, 0.0f};
    assert_int_equal(occ_pose_from_ned(far_ned, occ_quat_identity(), &far), OCC_OK);
    assert_int_equal(occ_dronecan_poll_map(&node, t0 + 1000000u, &map, t0 + 1000000u, &far,
                                           t0 + 1000000u, &sc), OCC_ERR_RANGE);
    assert_int_equal(cap.n, 3);
    assert_int_equal(decode_prox(0).reading_type, OCC_PROX_NO_DATA);
    assert_int_equal(cap.frames[2].id, occ_dronecan_msg_id(31, 341, 7));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_init_args, setup),
        cmocka_unit_test_setup(test_tid_and_toggle_wrap, setup),
        cmocka_unit_test_setup(test_queue_full_counted, setup),
        cmocka_unit_test_setup(test_get_node_info, setup),
        cmocka_unit_test_setup(test_name_truncated, setup),
        cmocka_unit_test_setup(test_poll_schedule_and_states, setup),
        cmocka_unit_test_setup(test_sector_yaw_wrap, setup),
        cmocka_unit_test_setup(test_poll_map, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
