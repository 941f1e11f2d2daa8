/*
 * lookup.c - point lookups with a path cache for streams of nearby points (a trajectory, a sensor
 * footprint): only the levels below the highest key bit that changed are walked again.
 */
#include "map/query_internal.h"

void occ_lookup_init(occ_lookup_t *lk, const occ_map_t *map)
{
    lk->map = map;
    lk->valid = false;
    lk->lu = 0;
    lk->val = OCC_VALUE_UNOBSERVED;
    lk->key.k[0] = lk->key.k[1] = lk->key.k[2] = 0u;
}

/* occ_map_key's arithmetic for one axis, inline (NaN and Inf fail the range test). */
static inline bool lookup_key1(const occ_map_t *m, float c, int32_t half, uint32_t *key)
{
#if OCC_RAY_DOUBLE
    const double scaled = (double)c * m->inv_res_d;
    if (!(scaled >= -(double)half) || !(scaled < (double)half)) {
        return false;
    }
    double fl = (double)(int32_t)scaled;
    fl -= fl > scaled ? 1.0 : 0.0;
#else
    const float scaled = c * m->inv_res;
    if (!(scaled >= -(float)half) || !(scaled < (float)half)) {
        return false;
    }
    float fl = (float)(int32_t)scaled;
    fl -= fl > scaled ? 1.0f : 0.0f;
#endif
    *key = (uint32_t)((int32_t)fl + half);
    return true;
}

occ_state_t occ_lookup_state(occ_lookup_t *lk, occ_vec3_t p)
{
    const occ_map_t *const m = lk->map;
    const int32_t half = (int32_t)1 << (m->cfg.depth_levels - 1u);
    occ_key_t k;
    if (!lookup_key1(m, p.x, half, &k.k[0]) || !lookup_key1(m, p.y, half, &k.k[1]) ||
        !lookup_key1(m, p.z, half, &k.k[2])) {
        return OCC_STATE_UNKNOWN;
    }
    const unsigned depth = m->cfg.depth_levels;
    unsigned level;
    uint32_t b;
    if (lk->valid) {
        const uint32_t x = (k.k[0] ^ lk->key.k[0]) | (k.k[1] ^ lk->key.k[1]) |
                           (k.k[2] ^ lk->key.k[2]);
        lk->key = k;
        if ((x >> lk->lu) == 0u) {
            return occ_q_state(m, lk->val); /* same uniform node (or voxel) */
        }
        level = occ_bit_length32(x); /* highest changed bit + 1 */
        b = lk->blk[level];
    } else {
        lk->key = k;
        lk->valid = true;
        if (m->root_child == OCC_NONE) {
            lk->lu = (uint8_t)depth;
            lk->val = m->root_value;
            return occ_q_state(m, lk->val);
        }
        level = depth;
        b = m->root_child;
        lk->blk[depth] = b;
    }
    while (level > 1u) {
        level--;
        const unsigned slot = ((k.k[0] >> level) & 1u) | (((k.k[1] >> level) & 1u) << 1) |
                              (((k.k[2] >> level) & 1u) << 2);
        const occ_inner_block_t *const ib = occ_inner_at(m, b);
        const uint32_t ch = ib->child[slot];
        if (ch == OCC_NONE) {
            lk->lu = (uint8_t)level;
            lk->val = ib->value[slot];
            return occ_q_state(m, lk->val);
        }
        lk->blk[level] = ch;
        b = ch;
    }
    lk->lu = 0;
    lk->val = occ_leaf_at(m, b)->value[(k.k[0] & 1u) | ((k.k[1] & 1u) << 1) | ((k.k[2] & 1u) << 2)];
    return occ_q_state(m, lk->val);
}
