/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * coarse.c - one log-odds delta applied to whole nodes above the voxels (FAST_DISCRETE's coarse
 * free space): every voxel below a node gets the delta; uniform nodes stay uniform (O(1)), nodes
 * with children are updated through their subtree and refreshed bottom-up (iterative).
 */
#include "coarse_internal.h"
#include "../core/shared_internal.h"

void occi_coarse_need(const occ_code_t *const codes, const size_t n, const unsigned level,
                      const unsigned depth, uint64_t *const inner, uint64_t *const leaf)
{
    /* Neighbours in sorted order whose highest differing bit is in level j's bits: their paths
     * part at level j, so nodes at level l = 1 + pairs parting at j >= l. */
    uint64_t parts_at[OCC_MAX_DEPTH + 2u] = {0};
    for (size_t i = 1; i < n; i++) {
        const occ_code_t x = ((codes[i] ^ codes[i - 1u]) & ~OCC_CODE_HIT_BIT);
        if (x == 0u) {
            continue;
        }
        const unsigned hb = 63u - (unsigned)__builtin_clzll(x);
        parts_at[hb / 3u]++;
    }
    uint64_t in = 0, lf = 0, run = n > 0u ? 1u : 0u;
    for (int l = (int)OCC_MAX_DEPTH; l >= 0; l--) {
        run += parts_at[l];
        const unsigned ul = (unsigned)l;
        if (ul > level && ul <= depth && n > 0u) {
            if (ul == 1u) {
                lf += run; /* nodes at level 1 own leaf blocks */
            } else {
                in += run;
            }
        }
    }
    *inner = in;
    *leaf = lf;
}

/* Apply to a node's value (a uniform node). */
static void apply_uniform(occ_map_t *const m, const occ_nodep_t node, const occ_value_t delta)
{
    *node.value = occ_value_apply_delta(m, *node.value, delta);
    *node.flags = occ_value_flags(m, *node.value);
    occ_touch_node(m, node);
}

/* A node by where it lives: slot `slot` of inner block `block`, or the root (block OCC_NONE). */
static occ_nodep_t node_at(occ_map_t *const m, const uint32_t block, const unsigned slot)
{
    return block == OCC_NONE ? occ_root(m) : occ_inner_node(m, block, slot);
}

/* Every voxel below the node (level >= 1) gets delta; values and flags refreshed bottom-up. */
static void apply_subtree(occ_map_t *const m, const uint32_t block, const unsigned slot,
                          const unsigned level, const occ_value_t delta)
{
    OCC_ASSERT(level >= 1u && level <= m->cfg.depth_levels);
    const occ_nodep_t top = node_at(m, block, slot);
    if (*top.child == OCC_NONE) {
        apply_uniform(m, top, delta);
        return;
    }
    struct {
        uint32_t block; /* where the node lives */
        uint8_t slot, level, next;
    } stack[OCC_MAX_DEPTH + 1u];
    unsigned sp = 1;
    stack[0].block = block;
    stack[0].slot = (uint8_t)slot;
    stack[0].level = (uint8_t)level;
    stack[0].next = 0;
    while (sp > 0u) {
        const unsigned t = sp - 1u;
        const occ_nodep_t nd = node_at(m, stack[t].block, stack[t].slot);
        if (stack[t].level == 1u) {
            occ_leaf_block_t *const b = occ_leaf_at(m, *nd.child);
            for (unsigned i = 0; i < 8u; i++) {
                b->value[i] = occ_value_apply_delta(m, b->value[i], delta);
            }
            occi_shared_touch(m, b, sizeof *b);
            (void)occi_tree_refresh(m, nd, 1u);
            sp--;
            continue;
        }
        if (stack[t].next == 8u) {
            (void)occi_tree_refresh(m, nd, stack[t].level);
            sp--;
            continue;
        }
        const unsigned s = stack[t].next++;
        const occ_nodep_t c = occ_inner_node(m, *nd.child, s);
        if (*c.child == OCC_NONE) {
            apply_uniform(m, c, delta);
        } else {
            OCC_ASSERT(sp <= OCC_MAX_DEPTH);
            stack[sp].block = *nd.child;
            stack[sp].slot = (uint8_t)s;
            stack[sp].level = (uint8_t)(stack[t].level - 1u);
            stack[sp].next = 0;
            sp++;
        }
    }
}

/* Refresh the path's nodes at levels from..to (bottom-up). */
static void refresh_path(occ_map_t *const m, const uint32_t *const blk, const occ_code_t c,
                         const unsigned from, const unsigned to, const unsigned depth)
{
    for (unsigned l = from; l <= to; l++) {
        const occ_nodep_t nd = node_at(m, blk[l], l < depth ? occ_code_slot(c, l + 1u) : 0u);
        (void)occi_tree_refresh(m, nd, l);
    }
}

size_t occi_coarse_apply(occ_map_t *const m, const occ_code_t *const codes, const size_t n,
                         const unsigned level, const occ_value_t delta)
{
    const unsigned depth = m->cfg.depth_levels;
    if (n > 0u) {
        m->write_gen++; /* the coarse pass writes the tree directly: handles on it are stale */
    }
    /* blk[l]: the block holding the path's node at level l (OCC_NONE: the root). Sorted codes
     * share the path above their split; nodes below it are finished and refreshed (and maybe
     * pruned) before the next code descends, as the core's batch update does. */
    uint32_t blk[OCC_MAX_DEPTH + 1u];
    blk[depth] = OCC_NONE;
    occ_code_t prev = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_code_t c = codes[i] & ~OCC_CODE_HIT_BIT;
        unsigned start = depth;
        if (i > 0u) {
            const unsigned hb = 63u - (unsigned)__builtin_clzll(c ^ prev);
            start = hb / 3u + 1u; /* lowest level whose node both codes share */
            refresh_path(m, blk, prev, level + 1u, start - 1u, depth);
        }
        for (unsigned l = start; l > level; l--) {
            const occ_nodep_t nd = node_at(m, blk[l], l < depth ? occ_code_slot(c, l + 1u) : 0u);
            if (*nd.child == OCC_NONE) {
                occi_tree_expand(m, nd, l);
            }
            blk[l - 1u] = *nd.child;
        }
        apply_subtree(m, blk[level], occ_code_slot(c, level + 1u), level, delta);
        prev = c;
    }
    if (n > 0u) {
        refresh_path(m, blk, prev, level + 1u, depth, depth);
        occi_shared_written(m);
    }
    return n;
}
