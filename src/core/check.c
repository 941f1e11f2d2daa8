/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * check.c - occ_map_check(): an O(n) audit of pools and tree that never writes.
 *
 * Block ownership is verified without extra memory: every block index below the pool's
 * high-water mark must be owned exactly once, by the tree or by the free list. The count,
 * the sum and the sum of squares of all owned indices must equal those of 0..hwm-1; a leak,
 * a block owned twice or a free block still in the tree changes at least one of them
 * (barring adversarial coincidences of both sums).
 */
#include <string.h>

#include "tree_internal.h"

typedef struct {
    uint64_t count, sum, sum_sq;
} tally_t;

static void tally_add(tally_t *const t, const uint32_t idx)
{
    t->count++;
    t->sum += idx;
    t->sum_sq += (uint64_t)idx * idx;
}

static bool tally_complete(const tally_t *const t, const uint32_t hwm)
{
    const uint64_t n = hwm;
    const uint64_t sum = n == 0u ? 0u : n * (n - 1u) / 2u;
    /* sum of squares 0..n-1 = (n-1) n (2n-1) / 6, computed without overflow for n < 2^32 */
    uint64_t a = n == 0u ? 0u : n - 1u, b = n, c = n == 0u ? 0u : 2u * n - 1u;
    if (a % 2u == 0u) a /= 2u; else b /= 2u;
    if (a % 3u == 0u) a /= 3u; else if (b % 3u == 0u) b /= 3u; else c /= 3u;
    return t->count == n && t->sum == sum && t->sum_sq == a * b * c;
}

static bool check_free_lists(const occ_map_t *const m, tally_t *const inner, tally_t *const leaf)
{
    uint32_t n = 0u;
    for (uint32_t i = m->inner.priv.free_head; i != OCC_NONE; i = occ_inner_child(occ_inner_at(m, i), 0)) {
        if (i >= m->inner.hwm || n++ > m->inner.hwm ||
            !occ_inner_is_free(occ_inner_at(m, i))) {
            return false; /* foreign index, cycle, or a used block on the list */
        }
        tally_add(inner, i);
    }
    if (n != m->inner.free_count) {
        return false;
    }
    n = 0u;
    uint32_t i = m->leaf.priv.free_head;
    while (i != OCC_NONE) {
        if (i >= m->leaf.hwm || n++ > m->leaf.hwm) {
            return false;
        }
        tally_add(leaf, i);
        memcpy(&i, occ_leaf_at(m, i)->value, sizeof i);
    }
    return n == m->leaf.free_count;
}

/* Expected value and flags of a node from its child block, and whether the block is prunable. */
static bool check_block(const occ_map_t *const m, const uint32_t child, const unsigned level,
                        const occ_value_t value, const uint8_t flags)
{
    occ_value_t mx = OCC_VALUE_UNOBSERVED;
    uint8_t f = 0u;
    bool prunable = true;
    if (level == 1u) {
        const occ_leaf_block_t *const b = occ_leaf_at(m, child);
        for (unsigned s = 0; s < 8u; s++) {
            mx = b->value[s] > mx ? b->value[s] : mx;
            f = (uint8_t)(f | occ_value_flags(m, b->value[s]));
            prunable = prunable && occ_value_eq(b->value[s], b->value[0]);
        }
    } else {
        const occ_inner_block_t *const b = occ_inner_at(m, child);
        if (occ_inner_is_free(b)) {
            return false;
        }
        for (unsigned s = 0; s < 8u; s++) {
            mx = b->value[s] > mx ? b->value[s] : mx;
            f = (uint8_t)(f | occ_inner_flags(b, s));
            prunable = prunable && occ_inner_child(b, s) == OCC_NONE && occ_value_eq(b->value[s], b->value[0]);
            if (occ_inner_child(b, s) == OCC_NONE && occ_inner_flags(b, s) != occ_value_flags(m, b->value[s])) {
                return false;
            }
        }
    }
    return !prunable && occ_value_eq(mx, value) && f == flags;
}

/* Pool counters agree with each other and the blocks fit the arena. */
static bool pools_consistent(const occ_map_t *const m)
{
    const occ_pool_t *const pools[2] = {&m->inner, &m->leaf};
    for (unsigned k = 0; k < 2u; k++) {
        const occ_pool_t *const p = pools[k];
        if ((uint64_t)p->used + p->free_count != p->hwm || p->used > p->peak) {
            return false;
        }
    }
    return (uint64_t)m->inner.hwm * sizeof(occ_inner_block_t) +
               (uint64_t)m->leaf.hwm * sizeof(occ_leaf_block_t) <=
           m->arena_bytes;
}

/* Child `c` of a node at level l + 1 with value and flags v, f: in range, consistent, and
 * tallied (false, too, when more blocks were reached than exist: a cycle or shared blocks). */
static bool check_child(const occ_map_t *const m, const uint32_t c, const unsigned l,
                        const occ_value_t v, const uint8_t f, tally_t *const inner,
                        tally_t *const leaf)
{
    if (c >= (l == 1u ? m->leaf.hwm : m->inner.hwm) || !check_block(m, c, l, v, f)) {
        return false;
    }
    tally_t *const t = l == 1u ? leaf : inner;
    tally_add(t, c);
    return t->count <= (l == 1u ? m->leaf.hwm : m->inner.hwm);
}

/* Every block below the root's child (inner blocks at depth >= 2), checked and tallied by an
 * iterative DFS: frame = block whose nodes sit at lvl, next slot. */
static bool check_subtree(const occ_map_t *const m, const unsigned depth, tally_t *const inner,
                          tally_t *const leaf)
{
    uint32_t blk[OCC_MAX_DEPTH + 1];
    uint8_t lvl[OCC_MAX_DEPTH + 1], next[OCC_MAX_DEPTH + 1];
    unsigned sp = 0;
    blk[0] = occ_root_child(m);
    lvl[0] = (uint8_t)(depth - 1u);
    next[0] = 0u;
    for (;;) {
        if (next[sp] >= 8u) {
            if (sp == 0u) {
                return true;
            }
            sp--;
            continue;
        }
        const occ_inner_block_t *const b = occ_inner_at(m, blk[sp]);
        const unsigned s = next[sp]++;
        const uint32_t c = occ_inner_child(b, s);
        if (c == OCC_NONE) {
            continue;
        }
        const unsigned l = lvl[sp];
        if (!check_child(m, c, l, b->value[s], occ_inner_flags(b, s), inner, leaf)) {
            return false;
        }
        if (l > 1u) {
            if (sp + 1u > OCC_MAX_DEPTH) {
                return false;
            }
            sp++;
            blk[sp] = c;
            lvl[sp] = (uint8_t)(l - 1u);
            next[sp] = 0u;
        }
    }
}

/* The tree from the root: every block reached is checked and tallied. */
static bool check_tree(const occ_map_t *const m, tally_t *const inner, tally_t *const leaf)
{
    const unsigned depth = m->cfg.depth_levels;
    if (occ_root_child(m) == OCC_NONE) {
        return occ_root_flags(m) == occ_value_flags(m, m->priv.root_value);
    }
    /* The auditor survives any bytes: depth, counters and every index are range-checked here
     * before they are followed, so the accessors' asserts never see a bad one from this walk. */
    if (depth < 1u || depth > OCC_MAX_DEPTH) {
        return false;
    }
    if (!check_child(m, occ_root_child(m), depth, m->priv.root_value, occ_root_flags(m), inner, leaf)) {
        return false;
    }
    return depth == 1u || check_subtree(m, depth, inner, leaf);
}

occ_err_t occ_map_check(const occ_map_t *const m)
{
    if (m == NULL) {
        return OCC_ERR_ARG;
    }
    tally_t inner = {0u, 0u, 0u}, leaf = {0u, 0u, 0u};
    if (!pools_consistent(m) || !check_free_lists(m, &inner, &leaf) ||
        !check_tree(m, &inner, &leaf)) {
        return OCC_ERR_CORRUPT;
    }
    /* Every block below the high-water marks owned exactly once, by the tree or a free list;
     * an empty tree owns none (its blocks are all free). */
    if (occ_root_child(m) != OCC_NONE && (inner.count - m->inner.free_count != m->inner.used ||
                                      leaf.count - m->leaf.free_count != m->leaf.used)) {
        return OCC_ERR_CORRUPT;
    }
    return tally_complete(&inner, m->inner.hwm) && tally_complete(&leaf, m->leaf.hwm)
               ? OCC_OK
               : OCC_ERR_CORRUPT;
}
