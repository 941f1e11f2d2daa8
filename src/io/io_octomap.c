/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * io_octomap.c - the tree data of OctoMap's .bt and .ot files: parsers that drive a builder
 * (validating every byte: lengths, impossible child patterns, node count, values) and emitters
 * that walk the map iteratively. Headers are in io_header.c.
 */
#include "io_internal.h"

/* ---- .bt ------------------------------------------------------------------------------------ */

/* Child i's 2-bit code sits at bits 2i..2i+1 of the little-endian byte pair:
 * 1 = free leaf, 2 = occupied leaf, 3 = has children, 0 = absent. */
#define BT_FREE 1u
#define BT_OCC 2u
#define BT_INNER 3u

static unsigned bt_code(const uint16_t codes, const unsigned i)
{
    return (unsigned)(codes >> (2u * i)) & 3u;
}

static unsigned bt_count(const uint16_t codes)
{
    unsigned n = 0u;
    for (unsigned i = 0; i < 8u; i++) {
        n += bt_code(codes, i) != 0u ? 1u : 0u;
    }
    return n;
}

static void bt_leaves(occ_build_t *const b, const uint16_t codes, const occ_value_t q_free,
                      const occ_value_t q_occ)
{
    for (unsigned i = 0; i < 8u; i++) {
        const unsigned k = bt_code(codes, i);
        if (k == BT_FREE) {
            occi_build_leaf(b, i, q_free);
        } else if (k == BT_OCC) {
            occi_build_leaf(b, i, q_occ);
        }
    }
}

occ_err_t occi_bt_parse(occ_cursor_t *const c, occ_build_t *const b, const uint64_t header_size,
                        const occ_value_t q_free, const occ_value_t q_occ)
{
    if (header_size == 0u) {
        return OCC_OK;  /* OctoMap reads no data for an empty tree */
    }
    struct {
        uint16_t codes;
        uint8_t next;
    } st[OCC_MAX_DEPTH + 1];
    if (c->len - c->pos < 2u) {
        return occ_cursor_fail(c, c->pos, "truncated .bt data");
    }
    uint16_t codes = occi_rd_u16(c->buf + c->pos);
    if (codes == 0u) {
        return occ_cursor_fail(c, c->pos, "root node without children");
    }
    if (1u + bt_count(codes) > header_size) {
        return occ_cursor_fail(c, c->pos, "more nodes than the header's size");
    }
    c->pos += 2u;
    occi_build_open_root(b);
    st[0].codes = codes;
    st[0].next = 0u;
    bt_leaves(b, codes, q_free, q_occ);
    while (b->sp > 0u) {
        const unsigned top = b->sp - 1u;
        unsigned i = st[top].next;
        while (i < 8u && bt_code(st[top].codes, i) != BT_INNER) {
            i++;
        }
        if (i == 8u) {
            occi_build_close(b);
            continue;
        }
        st[top].next = (uint8_t)(i + 1u);
        if (occ_build_level(b) <= 1u) {
            return occ_cursor_fail(c, c->pos, "a voxel marked as having children");
        }
        if (c->len - c->pos < 2u) {
            return occ_cursor_fail(c, c->pos, "truncated .bt data");
        }
        codes = occi_rd_u16(c->buf + c->pos);
        if (codes == 0u) {
            return occ_cursor_fail(c, c->pos, "inner node without children");
        }
        if (b->nodes + bt_count(codes) > header_size) {
            return occ_cursor_fail(c, c->pos, "more nodes than the header's size");
        }
        c->pos += 2u;
        occi_build_open(b, i);
        st[top + 1u].codes = codes;
        st[top + 1u].next = 0u;
        bt_leaves(b, codes, q_free, q_occ);
    }
    if (b->nodes != header_size) {
        return occ_cursor_fail(c, c->pos, "fewer nodes than the header's size");
    }
    return OCC_OK;
}

/* ---- .ot ------------------------------------------------------------------------------------ */

static occ_value_t ot_value(occ_cursor_t *const c, const float f)
{
    const occ_value_t q = occ_value_from_logodds(f);
    const float back = occ_value_to_logodds(q);
    if (back < f || f < back) {
        c->warnings |= (f > OCC_VALUE_MAX / (float)OCC_FIXED_ONE ||
                        f < OCC_VALUE_MIN / (float)OCC_FIXED_ONE) ? OCC_IO_WARN_CLAMPED
                                                                  : OCC_IO_WARN_QUANTIZED;
    }
    return q;
}

/* One node record at c->pos: value, extra payload, child mask. */
static occ_err_t ot_record(occ_cursor_t *const c, const size_t extra, occ_value_t *const v,
                           uint8_t *const mask)
{
    if (c->len - c->pos < 5u + extra) {
        return occ_cursor_fail(c, c->pos, "truncated .ot data");
    }
    const float f = occi_rd_f32(c->buf + c->pos);
    if (!occ_finite(f)) {
        return occ_cursor_fail(c, c->pos, "non-finite log-odds");
    }
    *v = ot_value(c, f);
    *mask = c->buf[c->pos + 4u + extra];
    c->pos += 5u + extra;
    return OCC_OK;
}

/* -fanalyzer reads st[top] as uninitialised: st[] mirrors the builder's stack, frame for frame
 * (occi_build_open_root / occi_build_open push b->sp exactly where st[0] / st[top + 1] are
 * written, occi_build_close pops), which it cannot see across the calls. */
OCC_ANALYZER_UNINIT_OFF
occ_err_t occi_ot_parse(occ_cursor_t *const c, occ_build_t *const b, const uint64_t header_size,
                        const size_t extra)
{
    if (header_size == 0u) {
        return OCC_OK;
    }
    struct {
        occ_value_t stored;
        uint8_t mask;
        uint8_t next;
    } st[OCC_MAX_DEPTH + 1];
    occ_value_t v;
    uint8_t mask;
    occ_err_t e = ot_record(c, extra, &v, &mask);
    if (e != OCC_OK) {
        return e;
    }
    if (mask == 0u) {
        occi_build_root_uniform(b, v);
    } else {
        if (1u + occ_popcount8(mask) > header_size) {
            return occ_cursor_fail(c, c->pos - 1u, "more nodes than the header's size");
        }
        occi_build_open_root(b);
        st[0].stored = v;
        st[0].mask = mask;
        st[0].next = 0u;
    }
    while (b->sp > 0u) {
        const unsigned top = b->sp - 1u;
        unsigned i = st[top].next;
        while (i < 8u && (((unsigned)st[top].mask >> i) & 1u) == 0u) {
            i++;
        }
        if (i == 8u) {
            if (!occ_value_eq(b->st[top].vmax, st[top].stored)) {
                c->warnings |= OCC_IO_WARN_INNER_VALUE;
            }
            occi_build_close(b);
            continue;
        }
        st[top].next = (uint8_t)(i + 1u);
        const size_t at = c->pos;
        e = ot_record(c, extra, &v, &mask);
        if (e != OCC_OK) {
            return e;
        }
        if (mask == 0u) {
            occi_build_leaf(b, i, v);
            continue;
        }
        if (occ_build_level(b) <= 1u) {
            return occ_cursor_fail(c, at, "a voxel with children");
        }
        if (b->nodes + 1u + occ_popcount8(mask) > header_size) {
            return occ_cursor_fail(c, at, "more nodes than the header's size");
        }
        occi_build_open(b, i);
        st[top + 1u].stored = v;
        st[top + 1u].mask = mask;
        st[top + 1u].next = 0u;
    }
    if (b->nodes != header_size) {
        return occ_cursor_fail(c, c->pos, "node count differs from the header's size");
    }
    return OCC_OK;
}
OCC_ANALYZER_UNINIT_ON

/* ---- emitters ------------------------------------------------------------------------------- */

typedef struct {
    uint32_t block;
    uint8_t level;
    uint8_t next;
    uint16_t codes;
} emit_frame_t;

/* True when some voxel under the child block `block` of a node at `level` is unobserved. */
static bool has_unobserved(const occ_map_t *const m, const uint32_t block, const unsigned level)
{
    emit_frame_t st[OCC_MAX_DEPTH + 1];
    unsigned sp = 0u;
    st[sp].block = block;
    st[sp].level = (uint8_t)level;
    st[sp].next = 0u;
    sp++;
    while (sp > 0u) {
        emit_frame_t *const f = &st[sp - 1u];
        if (f->level == 1u) {
            const occ_leaf_block_t *const lb = occ_leaf_at(m, f->block);
            for (unsigned i = 0; i < 8u; i++) {
                if (!occ_is_observed(lb->value[i])) {
                    return true;
                }
            }
            sp--;
            continue;
        }
        if (f->next == 8u) {
            sp--;
            continue;
        }
        const occ_inner_block_t *const ib = occ_inner_at(m, f->block);
        const unsigned i = f->next++;
        if (!occ_is_observed(ib->value[i])) {
            return true;
        }
        if (occ_inner_child(ib, i) != OCC_NONE) {
            OCC_ASSERT(sp <= OCC_MAX_DEPTH && f->level > 1u);
            st[sp].block = occ_inner_child(ib, i);
            st[sp].level = (uint8_t)(f->level - 1u);
            st[sp].next = 0u;
            sp++;
        }
    }
    return false;
}

static unsigned ml_of_value(const occ_map_t *const m, const occ_value_t v)
{
    if (!occ_is_observed(v)) {
        return 0u;
    }
    return occ_value_state(m, v) == OCC_STATE_OCCUPIED ? BT_OCC : BT_FREE;
}

/* .bt code of an inner-block entry at `level`: its maximum-likelihood class after pruning. */
static unsigned ml_of_entry(const occ_map_t *const m, const occ_inner_block_t *const ib,
                            const unsigned slot, const unsigned level)
{
    if (occ_inner_child(ib, slot) == OCC_NONE) {
        return ml_of_value(m, ib->value[slot]);
    }
    const uint8_t f = occ_inner_flags(ib, slot);
    const bool occ = (f & OCC_NODE_HAS_OCCUPIED) != 0u;
    const bool fr = (f & OCC_NODE_HAS_FREE) != 0u;
    const bool unk = (f & OCC_NODE_HAS_UNKNOWN) != 0u;
    if (unk) {
        const bool band_empty = !(m->priv.q_free_max < m->priv.q_occ_min);
        if (band_empty || has_unobserved(m, occ_inner_child(ib, slot), level)) {
            return BT_INNER;
        }
        return occ ? BT_INNER : BT_FREE;  /* all observed; band values count as free */
    }
    if (occ && fr) {
        return BT_INNER;
    }
    return occ ? BT_OCC : BT_FREE;
}

static uint16_t bt_codes_of(const occ_map_t *const m, const uint32_t block, const unsigned level)
{
    uint16_t codes = 0u;
    if (level == 1u) {
        const occ_leaf_block_t *const lb = occ_leaf_at(m, block);
        for (unsigned i = 0; i < 8u; i++) {
            codes = (uint16_t)(codes | (ml_of_value(m, lb->value[i]) << (2u * i)));
        }
    } else {
        const occ_inner_block_t *const ib = occ_inner_at(m, block);
        for (unsigned i = 0; i < 8u; i++) {
            codes = (uint16_t)(codes | (ml_of_entry(m, ib, i, level - 1u) << (2u * i)));
        }
    }
    return codes;
}

void occi_bt_emit(const occ_map_t *const m, occ_sink_t *const s, uint64_t *const nodes)
{
    *nodes = 0u;
    if (!occ_is_observed(m->priv.root_value)) {
        return;
    }
    if (occ_root_child(m) == OCC_NONE) {
        /* OctoMap never prunes the root: a uniform map is a root with 8 equal leaves. */
        const unsigned k = ml_of_value(m, m->priv.root_value);
        uint16_t codes = 0u;
        for (unsigned i = 0; i < 8u; i++) {
            codes = (uint16_t)(codes | (k << (2u * i)));
        }
        occi_sink_u16(s, codes);
        *nodes = 9u;
        return;
    }
    emit_frame_t st[OCC_MAX_DEPTH + 1];
    unsigned sp = 0u;
    st[0].block = occ_root_child(m);
    st[0].level = m->cfg.depth_levels;
    st[0].next = 0u;
    st[0].codes = bt_codes_of(m, occ_root_child(m), m->cfg.depth_levels);
    occi_sink_u16(s, st[0].codes);
    *nodes = 1u + bt_count(st[0].codes);
    sp = 1u;
    while (sp > 0u && s->err == OCC_OK) {
        emit_frame_t *const f = &st[sp - 1u];
        unsigned i = f->next;
        while (i < 8u && bt_code(f->codes, i) != BT_INNER) {
            i++;
        }
        if (i == 8u) {
            sp--;
            continue;
        }
        f->next = (uint8_t)(i + 1u);
        const uint32_t child = occ_inner_child(occ_inner_at(m, f->block), i);
        OCC_ASSERT(sp <= OCC_MAX_DEPTH && f->level > 1u);
        emit_frame_t *const g = &st[sp];
        g->block = child;
        g->level = (uint8_t)(f->level - 1u);
        g->next = 0u;
        g->codes = bt_codes_of(m, child, g->level);
        occi_sink_u16(s, g->codes);
        *nodes += bt_count(g->codes);
        sp++;
    }
}

static uint8_t observed_mask(const occ_map_t *const m, const uint32_t block, const unsigned level)
{
    uint8_t mask = 0u;
    for (unsigned i = 0; i < 8u; i++) {
        const occ_value_t v = level == 1u ? occ_leaf_at(m, block)->value[i]
                                          : occ_inner_at(m, block)->value[i];
        if (occ_is_observed(v)) {
            mask = (uint8_t)(mask | (1u << i));
        }
    }
    return mask;
}

static void ot_rec(occ_sink_t *const s, const occ_value_t v, const uint8_t mask)
{
    occi_sink_f32(s, occ_value_to_logodds(v));
    occi_sink_u8(s, mask);
}

void occi_ot_emit(const occ_map_t *const m, occ_sink_t *const s, uint64_t *const nodes)
{
    *nodes = 0u;
    if (!occ_is_observed(m->priv.root_value)) {
        return;
    }
    if (occ_root_child(m) == OCC_NONE) {
        ot_rec(s, m->priv.root_value, 0xFFu);
        for (unsigned i = 0; i < 8u; i++) {
            ot_rec(s, m->priv.root_value, 0u);
        }
        *nodes = 9u;
        return;
    }
    emit_frame_t st[OCC_MAX_DEPTH + 1];
    unsigned sp = 1u;
    st[0].block = occ_root_child(m);
    st[0].level = m->cfg.depth_levels;
    st[0].next = 0u;
    ot_rec(s, m->priv.root_value, observed_mask(m, occ_root_child(m), st[0].level));
    *nodes = 1u;
    while (sp > 0u && s->err == OCC_OK) {
        emit_frame_t *const f = &st[sp - 1u];
        if (f->next == 8u) {
            sp--;
            continue;
        }
        const unsigned i = f->next++;
        if (f->level == 1u) {
            const occ_value_t v = occ_leaf_at(m, f->block)->value[i];
            if (occ_is_observed(v)) {
                ot_rec(s, v, 0u);
                (*nodes)++;
            }
            continue;
        }
        const occ_inner_block_t *const ib = occ_inner_at(m, f->block);
        if (!occ_is_observed(ib->value[i])) {
            continue;
        }
        (*nodes)++;
        if (occ_inner_child(ib, i) == OCC_NONE) {
            ot_rec(s, ib->value[i], 0u);
            continue;
        }
        OCC_ASSERT(sp <= OCC_MAX_DEPTH && f->level > 1u);
        emit_frame_t *const g = &st[sp];
        g->block = occ_inner_child(ib, i);
        g->level = (uint8_t)(f->level - 1u);
        g->next = 0u;
        ot_rec(s, ib->value[i], observed_mask(m, g->block, g->level));
        sp++;
    }
}
