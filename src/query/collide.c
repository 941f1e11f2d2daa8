/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * collide.c - "is this volume safe?": a depth-first walk in Morton order that opens only the
 * blocks whose entries hold a blocking state (occupied, and unknown under OCC_UNKNOWN_UNSAFE) and
 * touch the volume, and stops at the first blocking node. The same nodes in the same order as the
 * volume iterator (query.c) asked for those states, without its generality (splitting, min
 * level, resuming), which is most of its cost on a check this small.
 */
#include "query_internal.h"

/* walk_below's open blocks live in walk's blk[] (blk[L]: children block of the path node at level
 * L), with masks[L] the children of blk[L] still to visit: the path above the start node and the
 * one below it are one array, not two (the walk's stack is on every collision check's call
 * chain). Neither the key nor the level is kept per frame: `path` holds the key bits. */

static OCC_ALWAYS_INLINE unsigned open_mask(const occ_map_t *m, const occ_volume_t *v,
                                            unsigned states, uint32_t block, occ_key_t key,
                                            unsigned level)
{
    const unsigned pm = level == 0u ? occ_q_leaf_match(m, occ_leaf_at(m, block), states)
                                    : occ_q_open_inner(m, block, states);
    return pm != 0u ? occ_q_touch_mask(m, v, key, level, pm) : 0u;
}

/* Below a start node at level `top` (first voxel `path`, children in blk[top]): the first child
 * voxel or uniform node that blocks and touches, into *out. Writes blk[] and masks[] at levels
 * <= top only: walk keeps the path above in them. */
static bool walk_below(const occ_map_t *m, const occ_volume_t *v, unsigned states, occ_key_t path,
                       unsigned top, uint32_t *blk, uint8_t *masks, occ_query_node_t *out)
{
    unsigned at = top; /* the node whose children are being visited */
    masks[top] = (uint8_t)open_mask(m, v, states, blk[top], path, top - 1u);
    for (;;) {
        const unsigned mk = masks[at];
        if (mk == 0u) {
            if (at == top) {
                return false;
            }
            at++;
            continue;
        }
        const unsigned slot = occ_first_slot(mk);
        masks[at] = (uint8_t)(mk & (mk - 1u));
        const unsigned l = at - 1u;              /* the child's level */
        const uint32_t keep = ~((2u << l) - 1u); /* bits above level l */
        path.k[0] = (path.k[0] & keep) | ((slot & 1u) << l);
        path.k[1] = (path.k[1] & keep) | (((slot >> 1) & 1u) << l);
        path.k[2] = (path.k[2] & keep) | (((slot >> 2) & 1u) << l);
        const occ_entry_t e = occ_entry_at(m, blk[at], l, slot);
        if (e.child == OCC_NONE) { /* a voxel, or a uniform node: it blocks and touches */
            occi_q_fill_node(m, path, l, e.value, e.flags, true, out);
            return true;
        }
        OCC_ASSERT(l >= 1u);
        blk[l] = e.child;
        masks[l] = (uint8_t)open_mask(m, v, states, e.child, path, l - 1u);
        at = l;
    }
}

/* The start cells (query.c) in Morton order, each reached from the root along the path of the
 * previous one (only the levels below their highest differing key bit are walked again).
 * -fanalyzer reads blk[level] as uninitialised: blk[stopped + 1 .. depth] always hold the path
 * of the last cell descended (the first starts at the root, each later one rewrites from its
 * common ancestor down), and a jump reads only level = hb + 1 > stopped. */
OCC_ANALYZER_UNINIT_OFF
static bool walk(const occ_map_t *m, const occ_volume_t *v, unsigned states, occ_query_node_t *out)
{
    occi_q_starts_t st;
    occi_q_starts(m, v, 0u, &st);
    const unsigned lc = st.level;
    occ_key_t prev = st.first;
    const unsigned depth = m->cfg.depth_levels;
    uint32_t blk[OCC_MAX_DEPTH + 1u]; /* blk[L]: children block of the path node at level L */
    uint8_t masks[OCC_MAX_DEPTH + 1u]; /* walk_below's children still to visit, per level */
    unsigned stopped = depth + 1u;     /* level where the previous descent ended */
    for (unsigned t = 0; t < st.n; t++) {
        const occ_key_t key = occi_q_start_key(&st, t);
        unsigned level = depth;
        uint32_t child = occ_root_child(m);
        occ_value_t val = m->priv.root_value;
        uint8_t flags = occ_root_flags(m);
        bool check = true;
        if (t > 0u) {
            const uint32_t x = (key.k[0] ^ prev.k[0]) | (key.k[1] ^ prev.k[1]) |
                               (key.k[2] ^ prev.k[2]);
            prev = key;
            const unsigned hb = occ_bit_length32(x) - 1u; /* x != 0: distinct cells */
            if (hb < stopped) {
                continue; /* inside the node the previous descent ended at: done with it */
            }
            if (hb + 1u < depth) {
                level = hb + 1u; /* the common ancestor: passed, so it has wanted children */
                child = blk[level];
                check = false;
            }
        }
        while (level > lc && child != OCC_NONE) {
            if (check && !occ_q_contains(flags, states)) {
                break;
            }
            check = true;
            blk[level] = child;
            level--;
            const occ_entry_t e = occ_entry_at(m, child, level, occ_key_slot(&key, level));
            val = e.value;
            flags = e.flags;
            child = e.child;
        }
        stopped = level;
        const bool uniform = child == OCC_NONE;
        const bool wanted = occ_q_node_wanted(m, val, flags, uniform, states);
        const occ_key_t nk = occ_key_at_level(key, level);
        if (!wanted ||
            !occ_volume_hits_box(v, occ_geom_center(m, nk, level), occ_q_half(m, level))) {
            continue;
        }
        if (uniform) {
            occi_q_fill_node(m, nk, level, val, flags, true, out);
            return true;
        }
        blk[level] = child;
        if (walk_below(m, v, states, nk, level, blk, masks, out)) {
            return true;
        }
    }
    return false;
}
OCC_ANALYZER_UNINIT_ON

void occi_q_collision_unsafe(occ_collision_t *out)
{
    if (out == NULL) {
        return;
    }
    memset(out, 0, sizeof *out);
    out->safe = false;
    out->outside = false;
    out->node.uniform = true;
    out->node.observed = false;
    out->node.state = OCC_STATE_UNKNOWN;
    out->node.flags = (uint8_t)(OCC_NODE_HAS_UNKNOWN | OCC_NODE_UNIFORM);
}

static bool leaves_map(const occ_map_t *map, const occ_volume_t *vol)
{
    const float half = occ_map_node_size(map, map->cfg.depth_levels) * 0.5f;
    return vol->bmin.x < -half || vol->bmin.y < -half || vol->bmin.z < -half ||
           vol->bmax.x >= half || vol->bmax.y >= half || vol->bmax.z >= half;
}

occ_err_t occ_collide_volume(const occ_map_t *map, const occ_volume_t *vol,
                             occ_unknown_policy_t policy, occ_collision_t *out)
{
    occi_q_collision_unsafe(out); /* until the walk proves otherwise */
    if (map == NULL || vol == NULL || out == NULL ||
        (policy != OCC_UNKNOWN_UNSAFE && policy != OCC_UNKNOWN_SAFE)) {
        return OCC_ERR_ARG;
    }
    if (policy == OCC_UNKNOWN_UNSAFE && leaves_map(map, vol)) {
        out->outside = true;
        return OCC_OK;
    }
    const unsigned states = occ_q_blocking_states(policy);
    out->safe = !walk(map, vol, states, &out->node);
    return OCC_OK;
}

occ_err_t occ_collide_sphere(const occ_map_t *map, occ_vec3_t center, float radius_m,
                             occ_unknown_policy_t policy, occ_collision_t *out)
{
    occ_volume_t v;
    occi_q_collision_unsafe(out); /* also when the volume is refused */
    const occ_err_t e = occ_volume_sphere(&v, center, radius_m);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_collide_aabb(const occ_map_t *map, occ_vec3_t min, occ_vec3_t max,
                           occ_unknown_policy_t policy, occ_collision_t *out)
{
    occ_volume_t v;
    occi_q_collision_unsafe(out); /* also when the volume is refused */
    const occ_err_t e = occ_volume_aabb(&v, min, max);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_collide_obb(const occ_map_t *map, occ_vec3_t center, const float half_m[3],
                          const occ_vec3_t axes[3], occ_unknown_policy_t policy,
                          occ_collision_t *out)
{
    occ_volume_t v;
    occi_q_collision_unsafe(out); /* also when the volume is refused */
    const occ_err_t e = occ_volume_obb(&v, center, half_m, axes);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_collide_capsule(const occ_map_t *map, occ_vec3_t a, occ_vec3_t b, float radius_m,
                              occ_unknown_policy_t policy, occ_collision_t *out)
{
    occ_volume_t v;
    occi_q_collision_unsafe(out); /* also when the volume is refused */
    const occ_err_t e = occ_volume_capsule(&v, a, b, radius_m);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_distance_to_obstacle(const occ_map_t *map, occ_vec3_t p, float max_dist_m,
                                   occ_unknown_policy_t policy, occ_nearest_entry_t *buf,
                                   size_t cap, float *dist_m, occ_obstacle_t *result)
{
    /* Undecided (an obstacle right here) until the search decides. */
    if (dist_m != NULL) {
        *dist_m = 0.0f;
    }
    if (result != NULL) {
        *result = OCC_OBSTACLE_UNDECIDED;
    }
    if (dist_m == NULL || result == NULL ||
        (policy != OCC_UNKNOWN_UNSAFE && policy != OCC_UNKNOWN_SAFE)) {
        return OCC_ERR_ARG;
    }
    occ_pred_t pred;
    pred.states = (uint8_t)occ_q_blocking_states(policy);
    pred.min_level = 0;
    pred.options = 0;
    occ_nearest_t it;
    occ_err_t e = occ_nearest_begin(&it, map, p, max_dist_m, pred, buf, cap);
    if (e != OCC_OK) {
        return e;
    }
    occ_query_node_t node;
    bool found = false;
    float dist = 0.0f;
    e = occ_nearest_next(&it, &node, &dist, &found);
    if (e != OCC_OK) {
        return e; /* heap overflow: what lies beyond the nodes searched is not known */
    }
    *dist_m = found ? dist : max_dist_m;
    *result = found ? OCC_OBSTACLE_FOUND : OCC_OBSTACLE_NONE;
    return OCC_OK;
}
