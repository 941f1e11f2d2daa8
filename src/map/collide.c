/*
 * collide.c - "is this volume safe?": the volume iterator asked for blocking states only, so
 * branches holding neither occupied nor (policy) unknown voxels are never opened.
 */
#include "map/query_internal.h"

static bool leaves_map(const occ_map_t *map, const occ_volume_t *vol)
{
    const float half = occ_map_node_size(map, map->cfg.depth_levels) * 0.5f;
    return vol->bmin.x < -half || vol->bmin.y < -half || vol->bmin.z < -half ||
           vol->bmax.x >= half || vol->bmax.y >= half || vol->bmax.z >= half;
}

occ_err_t occ_collide_volume(const occ_map_t *map, const occ_volume_t *vol,
                             occ_unknown_policy_t policy, occ_collision_t *out)
{
    if (map == NULL || vol == NULL || out == NULL ||
        (policy != OCC_UNKNOWN_UNSAFE && policy != OCC_UNKNOWN_SAFE)) {
        return OCC_ERR_ARG;
    }
    out->safe = true;
    out->outside = false;
    if (policy == OCC_UNKNOWN_UNSAFE && leaves_map(map, vol)) {
        out->safe = false;
        out->outside = true;
        return OCC_OK;
    }
    occ_pred_t pred;
    pred.states = (uint8_t)(OCC_PRED_OCCUPIED | (policy == OCC_UNKNOWN_UNSAFE ? OCC_PRED_UNKNOWN : 0u));
    pred.min_level = 0;
    pred.options = 0;
    occ_query_iter_t it;
    const occ_err_t e = occ_query_begin(&it, map, vol, pred);
    if (e != OCC_OK) {
        return e;
    }
    if (occ_query_next(&it, &out->node)) {
        out->safe = false;
    }
    return OCC_OK;
}

occ_err_t occ_collide_sphere(const occ_map_t *map, occ_vec3_t center, float radius_m,
                             occ_unknown_policy_t policy, occ_collision_t *out)
{
    occ_volume_t v;
    const occ_err_t e = occ_volume_sphere(&v, center, radius_m);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_collide_aabb(const occ_map_t *map, occ_vec3_t min, occ_vec3_t max,
                           occ_unknown_policy_t policy, occ_collision_t *out)
{
    occ_volume_t v;
    const occ_err_t e = occ_volume_aabb(&v, min, max);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_collide_obb(const occ_map_t *map, occ_vec3_t center, const float half_m[3],
                          const occ_vec3_t axes[3], occ_unknown_policy_t policy,
                          occ_collision_t *out)
{
    occ_volume_t v;
    const occ_err_t e = occ_volume_obb(&v, center, half_m, axes);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_collide_capsule(const occ_map_t *map, occ_vec3_t a, occ_vec3_t b, float radius_m,
                              occ_unknown_policy_t policy, occ_collision_t *out)
{
    occ_volume_t v;
    const occ_err_t e = occ_volume_capsule(&v, a, b, radius_m);
    return e != OCC_OK ? e : occ_collide_volume(map, &v, policy, out);
}

occ_err_t occ_distance_to_obstacle(const occ_map_t *map, occ_vec3_t p, float max_dist_m,
                                   occ_unknown_policy_t policy, occ_nearest_entry_t *buf,
                                   size_t cap, float *dist_m, bool *found)
{
    if (dist_m == NULL || found == NULL ||
        (policy != OCC_UNKNOWN_UNSAFE && policy != OCC_UNKNOWN_SAFE)) {
        return OCC_ERR_ARG;
    }
    occ_pred_t pred;
    pred.states = (uint8_t)(OCC_PRED_OCCUPIED | (policy == OCC_UNKNOWN_UNSAFE ? OCC_PRED_UNKNOWN : 0u));
    pred.min_level = 0;
    pred.options = 0;
    occ_nearest_t it;
    occ_err_t e = occ_nearest_begin(&it, map, p, max_dist_m, pred, buf, cap);
    if (e != OCC_OK) {
        return e;
    }
    occ_query_node_t node;
    *found = false;
    e = occ_nearest_next(&it, &node, dist_m, found);
    return e;
}
