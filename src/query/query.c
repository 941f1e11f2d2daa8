/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * query.c - the volume iterator and voxel counts. The iterator is a depth-first walk in Morton
 * order on a fixed stack; a branch is skipped as soon as its cube misses the volume (volume.c) or
 * its max value / indicators rule the predicate out.
 */
#include "query_internal.h"

void occi_q_fill_node(const occ_map_t *m, occ_key_t key, unsigned level, occ_value_t v,
                      uint8_t flags, bool uniform, occ_query_node_t *out)
{
    out->key = occ_key_at_level(key, level);
    out->level = (uint8_t)level;
    out->uniform = uniform;
    out->inside = false;
    out->observed = occ_is_observed(v);
    out->state = occ_value_state(m, v);
    out->flags = uniform ? (uint8_t)(occ_value_flags(m, v) | OCC_NODE_UNIFORM) : flags;
    out->logodds = out->observed ? occ_value_to_logodds(v) : 0.0f;
    out->center = occ_geom_center(m, out->key, level);
    out->size_m = occ_map_node_size(m, level);
}

static bool same_above(occ_key_t a, occ_key_t b, unsigned level)
{
    return ((a.k[0] ^ b.k[0]) >> level) == 0u && ((a.k[1] ^ b.k[1]) >> level) == 0u &&
           ((a.k[2] ^ b.k[2]) >> level) == 0u;
}

void occi_q_starts(const occ_map_t *map, const occ_volume_t *vol, unsigned min_level,
                   occi_q_starts_t *s)
{
    const unsigned depth = map->cfg.depth_levels;
    memset(s, 0, sizeof *s);
    s->level = (uint8_t)depth;
    uint32_t lo[3];
    uint32_t hi[3];
    if (!occi_q_bounds_keys(map, vol, lo, hi)) {
        return; /* nothing of the map is near the volume */
    }
    /* Smallest level whose cells are at least as wide as the key range: the range then spans
     * at most two cells per axis. */
    uint32_t ext = 0;
    for (unsigned i = 0; i < 3u; i++) {
        ext = (hi[i] - lo[i]) > ext ? (hi[i] - lo[i]) : ext;
    }
    unsigned lc = occ_bit_length32(ext); /* 2^lc > ext */
    lc = lc < min_level ? min_level : lc; /* never start below the level nodes are reported at */
    s->n = 1u;
    if (lc >= depth) {
        return; /* the root */
    }
    s->level = (uint8_t)lc;
    /* The cells c0 or c0 + 1 per axis. In Morton order the axis whose +1 flips the highest bit
     * (z before y before x on ties) is the most significant, so count in that bit order. */
    unsigned rank[3] = {0u, 0u, 0u};
    unsigned na = 0;
    for (unsigned i = 0; i < 3u; i++) {
        const uint32_t c0 = lo[i] >> lc;
        s->first.k[i] = c0 << lc;
        if ((hi[i] >> lc) != c0) {
            rank[na] = (occ_bit_length32(c0 ^ (c0 + 1u)) - 1u) * 3u + i;
            s->ax[na++] = (uint8_t)i;
        }
    }
    for (unsigned j = 1; j < na; j++) { /* most significant first */
        for (unsigned q = j; q > 0u && rank[q] > rank[q - 1u]; q--) {
            const unsigned tr = rank[q];
            const uint8_t ta = s->ax[q];
            rank[q] = rank[q - 1u];
            s->ax[q] = s->ax[q - 1u];
            rank[q - 1u] = tr;
            s->ax[q - 1u] = ta;
        }
    }
    s->na = (uint8_t)na;
    s->n = (uint8_t)(1u << na);
}

occ_err_t occ_query_begin(occ_query_iter_t *it, const occ_map_t *map, const occ_volume_t *vol,
                          occ_pred_t pred)
{
    if (it != NULL) {
        it->map = NULL; /* refused: occ_query_next answers false, occ_query_status ARG */
    }
    if (it == NULL || map == NULL || vol == NULL || (pred.states & ~OCC_PRED_ANY) != 0u ||
        pred.min_level > map->cfg.depth_levels || (pred.options & ~OCC_ITER_SPLIT) != 0u) {
        return OCC_ERR_ARG;
    }
    if (pred.states == 0u) {
        pred.states = (uint8_t)OCC_PRED_ANY;
    }
    it->map = map;
    it->vol = vol;
    it->pred = pred;
    it->sp = 0;
    it->base = 0;
    it->virt_sp = OCC_MAX_DEPTH;
    it->virt_value = OCC_VALUE_UNOBSERVED;
    it->path.k[0] = it->path.k[1] = it->path.k[2] = 0u;
    it->istart = 0;
    it->gen = map->write_gen;
    occi_q_starts_t st;
    occi_q_starts(map, vol, pred.min_level, &st);
    for (unsigned t = 0; t < st.n; t++) {
        it->start[t] = occi_q_start_key(&st, t);
    }
    it->nstart = st.n;
    it->start_level = st.level;
    return OCC_OK;
}

static occ_key_t mask_key(occ_key_t k, unsigned level)
{
    const uint32_t m = ~(((uint32_t)1 << level) - 1u);
    k.k[0] &= m;
    k.k[1] &= m;
    k.k[2] &= m;
    return k;
}

/* Does one node match the predicate (uniform: its state; with children: contains)? */
static bool pred_match(const occ_query_iter_t *it, occ_value_t v, uint8_t flags, bool uniform)
{
    return occ_q_node_wanted(it->map, v, flags, uniform, it->pred.states);
}

/* Push the children of the node with first voxel `pkey` (children at `level`, in stack entry i):
 * a stored block, or (block OCC_NONE) the virtual split of a uniform node of value `uv`. */
static inline void push(occ_query_iter_t *it, occ_key_t pkey, unsigned level, uint32_t block,
                 occ_value_t uv, unsigned i)
{
    const occ_map_t *const m = it->map;
    OCC_ASSERT(i < OCC_MAX_DEPTH && level < m->cfg.depth_levels);
    unsigned pm;
    if (block == OCC_NONE) {
        pm = 0xFFu; /* the uniform parent matched, so does every part of it */
        if (it->virt_sp == OCC_MAX_DEPTH) {
            it->virt_sp = (uint8_t)i;
            it->virt_value = uv;
        }
    } else if (level == 0u) {
        pm = occ_q_leaf_match(m, occ_leaf_at(m, block), it->pred.states);
    } else {
        pm = occ_q_open_inner(m, block, it->pred.states);
    }
    it->block[i] = block;
    if (pm != 0u) {
        pm = occ_q_touch_mask(m, it->vol, pkey, level, pm);
    }
    it->mask[i] = (uint8_t)pm;
    it->sp = (uint8_t)(i + 1u);
}

/* A node that matches and touches: report it (true), or push its children. */
static inline bool take(occ_query_iter_t *it, occ_key_t key, unsigned level, occ_value_t v, uint8_t flags,
                 uint32_t child, unsigned i, occ_query_node_t *out)
{
    const bool uniform = child == OCC_NONE;
    bool inside = false;
    if (level > it->pred.min_level) {
        if (!uniform) {
            push(it, key, level - 1u, child, v, i);
            return false;
        }
        if ((it->pred.options & OCC_ITER_SPLIT) != 0u) {
            inside = occ_volume_holds_box(it->vol, occ_geom_center(it->map, key, level),
                                          occ_q_half(it->map, level));
            if (!inside) {
                push(it, key, level - 1u, OCC_NONE, v, i);
                return false;
            }
        }
    }
    occi_q_fill_node(it->map, key, level, v, flags, uniform, out);
    out->inside = inside;
    return true;
}

/* A start node: test it, then take it. */
static bool enter(occ_query_iter_t *it, occ_key_t key, unsigned level, occ_value_t v,
                  uint8_t flags, uint32_t child, unsigned i, occ_query_node_t *out)
{
    if (!pred_match(it, v, flags, child == OCC_NONE) ||
        !occ_volume_hits_box(it->vol, occ_geom_center(it->map, key, level), occ_q_half(it->map, level))) {
        return false;
    }
    return take(it, key, level, v, flags, child, i, out);
}

/* Descend to the next start node and enter it. The path of the previous start is kept in
 * block[D-L] (entries above the DFS stack), so only the levels below the highest key bit in which
 * the two starts differ are walked again. */
static bool next_start(occ_query_iter_t *it, occ_query_node_t *out)
{
    const occ_map_t *const m = it->map;
    const unsigned depth = m->cfg.depth_levels;
    const occ_key_t key = it->start[it->istart];
    unsigned level = depth;
    uint32_t child = occ_root_child(m);
    occ_value_t v = m->priv.root_value;
    uint8_t flags = occ_root_flags(m);
    bool check = true;
    if (it->istart > 0u) {
        const uint32_t x = (key.k[0] ^ it->path.k[0]) | (key.k[1] ^ it->path.k[1]) |
                           (key.k[2] ^ it->path.k[2]);
        const unsigned hb = occ_bit_length32(x) - 1u; /* x != 0: distinct starts */
        if (hb + 1u < depth) {
            level = hb + 1u; /* the common ancestor, already checked */
            child = it->block[depth - level];
            check = false;
        }
    }
    it->istart++;
    const occ_code_t code = occ_morton_encode(key);
    OCC_ASSERT(level <= depth);
    while (level > it->start_level && child != OCC_NONE) {
        if (check && !occ_q_contains(flags, it->pred.states)) {
            break; /* nothing wanted below: skip this node */
        }
        check = true;
        it->block[depth - level] = child;
        const unsigned slot = occ_code_slot(code, level);
        level--;
        const occ_entry_t e = occ_entry_at(m, child, level, slot);
        v = e.value;
        flags = e.flags;
        child = e.child;
    }
    /* Later starts inside the node reached (uniform, or without anything wanted) are this node. */
    while (it->istart < it->nstart && same_above(it->start[it->istart], key, level)) {
        it->istart++;
    }
    it->path = mask_key(key, level);
    it->virt_sp = OCC_MAX_DEPTH;
    it->base = (uint8_t)(depth - level);
    it->sp = it->base;
    return enter(it, it->path, level, v, flags, child, depth - level, out);
}

occ_err_t occ_query_status(const occ_query_iter_t *it)
{
    if (it == NULL || it->map == NULL) {
        return OCC_ERR_ARG;
    }
    return it->gen == it->map->write_gen ? OCC_OK : OCC_ERR_STATE;
}

bool occ_query_next(occ_query_iter_t *it, occ_query_node_t *out)
{
    if (occ_query_status(it) != OCC_OK) {
        return false; /* the stacked block indices may name freed or reused blocks */
    }
    const occ_map_t *const m = it->map;
    const unsigned depth = m->cfg.depth_levels;
    for (;;) {
        while (it->sp > it->base) {
            const unsigned i = it->sp - 1u;
            const unsigned mk = it->mask[i];
            if (mk == 0u) {
                it->sp = (uint8_t)i;
                if (i == it->virt_sp) {
                    it->virt_sp = OCC_MAX_DEPTH;
                }
                continue;
            }
            const unsigned slot = occ_first_slot(mk);
            it->mask[i] = (uint8_t)(mk & (mk - 1u));
            OCC_ASSERT(i < depth);
            const unsigned level = depth - 1u - i;
            const uint32_t bit = 1u << level;
            it->path.k[0] = (it->path.k[0] & ~bit) | ((slot & 1u) ? bit : 0u);
            it->path.k[1] = (it->path.k[1] & ~bit) | ((slot & 2u) ? bit : 0u);
            it->path.k[2] = (it->path.k[2] & ~bit) | ((slot & 4u) ? bit : 0u);
            occ_entry_t e;
            if (i >= it->virt_sp) {
                e.value = it->virt_value;
                e.flags = 0u;
                e.child = OCC_NONE;
            } else {
                e = occ_entry_at(m, it->block[i], level, slot);
            }
            const occ_key_t key = mask_key(it->path, level);
            if (take(it, key, level, e.value, e.flags, e.child, i + 1u, out)) {
                return true;
            }
        }
        if (it->istart >= it->nstart) {
            return false;
        }
        if (next_start(it, out)) {
            return true;
        }
    }
}

occ_err_t occ_query_count(const occ_map_t *map, const occ_volume_t *vol, occ_query_counts_t *out)
{
    if (map == NULL || vol == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    occ_pred_t pred;
    pred.states = (uint8_t)OCC_PRED_ANY;
    pred.min_level = 0;
    pred.options = (uint8_t)OCC_ITER_SPLIT;
    occ_query_iter_t it;
    const occ_err_t e = occ_query_begin(&it, map, vol, pred);
    if (e != OCC_OK) {
        return e;
    }
    out->occupied = out->free = out->unknown = 0u;
    occ_query_node_t n;
    while (occ_query_next(&it, &n)) {
        const uint64_t cnt = n.inside ? ((uint64_t)1 << (3u * n.level)) : 1u;
        switch (n.state) {
        case OCC_STATE_OCCUPIED:
            out->occupied += cnt;
            break;
        case OCC_STATE_FREE:
            out->free += cnt;
            break;
        case OCC_STATE_UNKNOWN:
        default:
            out->unknown += cnt;
            break;
        }
    }
    const float half = occ_map_node_size(map, map->cfg.depth_levels) * 0.5f;
    out->outside = vol->bmin.x < -half || vol->bmin.y < -half || vol->bmin.z < -half ||
                   vol->bmax.x >= half || vol->bmax.y >= half || vol->bmax.z >= half;
    return OCC_OK;
}
