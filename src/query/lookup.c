/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * lookup.c - point lookups: occ_map_state_at (one descent from the root), the cursor with a
 * path cache for streams of nearby points (a trajectory, a sensor footprint), which walks again
 * only the levels below the highest key bit that changed, and occ_map_states_at (many points
 * through one cursor).
 */
#include "query_internal.h"

static inline bool point_key(const occ_map_t *m, occ_vec3_t p, occ_key_t *k)
{
    return occ_coord_to_key(m, p.x, &k->k[0]) && occ_coord_to_key(m, p.y, &k->k[1]) &&
           occ_coord_to_key(m, p.z, &k->k[2]);
}

/* Down from block `b`, whose nodes sit at level - 1, to the node without children that holds
 * `k`: its value, and its level in *lu. Only the child index is read on the way (no value, no
 * flags), so a level costs one dependent load. With `path`, path[L] = the block entered at L. */
static inline occ_value_t descend(const occ_map_t *m, const occ_key_t *k, unsigned level,
                                  uint32_t b, uint32_t *path, unsigned *lu)
{
    OCC_ASSERT(level >= 1u && level <= m->cfg.depth_levels);
    while (level > 1u) {
        level--;
        const occ_inner_block_t *const ib = occ_inner_at(m, b);
        const unsigned slot = occ_key_slot(k, level);
        const uint32_t ch = occ_inner_child(ib, slot);
        if (ch == OCC_NONE) {
            *lu = level;
            return ib->value[slot];
        }
        if (path != NULL) {
            path[level] = ch;
        }
        b = ch;
    }
    *lu = 0u;
    return occ_leaf_at(m, b)->value[occ_key_slot(k, 0u)];
}

occ_state_t occ_map_state_at(const occ_map_t *const map, const occ_vec3_t p)
{
    occ_key_t k;
    if (map == NULL || !point_key(map, p, &k)) {
        return OCC_STATE_UNKNOWN;
    }
    if (occ_root_child(map) == OCC_NONE) {
        return occ_value_state(map, map->priv.root_value);
    }
    unsigned lu;
    return occ_value_state(map, descend(map, &k, map->cfg.depth_levels, occ_root_child(map), NULL, &lu));
}

void occ_lookup_init(occ_lookup_t *lk, const occ_map_t *map)
{
    lk->map = map;
    lk->valid = false;
    lk->lu = 0;
    lk->val = OCC_VALUE_UNOBSERVED;
    lk->key.k[0] = lk->key.k[1] = lk->key.k[2] = 0u;
    lk->gen = map != NULL ? map->write_gen : 0u;
}

occ_err_t occ_lookup_status(const occ_lookup_t *const lk)
{
    if (lk == NULL || lk->map == NULL) {
        return OCC_ERR_ARG;
    }
    return lk->gen == lk->map->write_gen ? OCC_OK : OCC_ERR_STATE;
}

/* The cursor's answer for a valid cursor and a point on the map (key k). */
static inline occ_state_t cached_state(occ_lookup_t *lk, occ_key_t k)
{
    const occ_map_t *const m = lk->map;
    const unsigned depth = m->cfg.depth_levels;
    unsigned level;
    uint32_t b;
    if (lk->valid) {
        const uint32_t x = (k.k[0] ^ lk->key.k[0]) | (k.k[1] ^ lk->key.k[1]) |
                           (k.k[2] ^ lk->key.k[2]);
        lk->key = k;
        if ((x >> lk->lu) == 0u) {
            return occ_value_state(m, lk->val); /* same uniform node (or voxel) */
        }
        level = occ_bit_length32(x); /* highest changed bit + 1 */
        OCC_ASSERT(level > lk->lu && level <= depth); /* blk[level] is on the cached path */
        b = lk->blk[level];
    } else {
        lk->key = k;
        lk->valid = true;
        if (occ_root_child(m) == OCC_NONE) {
            lk->lu = (uint8_t)depth;
            lk->val = m->priv.root_value;
            return occ_value_state(m, lk->val);
        }
        level = depth;
        b = occ_root_child(m);
        lk->blk[depth] = b;
    }
    unsigned lu;
    lk->val = descend(m, &k, level, b, lk->blk, &lu);
    lk->lu = (uint8_t)lu;
    return occ_value_state(m, lk->val);
}

occ_state_t occ_lookup_state(occ_lookup_t *lk, occ_vec3_t p)
{
    occ_key_t k;
    if (occ_lookup_status(lk) != OCC_OK || !point_key(lk->map, p, &k)) {
        return OCC_STATE_UNKNOWN; /* stale cursor, NULL, NaN or off the map */
    }
    return cached_state(lk, k);
}

occ_err_t occ_map_states_at(const occ_map_t *const map, const occ_vec3_t *const pts, const size_t n,
                            uint8_t *const states_out)
{
    if (map == NULL || (n > 0u && (pts == NULL || states_out == NULL))) {
        for (size_t i = 0; states_out != NULL && i < n; i++) {
            states_out[i] = (uint8_t)OCC_STATE_UNKNOWN; /* fail closed */
        }
        return OCC_ERR_ARG;
    }
    /* Through occ_lookup_state, so that the cursor's body keeps one (inlined) copy: its staleness
     * check per point is two loads, and the map cannot change during this call. */
    occ_lookup_t lk;
    occ_lookup_init(&lk, map);
    for (size_t i = 0; i < n; i++) {
        states_out[i] = (uint8_t)occ_lookup_state(&lk, pts[i]);
    }
    return OCC_OK;
}

/* The key is computed twice here, so that occ_lookup_state, the hot path of trajectories, keeps
 * the only (inlined) copy of the cursor's body. */
occ_err_t occ_lookup_read(occ_lookup_t *lk, occ_vec3_t p, occ_state_t *state)
{
    occ_state_t s = OCC_STATE_UNKNOWN;
    occ_err_t e = occ_lookup_status(lk);
    occ_key_t k;
    if (e == OCC_OK && !point_key(lk->map, p, &k)) {
        e = occ_finite3(p) ? OCC_ERR_RANGE : OCC_ERR_ARG;
    } else if (e == OCC_OK) {
        s = occ_lookup_state(lk, p);
    }
    if (state != NULL) {
        *state = s;
    }
    return e;
}
