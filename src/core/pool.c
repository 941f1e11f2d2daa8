/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * pool.c - the two block pools in one arena. Leaf blocks are carved upwards from the bottom,
 * inner blocks downwards from the top, so the split between them follows the map's content
 * instead of a guess made at init. Each pool has an intrusive free list. All O(1).
 */
#include <string.h>

#include "sat_internal.h"
#include "tree_internal.h"

#ifndef OCC_POOL_PARANOID
#ifdef OCC_TESTING
#define OCC_POOL_PARANOID 1
#else
#define OCC_POOL_PARANOID 0
#endif
#endif

static size_t gap_bytes(const occ_map_t *const m)
{
    return m->arena_bytes - (size_t)m->inner.hwm * sizeof(occ_inner_block_t) -
           (size_t)m->leaf.hwm * sizeof(occ_leaf_block_t);
}

/* The carved blocks of both pools fit the arena (gap_bytes() did not wrap). */
static bool pools_fit(const occ_map_t *const m)
{
    return (uint64_t)m->inner.hwm * sizeof(occ_inner_block_t) +
               (uint64_t)m->leaf.hwm * sizeof(occ_leaf_block_t) <= (uint64_t)m->arena_bytes;
}

static void note_alloc(occ_pool_t *const p)
{
    p->used++;
    OCC_ASSERT(p->used + p->free_count == p->hwm);
    if (p->used > p->peak) {
        p->peak = p->used;
    }
}

bool occi_pool_can_supply(const occ_map_t *const m, const uint32_t n_inner, const uint32_t n_leaf)
{
    const uint64_t new_inner = n_inner > m->inner.free_count ? n_inner - m->inner.free_count : 0u;
    const uint64_t new_leaf = n_leaf > m->leaf.free_count ? n_leaf - m->leaf.free_count : 0u;
    const uint64_t need = new_inner * sizeof(occ_inner_block_t) + new_leaf * sizeof(occ_leaf_block_t);
    return need <= (uint64_t)gap_bytes(m);
}

uint32_t occi_pool_alloc_inner(occ_map_t *const m)
{
    uint32_t idx = m->inner.priv.free_head;
    OCC_ASSERT(pools_fit(m));
    if (idx != OCC_NONE) {
        OCC_ASSERT(m->inner.free_count > 0u);
        OCC_ASSERT(occ_inner_is_free(occ_inner_at(m, idx)));
        m->inner.priv.free_head = occ_inner_child(occ_inner_at(m, idx), 0);
        OCC_ASSERT(m->inner.priv.free_head == OCC_NONE || m->inner.priv.free_head < m->inner.hwm);
        m->inner.free_count--;
    } else if (gap_bytes(m) >= sizeof(occ_inner_block_t)) {
        idx = m->inner.hwm++;
    } else {
        return OCC_NONE;
    }
    occ_inner_mark_used(occ_inner_at(m, idx));
    occi_shared_touch(m, occ_inner_at(m, idx), sizeof(occ_inner_block_t)); /* the caller fills it */
    note_alloc(&m->inner);
    return idx;
}

uint32_t occi_pool_alloc_leaf(occ_map_t *const m)
{
    uint32_t idx = m->leaf.priv.free_head;
    OCC_ASSERT(pools_fit(m));
    if (idx != OCC_NONE) {
        OCC_ASSERT(m->leaf.free_count > 0u);
        memcpy(&m->leaf.priv.free_head, occ_leaf_at(m, idx)->value, sizeof(uint32_t));
        OCC_ASSERT(m->leaf.priv.free_head == OCC_NONE || m->leaf.priv.free_head < m->leaf.hwm);
        m->leaf.free_count--;
    } else if (gap_bytes(m) >= sizeof(occ_leaf_block_t)) {
        idx = m->leaf.hwm++;
    } else {
        return OCC_NONE;
    }
    occi_shared_touch(m, occ_leaf_at(m, idx), sizeof(occ_leaf_block_t)); /* the caller fills it */
    note_alloc(&m->leaf);
    return idx;
}

bool occi_pool_free_inner(occ_map_t *const m, const uint32_t idx)
{
    if (idx >= m->inner.hwm || m->inner.used == 0u) {
        return false;
    }
    occ_inner_block_t *const b = occ_inner_at(m, idx);
    if (occ_inner_is_free(b)) {
        return false;  /* already free */
    }
    occ_inner_mark_free(b);
    occ_inner_set_child(b, 0, m->inner.priv.free_head);
    occi_shared_touch(m, b, sizeof *b);
    m->inner.priv.free_head = idx;
    m->inner.free_count++;
    m->inner.used--;
    return true;
}

bool occi_pool_free_leaf(occ_map_t *const m, const uint32_t idx)
{
    if (idx >= m->leaf.hwm || m->leaf.used == 0u) {
        return false;
    }
#if OCC_POOL_PARANOID
    uint32_t it = m->leaf.priv.free_head;
    for (uint32_t n = 0; it != OCC_NONE && n <= m->leaf.free_count; n++) {
        if (it == idx) {
            return false;  /* already free */
        }
        memcpy(&it, occ_leaf_at(m, it)->value, sizeof it);
    }
#endif
    memcpy(occ_leaf_at(m, idx)->value, &m->leaf.priv.free_head, sizeof(uint32_t));
    occi_shared_touch(m, occ_leaf_at(m, idx), sizeof(occ_leaf_block_t));
    m->leaf.priv.free_head = idx;
    m->leaf.free_count++;
    m->leaf.used--;
    return true;
}

uint32_t occ_arena_blocks_for_bytes(const size_t arena_bytes, const uint32_t n_inner)
{
    if (arena_bytes < OCC_ARENA_ALIGN) {
        return 0u;
    }
#if OCC_INNER_PACKED
    const size_t all = arena_bytes - OCC_ARENA_ALIGN;
    const size_t usable = all < OCC_ARENA_CAP_BYTES ? all : OCC_ARENA_CAP_BYTES; /* as map.c */
#else
    const size_t usable = arena_bytes - OCC_ARENA_ALIGN;
#endif
    const size_t inner_bytes = occ_sat_mul(n_inner, sizeof(occ_inner_block_t));
    if (inner_bytes > usable) {
        return 0u;
    }
    const size_t n = (usable - inner_bytes) / sizeof(occ_leaf_block_t);
    return n > (size_t)OCC_POOL_MAX_BLOCKS ? OCC_POOL_MAX_BLOCKS : (uint32_t)n;
}
