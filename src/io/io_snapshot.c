/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * io_snapshot.c - occmap's native snapshot (.occ). Layout (little endian):
 *   0 "OCCMAPSN"   8 u16 version (1)   10 u16 header bytes (64)   12 u8 value kind (0: int16
 *   fixed point, step 1/1024; 1: float32 log-odds; 2: int8 fixed point, step 1/36)   13 u8 depth_levels   14 u16 flags (0)
 *   16 f32 resolution_m, hit, miss, clamp_min, clamp_max, free_max, occupied_min
 *   44 u32 inner blocks   48 u32 leaf blocks   52 u64 payload bytes   60 u32 reserved (0)
 *   64 payload: root tag (0 unobserved, 1 uniform + value, 2 has children); then per node with
 *      children, preorder: u8 observed mask, u8 has-children mask (a subset; 0 at level 1),
 *      the values of its observed childless children in slot order, then those children.
 *   64 + payload: u32 CRC-32 of bytes [0, 64 + payload).
 * Values are stored raw, so a snapshot reloads bit-exactly in the build that wrote it.
 * Kinds 0 and 1 load in the 16-bit and float builds (converted, QUANTIZED when not exact);
 * kind 2 loads only in the 8-bit build (OCC_VALUE_BITS 8), which loads only kind 2: the
 * others give OCC_ERR_UNSUPPORTED (their grids do not map onto each other exactly).
 */
#include <string.h>

#include "io_internal.h"

static const char magic[8] = {'O', 'C', 'C', 'M', 'A', 'P', 'S', 'N'};

#if OCC_VALUE_FLOAT
#define OWN_KIND 1u
#elif OCC_VALUE_BITS == 8
#define OWN_KIND 2u
#else
#define OWN_KIND 0u
#endif
#define KIND_INT8 2u

occ_err_t occi_snap_header_parse(occ_cursor_t *const c, occ_snap_header_t *const h)
{
    const uint8_t *const p = c->buf;
    if (c->len < 8u || memcmp(p, magic, 8u) != 0) {
        return occ_cursor_fail(c, 0u, "wrong magic: not an occmap snapshot");
    }
    if (c->len < OCC_SNAPSHOT_HEADER_BYTES + 4u) {
        return occ_cursor_fail(c, c->len, "truncated snapshot header");
    }
    if (occi_rd_u16(p + 8) != OCC_SNAPSHOT_VERSION) {
        c->error = "unsupported snapshot version";
        c->error_offset = 8u;
        return OCC_ERR_UNSUPPORTED;
    }
    if (occi_rd_u16(p + 10) != OCC_SNAPSHOT_HEADER_BYTES || occi_rd_u16(p + 14) != 0u ||
        occi_rd_u32(p + 60) != 0u) {
        return occ_cursor_fail(c, 10u, "bad snapshot header fields");
    }
    h->payload_bytes = occi_rd_u64(p + 52);
    if (h->payload_bytes != (uint64_t)(c->len - OCC_SNAPSHOT_HEADER_BYTES - 4u)) {
        return occ_cursor_fail(c, 52u, h->payload_bytes > (uint64_t)(c->len - 68u)
                                           ? "truncated snapshot (payload length)"
                                           : "payload length does not match the file");
    }
    const size_t end = OCC_SNAPSHOT_HEADER_BYTES + (size_t)h->payload_bytes;
    if (occ_crc32(0u, p, end) != occi_rd_u32(p + end)) {
        return occ_cursor_fail(c, end, "CRC mismatch");
    }
    h->value_kind = p[12];
    if (h->value_kind > 2u) {
        return occ_cursor_fail(c, 12u, "unknown value encoding");
    }
    if ((h->value_kind == KIND_INT8) != (OWN_KIND == KIND_INT8)) {
        c->error = "snapshot value kind (8-bit vs 16-bit/float) not loadable by this build";
        c->error_offset = 12u;
        return OCC_ERR_UNSUPPORTED;
    }
    occ_map_config_t *const cfg = &h->cfg;
    cfg->depth_levels = p[13];
    cfg->resolution_m = occi_rd_f32(p + 16);
    cfg->hit = occi_rd_f32(p + 20);
    cfg->miss = occi_rd_f32(p + 24);
    cfg->clamp_min = occi_rd_f32(p + 28);
    cfg->clamp_max = occi_rd_f32(p + 32);
    cfg->free_max = occi_rd_f32(p + 36);
    cfg->occupied_min = occi_rd_f32(p + 40);
    h->inner_blocks = occi_rd_u32(p + 44);
    h->leaf_blocks = occi_rd_u32(p + 48);
    /* Config validity: occ_map_init's rules. */
    if (!occi_map_config_ok(cfg)) {
        return occ_cursor_fail(c, 13u, "invalid config (resolution, depth or sensor model)");
    }
    c->pos = OCC_SNAPSHOT_HEADER_BYTES;
    c->len = end;  /* the payload parser must not read the CRC */
    return OCC_OK;
}

static occ_err_t read_value(occ_cursor_t *const c, const uint8_t kind, occ_value_t *const v)
{
    const size_t n = kind == 0u ? 2u : kind == KIND_INT8 ? 1u : 4u;
    if (c->len - c->pos < n) {
        return occ_cursor_fail(c, c->pos, "truncated snapshot payload");
    }
#if OWN_KIND == KIND_INT8
    /* The header parser let only kind 2 through. */
    const int8_t raw8 = (int8_t)c->buf[c->pos];
    if (raw8 == INT8_MIN) {
        return occ_cursor_fail(c, c->pos, "unobserved value stored as observed");
    }
    *v = raw8;
#else
    if (kind == 0u) {
        const int16_t raw = (int16_t)occi_rd_u16(c->buf + c->pos);
        if (raw == INT16_MIN) {
            return occ_cursor_fail(c, c->pos, "unobserved value stored as observed");
        }
#if OCC_VALUE_FLOAT
        *v = (float)raw / (float)OCC_FIXED_ONE;
#else
        *v = raw;
#endif
    } else {
        const float f = occi_rd_f32(c->buf + c->pos);
        if (!occ_finite(f)) {
            return occ_cursor_fail(c, c->pos, "non-finite value");
        }
        *v = occ_value_from_logodds(f);
        const float back = occ_value_to_logodds(*v);
        if (back < f || f < back) {
            c->warnings |= OCC_IO_WARN_QUANTIZED;
        }
    }
#endif
    c->pos += n;
    return OCC_OK;
}

/* A node's record after it was opened: masks, then its childless observed children. */
static occ_err_t read_node(occ_cursor_t *const c, occ_build_t *const b, const uint8_t kind,
                           uint8_t *const blk)
{
    if (c->len - c->pos < 2u) {
        return occ_cursor_fail(c, c->pos, "truncated snapshot payload");
    }
    const uint8_t obs = c->buf[c->pos];
    *blk = c->buf[c->pos + 1u];
    if (obs == 0u || (*blk & (uint8_t)~obs) != 0u) {
        return occ_cursor_fail(c, c->pos, "impossible child masks");
    }
    if (occ_build_level(b) == 1u && *blk != 0u) {
        return occ_cursor_fail(c, c->pos, "a voxel with children");
    }
    c->pos += 2u;
    for (unsigned i = 0; i < 8u; i++) {
        if ((((unsigned)obs & ~(unsigned)*blk) >> i) & 1u) {
            occ_value_t v;
            const occ_err_t e = read_value(c, kind, &v);
            if (e != OCC_OK) {
                return e;
            }
            occi_build_leaf(b, i, v);
        }
    }
    return OCC_OK;
}

occ_err_t occi_snap_parse(occ_cursor_t *const c, occ_build_t *const b, const occ_snap_header_t *const h)
{
    if (c->pos >= c->len) {
        return occ_cursor_fail(c, c->pos, "truncated snapshot payload");
    }
    const uint8_t tag = c->buf[c->pos++];
    occ_err_t e = OCC_OK;
    struct {
        uint8_t blk;
        uint8_t next;
    } st[OCC_MAX_DEPTH + 1];
    if (tag == 1u) {
        occ_value_t v;
        e = read_value(c, h->value_kind, &v);
        if (e != OCC_OK) {
            return e;
        }
        occi_build_root_uniform(b, v);
    } else if (tag == 2u) {
        occi_build_open_root(b);
        e = read_node(c, b, h->value_kind, &st[0].blk);
        st[0].next = 0u;
    } else if (tag != 0u) {
        return occ_cursor_fail(c, c->pos - 1u, "bad root tag");
    }
    while (e == OCC_OK && b->sp > 0u) {
        const unsigned top = b->sp - 1u;
        unsigned i = st[top].next;
        while (i < 8u && (((unsigned)st[top].blk >> i) & 1u) == 0u) {
            i++;
        }
        if (i == 8u) {
            occi_build_close(b);
            continue;
        }
        st[top].next = (uint8_t)(i + 1u);
        occi_build_open(b, i);
        st[top + 1u].next = 0u;
        e = read_node(c, b, h->value_kind, &st[top + 1u].blk);
    }
    if (e != OCC_OK) {
        return e;
    }
    if (c->pos != c->len) {
        return occ_cursor_fail(c, c->pos, "payload length does not match the tree");
    }
    if (b->live_inner != h->inner_blocks || b->live_leaf != h->leaf_blocks) {
        return occ_cursor_fail(c, 44u, "block counts do not match the tree");
    }
    return OCC_OK;
}

/* ---- writer ------------------------------------------------------------------------------- */

typedef struct {
    uint32_t block;
    uint8_t level;
    uint8_t blk;
    uint8_t next;
} snap_frame_t;

static void put_value(occ_sink_t *const s, const occ_value_t v)
{
#if OCC_VALUE_FLOAT
    occi_sink_f32(s, v);
#elif OCC_VALUE_BITS == 8
    occi_sink_u8(s, (uint8_t)v);
#else
    occi_sink_u16(s, (uint16_t)v);
#endif
}

/* Emit a node record for child block `block` of a node at `level`; returns the has-children
 * mask. */
static uint8_t put_node(const occ_map_t *const m, occ_sink_t *const s, const uint32_t block,
                        const unsigned level)
{
    uint8_t obs = 0u, blk = 0u;
    if (level == 1u) {
        const occ_leaf_block_t *const lb = occ_leaf_at(m, block);
        for (unsigned i = 0; i < 8u; i++) {
            obs = (uint8_t)(obs | (occ_is_observed(lb->value[i]) ? 1u << i : 0u));
        }
        occi_sink_u8(s, obs);
        occi_sink_u8(s, 0u);
        for (unsigned i = 0; i < 8u; i++) {
            if ((((unsigned)obs >> i) & 1u) != 0u) {
                put_value(s, lb->value[i]);
            }
        }
        return 0u;
    }
    const occ_inner_block_t *const ib = occ_inner_at(m, block);
    for (unsigned i = 0; i < 8u; i++) {
        obs = (uint8_t)(obs | (occ_is_observed(ib->value[i]) ? 1u << i : 0u));
        blk = (uint8_t)(blk | (occ_inner_child(ib, i) != OCC_NONE ? 1u << i : 0u));
    }
    occi_sink_u8(s, obs);
    occi_sink_u8(s, blk);
    for (unsigned i = 0; i < 8u; i++) {
        if (((((unsigned)obs & ~(unsigned)blk) >> i) & 1u) != 0u) {
            put_value(s, ib->value[i]);
        }
    }
    return blk;
}

static void put_payload(const occ_map_t *const m, occ_sink_t *const s)
{
    if (!occ_is_observed(m->priv.root_value)) {
        occi_sink_u8(s, 0u);
        return;
    }
    if (occ_root_child(m) == OCC_NONE) {
        occi_sink_u8(s, 1u);
        put_value(s, m->priv.root_value);
        return;
    }
    occi_sink_u8(s, 2u);
    snap_frame_t st[OCC_MAX_DEPTH + 1];
    unsigned sp = 1u;
    st[0].block = occ_root_child(m);
    st[0].level = m->cfg.depth_levels;
    st[0].next = 0u;
    st[0].blk = put_node(m, s, occ_root_child(m), st[0].level);
    while (sp > 0u && s->err == OCC_OK) {
        snap_frame_t *const f = &st[sp - 1u];
        unsigned i = f->next;
        while (i < 8u && (((unsigned)f->blk >> i) & 1u) == 0u) {
            i++;
        }
        if (i == 8u) {
            sp--;
            continue;
        }
        f->next = (uint8_t)(i + 1u);
        OCC_ASSERT(sp <= OCC_MAX_DEPTH && f->level > 1u);
        snap_frame_t *const g = &st[sp++];
        g->block = occ_inner_child(occ_inner_at(m, f->block), i);
        g->level = (uint8_t)(f->level - 1u);
        g->next = 0u;
        g->blk = put_node(m, s, g->block, g->level);
    }
}

occ_err_t occi_snap_write(const occ_map_t *const m, occ_sink_t *const s)
{
    occ_sink_t counter;
    occi_sink_init(&counter, NULL, NULL);
    put_payload(m, &counter);
    const occ_map_config_t *const cfg = &m->cfg;
    s->crc_on = true;
    s->crc = 0u;
    occi_sink_put(s, magic, 8u);
    occi_sink_u16(s, (uint16_t)OCC_SNAPSHOT_VERSION);
    occi_sink_u16(s, (uint16_t)OCC_SNAPSHOT_HEADER_BYTES);
    occi_sink_u8(s, (uint8_t)OWN_KIND);
    occi_sink_u8(s, cfg->depth_levels);
    occi_sink_u16(s, 0u);
    occi_sink_f32(s, cfg->resolution_m);
    occi_sink_f32(s, cfg->hit);
    occi_sink_f32(s, cfg->miss);
    occi_sink_f32(s, cfg->clamp_min);
    occi_sink_f32(s, cfg->clamp_max);
    occi_sink_f32(s, cfg->free_max);
    occi_sink_f32(s, cfg->occupied_min);
    occi_sink_u32(s, m->inner.used);
    occi_sink_u32(s, m->leaf.used);
    const uint64_t pl = (uint64_t)counter.total;
    occi_sink_u32(s, (uint32_t)(pl & 0xFFFFFFFFu));
    occi_sink_u32(s, (uint32_t)(pl >> 32));
    occi_sink_u32(s, 0u);
    put_payload(m, s);
    (void)occi_sink_flush(s);
    s->crc_on = false;
    occi_sink_u32(s, s->crc);
    return occi_sink_flush(s);
}
