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

/* A node by where it lives: slot `slot` of inner block `block`, or the root (block OCC_NONE). */
static occ_nodep_t node_at(occ_map_t *const m, const uint32_t block, const unsigned slot)
{
    return block == OCC_NONE ? occ_root(m) : occ_inner_node(m, block, slot);
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
            if (occ_node_child(nd) == OCC_NONE) {
                occi_tree_expand(m, nd, l);
            }
            blk[l - 1u] = occ_node_child(nd);
        }
        occi_tree_apply_subtree(m, node_at(m, blk[level], occ_code_slot(c, level + 1u)), level,
                                delta);
        prev = c;
    }
    if (n > 0u) {
        refresh_path(m, blk, prev, level + 1u, depth, depth);
        occi_shared_written(m);
    }
    return n;
}
