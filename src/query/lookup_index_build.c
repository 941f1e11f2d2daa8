/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * lookup_index_build.c - building the lookup index (occ_query.h): the bounding box of the
 * observed space, the table's size, and its fill from one walk over the tree down to the table's
 * level. The lookups themselves are in lookup_index.c.
 */
#include "lookup_internal.h"
#include "../core/sat_internal.h"

void occi_idx_walk_begin(occ_idx_walk_t *const w, const occ_map_t *const m, const unsigned stop)
{
    w->top = (unsigned)m->cfg.depth_levels + 1u;
    w->stop = stop;
    w->root_pending = true;
    w->key.k[0] = w->key.k[1] = w->key.k[2] = 0u;
}

/* The root: reported when uniform and observed, or when the walk stops at its level; else its
 * block is pushed. False when there is nothing to report. */
static bool walk_root(occ_idx_walk_t *const w, const occ_map_t *const m, occ_idx_node_t *const out)
{
    const unsigned depth = m->cfg.depth_levels;
    w->root_pending = false;
    if (occ_root_child(m) != OCC_NONE && w->stop < depth) {
        w->top = depth;
        w->blk[depth] = occ_root_child(m);
        w->next[depth] = 0u;
        return false;
    }
    if (occ_root_child(m) == OCC_NONE && !occ_is_observed(m->priv.root_value)) {
        return false;
    }
    out->key = w->key;
    out->level = depth;
    out->child = occ_root_child(m);
    out->value = m->priv.root_value;
    return true;
}

bool occi_idx_walk_next(occ_idx_walk_t *const w, const occ_map_t *const m, occ_idx_node_t *const out)
{
    const unsigned depth = m->cfg.depth_levels;
    if (w->root_pending && walk_root(w, m, out)) {
        return true;
    }
    while (w->top <= depth) {
        const unsigned top = w->top;
        if (w->next[top] == 8u) {
            w->top = top + 1u;
            continue;
        }
        const unsigned slot = w->next[top]++;
        const unsigned lv = top - 1u;
        for (unsigned a = 0; a < 3u; a++) {
            w->key.k[a] = (w->key.k[a] & ~(1u << lv)) | (((slot >> a) & 1u) << lv);
        }
        const occ_entry_t e = occ_entry_at(m, w->blk[top], lv, slot);
        if (e.child != OCC_NONE && lv > w->stop) {
            OCC_ASSERT(lv >= 1u);
            w->top = lv;
            w->blk[lv] = e.child;
            w->next[lv] = 0u;
            continue;
        }
        if (e.child == OCC_NONE && !occ_is_observed(e.value)) {
            continue;
        }
        const uint32_t low = (1u << lv) - 1u;
        for (unsigned a = 0; a < 3u; a++) {
            out->key.k[a] = w->key.k[a] & ~low;
        }
        out->level = lv;
        out->child = e.child;
        out->value = e.value;
        return true;
    }
    return false;
}

void occi_idx_box(const occ_map_t *const m, const unsigned shift, uint32_t lo[3], uint32_t n[3])
{
    uint32_t mn[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX}, mx[3] = {0u, 0u, 0u};
    bool any = false;
    occ_idx_walk_t w;
    occ_idx_node_t nd;
    occi_idx_walk_begin(&w, m, shift);
    while (occi_idx_walk_next(&w, m, &nd)) {
        any = true;
        for (unsigned a = 0; a < 3u; a++) {
            const uint32_t last = nd.key.k[a] + ((1u << nd.level) - 1u);
            mn[a] = nd.key.k[a] < mn[a] ? nd.key.k[a] : mn[a];
            mx[a] = last > mx[a] ? last : mx[a];
        }
    }
    for (unsigned a = 0; a < 3u; a++) {
        lo[a] = any ? (mn[a] >> shift) << shift : 0u;
        n[a] = any ? (mx[a] >> shift) - (mn[a] >> shift) + 1u : 0u;
    }
}

size_t occi_idx_bytes(const unsigned level, const uint32_t n[3], const size_t mixed)
{
    const size_t cells = occ_sat_mul(occ_sat_mul((size_t)n[0], (size_t)n[1]), (size_t)n[2]);
    if (level == 0u && cells != 0u) {
        const size_t bricks = occ_sat_add(mixed, OCC_IDX_CONST_BRICKS);
        return occ_sat_add(occ_sat_mul(cells, sizeof(uint32_t)),
                           occ_sat_mul(bricks, OCC_IDX_BRICK_WORDS * sizeof(uint32_t)));
    }
    return occ_sat_mul(cells, sizeof(uint32_t));
}

/* Cells of 2^shift voxels per axis: 8x8x8 bricks at level 0. */
static unsigned idx_shift(const unsigned level)
{
    return level == 0u ? OCC_IDX_BRICK_SHIFT : level;
}

/* Box and bytes of the table at `level`. */
static size_t idx_size(const occ_map_t *const m, const unsigned level, uint32_t lo[3], uint32_t n[3],
                       size_t *const mixed)
{
    occi_idx_box(m, idx_shift(level), lo, n);
    *mixed = level == 0u && n[0] != 0u ? occi_idx_mixed(m) : 0u;
    return occi_idx_bytes(level, n, *mixed);
}

occ_err_t occ_lookup_index_need(const occ_map_t *const map, const unsigned level, size_t *const bytes)
{
    if (map == NULL || bytes == NULL || level > map->cfg.depth_levels) {
        return OCC_ERR_ARG;
    }
    uint32_t lo[3], n[3];
    size_t mixed;
    *bytes = idx_size(map, level, lo, n, &mixed);
    return OCC_OK;
}

occ_err_t occ_lookup_index_pick(const occ_map_t *const map, const size_t budget_bytes,
                                unsigned *const level)
{
    if (map == NULL || level == NULL) {
        return OCC_ERR_ARG;
    }
    for (unsigned l = 0; l <= map->cfg.depth_levels; l++) {
        size_t b;
        (void)occ_lookup_index_need(map, l, &b);
        if (b <= budget_bytes) {
            *level = l;
            return OCC_OK;
        }
    }
    return OCC_ERR_NOMEM;
}

/* Index of the cell holding voxel key k (inside the box). */
static size_t cell_at(const occ_lookup_index_t *const ix, const uint32_t k[3])
{
    const unsigned L = ix->level;
    return (size_t)((k[0] - ix->lo[0]) >> L) * ix->priv.stride_x +
           (size_t)((k[1] - ix->lo[1]) >> L) * ix->priv.stride_y + (size_t)((k[2] - ix->lo[2]) >> L);
}

void occi_idx_fill_cube(const occ_lookup_index_t *const ix, uint32_t *const table, const size_t c0,
                        const uint32_t span, const uint32_t word)
{
    for (uint32_t x = 0; x < span; x++) {
        for (uint32_t y = 0; y < span; y++) {
            const size_t row = c0 + (size_t)x * ix->priv.stride_x + (size_t)y * ix->priv.stride_y;
            for (uint32_t z = 0; z < span; z++) {
                table[row + z] = word;
            }
        }
    }
}

/* Every cell of the uniform node nd (state s, inside the box) gets its tag. */
static void fill_node(const occ_lookup_index_t *ix, uint32_t *cells, const occ_idx_node_t *nd,
                      const occ_state_t s)
{
    const unsigned L = ix->level;
    OCC_ASSERT(nd->level >= L);
    occi_idx_fill_cube(ix, cells, cell_at(ix, nd->key.k), 1u << (nd->level - L),
                       OCC_IDX_TAG | (uint32_t)s);
}

/* A level >= 1 table: UNKNOWN everywhere, then every node the walk reports down to the level. */
static void fill_table(const occ_lookup_index_t *const ix, const occ_map_t *const m,
                       uint32_t *const cells)
{
    const size_t words = ix->bytes / sizeof(uint32_t);
    for (size_t i = 0; i < words; i++) {
        cells[i] = OCC_IDX_TAG | (uint32_t)OCC_STATE_UNKNOWN;
    }
    occ_idx_walk_t w;
    occ_idx_node_t nd;
    occi_idx_walk_begin(&w, m, ix->level);
    while (occi_idx_walk_next(&w, m, &nd)) {
        if (nd.child != OCC_NONE) {
            OCC_ASSERT(nd.level == ix->level && nd.child < OCC_IDX_TAG);
            cells[cell_at(ix, nd.key.k)] = nd.child;
            continue;
        }
        const occ_state_t s = occ_value_state(m, nd.value);
        if (s != OCC_STATE_UNKNOWN) {
            fill_node(ix, cells, &nd, s);
        }
    }
}

occ_err_t occ_lookup_index_build(occ_lookup_index_t *const idx, const occ_map_t *const map,
                                 const unsigned level, void *const mem, const size_t mem_bytes)
{
    if (idx == NULL) {
        return OCC_ERR_ARG;
    }
    idx->map = NULL; /* unbuilt until the end */
    if (map == NULL || level > map->cfg.depth_levels) {
        return OCC_ERR_ARG;
    }
    if (map->inner.hwm >= OCC_IDX_TAG || map->leaf.hwm >= OCC_IDX_TAG) {
        return OCC_ERR_UNSUPPORTED;
    }
    size_t mixed;
    idx->bytes = idx_size(map, level, idx->lo, idx->n, &mixed);
    idx->level = (uint8_t)level;
    idx->priv.shift = (uint8_t)idx_shift(level);
    if (mixed > (size_t)(UINT32_MAX - OCC_IDX_CONST_BRICKS)) {
        return OCC_ERR_UNSUPPORTED; /* brick numbers are 32-bit */
    }
    if (idx->bytes != 0u && mem == NULL) {
        return OCC_ERR_ARG;
    }
    const size_t pad = mem == NULL ? 0u : (size_t)((4u - ((uintptr_t)mem & 3u)) & 3u);
    if (idx->bytes == SIZE_MAX || occ_sat_add(idx->bytes, pad) > mem_bytes) {
        return OCC_ERR_NOMEM;
    }
    uint32_t *const cells = idx->bytes == 0u ? NULL : (uint32_t *)(void *)((uint8_t *)mem + pad);
    idx->priv.stride_y = idx->n[2];
    idx->priv.stride_x = (size_t)idx->n[1] * (size_t)idx->n[2];
    const size_t n_cells = (size_t)idx->n[0] * idx->priv.stride_x;
    uint32_t *const bricks = cells == NULL || level != 0u ? NULL : cells + n_cells;
    if (bricks != NULL) {
        occi_idx_fill_bricks(idx, map, cells, bricks, mixed);
    } else if (cells != NULL) {
        fill_table(idx, map, cells);
    }
    idx->priv.cells = cells;
    idx->priv.bricks = bricks;
    idx->priv.gen = map->write_gen;
    idx->priv.root = occ_root_child(map);
    idx->priv.arena = map->priv.arena;
    idx->map = map;
    return OCC_OK;
}
