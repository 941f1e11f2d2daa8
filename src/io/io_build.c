/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * io_build.c - builds a tree from a preorder description, or (map == NULL) counts what that
 * build allocates and frees, so readers can check fit before touching the destination.
 * The dry run prunes exactly when occi_tree_refresh() would: eight childless equal entries.
 */
#include "io_internal.h"

static void note_alloc(occ_build_t *const b, const unsigned child_level)
{
    if (child_level == 0u) {
        b->live_leaf++;
        if (b->live_leaf > b->peak_leaf) {
            b->peak_leaf = b->live_leaf;
        }
    } else {
        b->live_inner++;
        if (b->live_inner > b->peak_inner) {
            b->peak_inner = b->live_inner;
        }
    }
}

void occi_build_begin(occ_build_t *const b, occ_map_t *const map, const unsigned depth_levels)
{
    b->map = map;
    b->top = (uint8_t)depth_levels;
    b->sp = 0u;
    b->root_uniform = false;
    b->root_value = OCC_VALUE_UNOBSERVED;
    b->live_inner = 0u;
    b->live_leaf = 0u;
    b->peak_inner = 0u;
    b->peak_leaf = 0u;
    b->nodes = 0u;
}

void occi_build_root_uniform(occ_build_t *const b, const occ_value_t v)
{
    b->nodes++;
    b->root_uniform = true;
    b->root_value = v;
    if (b->map != NULL) {
        occ_root_set_child(b->map, OCC_NONE);
        b->map->priv.root_value = v;
        occ_root_set_flags(b->map, occ_value_flags(b->map, v));
    }
}

/* A fresh child block for a node at `level`, every entry unobserved. */
static uint32_t new_block(occ_map_t *const m, const unsigned level)
{
    if (level == 1u) {
        const uint32_t idx = occi_pool_alloc_leaf(m);
        if (idx != OCC_NONE) {
            occ_leaf_block_t *const lb = occ_leaf_at(m, idx);
            for (unsigned i = 0; i < 8u; i++) {
                lb->value[i] = OCC_VALUE_UNOBSERVED;
            }
        }
        return idx;
    }
    const uint32_t idx = occi_pool_alloc_inner(m);
    if (idx != OCC_NONE) {
        occ_inner_block_t *const ib = occ_inner_at(m, idx);
        occ_inner_fill(ib, OCC_VALUE_UNOBSERVED, occ_value_flags(m, OCC_VALUE_UNOBSERVED));
    }
    return idx;
}

static void push(occ_build_t *const b, const unsigned level, const unsigned slot, const uint32_t blk)
{
    OCC_ASSERT(b->sp <= OCC_MAX_DEPTH && slot < 8u);
    occ_build_frame_t *const f = &b->st[b->sp++];
    f->block = blk;
    f->level = (uint8_t)level;
    f->slot = (uint8_t)slot;
    f->set = 0u;
    f->any_block = false;
    f->vmin = OCC_VALUE_MAX;
    f->vmax = OCC_VALUE_UNOBSERVED;
}

void occi_build_open_root(occ_build_t *const b)
{
    b->nodes++;
    note_alloc(b, b->top - 1u);
    uint32_t blk = OCC_NONE;
    if (b->map != NULL) {
        blk = new_block(b->map, b->top);
        OCC_ASSERT(blk != OCC_NONE);
        occ_root_set_child(b->map, blk);
    }
    push(b, b->top, 0u, blk);
}

void occi_build_open(occ_build_t *const b, const unsigned slot)
{
    OCC_ASSERT(b->sp >= 1u && slot < 8u);
    occ_build_frame_t *const p = &b->st[b->sp - 1u];
    const unsigned level = p->level - 1u;
    OCC_ASSERT(level >= 1u && b->sp <= OCC_MAX_DEPTH);
    b->nodes++;
    p->set = (uint8_t)(p->set | (1u << slot));
    note_alloc(b, level - 1u);
    uint32_t blk = OCC_NONE;
    if (b->map != NULL) {
        blk = new_block(b->map, level);
        OCC_ASSERT(blk != OCC_NONE);
        occ_inner_set_child(occ_inner_at(b->map, p->block), slot, blk);
    }
    push(b, level, slot, blk);
}

static void dry_child(occ_build_frame_t *const p, const occ_value_t v, const bool has_block)
{
    if (v < p->vmin) {
        p->vmin = v;
    }
    if (v > p->vmax) {
        p->vmax = v;
    }
    p->any_block = p->any_block || has_block;
}

void occi_build_leaf(occ_build_t *const b, const unsigned slot, const occ_value_t v)
{
    OCC_ASSERT(b->sp >= 1u && slot < 8u);
    occ_build_frame_t *const p = &b->st[b->sp - 1u];
    b->nodes++;
    p->set = (uint8_t)(p->set | (1u << slot));
    dry_child(p, v, false);
    if (b->map != NULL) {
        if (p->level == 1u) {
            occ_leaf_at(b->map, p->block)->value[slot] = v;
        } else {
            occ_inner_block_t *const ib = occ_inner_at(b->map, p->block);
            ib->value[slot] = v;
            occ_inner_set_flags(ib, slot, occ_value_flags(b->map, v));
        }
    }
}

void occi_build_close(occ_build_t *const b)
{
    OCC_ASSERT(b->sp >= 1u);
    occ_build_frame_t *const f = &b->st[b->sp - 1u];
    const bool prune = f->set == 0xFFu && !f->any_block && occ_value_eq(f->vmin, f->vmax);
    if (prune) {
        if (f->level == 1u) {
            b->live_leaf--;
        } else {
            b->live_inner--;
        }
    }
    if (b->sp == 1u) {
        b->root_uniform = prune;
        b->root_value = f->vmax;
    } else {
        dry_child(&b->st[b->sp - 2u], f->vmax, !prune);
    }
    if (b->map != NULL) {
        occ_nodep_t node;
        if (b->sp == 1u) {
            node = occ_root(b->map);
        } else {
            node = occ_inner_node(b->map, b->st[b->sp - 2u].block, f->slot);
        }
        (void)occi_tree_refresh(b->map, node, f->level);
    }
    b->sp--;
}
