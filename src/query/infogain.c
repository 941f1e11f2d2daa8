/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * infogain.c - information gain of a sensor volume: the unknown cells at a chosen level, found by
 * the volume iterator (branches without unknown space are skipped through the indicators).
 */
#include "query_internal.h"

static float entropy_bits(const occ_map_t *m, occ_value_t v)
{
    if (!occ_is_observed(v)) {
        return 1.0f;
    }
    const float l = occ_value_to_logodds(v);
    const float p = 1.0f / (1.0f + expf(-l));
    const float q = 1.0f - p;
    float h = 0.0f;
    if (p > 0.0f) {
        h -= p * log2f(p);
    }
    if (q > 0.0f) {
        h -= q * log2f(q);
    }
    (void)m;
    return h;
}

static occ_vec3_t sensor_origin(const occ_volume_t *v)
{
    switch (v->kind) {
    case OCC_VOL_FRUSTUM:
        return v->u.frustum.origin;
    case OCC_VOL_SPHERE:
        return v->u.sphere.c;
    case OCC_VOL_OBB:
        return v->u.obb.c;
    case OCC_VOL_CAPSULE:
    case OCC_VOL_SEGMENT:
        return v->u.capsule.a;
    case OCC_VOL_AABB:
    default: {
        occ_vec3_t c;
        c.x = 0.5f * (v->bmin.x + v->bmax.x);
        c.y = 0.5f * (v->bmin.y + v->bmax.y);
        c.z = 0.5f * (v->bmin.z + v->bmax.z);
        return c;
    }
    }
}

static bool visible(const occ_map_t *m, occ_vec3_t from, occ_key_t cell, unsigned level)
{
    bool vis = false;
    const occ_vec3_t to = occ_geom_center(m, cell, level);
    if (occ_line_of_sight(m, from, to, OCC_UNKNOWN_SAFE, &vis, NULL) != OCC_OK) {
        return false;
    }
    return vis;
}

/* OCC_GAIN_OCCLUSION: the cells at `level` of one reported UNKNOWN node (entropy h each), each
 * counted after its own line of sight. Out of line: inlined, its frame and the line of sight's
 * sat on top of the iterator in occ_info_gain's (make cross). */
OCC_NOINLINE static void add_visible(const occ_map_t *map, const occ_query_node_t *n,
                                     unsigned level, occ_vec3_t from, float h,
                                     occ_info_gain_t *out)
{
    const uint32_t span = (uint32_t)1 << (n->level - level);
    const uint32_t stride = (uint32_t)1 << level;
    for (uint32_t z = 0; z < span; z++) {
        for (uint32_t y = 0; y < span; y++) {
            for (uint32_t x = 0; x < span; x++) {
                occ_key_t k = n->key;
                k.k[0] += x * stride;
                k.k[1] += y * stride;
                k.k[2] += z * stride;
                if (visible(map, from, k, level)) {
                    out->unknown_cells++;
                    out->entropy_bits += h;
                }
            }
        }
    }
}

occ_err_t occ_info_gain(const occ_map_t *map, const occ_volume_t *vol, unsigned level,
                        unsigned options, occ_info_gain_t *out)
{
    if (out != NULL) { /* on any error: nothing to gain, never a stale count */
        out->unknown_cells = 0u;
        out->entropy_bits = 0.0f;
    }
    if (map == NULL || vol == NULL || out == NULL || level > map->cfg.depth_levels ||
        (options & ~OCC_GAIN_OCCLUSION) != 0u) {
        return OCC_ERR_ARG;
    }
    occ_pred_t pred;
    pred.states = (uint8_t)OCC_PRED_UNKNOWN;
    pred.min_level = (uint8_t)level;
    pred.options = (uint8_t)OCC_ITER_SPLIT;
    occ_query_iter_t it;
    const occ_err_t e = occ_query_begin(&it, map, vol, pred);
    if (e != OCC_OK) {
        return e;
    }
    const bool occl = (options & OCC_GAIN_OCCLUSION) != 0u;
    const occ_vec3_t from = sensor_origin(vol);
    occ_query_node_t n;
    while (occ_query_next(&it, &n)) {
        if (n.state != OCC_STATE_UNKNOWN) {
            continue; /* a mixed cell at `level` that merely contains unknown voxels */
        }
        const occ_value_t v = n.observed ? occ_value_from_logodds(n.logodds) : OCC_VALUE_UNOBSERVED;
        const float h = entropy_bits(map, v);
        if (occl) {
            add_visible(map, &n, level, from, h, out);
            continue;
        }
        const uint64_t cells = (uint64_t)1 << (3u * (n.level - level));
        out->unknown_cells += cells;
        out->entropy_bits += h * (float)cells;
    }
    return OCC_OK;
}
