/*
 * query_internal.h - helpers shared by the query modules (query, nearest, collide, castray,
 * infogain): node geometry from keys and the state of a stored value, inline for speed.
 */
#ifndef OCC_QUERY_INTERNAL_H_INCLUDED
#define OCC_QUERY_INTERNAL_H_INCLUDED

#include <math.h>
#include "map/tree_internal.h"

static inline occ_state_t occ_q_state(const occ_map_t *m, occ_value_t v)
{
    if (!occ_is_observed(v)) {
        return OCC_STATE_UNKNOWN;
    }
    if (v >= m->q_occ_min) {
        return OCC_STATE_OCCUPIED;
    }
    return (v < m->q_free_max) ? OCC_STATE_FREE : OCC_STATE_UNKNOWN;
}

static inline uint8_t occ_q_state_bit(occ_state_t s)
{
    switch (s) {
    case OCC_STATE_OCCUPIED:
        return (uint8_t)OCC_PRED_OCCUPIED;
    case OCC_STATE_FREE:
        return (uint8_t)OCC_PRED_FREE;
    case OCC_STATE_UNKNOWN:
        return (uint8_t)OCC_PRED_UNKNOWN;
    default:
        return 0u;
    }
}

/* Flags of a uniform value. */
static inline uint8_t occ_q_uniform_flags(const occ_map_t *m, occ_value_t v)
{
    switch (occ_q_state(m, v)) {
    case OCC_STATE_OCCUPIED:
        return (uint8_t)(OCC_NODE_HAS_OCCUPIED | OCC_NODE_UNIFORM);
    case OCC_STATE_FREE:
        return (uint8_t)(OCC_NODE_HAS_FREE | OCC_NODE_UNIFORM);
    case OCC_STATE_UNKNOWN:
    default:
        return (uint8_t)(OCC_NODE_HAS_UNKNOWN | OCC_NODE_UNIFORM);
    }
}

/* Does a node with children (max `v`, indicator `flags`) contain a state in `mask`? */
static inline bool occ_q_contains(const occ_map_t *m, occ_value_t v, uint8_t flags, unsigned mask)
{
    if ((mask & OCC_PRED_OCCUPIED) != 0u && occ_is_observed(v) && v >= m->q_occ_min) {
        return true;
    }
    if ((mask & OCC_PRED_FREE) != 0u && (flags & OCC_NODE_HAS_FREE) != 0u) {
        return true;
    }
    return (mask & OCC_PRED_UNKNOWN) != 0u && (flags & OCC_NODE_HAS_UNKNOWN) != 0u;
}

/* Centre coordinate (metres) of the node at `level` whose first voxel key on an axis is `k`
 * (the same arithmetic as occ_map_key_center). */
static inline float occ_q_center1(const occ_map_t *m, uint32_t k, unsigned level)
{
    const int32_t half = (int32_t)1 << (m->cfg.depth_levels - 1u);
    const float res = m->cfg.resolution_m;
    return (float)((int32_t)k - half) * res + 0.5f * (res * (float)((uint32_t)1 << level));
}

static inline occ_vec3_t occ_q_center(const occ_map_t *m, occ_key_t k, unsigned level)
{
    occ_vec3_t c;
    c.x = occ_q_center1(m, k.k[0], level);
    c.y = occ_q_center1(m, k.k[1], level);
    c.z = occ_q_center1(m, k.k[2], level);
    return c;
}

static inline float occ_q_half(const occ_map_t *m, unsigned level)
{
    return (float)(1u << level) * 0.5f * m->cfg.resolution_m;
}

static inline bool occ_q_finite(float f)
{
    return isfinite(f) != 0;
}

static inline bool occ_q_finite3(occ_vec3_t v)
{
    return occ_q_finite(v.x) && occ_q_finite(v.y) && occ_q_finite(v.z);
}

/* Fill a reported node. */
void occ_q_fill_node(const occ_map_t *m, occ_key_t key, unsigned level, occ_value_t v,
                     uint8_t flags, bool uniform, occ_query_node_t *out);

#endif /* OCC_QUERY_INTERNAL_H_INCLUDED */
