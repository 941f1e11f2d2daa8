/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * tree_frame.c - one frame's updates in a single pass over the tree: bricks (a level-2 node's
 * voxels by the miss and by the hit, tree_dense.c's update) and whole nodes (every voxel below
 * gets one delta) in one stream in Morton order, so that each part of the tree is descended,
 * written and refreshed once (the projective integrator's output). All-or-nothing: a bound of
 * the blocks the pass can allocate is checked first.
 */
#include "tree_path.h"

/* ---- a whole node's subtree ------------------------------------------------------------------ */

/* A uniform node gets the delta (it stays uniform). */
static void apply_uniform(occ_map_t *const m, const occ_nodep_t node, const occ_delta_t delta)
{
    *node.value = occ_value_apply_delta(m, *node.value, delta);
    occ_node_set_flags(node, occ_value_flags(m, *node.value));
    occ_touch_node(m, node);
}

void occi_tree_apply_subtree(occ_map_t *const m, const occ_nodep_t top, const unsigned level,
                             const occ_delta_t delta)
{
    OCC_ASSERT(level >= 1u && level <= m->cfg.depth_levels);
    if (occ_node_child(top) == OCC_NONE) {
        apply_uniform(m, top, delta);
        return;
    }
    /* An explicit stack of the blocks being updated, each with the node that owns it (block
     * OCC_NONE: `top`), refreshed bottom-up once its 8 children are done. */
    struct {
        uint32_t block, owner_block;
        uint8_t level, owner_slot, next; /* level: the owner's */
    } st[OCC_MAX_DEPTH + 1u];
    unsigned sp = 1;
    st[0].block = occ_node_child(top);
    st[0].owner_block = OCC_NONE;
    st[0].level = (uint8_t)level;
    st[0].owner_slot = 0u;
    st[0].next = 0u;
    while (sp > 0u) {
        const unsigned t = sp - 1u;
        const occ_nodep_t owner = st[t].owner_block == OCC_NONE
                                      ? top
                                      : occ_inner_node(m, st[t].owner_block, st[t].owner_slot);
        if (st[t].level == 1u) {
            occ_leaf_block_t *const b = occ_leaf_at(m, st[t].block);
            for (unsigned i = 0; i < 8u; i++) {
                b->value[i] = occ_value_apply_delta(m, b->value[i], delta);
            }
            occi_shared_touch(m, b, sizeof *b);
        }
        if (st[t].level == 1u || st[t].next == 8u) {
            (void)occi_tree_refresh(m, owner, st[t].level);
            sp--;
            continue;
        }
        const unsigned s = st[t].next++;
        const occ_nodep_t c = occ_inner_node(m, st[t].block, s);
        if (occ_node_child(c) == OCC_NONE) {
            apply_uniform(m, c, delta);
            continue;
        }
        OCC_ASSERT(sp <= OCC_MAX_DEPTH);
        st[sp].block = occ_node_child(c);
        st[sp].owner_block = st[t].block;
        st[sp].level = (uint8_t)(st[t].level - 1u);
        st[sp].owner_slot = (uint8_t)s;
        st[sp].next = 0u;
        sp++;
    }
}

/* ---- the frame's stream in Morton order ------------------------------------------------------- */

/* Level of a whole-node entry: its lowest set bit is the marker 3 level - 1. */
static unsigned node_level(const occ_code_t e)
{
    return ((unsigned)__builtin_ctzll(e) + 1u) / 3u;
}

static occ_code_t node_code(const occ_code_t e, const unsigned level)
{
    return e & ~(((occ_code_t)1 << (3u * level)) - 1u);
}

static bool is_brick(const occ_code_t e)
{
    return (e & OCC_CODE_HIT_BIT) != 0u;
}

/* Blocks the stream can allocate, as if no node existed, over-approximated by counting the
 * bricks and the whole nodes as two sorted chains: the entry that first goes below a node on
 * its chain's paths (its split from the chain's previous entry is above that node) counts the
 * node's child block for the levels below the split (a brick: brick_need). */
static void frame_need(const occ_map_t *const m, const occi_frame_t *const f,
                       uint64_t *const inner, uint64_t *const leaf)
{
    const unsigned top = m->cfg.depth_levels + 1u; /* a chain's first entry splits above the root */
    occ_code_t prev_b = 0, prev_n = 0;
    bool first_b = true, first_n = true;
    *inner = 0u;
    *leaf = 0u;
    for (size_t i = 0; i < f->n;) {
        const occ_code_t e = f->s[i];
        if (is_brick(e)) {
            const occ_code_t code = e & ~OCC_CODE_HIT_BIT;
            const unsigned s = first_b ? top : split_level(code, prev_b);
            brick_need(s, f->s[i + 1u] | f->s[i + 2u], inner, leaf);
            prev_b = code;
            first_b = false;
            i += OCC_FRAME_BRICK_SLOTS;
        } else {
            const unsigned lv = node_level(e);
            const occ_code_t code = node_code(e, lv);
            const unsigned s = first_n ? top : split_level(code, prev_n);
            *inner += s >= lv + 2u ? s - lv - 1u : 0u; /* inner blocks at levels lv + 1 .. s - 1 */
            prev_n = code;
            first_n = false;
            i++;
        }
    }
}

/* One whole-node entry at level L >= 3: descend to it (expanding a uniform ancestor whose
 * value the delta changes), then the delta on every voxel below. */
static void node_step(occ_map_t *const m, path_t *const p, const occ_code_t code,
                      const unsigned lv, const occ_delta_t delta, const unsigned start)
{
    unsigned l = start;
    while (l > lv && occ_node_child(p->node[l]) != OCC_NONE) {
        p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(code, l));
        l--;
    }
    p->low = l;
    if (l > lv) { /* a uniform ancestor: split it only when the value moves */
        const occ_value_t v = *p->node[l].value;
        if (occ_value_eq(occ_value_apply_delta(m, v, delta), v)) {
            return;
        }
        for (; l > lv; l--) {
            occi_tree_expand(m, p->node[l], l);
            p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(code, l));
        }
        p->low = lv;
    }
    occi_tree_apply_subtree(m, p->node[lv], lv, delta);
    p->dirty[lv + 1u] = true;
}

/* Can the pools supply the blocks the pass may allocate? First a crude bound in O(1), above
 * frame_need's (each slot at most depth - 1 inner blocks, each brick slot at most 2 leaf
 * blocks: a brick is 4 slots naming at most 8 level-1 nodes): when the pools can supply it,
 * the exact count (a pass over every entry) is not needed. */
static bool frame_fits(const occ_map_t *const m, const occi_frame_t *const f)
{
    const uint64_t crude_inner = (uint64_t)f->n * (m->cfg.depth_levels - 1u);
    const uint64_t crude_leaf = 2u * (uint64_t)f->n;
    if (crude_inner <= OCC_NONE && crude_leaf <= OCC_NONE &&
        occi_pool_can_supply(m, (uint32_t)crude_inner, (uint32_t)crude_leaf)) {
        return true;
    }
    uint64_t inner, leaf;
    frame_need(m, f, &inner, &leaf);
    return inner <= OCC_NONE && leaf <= OCC_NONE &&
           occi_pool_can_supply(m, (uint32_t)inner, (uint32_t)leaf);
}

occ_err_t occi_tree_apply_frame(occ_map_t *const m, const occi_frame_t *const f,
                                occi_frame_out_t *const out)
{
    out->changed = 0u;
    if (!frame_fits(m, f)) {
        m->oom_count++;
        return OCC_ERR_NOMEM;
    }
    path_t p;
    path_begin(m, &p);
    occ_code_t prev = 0, end = 0; /* end: past the previous entry's voxels */
    bool first = true;
    for (size_t i = 0; i < f->n;) {
        const occ_code_t e = f->s[i];
        if (is_brick(e)) {
            OCC_ASSERT(i + OCC_FRAME_BRICK_SLOTS <= f->n);
            const occi_brick_t b = {e & ~OCC_CODE_HIT_BIT, f->s[i + 1u], f->s[i + 2u]};
            OCC_ASSERT((b.code & 63u) == 0u && (b.miss & b.hit) == 0u);
            OCC_ASSERT(first || b.code >= end); /* in code order, nothing inside a whole node */
            const unsigned start = path_start(m, &p, b.code, prev, first);
            out->changed += occi_tree_brick_step(m, &p, &b, start, ~f->s[i + 3u]);
            prev = b.code;
            end = b.code + 64u;
            i += OCC_FRAME_BRICK_SLOTS;
        } else {
            const unsigned lv = node_level(e);
            const occ_code_t code = node_code(e, lv);
            OCC_ASSERT(lv >= 3u && (first || code >= end));
            const unsigned start = path_start(m, &p, code, prev, first);
            node_step(m, &p, code, lv, f->node_delta, start);
            prev = code;
            end = code + ((occ_code_t)1 << (3u * lv));
            i++;
        }
        first = false;
    }
    refresh_up_to(m, &p, m->cfg.depth_levels);
    occi_shared_written(m);
    return OCC_OK;
}
