/*
 * evict_need.c - occ_map_observe_need(): the blocks a batch of observations would allocate,
 * so an integrator in automatic mode can ask eviction for exactly that before retrying.
 */
#include "occmap/occ_evict.h"

#include "tree_internal.h"

/* Lowest level whose node contains both voxel codes. */
static unsigned common_level(const occ_code_t a, const occ_code_t b)
{
    occ_code_t d = a ^ b;
    unsigned h = 0u;
    while (d > 1u) {
        d >>= 1;
        h++;
    }
    return h / 3u + 1u;
}

/* Value of voxel `code` and the level of the uniform node holding it (0: in a leaf block). */
static occ_value_t lookup(const occ_map_t *const m, const occ_code_t code, unsigned *const stop)
{
    unsigned l = m->cfg.depth_levels;
    uint32_t child = m->root_child;
    occ_value_t v = m->root_value;
    while (child != OCC_NONE && l > 1u) {
        const occ_inner_block_t *const b = occ_inner_at(m, child);
        const unsigned s = occ_code_slot(code, l);
        v = b->value[s];
        child = b->child[s];
        l--;
    }
    if (child != OCC_NONE) {
        *stop = 0u;
        return occ_leaf_at(m, child)->value[occ_code_slot(code, 1u)];
    }
    *stop = l;
    return v;
}

occ_err_t occ_map_observe_need(const occ_map_t *const map, const occ_code_t *const codes,
                               const size_t n, uint32_t *const n_inner, uint32_t *const n_leaf)
{
    if (map == NULL || n_inner == NULL || n_leaf == NULL || (codes == NULL && n != 0u)) {
        return OCC_ERR_ARG;
    }
    *n_inner = 0u;
    *n_leaf = 0u;
    const occ_code_t limit = (occ_code_t)1 << (3u * map->cfg.depth_levels);
    uint64_t inner = 0u, leaf = 0u;
    occ_code_t last_changing = 0u;
    bool have_changing = false;
    for (size_t i = 0; i < n; i++) {
        const occ_code_t c = codes[i] & ~OCC_CODE_HIT_BIT;
        if (c >= limit || (i > 0u && c <= (codes[i - 1u] & ~OCC_CODE_HIT_BIT))) {
            return OCC_ERR_ARG;
        }
        unsigned stop;
        const occ_value_t v = lookup(map, c, &stop);
        const occ_value_t d = (codes[i] & OCC_CODE_HIT_BIT) != 0u ? map->q_hit : map->q_miss;
        if (occ_value_eq(occ_value_apply_delta(map, v, d), v)) {
            continue;
        }
        /* The uniform node at `stop` is split down to level 1, except the part of the path an
         * earlier changing code (the latest shares the longest prefix) split already. */
        unsigned fresh = stop;
        if (have_changing) {
            const unsigned s = common_level(c, last_changing) - 1u;
            fresh = s < fresh ? s : fresh;
        }
        if (fresh > 0u) {
            leaf += 1u;
            inner += fresh - 1u;
        }
        have_changing = true;
        last_changing = c;
    }
    *n_inner = inner > OCC_NONE ? OCC_NONE : (uint32_t)inner;
    *n_leaf = leaf > OCC_NONE ? OCC_NONE : (uint32_t)leaf;
    return OCC_OK;
}
