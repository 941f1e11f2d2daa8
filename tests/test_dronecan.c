/* test_dronecan.c - DroneCAN transfer layer, messages and node against hand-checked bytes. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occ_can.h"

/* ---- A capturing transmit hook with a settable queue limit ---------------------------------- */
#define CAP_MAX 512
typedef struct {
    occ_can_frame_t frames[CAP_MAX];
    size_t n;
    size_t limit;         /* frames accepted before "queue full" */
    bool report_space;    /* offer tx_space */
    bool fail_io;
} capture_t;

static occ_err_t cap_tx(void *user, const occ_can_frame_t *f)
{
    capture_t *c = user;
    if (c->fail_io) {
        return OCC_ERR_IO;
    }
    if (c->n >= c->limit || c->n >= CAP_MAX) {
        return OCC_ERR_NOMEM;
    }
    c->frames[c->n++] = *f;
    return OCC_OK;
}

static uint32_t cap_space(void *user)
{
    const capture_t *c = user;
    return (uint32_t)(c->limit > c->n ? c->limit - c->n : 0u);
}

static capture_t cap;

static occ_can_iface_t cap_iface(void)
{
    occ_can_iface_t i = {cap_tx, cap.report_space ? cap_space : NULL, &cap};
    return i;
}

static int setup(void **state)
{
    (void)state;
    memset(&cap, 0, sizeof cap);
    cap.limit = CAP_MAX;
    return 0;
}

static void assert_frame(const occ_can_frame_t *f, uint32_t id, const uint8_t *data, size_t len)
{
    assert_int_equal(f->id, id);
    assert_int_equal(f->flags, OCC_CAN_FLAG_EXT);
    assert_int_equal(f->len, len);
    assert_memory_equal(f->data, data, len);
}

/* ---- Golden examples from ../shared/notes/autopilot-protocols.md (checked with pydronecan) ---- */
static void test_ids(void **state)
{
    (void)state;
    assert_int_equal(occ_dronecan_msg_id(31, 21910, 100), 0x1F559664u);
    assert_int_equal(occ_dronecan_msg_id(31, 341, 100), 0x1F015564u);
    /* service response, GetNodeInfo, from 100 to 10 */
    assert_int_equal(occ_dronecan_svc_id(30, 1, false, 10, 100), 0x1E010AE4u);
    assert_int_equal(occ_dronecan_svc_id(30, 1, true, 100, 10), 0x1E01E48Au);
}

static void test_crc(void **state)
{
    (void)state;
    const uint8_t check[] = "123456789";
    assert_int_equal(occ_dronecan_crc16(0xFFFF, check, 9), 0x29B1u);
    /* The golden Proximity example: CRC 0x6B49. */
    const uint8_t payload[8] = {0x01, 0x40, 0xa0, 0x51, 0x00, 0x00, 0x00, 0x43};
    assert_int_equal(occ_dronecan_crc16(occ_dronecan_crc_seed(OCC_DRONECAN_PROXIMITY_SIG), payload, 8),
                     0x6B49u);
}

static void test_golden_proximity(void **state)
{
    (void)state;
    const occ_dronecan_proximity_t m = {1, OCC_PROX_GOOD, 0, 45.0f, 0.0f, 3.5f};
    uint8_t p[8];
    assert_int_equal(occ_dronecan_encode_proximity(&m, p), 8);
    const uint8_t want[8] = {0x01, 0x40, 0xa0, 0x51, 0x00, 0x00, 0x00, 0x43};
    assert_memory_equal(p, want, 8);

    const occ_can_iface_t iface = cap_iface();
    size_t sent = 0;
    assert_int_equal(occ_dronecan_send_transfer(&iface, occ_dronecan_msg_id(31, 21910, 100),
                                                OCC_DRONECAN_PROXIMITY_SIG, 0, p, 8, &sent),
                     OCC_OK);
    assert_int_equal(sent, 2);
    assert_int_equal(cap.n, 2);
    const uint8_t f0[8] = {0x49, 0x6b, 0x01, 0x40, 0xa0, 0x51, 0x00, 0x80};
    const uint8_t f1[4] = {0x00, 0x00, 0x43, 0x60};
    assert_frame(&cap.frames[0], 0x1F559664u, f0, 8);
    assert_frame(&cap.frames[1], 0x1F559664u, f1, 4);
}

static void test_golden_node_status(void **state)
{
    (void)state;
    const occ_dronecan_node_status_t st = {1, 0, 0, 0, 0};
    uint8_t p[7];
    assert_int_equal(occ_dronecan_encode_node_status(&st, p), 7);
    const occ_can_iface_t iface = cap_iface();
    assert_int_equal(occ_dronecan_send_transfer(&iface, occ_dronecan_msg_id(31, 341, 100),
                                                OCC_DRONECAN_NODESTATUS_SIG, 0, p, 7, NULL),
                     OCC_OK);
    const uint8_t want[8] = {0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xc0};
    assert_int_equal(cap.n, 1);
    assert_frame(&cap.frames[0], 0x1F015564u, want, 8);

    /* Bit layout of the packed byte: health in bits 7..6, mode 5..3, sub mode 2..0. */
    const occ_dronecan_node_status_t st2 = {0x01020304u, 2, 1, 5, 0xBEEF};
    (void)occ_dronecan_encode_node_status(&st2, p);
    const uint8_t want2[7] = {0x04, 0x03, 0x02, 0x01, (2u << 6) | (1u << 3) | 5u, 0xEF, 0xBE};
    assert_memory_equal(p, want2, 7);
}

/* ---- float16 ------------------------------------------------------------------------------- */
static float f_from_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* Exact float equality without -Wfloat-equal noise: same bits. */
static bool same_float(float a, float b)
{
    uint32_t ua, ub;
    memcpy(&ua, &a, 4);
    memcpy(&ub, &b, 4);
    return ua == ub;
}

static void test_float16_edges(void **state)
{
    (void)state;
    assert_int_equal(occ_float16_from_float(0.0f), 0x0000u);
    assert_int_equal(occ_float16_from_float(-0.0f), 0x8000u);
    assert_int_equal(occ_float16_from_float(1.0f), 0x3C00u);
    assert_int_equal(occ_float16_from_float(-2.0f), 0xC000u);
    assert_int_equal(occ_float16_from_float(45.0f), 0x51A0u);
    assert_int_equal(occ_float16_from_float(3.5f), 0x4300u);
    assert_int_equal(occ_float16_from_float(65504.0f), 0x7BFFu);
    /* Saturated: beyond the largest half and infinities clamp to +-65504. */
    assert_int_equal(occ_float16_from_float(65520.0f), 0x7BFFu);
    assert_int_equal(occ_float16_from_float(1e9f), 0x7BFFu);
    assert_int_equal(occ_float16_from_float(INFINITY), 0x7BFFu);
    assert_int_equal(occ_float16_from_float(-INFINITY), 0xFBFFu);
    assert_int_equal(occ_float16_from_float(NAN) & 0x7FFFu, 0x7FFFu);
    /* Smallest normal and subnormals. */
    assert_int_equal(occ_float16_from_float(6.103515625e-05f), 0x0400u);
    assert_int_equal(occ_float16_from_float(5.9604644775390625e-08f), 0x0001u); /* 2^-24 */
    assert_int_equal(occ_float16_from_float(1e-10f), 0x0000u);
    /* Rounding: 1 + 2^-11 is half way between 1 and the next half: rounds away from zero. */
    assert_int_equal(occ_float16_from_float(1.00048828125f), 0x3C01u);
    assert_int_equal(occ_float16_from_float(1.000244140625f), 0x3C00u); /* below half: down */
    /* 0.1 = 0x2E66 (nearest). */
    assert_int_equal(occ_float16_from_float(0.1f), 0x2E66u);

    /* Back: exact for every half; Inf and NaN survive. */
    assert_true(same_float(occ_float16_to_float(0x7BFFu), 65504.0f));
    assert_true(same_float(occ_float16_to_float(0x0001u), f_from_bits(0x33800000u)));
    assert_true(isinf(occ_float16_to_float(0x7C00u)));
    assert_true(isnan(occ_float16_to_float(0x7E00u)));
    assert_true(signbit(occ_float16_to_float(0x8000u)));
    unsigned mismatches = 0;
    for (uint32_t h = 0; h < 0x10000u; h++) {
        const uint16_t hh = (uint16_t)h;
        const float f = occ_float16_to_float(hh);
        if ((hh & 0x7C00u) == 0x7C00u) {
            continue; /* Inf saturates, NaN payloads collapse: checked above */
        }
        if (occ_float16_from_float(f) != hh) {
            mismatches++;
        }
    }
    assert_int_equal(mismatches, 0);
}

/* ---- Bit packing ------------------------------------------------------------------------------- */
static void test_bits_roundtrip(void **state)
{
    (void)state;
    uint8_t buf[16];
    for (unsigned len = 1; len <= 64; len++) {
        for (unsigned off = 0; off < 13; off++) {
            memset(buf, 0, sizeof buf);
            const uint64_t v = (0x9E3779B97F4A7C15ull * (len + 31u * off)) &
                               (len == 64 ? ~0ull : ((1ull << len) - 1u));
            occ_dronecan_put_bits(buf, off, len, v);
            assert_true(occ_dronecan_get_bits(buf, off, len) == v);
        }
    }
    /* 12-bit value at bit 0: low byte first, then the high nibble in the top of byte 1. */
    memset(buf, 0, sizeof buf);
    occ_dronecan_put_bits(buf, 0, 12, 0xABCu);
    assert_int_equal(buf[0], 0xBCu);
    assert_int_equal(buf[1], 0xA0u);
}

/* ---- Multi-frame split and CRC -------------------------------------------------------------- */
static void test_multiframe_split(void **state)
{
    (void)state;
    uint8_t payload[OCC_DRONECAN_MAX_PAYLOAD];
    for (size_t i = 0; i < sizeof payload; i++) {
        payload[i] = (uint8_t)(i * 7u + 3u);
    }
    const uint64_t sig = 0x0123456789ABCDEFull;
    for (size_t len = 0; len <= OCC_DRONECAN_MAX_PAYLOAD; len++) {
        cap.n = 0;
        const occ_can_iface_t iface = cap_iface();
        const uint8_t tid = (uint8_t)(len % 32u);
        assert_int_equal(occ_dronecan_send_transfer(&iface, 0x10203u, sig, tid, payload, len, NULL),
                         OCC_OK);
        const size_t nf = occ_dronecan_frame_count(len);
        assert_int_equal(cap.n, nf);
        uint8_t stream[OCC_DRONECAN_MAX_PAYLOAD + 2];
        size_t sl = 0;
        for (size_t i = 0; i < nf; i++) {
            const occ_can_frame_t *f = &cap.frames[i];
            assert_true(f->len >= 1u && f->len <= 8u);
            if (i + 1u < nf) {
                assert_int_equal(f->len, 8); /* only the last frame is short */
            }
            const uint8_t tail = f->data[f->len - 1u];
            assert_int_equal(tail & 0x1Fu, tid);
            assert_int_equal((tail & 0x80u) != 0u, i == 0u);
            assert_int_equal((tail & 0x40u) != 0u, i + 1u == nf);
            assert_int_equal((tail & 0x20u) != 0u, (i % 2u) == 1u);
            memcpy(stream + sl, f->data, f->len - 1u);
            sl += f->len - 1u;
        }
        if (nf == 1u) {
            assert_int_equal(sl, len);
            assert_memory_equal(stream, payload, len);
        } else {
            assert_int_equal(sl, len + 2u);
            const uint16_t crc = occ_dronecan_crc16(occ_dronecan_crc_seed(sig), payload, len);
            assert_int_equal(stream[0] | (stream[1] << 8), crc);
            assert_memory_equal(stream + 2, payload, len);
        }
    }
    /* Bad arguments */
    const occ_can_iface_t iface = cap_iface();
    assert_int_equal(occ_dronecan_send_transfer(&iface, 1, sig, 32, payload, 1, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_send_transfer(&iface, 1, sig, 0, payload,
                                                OCC_DRONECAN_MAX_PAYLOAD + 1u, NULL),
                     OCC_ERR_ARG);
    assert_int_equal(occ_dronecan_send_transfer(NULL, 1, sig, 0, payload, 1, NULL), OCC_ERR_ARG);
}

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
    assert_int_equal(node.tid_proximity, 2);

    /* With tx_space: all or nothing, and the transfer id is not spent. */
    memset(&cap, 0, sizeof cap);
    cap.limit = 1;
    cap.report_space = true;
    make_node(100);
    assert_int_equal(occ_dronecan_publish_proximity(&node, &m), OCC_ERR_NOMEM);
    assert_int_equal(cap.n, 0);
    assert_int_equal(node.tid_proximity, 0);
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
    const occ_pose_t pose = occ_pose_from_ned(0.0f, 0.0f, -0.05f, 1.57079633f);
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
    const occ_pose_t far = occ_pose_from_ned(1e7f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_dronecan_poll_map(&node, t0 + 1000000u, &map, t0 + 1000000u, &far,
                                           t0 + 1000000u, &sc), OCC_ERR_RANGE);
    assert_int_equal(cap.n, 3);
    assert_int_equal(decode_prox(0).reading_type, OCC_PROX_NO_DATA);
    assert_int_equal(cap.frames[2].id, occ_dronecan_msg_id(31, 341, 7));
}

/* ---- CAN over UDP multicast packets (port/posix/can_mcast.c); bytes from pydronecan's driver --- */
static void test_mcast_packet(void **state)
{
    (void)state;
    occ_can_frame_t f;
    memset(&f, 0, sizeof f);
    f.id = 0x1F559664u;
    f.flags = OCC_CAN_FLAG_EXT;
    f.len = 8;
    const uint8_t d[8] = {0x49, 0x6b, 0x01, 0x40, 0xa0, 0x51, 0x00, 0x80};
    memcpy(f.data, d, 8);
    const uint8_t want[18] = {0x34, 0x29, 0xfd, 0x7b, 0x00, 0x00, 0x64, 0x96, 0x55,
                              0x9f, 0x49, 0x6b, 0x01, 0x40, 0xa0, 0x51, 0x00, 0x80};
    uint8_t pkt[80];
    assert_int_equal(occ_can_mcast_encode(&f, pkt, sizeof pkt), 18);
    assert_memory_equal(pkt, want, 18);
    occ_can_frame_t g;
    assert_int_equal(occ_can_mcast_decode(pkt, 18, &g), OCC_OK);
    assert_int_equal(g.id, f.id);
    assert_int_equal(g.flags, f.flags);
    assert_int_equal(g.len, 8);
    assert_memory_equal(g.data, d, 8);

    /* 11-bit FD frame with 12 bytes. */
    memset(&f, 0, sizeof f);
    f.id = 0x123u;
    f.flags = OCC_CAN_FLAG_FD;
    f.len = 12;
    for (unsigned i = 0; i < 12; i++) {
        f.data[i] = (uint8_t)i;
    }
    const uint8_t want2[22] = {0x34, 0x29, 0xb5, 0x47, 0x01, 0x00, 0x23, 0x01, 0x00, 0x00, 0x00,
                               0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a, 0x0b};
    assert_int_equal(occ_can_mcast_encode(&f, pkt, sizeof pkt), 22);
    assert_memory_equal(pkt, want2, 22);
    assert_int_equal(occ_can_mcast_encode(&f, pkt, 21), 0);
    assert_int_equal(occ_can_mcast_decode(pkt, 22, &g), OCC_OK);
    assert_int_equal(g.flags, OCC_CAN_FLAG_FD);
    assert_int_equal(g.id, 0x123u);

    /* Corrupt packets are refused: CRC, magic, short, classic over 8 bytes. */
    pkt[15] ^= 1u;
    assert_int_equal(occ_can_mcast_decode(pkt, 22, &g), OCC_ERR_FORMAT);
    pkt[15] ^= 1u;
    pkt[0] = 0;
    assert_int_equal(occ_can_mcast_decode(pkt, 22, &g), OCC_ERR_FORMAT);
    assert_int_equal(occ_can_mcast_decode(want, 9, &g), OCC_ERR_FORMAT);
    f.flags = 0;
    (void)occ_can_mcast_encode(&f, pkt, sizeof pkt); /* classic with 12 bytes: not a CAN frame */
    assert_int_equal(occ_can_mcast_decode(pkt, 22, &g), OCC_ERR_FORMAT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_ids, setup),
        cmocka_unit_test_setup(test_crc, setup),
        cmocka_unit_test_setup(test_golden_proximity, setup),
        cmocka_unit_test_setup(test_golden_node_status, setup),
        cmocka_unit_test_setup(test_float16_edges, setup),
        cmocka_unit_test_setup(test_bits_roundtrip, setup),
        cmocka_unit_test_setup(test_multiframe_split, setup),
        cmocka_unit_test_setup(test_init_args, setup),
        cmocka_unit_test_setup(test_tid_and_toggle_wrap, setup),
        cmocka_unit_test_setup(test_queue_full_counted, setup),
        cmocka_unit_test_setup(test_get_node_info, setup),
        cmocka_unit_test_setup(test_name_truncated, setup),
        cmocka_unit_test_setup(test_poll_schedule_and_states, setup),
        cmocka_unit_test_setup(test_sector_yaw_wrap, setup),
        cmocka_unit_test_setup(test_mcast_packet, setup),
        cmocka_unit_test_setup(test_poll_map, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
