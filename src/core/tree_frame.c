/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * tree_frame.c - one frame's updates in a single pass over the tree: voxel hits, voxel misses
 * and whole nodes (every voxel below gets one delta), merged in Morton order so that each part
 * of the tree is descended, written and refreshed once (the projective integrator's output).
 * All-or-nothing: a bound of the blocks the pass can allocate is checked first.
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

/* ---- the frame's entries in Morton order ------------------------------------------------------ */

/* The three streams merged: the head of each (code with the hit bit cleared; NONE when done),
 * the next entry's code, level (0: a voxel) and delta. Voxels named by both hits and misses
 * are hits. */
#define NONE (~(occ_code_t)0)

typedef struct {
    const occi_frame_t *f;
    size_t h, v, n;
    occ_code_t hc, vc, nc;
    unsigned nl;
} cursor_t;

typedef struct {
    occ_code_t code;
    unsigned level;
    occ_delta_t delta;
} entry_t;

/* Level of a whole-node entry: its lowest set bit is the marker 3 level - 1. */
static unsigned node_level(const occ_code_t e)
{
    return ((unsigned)__builtin_ctzll(e) + 1u) / 3u;
}

static void load_hit(cursor_t *const c)
{
    c->hc = c->h < c->f->nh ? c->f->hits[c->h] & ~OCC_CODE_HIT_BIT : NONE;
}

static void load_voxel(cursor_t *const c)
{
    c->vc = c->v < c->f->nv ? c->f->voxels[c->v] & ~OCC_CODE_HIT_BIT : NONE;
}

static void load_node(cursor_t *const c)
{
    if (c->n < c->f->nn) {
        const occ_code_t raw = c->f->nodes[c->n];
        c->nl = node_level(raw);
        c->nc = raw & ~(((occ_code_t)1 << (3u * c->nl)) - 1u);
    } else {
        c->nc = NONE;
    }
}

static void cursor_init(cursor_t *const c, const occi_frame_t *const f)
{
    c->f = f;
    c->h = c->v = c->n = 0u;
    load_hit(c);
    load_voxel(c);
    load_node(c);
}

static bool next_entry(const occ_map_t *const m, cursor_t *const c, entry_t *const e)
{
    /* the walk emits no free voxel that is also a hit (hits win there) */
    OCC_ASSERT(c->vc == NONE || c->vc != c->hc);
    OCC_ASSERT(c->nc == NONE || (c->nc != c->hc && c->nc != c->vc)); /* never at a voxel entry */
    if (c->nc < c->hc && c->nc < c->vc) {
        e->code = c->nc;
        e->level = c->nl;
        e->delta = c->f->node_delta;
        c->n++;
        load_node(c);
    } else if (c->hc < c->vc) {
        e->code = c->hc;
        e->level = 0u;
        e->delta = m->priv.q_hit;
        c->h++;
        load_hit(c);
    } else if (c->vc != NONE) {
        e->code = c->vc;
        e->level = 0u;
        e->delta = c->f->voxel_delta;
        c->v++;
        load_voxel(c);
    } else {
        return false;
    }
    return true;
}

/* Blocks one sorted stream's entries can allocate, as if no node existed: the entry that first
 * goes below a node on the union of their paths (its split from the previous entry is above
 * that node) counts the node's child block (a leaf block at level 1, else an inner block), for
 * the levels level + 1 .. split - 1. Voxels (level 0) here, whole nodes below. */
static void voxels_need(const occ_map_t *const m, const occ_code_t *const codes, const size_t n,
                        uint64_t *const inner, uint64_t *const leaf)
{
    if (n == 0u) {
        return;
    }
    const unsigned top = m->cfg.depth_levels; /* the first entry splits above the root */
    uint64_t in = top >= 2u ? top - 1u : 0u, lf = 1u;
    for (size_t i = 1; i < n; i++) {
        const unsigned s = split_level(codes[i], codes[i - 1u]);
        OCC_ASSERT((codes[i] & ~OCC_CODE_HIT_BIT) > (codes[i - 1u] & ~OCC_CODE_HIT_BIT));
        lf += s >= 2u ? 1u : 0u;
        in += s >= 3u ? s - 2u : 0u;
    }
    *inner += in;
    *leaf += lf;
}

static void nodes_need(const occ_map_t *const m, const occ_code_t *const codes, const size_t n,
                       uint64_t *const inner)
{
    occ_code_t prev = 0;
    for (size_t i = 0; i < n; i++) {
        const unsigned lv = node_level(codes[i]);
        const occ_code_t code = codes[i] & ~(((occ_code_t)1 << (3u * lv)) - 1u);
        const unsigned s = i == 0u ? m->cfg.depth_levels + 1u : split_level(code, prev);
        OCC_ASSERT(i == 0u || code > prev); /* sorted, unique */
        *inner += s >= lv + 2u ? s - lv - 1u : 0u; /* inner blocks at levels lv + 1 .. s - 1 */
        prev = code;
    }
}

/* The three streams' bounds summed: each block the merged pass allocates is counted by at
 * least one stream. */
static void frame_need(const occ_map_t *const m, const occi_frame_t *const f,
                       uint64_t *const inner, uint64_t *const leaf)
{
    *inner = 0u;
    *leaf = 0u;
    voxels_need(m, f->hits, f->nh, inner, leaf);
    voxels_need(m, f->voxels, f->nv, inner, leaf);
    nodes_need(m, f->nodes, f->nn, inner);
}

/* Voxel `code`'s new value into the leaf block the path ends in. */
static void leaf_write(occ_map_t *const m, path_t *const p, occ_value_t *const leaf,
                       const occ_code_t code, const occ_value_t nv)
{
    occ_value_t *const slot = &leaf[occ_code_slot(code, 1u)];
    *slot = nv;
    occi_shared_touch(m, slot, sizeof *slot);
    p->dirty[1] = true;
}

/* One voxel entry on the path (apply_batch's step): true when its value changed. */
static bool voxel_step(occ_map_t *const m, path_t *const p, const entry_t *const e,
                       const unsigned start)
{
    unsigned stop;
    const occ_value_t v = descend(m, p, e->code, start, &stop);
    const occ_value_t nv = occ_value_apply_delta(m, v, e->delta);
    if (occ_value_eq(nv, v)) {
        return false;
    }
    for (unsigned l = stop; l >= 1u; l--) {
        occi_tree_expand(m, p->node[l], l);
        if (l > 1u) {
            p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(e->code, l));
        }
    }
    p->low = 1u;
    leaf_write(m, p, occ_leaf_at(m, occ_node_child(p->node[1]))->value, e->code, nv);
    return true;
}

/* voxel_step for a voxel in the leaf block the path already ends in (the previous entry's):
 * about half the entries, with no split level, no descent and no refresh to decide. */
static bool leaf_step(occ_map_t *const m, path_t *const p, occ_value_t *const leaf,
                      const entry_t *const e)
{
    const occ_value_t v = leaf[occ_code_slot(e->code, 1u)];
    const occ_value_t nv = occ_value_apply_delta(m, v, e->delta);
    if (occ_value_eq(nv, v)) {
        return false;
    }
    leaf_write(m, p, leaf, e->code, nv);
    return true;
}

/* The leaf block's values the path ends in after a voxel entry, else NULL (a uniform node). */
static occ_value_t *path_leaf(const occ_map_t *const m, const path_t *const p)
{
    return p->low == 1u && occ_node_child(p->node[1]) != OCC_NONE
               ? occ_leaf_at(m, occ_node_child(p->node[1]))->value
               : NULL;
}

/* path_start for a voxel in another leaf block of the level-2 node the path ends in (the path
 * ends in a leaf block): only the level-1 node is finished. */
static unsigned sibling_start(occ_map_t *const m, path_t *const p)
{
    if (p->dirty[1]) {
        p->dirty[1] = false;
        if (occi_tree_refresh(m, p->node[1], 1u)) {
            p->dirty[2] = true;
        }
    }
    return 2u;
}

/* One whole-node entry at level L >= 1: descend to it (expanding a uniform ancestor whose
 * value the delta changes), then the delta on every voxel below. */
static void node_step(occ_map_t *const m, path_t *const p, const entry_t *const e,
                      const unsigned start)
{
    const unsigned lv = e->level;
    unsigned l = start;
    while (l > lv && occ_node_child(p->node[l]) != OCC_NONE) {
        p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(e->code, l));
        l--;
    }
    p->low = l;
    if (l > lv) { /* a uniform ancestor: split it only when the value moves */
        const occ_value_t v = *p->node[l].value;
        if (occ_value_eq(occ_value_apply_delta(m, v, e->delta), v)) {
            return;
        }
        for (; l > lv; l--) {
            occi_tree_expand(m, p->node[l], l);
            p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(e->code, l));
        }
        p->low = lv;
    }
    occi_tree_apply_subtree(m, p->node[lv], lv, e->delta);
    p->dirty[lv + 1u] = true;
}

/* Can the pools supply the blocks the pass may allocate? First a crude bound in O(1), above
 * frame_need's (each voxel entry at most one leaf block, each entry at most depth - 1 inner
 * ones): when the pools can supply it, the exact count (a pass over every entry) is not needed. */
static bool frame_fits(const occ_map_t *const m, const occi_frame_t *const f)
{
    const uint64_t nvox = (uint64_t)f->nh + f->nv;
    const uint64_t crude_inner = (nvox + f->nn) * (m->cfg.depth_levels - 1u);
    if (crude_inner <= OCC_NONE && nvox <= OCC_NONE &&
        occi_pool_can_supply(m, (uint32_t)crude_inner, (uint32_t)nvox)) {
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
    const unsigned depth = m->cfg.depth_levels;
    cursor_t c;
    cursor_init(&c, f);
    entry_t e;
    occ_code_t prev = 0, end = 0; /* end: past the previous entry's voxels */
    bool first = true;
    occ_value_t *leaf = NULL; /* the previous voxel's leaf block, while the path ends in it */
    while (next_entry(m, &c, &e)) {
        OCC_ASSERT(first || e.code >= end); /* nothing inside a whole node */
        end = e.code + ((occ_code_t)1 << (3u * e.level));
        if (leaf != NULL && e.level == 0u && ((e.code ^ prev) >> 3) == 0u) {
            out->changed += leaf_step(m, &p, leaf, &e) ? 1u : 0u;
            prev = e.code;
            continue;
        }
        const bool sibling = leaf != NULL && e.level == 0u && ((e.code ^ prev) >> 6) == 0u;
        const unsigned start = sibling ? sibling_start(m, &p) : path_start(m, &p, e.code, prev, first);
        prev = e.code;
        first = false;
        if (e.level == 0u) {
            out->changed += voxel_step(m, &p, &e, start) ? 1u : 0u;
            leaf = path_leaf(m, &p);
        } else {
            node_step(m, &p, &e, start);
            leaf = NULL;
        }
    }
    refresh_up_to(m, &p, depth);
    occi_shared_written(m);
    return OCC_OK;
}
