/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * lookup_index.c - point lookups through the lookup index (occ_query.h): the point's key (the
 * map's one conversion), one table load, then at level 0 one brick word, at level >= 1 the last
 * `level` levels of the tree. Built by lookup_index_build.c and lookup_index_bricks.c.
 */
#include "lookup_internal.h"

occ_err_t occ_lookup_index_status(const occ_lookup_index_t *const idx)
{
    if (idx == NULL) {
        return OCC_ERR_ARG;
    }
    const occ_map_t *const m = idx->map;
    if (m == NULL || m->write_gen != idx->priv.gen || occ_root_child(m) != idx->priv.root ||
        (const void *)m->priv.arena != idx->priv.arena) {
        return OCC_ERR_STATE;
    }
    return OCC_OK;
}

/* The key of p and its cell (a brick's directory entry at level 0); false for NaN / Inf, off
 * the map or outside the box. (k - lo) wraps for k < lo to >= 2^32 - 2^21, which stays >= n
 * after the shift (n <= 2^(21 - shift)). */
static inline bool cell_of(const occ_lookup_index_t *const ix, const occ_map_t *const m,
                           const occ_vec3_t p, occ_key_t *const k, size_t *const cell)
{
    if (!occ_coord_to_key(m, p.x, &k->k[0]) || !occ_coord_to_key(m, p.y, &k->k[1]) ||
        !occ_coord_to_key(m, p.z, &k->k[2])) {
        return false;
    }
    const unsigned L = ix->priv.shift;
    const uint32_t ux = (k->k[0] - ix->lo[0]) >> L;
    const uint32_t uy = (k->k[1] - ix->lo[1]) >> L;
    const uint32_t uz = (k->k[2] - ix->lo[2]) >> L;
    if (ux >= ix->n[0] || uy >= ix->n[1] || uz >= ix->n[2]) {
        return false;
    }
    *cell = (size_t)ux * ix->priv.stride_x + (size_t)uy * ix->priv.stride_y + (size_t)uz;
    return true;
}

/* Down from the cell's block `b` (its entries at level - 1) to the node without children that
 * holds k: one dependent load per level. */
static inline occ_value_t walk_down(const occ_map_t *const m, const occ_key_t *const k,
                                    unsigned level, uint32_t b)
{
    OCC_ASSERT(level >= 1u && level <= m->cfg.depth_levels);
    while (level > 1u) {
        level--;
        const occ_inner_block_t *const ib = occ_inner_at(m, b);
        const unsigned slot = occ_key_slot(k, level);
        const uint32_t ch = occ_inner_child(ib, slot);
        if (ch == OCC_NONE) {
            return ib->value[slot];
        }
        b = ch;
    }
    return occ_leaf_at(m, b)->value[occ_key_slot(k, 0u)];
}

/* The answer of a cell whose table entry (brick number or reference) was read as `w`. */
static inline occ_state_t cell_answer(const occ_lookup_index_t *const ix, const occ_map_t *m,
                                      const occ_key_t *const k, const uint32_t w)
{
    if (ix->level == 0u) {
        unsigned sh;
        const size_t i = occi_idx_brick_word(w, k, &sh);
        return (occ_state_t)((ix->priv.bricks[i] >> sh) & 3u);
    }
    if (w >= OCC_IDX_TAG) {
        return (occ_state_t)(w & 3u);
    }
    return occ_value_state(m, walk_down(m, k, ix->level, w));
}

/* The lookup of a valid index. */
static inline occ_state_t index_state(const occ_lookup_index_t *const ix, const occ_vec3_t p)
{
    const occ_map_t *const m = ix->map;
    occ_key_t k;
    size_t cell;
    if (!cell_of(ix, m, p, &k, &cell)) {
        return OCC_STATE_UNKNOWN; /* NaN, off the map, or outside the observed box */
    }
    return cell_answer(ix, m, &k, ix->priv.cells[cell]);
}

occ_state_t occ_lookup_index_state(const occ_lookup_index_t *const idx, const occ_vec3_t p)
{
    if (occ_lookup_index_status(idx) != OCC_OK) {
        return OCC_STATE_UNKNOWN;
    }
    return index_state(idx, p);
}

occ_err_t occ_lookup_index_read(const occ_lookup_index_t *const idx, const occ_vec3_t p,
                                occ_state_t *const state)
{
    occ_state_t s = OCC_STATE_UNKNOWN;
    occ_err_t e = occ_lookup_index_status(idx);
    if (e == OCC_OK) {
        occ_key_t k;
        if (!occ_finite3(p)) {
            e = OCC_ERR_ARG;
        } else if (occ_map_key(idx->map, p, &k) != OCC_OK) {
            e = OCC_ERR_RANGE;
        } else {
            s = index_state(idx, p);
        }
    }
    if (state != NULL) {
        *state = s;
    }
    return e;
}

#define BATCH 8u

/* Up to BATCH points: keys and cells first, each table entry prefetched, then the answers (the
 * brick word, or the block of a level >= 1 reference, prefetched first), so the misses overlap. */
static void batch_states(const occ_lookup_index_t *const ix, const occ_vec3_t *const pts,
                         const size_t n, occ_state_t *const out)
{
    const occ_map_t *const m = ix->map;
    occ_key_t k[BATCH];
    size_t cell[BATCH];
    uint32_t w[BATCH];
    bool in[BATCH];
    for (size_t i = 0; i < n; i++) {
        in[i] = cell_of(ix, m, pts[i], &k[i], &cell[i]);
        if (in[i]) {
            OCC_PREFETCH(&ix->priv.cells[cell[i]]);
        }
    }
    for (size_t i = 0; i < n; i++) {
        w[i] = in[i] ? ix->priv.cells[cell[i]] : OCC_IDX_TAG;
        if (ix->level == 0u && in[i]) {
            unsigned sh;
            OCC_PREFETCH(&ix->priv.bricks[occi_idx_brick_word(w[i], &k[i], &sh)]);
        } else if (ix->level == 1u && w[i] < OCC_IDX_TAG) {
            OCC_PREFETCH(occ_leaf_at(m, w[i]));
        } else if (ix->level > 1u && w[i] < OCC_IDX_TAG) {
            OCC_PREFETCH(occ_inner_at(m, w[i]));
        }
    }
    for (size_t i = 0; i < n; i++) {
        out[i] = in[i] ? cell_answer(ix, m, &k[i], w[i]) : OCC_STATE_UNKNOWN;
    }
}

occ_err_t occ_lookup_index_states(const occ_lookup_index_t *const idx, const occ_vec3_t *const pts,
                                  const size_t n, occ_state_t *const out)
{
    if (idx == NULL || (n > 0u && (pts == NULL || out == NULL))) {
        return OCC_ERR_ARG;
    }
    if (occ_lookup_index_status(idx) != OCC_OK) {
        for (size_t i = 0; i < n; i++) {
            out[i] = OCC_STATE_UNKNOWN;
        }
        return OCC_ERR_STATE;
    }
    for (size_t i = 0; i < n; i += BATCH) {
        const size_t c = n - i < BATCH ? n - i : BATCH;
        batch_states(idx, pts + i, c, out + i);
    }
    return OCC_OK;
}
