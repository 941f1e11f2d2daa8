/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * tree.c - reading and writing the octree: descent, expansion, refresh/prune, batch updates.
 *
 * Writes are all-or-nothing: each write first counts the blocks it will allocate (with no frees
 * assumed) and refuses with OCC_ERR_NOMEM before touching anything when the pools cannot supply
 * them. Pruning only ever frees, so the count is an upper bound.
 */
#include "shared_internal.h"
#include "tree_internal.h"
#include "tree_path.h"

/* ---- node helpers --------------------------------------------------------------------------- */

static bool key_in_range(const occ_map_t *const m, const occ_key_t key)
{
    const uint32_t limit = (uint32_t)1 << m->cfg.depth_levels;
    return key.k[0] < limit && key.k[1] < limit && key.k[2] < limit;
}

/* Max, indicator flags and "all eight equal" of a block's values, without data-dependent
 * branches (refresh runs once per written block: its compares would mispredict). The flags
 * from counts (occupied; free and not occupied; the rest unknown), so that the loop is only
 * compares, sums and a max, which a host compiler turns into a few vector operations. */
typedef struct {
    occ_value_t max;
    uint8_t flags;
    bool same;
} summary8_t;

static summary8_t summarize8(const occ_map_t *const m, const occ_value_t *const v)
{
    const occ_value_t occ_min = m->priv.q_occ_min, free_max = m->priv.q_free_max, v0 = v[0];
    occ_value_t mx = v0;
    unsigned n_occ = 0, n_free = 0, n_same = 0;
    for (unsigned i = 0; i < 8u; i++) {
        mx = v[i] > mx ? v[i] : mx;
        n_occ += (unsigned)(v[i] >= occ_min);
        n_free += (unsigned)occ_is_observed(v[i]) & (unsigned)(v[i] < free_max) &
                  (unsigned)(v[i] < occ_min);
        n_same += (unsigned)occ_value_eq(v[i], v0);
    }
    summary8_t s;
    s.max = mx;
    s.flags = (uint8_t)((n_occ != 0u ? OCC_NODE_HAS_OCCUPIED : 0u) |
                        (n_free != 0u ? OCC_NODE_HAS_FREE : 0u) |
                        (n_occ + n_free < 8u ? OCC_NODE_HAS_UNKNOWN : 0u));
    s.same = n_same == 8u;
    return s;
}

void occi_tree_expand(occ_map_t *const m, const occ_nodep_t node, const unsigned level)
{
    OCC_ASSERT(level >= 1u && occ_node_child(node) == OCC_NONE);
    OCC_ASSERT(level <= m->cfg.depth_levels);
    const occ_value_t v = *node.value;
    if (level == 1u) {
        const uint32_t idx = occi_pool_alloc_leaf(m);
        OCC_ASSERT(idx != OCC_NONE);
        occ_leaf_block_t *const b = occ_leaf_at(m, idx);
        for (unsigned i = 0; i < 8u; i++) {
            b->value[i] = v;
        }
        occ_node_set_child(node, idx);
        occ_touch_child(m, node);
    } else {
        const uint32_t idx = occi_pool_alloc_inner(m);
        OCC_ASSERT(idx != OCC_NONE);
        occ_inner_block_t *const b = occ_inner_at(m, idx);
        occ_inner_fill(b, v, occ_value_flags(m, v));
        occ_node_set_child(node, idx);
        occ_touch_child(m, node);
    }
}

bool occi_tree_refresh(occ_map_t *const m, const occ_nodep_t node, const unsigned level)
{
    const uint32_t child = occ_node_child(node);
    if (child == OCC_NONE) {
        return false;
    }
    OCC_ASSERT(level >= 1u && level <= m->cfg.depth_levels);
    occ_value_t nv;
    uint8_t nf = 0u;
    bool prunable;
    if (level == 1u) {
        const summary8_t s = summarize8(m, occ_leaf_at(m, child)->value);
        nv = s.max;
        nf = s.flags;
        prunable = s.same;
        if (prunable) {
            const bool freed = occi_pool_free_leaf(m, child);
            OCC_ASSERT(freed);
        }
    } else {
        const occ_inner_block_t *const b = occ_inner_at(m, child);
        nv = b->value[0];
        prunable = true;
#if OCC_INNER_PACKED
        /* Flags and children a byte test each, not eight unpackings. */
        for (unsigned i = 0; i < 8u; i++) {
            nv = b->value[i] > nv ? b->value[i] : nv;
            prunable = prunable & occ_value_eq(b->value[i], b->value[0]);
        }
        nf = occ_inner_flags_or(b);
        prunable = prunable & occ_inner_childless(b);
#else
        for (unsigned i = 0; i < 8u; i++) {
            nv = b->value[i] > nv ? b->value[i] : nv;
            nf = (uint8_t)(nf | occ_inner_flags(b, i));
            prunable = prunable & (occ_inner_child(b, i) == OCC_NONE) & occ_value_eq(b->value[i], b->value[0]);
        }
#endif
        if (prunable) {
            const bool freed = occi_pool_free_inner(m, child);
            OCC_ASSERT(freed);
        }
    }
    if (prunable) {
        occ_node_set_child(node, OCC_NONE);
    }
    const bool changed = prunable || !occ_value_eq(nv, *node.value) || nf != occ_node_flags(node);
    *node.value = nv;
    occ_node_set_flags(node, nf);
    if (changed) {
        occ_touch_node(m, node);
    }
    return changed;
}

void occi_tree_release_children(occ_map_t *const m, const occ_nodep_t node, const unsigned level)
{
    if (occ_node_child(node) == OCC_NONE) {
        return;
    }
    OCC_ASSERT(level >= 1u && level <= m->cfg.depth_levels);
    if (level == 1u) {
        const bool freed = occi_pool_free_leaf(m, occ_node_child(node));
        OCC_ASSERT(freed);
        occ_node_set_child(node, OCC_NONE);
        occ_touch_child(m, node);
        return;
    }
    /* Iterative post-order over inner blocks; frame i holds the block whose children sit at
     * level lvl[i] - 1 and the next slot to visit. */
    uint32_t blk[OCC_MAX_DEPTH + 1];
    uint8_t lvl[OCC_MAX_DEPTH + 1];
    uint8_t next[OCC_MAX_DEPTH + 1];
    unsigned sp = 0;
    blk[0] = occ_node_child(node);
    lvl[0] = (uint8_t)(level - 1u); /* level of the nodes inside blk[0] */
    next[0] = 0u;
    occ_node_set_child(node, OCC_NONE);
    occ_touch_child(m, node);
    for (;;) {
        occ_inner_block_t *const b = occ_inner_at(m, blk[sp]);
        if (next[sp] < 8u) {
            const unsigned slot = next[sp]++;
            const uint32_t c = occ_inner_child(b, slot);
            if (c == OCC_NONE) {
                continue;
            }
            if (lvl[sp] == 1u) {
                const bool freed = occi_pool_free_leaf(m, c);
                OCC_ASSERT(freed);
            } else {
                OCC_ASSERT(sp < OCC_MAX_DEPTH && lvl[sp] > 1u);
                sp++;
                blk[sp] = c;
                lvl[sp] = (uint8_t)(lvl[sp - 1u] - 1u);
                next[sp] = 0u;
            }
            continue;
        }
        const bool freed = occi_pool_free_inner(m, blk[sp]);
        OCC_ASSERT(freed);
        if (sp == 0u) {
            break;
        }
        sp--;
    }
}

/* ---- reading ---------------------------------------------------------------------------------- */

/* What a read that failed reports: an unobserved, UNKNOWN node that holds unknown space. */
static void read_failed(occ_node_info_t *const out)
{
    out->logodds = 0.0f;
    out->observed = false;
    out->state = OCC_STATE_UNKNOWN;
    out->flags = (uint8_t)(OCC_NODE_HAS_UNKNOWN | OCC_NODE_UNIFORM);
    out->level = 0u;
}

occ_err_t occ_map_read_key(const occ_map_t *const map, const occ_key_t key, const unsigned level,
                           occ_node_info_t *const out)
{
    if (out != NULL) {
        read_failed(out); /* fail closed: an ignored error reads UNKNOWN, never stale or FREE */
    }
    if (map == NULL || out == NULL || level > map->cfg.depth_levels) {
        return OCC_ERR_ARG;
    }
    if (!key_in_range(map, key)) {
        return OCC_ERR_RANGE;
    }
    const occ_code_t code = occ_morton_encode(key);
    unsigned l = map->cfg.depth_levels;
    uint32_t child = occ_root_child(map);
    occ_value_t v = map->priv.root_value;
    uint8_t f = occ_root_flags(map);
    while (l > level && child != OCC_NONE) {
        const unsigned slot = occ_code_slot(code, l);
        l--;
        const occ_entry_t e = occ_entry_at(map, child, l, slot);
        v = e.value;
        f = l == 0u ? occ_value_flags(map, v) : e.flags;
        child = e.child;
    }
    out->observed = occ_is_observed(v);
    out->logodds = occ_value_to_logodds(v);
    out->state = occ_value_state(map, v);
    out->flags = (uint8_t)(f | (child == OCC_NONE ? OCC_NODE_UNIFORM : 0u));
    out->level = (uint8_t)l;
    return OCC_OK;
}

occ_err_t occ_map_read(const occ_map_t *const map, const occ_vec3_t p, const unsigned level,
                       occ_node_info_t *const out)
{
    occ_key_t key;
    const occ_err_t e = occ_map_key(map, p, &key);
    if (e != OCC_OK) {
        if (out != NULL) {
            read_failed(out);
        }
        return e;
    }
    return occ_map_read_key(map, key, level, out);
}

/* ---- batch updates ---------------------------------------------------------------------------- */

typedef enum { DELTA_TAGGED, DELTA_FIXED } delta_mode_t;

static occ_delta_t delta_of(const occ_map_t *const m, const occ_code_t code, const delta_mode_t mode,
                            const occ_delta_t fixed)
{
    if (mode == DELTA_FIXED) {
        return fixed;
    }
    return (code & OCC_CODE_HIT_BIT) != 0u ? m->priv.q_hit : m->priv.q_miss;
}

/* Checks order and range, and bounds the blocks the batch can need without reading the tree:
 * every node that may need a child block (levels 1..D) is counted once, by the first code
 * under it, which splits from its predecessor above that level. */
static bool codes_valid(const occ_map_t *const m, const occ_code_t *const codes, const size_t n,
                        uint64_t *const bound_inner, uint64_t *const bound_leaf)
{
    const occ_code_t limit = (occ_code_t)1 << (3u * m->cfg.depth_levels);
    uint64_t inner = 0u, leaf = 0u;
    for (size_t i = 0; i < n; i++) {
        const occ_code_t c = codes[i] & ~OCC_CODE_HIT_BIT;
        if (c >= limit) {
            return false;
        }
        unsigned s = m->cfg.depth_levels + 1u; /* the first code may need the root's block too */
        if (i > 0u) {
            const occ_code_t p = codes[i - 1u] & ~OCC_CODE_HIT_BIT;
            if (c <= p) {
                return false;
            }
            s = split_level(c, p);
        }
        leaf += s >= 2u ? 1u : 0u;
        inner += s >= 3u ? s - 2u : 0u;
    }
    *bound_inner = inner;
    *bound_leaf = leaf;
    return true;
}

/* Read-only pass: blocks the batch will allocate if nothing is freed on the way. The path is
 * the caller's: apply_batch lends its own, which it sets up only after this pass (two paths
 * of 22 nodes were 290 B more on every update's call chain, make cross). */
static void count_blocks(const occ_map_t *const m, path_t *const p, const occ_code_t *const codes,
                         const size_t n, const delta_mode_t mode, const occ_delta_t fixed,
                         uint64_t *const n_inner, uint64_t *const n_leaf)
{
    const unsigned depth = m->cfg.depth_levels;
    /* Read only: the path starts at a copy of the root, so the map can stay const. */
#if OCC_INNER_PACKED
    memcpy(p->root_child, m->priv.root_child, sizeof p->root_child);
    memcpy(p->root_flags, m->priv.root_flags, sizeof p->root_flags);
    p->node[depth].child = p->root_child;
    p->node[depth].flags = p->root_flags;
    p->node[depth].bit = 1u;
    p->root_value = m->priv.root_value;
    p->node[depth].value = &p->root_value;
#else
    p->root_child = m->priv.root_child;
    p->root_value = m->priv.root_value;
    p->root_flags = m->priv.root_flags;
    p->node[depth].child = &p->root_child;
    p->node[depth].value = &p->root_value;
    p->node[depth].flags = &p->root_flags;
#endif
    occ_code_t prev = 0, last_changing = 0;
    bool have_changing = false;
    *n_inner = 0u;
    *n_leaf = 0u;
    for (size_t i = 0; i < n; i++) {
        const occ_code_t c = codes[i] & ~OCC_CODE_HIT_BIT;
        unsigned start = depth;
        if (i > 0u) {
            const unsigned s = split_level(c, prev);
            start = s > p->low ? s : p->low;
        }
        unsigned stop;
        const occ_value_t v = descend(m, p, c, start, &stop);
        prev = c;
        const occ_value_t nv = occ_value_apply_delta(m, v, delta_of(m, codes[i], mode, fixed));
        if (occ_value_eq(nv, v) || stop == 0u) {
            if (!occ_value_eq(nv, v)) {
                have_changing = true;
                last_changing = c;
            }
            continue;
        }
        /* The uniform node at `stop` needs blocks at levels stop..1, except where an earlier
         * changing code in this batch expanded the same nodes already. */
        unsigned fresh = stop;
        if (have_changing) {
            const unsigned s = split_level(c, last_changing);
            if (s - 1u < fresh) {
                fresh = s - 1u;
            }
        }
        if (fresh > 0u) {
            *n_leaf += 1u;
            *n_inner += fresh - 1u;
        }
        have_changing = true;
        last_changing = c;
    }
}

static bool can_supply64(const occ_map_t *const m, const uint64_t n_inner, const uint64_t n_leaf)
{
    return n_inner <= OCC_NONE && n_leaf <= OCC_NONE &&
           occi_pool_can_supply(m, (uint32_t)n_inner, (uint32_t)n_leaf);
}

/* `bound_fits`: the caller showed that an upper bound of the blocks needed fits, so the exact
 * read-only count can be skipped. */
static occ_err_t apply_batch(occ_map_t *const m, const occ_code_t *const codes, const size_t n,
                             const delta_mode_t mode, const occ_delta_t fixed,
                             const bool bound_fits, size_t *const n_changed)
{
    if (n_changed != NULL) {
        *n_changed = 0u;
    }
    if (n == 0u) {
        return OCC_OK;
    }
    path_t p;
    if (!bound_fits) {
        uint64_t need_inner, need_leaf;
        count_blocks(m, &p, codes, n, mode, fixed, &need_inner, &need_leaf);
        if (!can_supply64(m, need_inner, need_leaf)) {
            m->oom_count++;
            return OCC_ERR_NOMEM;
        }
    }
    m->write_gen++; /* every update path writes here: handles on the old tree are stale */
    const unsigned depth = m->cfg.depth_levels;
    for (unsigned l = 0; l <= depth + 1u; l++) {
        p.dirty[l] = false;
    }
    p.node[depth] = occ_root(m);
    p.low = depth;
    occ_code_t prev = 0;
    size_t changed = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_code_t c = codes[i] & ~OCC_CODE_HIT_BIT;
        const unsigned start = path_start(m, &p, c, prev, i == 0u);
        prev = c;
        unsigned stop;
        const occ_value_t v = descend(m, &p, c, start, &stop);
        const occ_value_t nv = occ_value_apply_delta(m, v, delta_of(m, codes[i], mode, fixed));
        if (occ_value_eq(nv, v)) {
            continue;
        }
        for (unsigned l = stop; l >= 1u; l--) {
            occi_tree_expand(m, p.node[l], l);
            if (l > 1u) {
                p.node[l - 1u] = occ_inner_node(m, occ_node_child(p.node[l]), occ_code_slot(c, l));
            }
        }
        p.low = 1u;
        occ_value_t *const slot_v = &occ_leaf_at(m, occ_node_child(p.node[1]))->value[occ_code_slot(c, 1u)];
        *slot_v = nv;
        occi_shared_touch(m, slot_v, sizeof *slot_v);
        p.dirty[1] = true;
        changed++;
    }
    refresh_up_to(m, &p, depth);
    if (n_changed != NULL) {
        *n_changed = changed;
    }
    occi_shared_written(m);
    return OCC_OK;
}

occ_err_t occ_map_observe_codes(occ_map_t *const map, const occ_code_t *const codes, const size_t n,
                                size_t *const n_changed)
{
    if (n_changed != NULL) {
        *n_changed = 0u;
    }
    if (map == NULL || (codes == NULL && n != 0u)) {
        return OCC_ERR_ARG;
    }
    uint64_t bound_inner, bound_leaf;
    if (!codes_valid(map, codes, n, &bound_inner, &bound_leaf)) {
        return OCC_ERR_ARG;
    }
    return apply_batch(map, codes, n, DELTA_TAGGED, 0, can_supply64(map, bound_inner, bound_leaf),
                       n_changed);
}

occ_err_t occ_map_observe_need(const occ_map_t *const map, const occ_code_t *const codes,
                               const size_t n, uint32_t *const n_inner, uint32_t *const n_leaf)
{
    if (map == NULL || n_inner == NULL || n_leaf == NULL || (codes == NULL && n != 0u)) {
        return OCC_ERR_ARG;
    }
    *n_inner = 0u;
    *n_leaf = 0u;
    uint64_t bound_inner, bound_leaf, inner, leaf;
    if (!codes_valid(map, codes, n, &bound_inner, &bound_leaf)) {
        return OCC_ERR_ARG;
    }
    path_t p;
    count_blocks(map, &p, codes, n, DELTA_TAGGED, 0, &inner, &leaf);
    *n_inner = inner > OCC_NONE ? OCC_NONE : (uint32_t)inner;
    *n_leaf = leaf > OCC_NONE ? OCC_NONE : (uint32_t)leaf;
    return OCC_OK;
}

occ_err_t occ_map_update_key(occ_map_t *const map, const occ_key_t key, const float delta_logodds)
{
    if (map == NULL || !occ_finite(delta_logodds)) {
        return OCC_ERR_ARG;
    }
    if (!key_in_range(map, key)) {
        return OCC_ERR_RANGE;
    }
    const occ_code_t code = occ_morton_encode(key);
    return apply_batch(map, &code, 1u, DELTA_FIXED, occi_delta_from_logodds(delta_logodds), false,
                       NULL);
}

occ_err_t occ_map_update(occ_map_t *const map, const occ_vec3_t p, const float delta_logodds)
{
    occ_key_t key;
    const occ_err_t e = occ_map_key(map, p, &key);
    return e != OCC_OK ? e : occ_map_update_key(map, key, delta_logodds);
}

occ_err_t occ_map_observe_key(occ_map_t *const map, const occ_key_t key, const bool occupied)
{
    if (map == NULL) {
        return OCC_ERR_ARG;
    }
    if (!key_in_range(map, key)) {
        return OCC_ERR_RANGE;
    }
    const occ_code_t code = occ_morton_encode(key) | (occupied ? OCC_CODE_HIT_BIT : 0u);
    return apply_batch(map, &code, 1u, DELTA_TAGGED, 0, false, NULL);
}

/* ---- setting whole nodes ---------------------------------------------------------------------- */

static occ_err_t set_raw(occ_map_t *const m, const occ_key_t key, const unsigned level,
                         const occ_value_t v)
{
    if (level > m->cfg.depth_levels) {
        return OCC_ERR_ARG;
    }
    if (!key_in_range(m, key)) {
        return OCC_ERR_RANGE;
    }
    const unsigned depth = m->cfg.depth_levels;
    const occ_code_t code = occ_morton_encode(key);
    path_t p;
    p.node[depth] = occ_root(m);
    /* Descend to the target level or to a uniform node above it. */
    unsigned l = depth;
    while (l > level && l > 1u && occ_node_child(p.node[l]) != OCC_NONE) {
        p.node[l - 1u] = occ_inner_node(m, occ_node_child(p.node[l]), occ_code_slot(code, l));
        l--;
    }
    occ_leaf_block_t *leaf = NULL;
    if (level == 0u && l == 1u && occ_node_child(p.node[1]) != OCC_NONE) {
        leaf = occ_leaf_at(m, occ_node_child(p.node[1]));
        if (occ_value_eq(leaf->value[occ_code_slot(code, 1u)], v)) {
            return OCC_OK;
        }
    } else if (occ_node_child(p.node[l]) == OCC_NONE && occ_value_eq(*p.node[l].value, v)) {
        return OCC_OK; /* the uniform node already holds v everywhere */
    }
    if (leaf == NULL && l > level) {
        /* Expand the uniform node at l down to the target level: blocks for levels l..level+1. */
        const unsigned n_blocks = l - level;
        const uint32_t n_leaf = level == 0u ? 1u : 0u;
        if (!occi_pool_can_supply(m, n_blocks - n_leaf, n_leaf)) {
            m->oom_count++;
            return OCC_ERR_NOMEM;
        }
        while (l > level) {
            occi_tree_expand(m, p.node[l], l);
            if (l - 1u >= 1u) {
                p.node[l - 1u] = occ_inner_node(m, occ_node_child(p.node[l]), occ_code_slot(code, l));
            }
            l--;
        }
        if (level == 0u) {
            leaf = occ_leaf_at(m, occ_node_child(p.node[1]));
        }
    }
    m->write_gen++; /* set and forget write from here (the expansion above, too) */
    unsigned first_dirty;
    if (level == 0u) {
        leaf->value[occ_code_slot(code, 1u)] = v;
        occi_shared_touch(m, &leaf->value[occ_code_slot(code, 1u)], sizeof v);
        first_dirty = 1u;
    } else {
        occi_tree_release_children(m, p.node[level], level);
        *p.node[level].value = v;
        occ_node_set_flags(p.node[level], occ_value_flags(m, v));
        occ_touch_node(m, p.node[level]);
        first_dirty = level + 1u;
    }
    for (unsigned k = first_dirty; k <= depth; k++) {
        if (!occi_tree_refresh(m, p.node[k], k)) {
            break;
        }
    }
    occi_shared_written(m);
    return OCC_OK;
}

occ_err_t occ_map_set_key(occ_map_t *const map, const occ_key_t key, const unsigned level,
                          const float logodds)
{
    if (map == NULL || !occ_finite(logodds)) {
        return OCC_ERR_ARG;
    }
    return set_raw(map, key, level, occ_value_from_logodds(logodds));
}

occ_err_t occ_map_forget_key(occ_map_t *const map, const occ_key_t key, const unsigned level)
{
    if (map == NULL) {
        return OCC_ERR_ARG;
    }
    return set_raw(map, key, level, OCC_VALUE_UNOBSERVED);
}
