/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * nearest.c - nearest-first (best-first) search: a binary min-heap of nodes keyed by the squared
 * distance from the query point to the node cube, in a caller buffer. A node is reported when it
 * reaches the top of the heap; a child is never closer than its parent, so the order is exact.
 */
#include "query_internal.h"

static float box_d2(occ_vec3_t p, occ_vec3_t c, float h)
{
    const float dx = fabsf(p.x - c.x) - h;
    const float dy = fabsf(p.y - c.y) - h;
    const float dz = fabsf(p.z - c.z) - h;
    const float x = dx > 0.0f ? dx : 0.0f;
    const float y = dy > 0.0f ? dy : 0.0f;
    const float z = dz > 0.0f ? dz : 0.0f;
    return x * x + y * y + z * z;
}

static bool matches(const occ_nearest_t *it, occ_value_t v, uint8_t flags, bool uniform)
{
    return occ_q_node_wanted(it->map, v, flags, uniform, it->pred.states);
}

static occ_err_t push(occ_nearest_t *it, const occ_nearest_entry_t *e)
{
    if (it->n >= it->cap) {
        return OCC_ERR_NOMEM;
    }
    size_t i = it->n++;
    while (i > 0u) {
        const size_t parent = (i - 1u) / 2u;
        if (!(it->heap[parent].dist2 > e->dist2)) {
            break;
        }
        it->heap[i] = it->heap[parent];
        i = parent;
    }
    it->heap[i] = *e;
    return OCC_OK;
}

static void pop(occ_nearest_t *it, occ_nearest_entry_t *top)
{
    *top = it->heap[0];
    const occ_nearest_entry_t last = it->heap[--it->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2u * i + 1u;
        if (c >= it->n) {
            break;
        }
        if (c + 1u < it->n && it->heap[c + 1u].dist2 < it->heap[c].dist2) {
            c++;
        }
        if (!(it->heap[c].dist2 < last.dist2)) {
            break;
        }
        it->heap[i] = it->heap[c];
        i = c;
    }
    if (it->n > 0u) {
        it->heap[i] = last;
    }
}

occ_err_t occ_nearest_begin(occ_nearest_t *it, const occ_map_t *map, occ_vec3_t p,
                            float max_dist_m, occ_pred_t pred, occ_nearest_entry_t *buf,
                            size_t cap)
{
    if (it != NULL) {
        it->map = NULL; /* refused: occ_nearest_next answers OCC_ERR_ARG */
    }
    if (it == NULL || map == NULL || buf == NULL || cap == 0u || !occ_finite3(p) ||
        !occ_finite(max_dist_m) || max_dist_m < 0.0f || (pred.states & ~OCC_PRED_ANY) != 0u ||
        pred.min_level > map->cfg.depth_levels) {
        return OCC_ERR_ARG;
    }
    if (pred.states == 0u) {
        pred.states = (uint8_t)OCC_PRED_ANY;
    }
    it->map = map;
    it->p = p;
    it->max_dist2 = max_dist_m * max_dist_m;
    it->pred = pred;
    it->heap = buf;
    it->cap = cap;
    it->n = 0;
    it->gen = map->write_gen;
    occ_nearest_entry_t e;
    e.key.k[0] = e.key.k[1] = e.key.k[2] = 0u;
    e.level = map->cfg.depth_levels;
    e.child = occ_root_child(map);
    e.value = map->priv.root_value;
    e.flags = occ_root_flags(map);
    if (matches(it, e.value, e.flags, e.child == OCC_NONE)) {
        e.dist2 = box_d2(p, occ_geom_center(map, e.key, e.level), occ_q_half(map, e.level));
        if (e.dist2 <= it->max_dist2) {
            (void)push(it, &e);
        }
    }
    return OCC_OK;
}

occ_err_t occ_nearest_next(occ_nearest_t *it, occ_query_node_t *out, float *dist_m, bool *found)
{
    if (found != NULL) {
        *found = false;
    }
    if (it == NULL || it->map == NULL || out == NULL || found == NULL) {
        return OCC_ERR_ARG;
    }
    const occ_map_t *const m = it->map;
    if (it->gen != m->write_gen) { /* the heap's child indices may name freed or reused blocks */
        it->n = 0;
        return OCC_ERR_STATE;
    }
    while (it->n > 0u) {
        occ_nearest_entry_t top;
        pop(it, &top);
        const bool uniform = top.child == OCC_NONE;
        if (uniform || top.level <= it->pred.min_level) {
            occi_q_fill_node(m, top.key, top.level, top.value, top.flags, uniform, out);
            if (dist_m != NULL) {
                *dist_m = sqrtf(top.dist2);
            }
            *found = true;
            return OCC_OK;
        }
        OCC_ASSERT(top.level >= 1u && top.level <= m->cfg.depth_levels);
        const unsigned level = top.level - 1u;
        const uint32_t bit = 1u << level;
        const float h = occ_q_half(m, level);
        for (unsigned s = 0; s < 8u; s++) {
            occ_nearest_entry_t e;
            e.level = (uint8_t)level;
            e.key = top.key;
            e.key.k[0] |= (s & 1u) ? bit : 0u;
            e.key.k[1] |= (s & 2u) ? bit : 0u;
            e.key.k[2] |= (s & 4u) ? bit : 0u;
            const occ_entry_t en = occ_entry_at(m, top.child, level, s);
            e.value = en.value;
            e.flags = en.flags;
            e.child = en.child;
            if (!matches(it, e.value, e.flags, e.child == OCC_NONE)) {
                continue;
            }
            e.dist2 = box_d2(it->p, occ_geom_center(m, e.key, level), h);
            if (e.dist2 > it->max_dist2) {
                continue;
            }
            if (push(it, &e) != OCC_OK) {
                it->n = 0;
                return OCC_ERR_NOMEM;
            }
        }
    }
    return OCC_OK;
}
