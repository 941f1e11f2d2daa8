/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * io_sink.c - the writers' buffered byte sink (chunks of OCC_SINK_BUF bytes to the caller's
 * callback, sticky first error, optional running CRC) and little-endian byte helpers.
 */
#include <string.h>

#include "io_internal.h"

void occi_sink_init(occ_sink_t *const s, const occ_io_write_fn fn, void *const ctx)
{
    s->fn = fn;
    s->ctx = ctx;
    s->err = OCC_OK;
    s->crc_on = false;
    s->crc = 0u;
    s->total = 0u;
    s->fill = 0u;
}

occ_err_t occi_sink_flush(occ_sink_t *const s)
{
    if (s->fill > 0u && s->err == OCC_OK) {
        if (s->crc_on) {
            s->crc = occ_crc32(s->crc, s->buf, s->fill);
        }
        if (s->fn != NULL) {
            s->err = s->fn(s->ctx, s->buf, s->fill);
        }
    }
    s->fill = 0u;
    return s->err;
}

void occi_sink_put(occ_sink_t *const s, const void *const data, const size_t len)
{
    const uint8_t *p = (const uint8_t *)data;
    size_t n = len;
    s->total += len;
    while (n > 0u && s->err == OCC_OK) {
        size_t k = OCC_SINK_BUF - s->fill;
        if (k > n) {
            k = n;
        }
        memcpy(s->buf + s->fill, p, k);
        s->fill += k;
        p += k;
        n -= k;
        if (s->fill == OCC_SINK_BUF) {
            (void)occi_sink_flush(s);
        }
    }
}

void occi_sink_u8(occ_sink_t *const s, const uint8_t v)
{
    occi_sink_put(s, &v, 1u);
}

void occi_sink_u16(occ_sink_t *const s, const uint16_t v)
{
    const uint8_t b[2] = {(uint8_t)(v & 0xFFu), (uint8_t)(v >> 8)};
    occi_sink_put(s, b, 2u);
}

void occi_sink_u32(occ_sink_t *const s, const uint32_t v)
{
    const uint8_t b[4] = {(uint8_t)(v & 0xFFu), (uint8_t)((v >> 8) & 0xFFu),
                          (uint8_t)((v >> 16) & 0xFFu), (uint8_t)(v >> 24)};
    occi_sink_put(s, b, 4u);
}

void occi_sink_f32(occ_sink_t *const s, const float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    occi_sink_u32(s, u);
}

void occi_sink_str(occ_sink_t *const s, const char *const str)
{
    occi_sink_put(s, str, strlen(str));
}

void occi_sink_dec(occ_sink_t *const s, const uint64_t v)
{
    char tmp[24];
    size_t n = 0u;
    uint64_t x = v;
    do {
        tmp[sizeof tmp - 1u - n] = (char)('0' + (int)(x % 10u));
        n++;
        x /= 10u;
    } while (x != 0u);
    occi_sink_put(s, tmp + sizeof tmp - n, n);
}

uint16_t occi_rd_u16(const uint8_t *const p)
{
    return (uint16_t)((unsigned)p[0] | ((unsigned)p[1] << 8));
}

uint32_t occi_rd_u32(const uint8_t *const p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

uint64_t occi_rd_u64(const uint8_t *const p)
{
    return (uint64_t)occi_rd_u32(p) | ((uint64_t)occi_rd_u32(p + 4) << 32);
}

float occi_rd_f32(const uint8_t *const p)
{
    const uint32_t u = occi_rd_u32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

occ_err_t occ_io_buf_write(void *const ctx, const void *const data, const size_t len)
{
    occ_io_buf_t *const b = (occ_io_buf_t *)ctx;
    if (b == NULL || data == NULL) {
        return OCC_ERR_ARG;
    }
    size_t k = len;
    if (k > b->cap - b->len) {
        k = b->cap - b->len;
    }
    if (k > 0u) {
        memcpy(b->data + b->len, data, k);
        b->len += k;
    }
    return k == len ? OCC_OK : OCC_ERR_NOMEM;
}
