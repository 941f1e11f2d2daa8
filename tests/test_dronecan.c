/* SPDX-License-Identifier: BSD-3-Clause */
/* test_dronecan.c - DroneCAN transfer layer, messages and CAN-over-UDP packets against
 * hand-checked bytes (the node: test_dronecan_node.c). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occ_dronecan.h"
#include "occmap/host/occ_can_mcast.h"
#include "support/can_capture.h"

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
        cmocka_unit_test_setup(test_mcast_packet, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

