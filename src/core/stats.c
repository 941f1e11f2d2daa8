/* SPDX-License-Identifier: BSD-3-Clause */
/* stats.c - pool counters and content statistics. */
#include "tree_internal.h"

/* The resolution as a user writes it (0.1f -> 0.1), as octomap::OcTree(0.1) and a .bt header
 * hold it: volumes built on (double)0.1f would be 1.3e-7 relative too large. The float build
 * keeps no double copy in the map, so it is worked out here. */
static double volume_resolution(const occ_map_t *const map)
{
#if OCC_RAY_DOUBLE
    return map->priv.geo_res;
#else
    return occi_geom_decimal(map->cfg.resolution_m);
#endif
}

void occ_map_pool_stats(const occ_map_t *const map, occ_map_stats_t *const out)
{
    *out = (occ_map_stats_t){0};
    const size_t ib = sizeof(occ_inner_block_t), lb = sizeof(occ_leaf_block_t);
    out->inner_used = map->inner.used;
    out->inner_peak = map->inner.peak;
    out->leaf_used = map->leaf.used;
    out->leaf_peak = map->leaf.peak;
    const size_t taken_leaf = (size_t)map->leaf.hwm * lb;
    const size_t taken_inner = (size_t)map->inner.hwm * ib;
    out->inner_capacity = (uint32_t)((map->arena_bytes - taken_leaf) / ib);
    out->leaf_capacity = (uint32_t)((map->arena_bytes - taken_inner) / lb);
    out->oom_count = map->oom_count;
    out->bytes_used = (size_t)map->inner.used * ib + (size_t)map->leaf.used * lb;
    out->bytes_peak = (size_t)map->inner.peak * ib + (size_t)map->leaf.peak * lb;
    out->arena_bytes = map->arena_bytes;
}

void occ_map_stats(const occ_map_t *const map, occ_map_stats_t *const out)
{
    occ_map_pool_stats(map, out);
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, map);
    while (occ_walk_next(&w, &n)) {
        out->nodes++;
        if (n.has_children) {
            out->inner_nodes++;
            continue;
        }
        out->leaf_nodes++;
        const uint64_t voxels = (uint64_t)1 << (3u * n.level);
        switch (occ_value_state(map, n.value)) {
        case OCC_STATE_OCCUPIED:
            out->occupied_leaves++;
            out->occupied_voxels += voxels;
            break;
        case OCC_STATE_FREE:
            out->free_leaves++;
            out->free_voxels += voxels;
            break;
        case OCC_STATE_UNKNOWN:
        default:
            out->unknown_band_leaves++;
            break;
        }
        const occ_vec3_t c = occ_map_key_center(map, n.key, n.level);
        const float h = 0.5f * occ_map_node_size(map, n.level);
        const occ_vec3_t lo = {c.x - h, c.y - h, c.z - h}, hi = {c.x + h, c.y + h, c.z + h};
        if (!out->has_known) {
            out->bbox_min = lo;
            out->bbox_max = hi;
            out->has_known = true;
        } else {
            if (lo.x < out->bbox_min.x) out->bbox_min.x = lo.x;
            if (lo.y < out->bbox_min.y) out->bbox_min.y = lo.y;
            if (lo.z < out->bbox_min.z) out->bbox_min.z = lo.z;
            if (hi.x > out->bbox_max.x) out->bbox_max.x = hi.x;
            if (hi.y > out->bbox_max.y) out->bbox_max.y = hi.y;
            if (hi.z > out->bbox_max.z) out->bbox_max.z = hi.z;
        }
    }
    /* Counts are exact integers: one multiplication each, no float accumulation. */
    const double res = volume_resolution(map);
    const double voxel_m3 = res * res * res;
    out->occupied_volume_m3 = (double)out->occupied_voxels * voxel_m3;
    out->free_volume_m3 = (double)out->free_voxels * voxel_m3;
}
