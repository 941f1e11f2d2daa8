/* SPDX-License-Identifier: BSD-3-Clause */
/* can_transfer.c - DroneCAN v0 transfer layer: ids, CRC, DSDL bit packing, frame split. */
#include <string.h>

#include "occmap/occ_dronecan.h"

uint32_t occ_dronecan_msg_id(uint8_t priority, uint16_t data_type_id, uint8_t src_node)
{
    return ((uint32_t)(priority & 0x1Fu) << 24) | ((uint32_t)data_type_id << 8) |
           (uint32_t)(src_node & 0x7Fu);
}

uint32_t occ_dronecan_svc_id(uint8_t priority, uint8_t service_id, bool request, uint8_t dst_node,
                             uint8_t src_node)
{
    return ((uint32_t)(priority & 0x1Fu) << 24) | ((uint32_t)service_id << 16) |
           ((request ? 1u : 0u) << 15) | ((uint32_t)(dst_node & 0x7Fu) << 8) | 0x80u |
           (uint32_t)(src_node & 0x7Fu);
}

uint16_t occ_dronecan_crc16(uint16_t crc, const uint8_t *data, size_t n)
{
    uint32_t c = crc;
    for (size_t i = 0; i < n; i++) {
        c ^= (uint32_t)data[i] << 8;
        for (unsigned b = 0; b < 8u; b++) {
            c = ((c & 0x8000u) != 0u) ? ((c << 1) ^ 0x1021u) : (c << 1);
        }
        c &= 0xFFFFu;
    }
    return (uint16_t)c;
}

uint16_t occ_dronecan_crc_seed(uint64_t signature)
{
    uint8_t sig[8];
    for (unsigned i = 0; i < 8u; i++) {
        sig[i] = (uint8_t)(signature >> (8u * i));
    }
    return occ_dronecan_crc16(0xFFFFu, sig, sizeof sig);
}

/* Bit k of a DSDL stream is bit (7 - k % 8) of byte k / 8. */
static unsigned bit_at(const uint8_t *buf, size_t k)
{
    return (unsigned)(buf[k / 8u] >> (7u - (unsigned)(k % 8u))) & 1u;
}

static void set_bit(uint8_t *buf, size_t k, unsigned v)
{
    const uint8_t mask = (uint8_t)(1u << (7u - (unsigned)(k % 8u)));
    if (v != 0u) {
        buf[k / 8u] = (uint8_t)(buf[k / 8u] | mask);
    } else {
        buf[k / 8u] = (uint8_t)(buf[k / 8u] & (uint8_t)~mask);
    }
}

void occ_dronecan_put_bits(uint8_t *buf, size_t bit_off, unsigned bit_len, uint64_t value)
{
    if (buf == NULL || bit_len == 0u || bit_len > 64u) {
        return;
    }
    /* Little-endian bytes; the partial last byte's bits move to its top, as libcanard does. */
    uint8_t tmp[8];
    for (unsigned i = 0; i < 8u; i++) {
        tmp[i] = (uint8_t)(value >> (8u * i));
    }
    if ((bit_len % 8u) != 0u) {
        tmp[bit_len / 8u] = (uint8_t)(tmp[bit_len / 8u] << (8u - bit_len % 8u));
    }
    for (unsigned i = 0; i < bit_len; i++) {
        set_bit(buf, bit_off + i, bit_at(tmp, i));
    }
}

uint64_t occ_dronecan_get_bits(const uint8_t *buf, size_t bit_off, unsigned bit_len)
{
    if (buf == NULL || bit_len == 0u || bit_len > 64u) {
        return 0u;
    }
    uint8_t tmp[8] = {0};
    for (unsigned i = 0; i < bit_len; i++) {
        set_bit(tmp, i, bit_at(buf, bit_off + i));
    }
    if ((bit_len % 8u) != 0u) {
        tmp[bit_len / 8u] = (uint8_t)(tmp[bit_len / 8u] >> (8u - bit_len % 8u));
    }
    uint64_t v = 0;
    for (unsigned i = 0; i < 8u; i++) {
        v |= (uint64_t)tmp[i] << (8u * i);
    }
    return v;
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float bits_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* libuavcan's conversion (which pydronecan copies): scale the exponent with one multiply so
 * subnormals fall out of the FPU, add half an output ulp, take the bits. */
uint16_t occ_float16_from_float(float f)
{
    /* DSDL "saturated": clamp to the largest finite half first (NaN passes through). */
    if (f > 65504.0f) {
        f = 65504.0f;
    } else if (f < -65504.0f) {
        f = -65504.0f;
    }
    uint32_t u = float_bits(f);
    const uint32_t sign = u & 0x80000000u;
    u ^= sign;
    uint32_t out;
    if (u >= 0x7F800000u) {
        out = (u > 0x7F800000u) ? 0x7FFFu : 0x7C00u;
    } else {
        u &= ~(uint32_t)0xFFFu;
        u = float_bits(bits_float(u) * bits_float(15u << 23));
        u += 0x1000u;
        if (u > (31u << 23)) {
            u = 31u << 23;
        }
        out = (u >> 13) & 0xFFFFu;
    }
    return (uint16_t)(out | (sign >> 16));
}

float occ_float16_to_float(uint16_t h)
{
    uint32_t u = (uint32_t)(h & 0x7FFFu) << 13;
    float f = bits_float(u) * bits_float((254u - 15u) << 23);
    if (f >= bits_float((127u + 16u) << 23)) {
        u = float_bits(f) | (255u << 23);
        f = bits_float(u);
    }
    return bits_float(float_bits(f) | ((uint32_t)(h & 0x8000u) << 16));
}

size_t occ_dronecan_frame_count(size_t payload_len)
{
    /* ceil((len + 2) / 7) without the sum, which wraps for a length near SIZE_MAX */
    return (payload_len <= 7u) ? 1u : payload_len / 7u + (payload_len % 7u + 2u + 6u) / 7u;
}

occ_err_t occ_dronecan_send_transfer(const occ_can_iface_t *iface, uint32_t can_id,
                                     uint64_t signature, uint8_t tid, const uint8_t *payload,
                                     size_t payload_len, size_t *frames_sent)
{
    if (frames_sent != NULL) {
        *frames_sent = 0;
    }
    if (iface == NULL || iface->tx == NULL || tid > OCC_DRONECAN_TAIL_TID ||
        payload_len > OCC_DRONECAN_MAX_PAYLOAD || (payload == NULL && payload_len > 0u)) {
        return OCC_ERR_ARG;
    }
    const size_t n_frames = occ_dronecan_frame_count(payload_len);
    if (iface->tx_space != NULL && iface->tx_space(iface->user) < n_frames) {
        return OCC_ERR_NOMEM;
    }
    /* The multi-frame stream is CRC (little endian) + payload, cut in 7-byte pieces. */
    uint8_t crc_bytes[2] = {0, 0};
    size_t stream_len = payload_len;
    if (n_frames > 1u) {
        const uint16_t crc = occ_dronecan_crc16(occ_dronecan_crc_seed(signature), payload,
                                                payload_len);
        crc_bytes[0] = (uint8_t)(crc & 0xFFu);
        crc_bytes[1] = (uint8_t)(crc >> 8);
        stream_len += 2u;
    }
    size_t pos = 0;
    unsigned toggle = 0;
    for (size_t fi = 0; fi < n_frames; fi++) {
        occ_can_frame_t fr;
        memset(&fr, 0, sizeof fr);
        fr.id = can_id & OCC_CAN_EXT_ID_MASK;
        fr.flags = OCC_CAN_FLAG_EXT;
        size_t k = 0;
        while (k < 7u && pos < stream_len) {
            if (n_frames > 1u && pos < 2u) {
                fr.data[k] = crc_bytes[pos];
            } else {
                fr.data[k] = payload[pos - ((n_frames > 1u) ? 2u : 0u)];
            }
            k++;
            pos++;
        }
        uint8_t tail = (uint8_t)(tid | (toggle != 0u ? OCC_DRONECAN_TAIL_TOGGLE : 0u));
        if (fi == 0u) {
            tail = (uint8_t)(tail | OCC_DRONECAN_TAIL_START);
        }
        if (fi + 1u == n_frames) {
            tail = (uint8_t)(tail | OCC_DRONECAN_TAIL_END);
        }
        fr.data[k] = tail;
        fr.len = (uint8_t)(k + 1u);
        const occ_err_t e = iface->tx(iface->user, &fr);
        if (e != OCC_OK) {
            return (e == OCC_ERR_NOMEM) ? OCC_ERR_NOMEM : OCC_ERR_IO;
        }
        if (frames_sent != NULL) {
            (*frames_sent)++;
        }
        toggle ^= 1u;
    }
    return OCC_OK;
}
