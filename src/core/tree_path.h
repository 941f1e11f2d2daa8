/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * tree_path.h - the path of a batch update through the tree (src/core only): sorted codes share
 * the path above their split level, nodes below it are finished and refreshed (maybe pruned)
 * before the next code descends. tree.c (voxel batches) and tree_frame.c (a frame's voxels and
 * whole nodes) walk it.
 */
#ifndef OCC_TREE_PATH_H_INCLUDED
#define OCC_TREE_PATH_H_INCLUDED

#include <string.h>

#include "tree_internal.h"

/* The path of the current code: node[l] for l in [low, D]; node[D] is the root. */
typedef struct {
    occ_nodep_t node[OCC_MAX_DEPTH + 1];
    bool dirty[OCC_MAX_DEPTH + 2];
    unsigned low;
    /* tree.c's count_blocks: a copy of the root, where its read-only path starts (the map stays
     * const) */
#if OCC_INNER_PACKED
    uint8_t root_child[3];
    occ_value_t root_value;
    uint8_t root_flags[3];
#else
    uint32_t root_child;
    occ_value_t root_value;
    uint8_t root_flags;
#endif
} path_t;

/* Lowest level whose node contains both codes. */
static inline unsigned split_level(const occ_code_t a, const occ_code_t b)
{
    occ_code_t x = (a ^ b) & ~OCC_CODE_HIT_BIT;
    if (x == 0u) {
        return 1u;
    }
#if defined(__GNUC__)
    const unsigned h = 63u - (unsigned)__builtin_clzll((unsigned long long)x);
#else
    unsigned h = 0;
    while (x > 1u) {
        x >>= 1;
        h++;
    }
#endif
    return h / 3u + 1u;
}

/* Descend from node[start] along `code` while nodes have inner children; stops at level 1 or at
 * a uniform node. Returns the voxel's value and sets *stop: 0 when it lies in a leaf block,
 * else the level of the uniform node holding it. */
static inline occ_value_t descend(const occ_map_t *const m, path_t *const p, const occ_code_t code,
                           unsigned start, unsigned *const stop)
{
    unsigned l = start;
    while (l > 1u && occ_node_child(p->node[l]) != OCC_NONE) {
        p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(code, l));
        l--;
    }
    p->low = l;
    if (occ_node_child(p->node[l]) != OCC_NONE) { /* l == 1 with a leaf block */
        *stop = 0u;
        return occ_leaf_at(m, occ_node_child(p->node[1]))->value[occ_code_slot(code, 1u)];
    }
    *stop = l;
    return *p->node[l].value;
}

/* Refresh dirty nodes from p->low up to level `top` (inclusive), marking parents dirty. */
static inline void refresh_up_to(occ_map_t *const m, path_t *const p, const unsigned top)
{
    for (unsigned l = p->low; l <= top; l++) {
        if (p->dirty[l]) {
            p->dirty[l] = false;
            if (occi_tree_refresh(m, p->node[l], l)) {
                p->dirty[l + 1u] = true;
            }
        }
    }
}

/* A pass's path, at the root, after bumping the write generation (handles on the old tree
 * are stale). */
static inline void path_begin(occ_map_t *const m, path_t *const p)
{
    m->write_gen++;
    memset(p, 0, sizeof *p); /* read only from node[low] up; cppcheck cannot tell */
    p->node[m->cfg.depth_levels] = occ_root(m);
    p->low = m->cfg.depth_levels;
}

/* The level the next sorted entry descends from: nodes below its split from the previous one
 * are finished (no later entry enters them), so they are refreshed and pruned now, never to
 * be re-expanded. `first`: no previous entry (start at the root). */
static inline unsigned path_start(occ_map_t *const m, path_t *const p, const occ_code_t code,
                                  const occ_code_t prev, const bool first)
{
    if (first) {
        return m->cfg.depth_levels;
    }
    const unsigned s = split_level(code, prev);
    if (s > p->low) {
        refresh_up_to(m, p, s - 1u);
        return s;
    }
    return p->low;
}

/* Blocks one brick can allocate, as if no node existed (the update by bricks' rule): split `s`
 * from the previous brick (depth + 1 for the first), an inner block per level 2 .. s - 1 and a
 * leaf block per level-1 node its voxels (miss | hit) name. */
static inline void brick_need(const unsigned s, uint64_t voxels, uint64_t *const inner,
                              uint64_t *const leaf)
{
    voxels |= voxels >> 4; /* each byte's bits gathered in its bit 0 */
    voxels |= voxels >> 2;
    voxels |= voxels >> 1;
    *leaf += occ_popcount64(voxels & 0x0101010101010101ull);
    *inner += s - 2u;
}

/* One brick (tree_dense.c) from path level `start`: descend to its level-2 node or a uniform
 * node above it, split that only where a value moves, update its voxels (miss: q_miss, hit:
 * q_hit). Returns the voxels of `count` whose value changed. */
size_t occi_tree_brick_step(occ_map_t *m, path_t *p, const occi_brick_t *b, unsigned start,
                            uint64_t count);

#endif
