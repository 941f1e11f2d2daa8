/* SPDX-License-Identifier: BSD-3-Clause */
/* map.c - configuration, init/clear, and the public coordinate <-> key calls (geom_internal.h). */
#include "shared_internal.h"
#include "tree_internal.h"

occ_map_config_t occ_map_config_default(void)
{
    occ_map_config_t c;
    c.resolution_m = 0.1f;
    c.depth_levels = 16u;
    /* What octomap::OcTree 1.9.7 sets: logit(0.7), logit(0.4), logit(0.1192), logit(0.971). */
    c.hit = 0.8472979f;
    c.miss = -0.4054651f;
    c.clamp_min = -2.0000279f;
    c.clamp_max = 3.5110307f;
    c.free_max = 0.0f;
    c.occupied_min = 0.0f;
    return c;
}

/* Log-odds a fixed-point value can hold exactly enough (|x| < 31). */
static bool in_value_range(const float x)
{
    return occ_finite(x) && x > -31.0f && x < 31.0f;
}

bool occi_map_config_ok(const occ_map_config_t *const cfg)
{
    return occ_finite(cfg->resolution_m) && cfg->resolution_m > 0.0f && cfg->depth_levels >= 1u &&
           cfg->depth_levels <= OCC_MAX_DEPTH && in_value_range(cfg->hit) && cfg->hit > 0.0f &&
           in_value_range(cfg->miss) && cfg->miss < 0.0f && in_value_range(cfg->clamp_min) &&
           in_value_range(cfg->clamp_max) && cfg->clamp_min < cfg->clamp_max &&
           in_value_range(cfg->free_max) && in_value_range(cfg->occupied_min) &&
           !(cfg->free_max > cfg->occupied_min);
}

occ_err_t occ_map_init(occ_map_t *const map, const occ_map_config_t *const cfg, void *const arena,
                       const size_t arena_bytes)
{
    if (map == NULL || cfg == NULL || (arena == NULL && arena_bytes != 0u) ||
        !occi_map_config_ok(cfg)) {
        return OCC_ERR_ARG;
    }
    map->cfg = *cfg;
    map->priv.q_hit = occ_value_from_logodds(cfg->hit);
    map->priv.q_miss = occ_value_from_logodds(cfg->miss);
    map->priv.q_clamp_min = occ_value_from_logodds(cfg->clamp_min);
    map->priv.q_clamp_max = occ_value_from_logodds(cfg->clamp_max);
    map->priv.q_free_max = occ_value_from_logodds(cfg->free_max);
    map->priv.q_occ_min = occ_value_from_logodds(cfg->occupied_min);
    occi_geom_init(map);
    /* Align the start and the size to 8 so both block kinds stay aligned from either end. */
    uintptr_t start = (uintptr_t)arena;
    size_t bytes = arena_bytes;
    const uintptr_t misalign = start % OCC_ARENA_ALIGN;
    if (misalign != 0u) {
        const size_t adj = OCC_ARENA_ALIGN - (size_t)misalign;
        bytes = bytes > adj ? bytes - adj : 0u;
        start += adj;
    }
    map->priv.arena = (uint8_t *)start;
#if OCC_INNER_PACKED
    /* 24-bit indices cap the arena; the size stays unrounded: a 35-byte block from the end is
     * byte-aligned anyway, and OCC_ARENA_BYTES has only the start's slack. */
    map->arena_bytes = bytes < OCC_ARENA_CAP_BYTES ? bytes : OCC_ARENA_CAP_BYTES;
#else
    map->arena_bytes = bytes - bytes % OCC_ARENA_ALIGN;
#endif
    map->priv.block_budget = (uint32_t)(map->arena_bytes / OCC_LEAF_BLOCK_BYTES);
    map->write_gen = 0u; /* occ_map_clear() makes it 1 */
    map->priv.shared = NULL; /* a fresh map is not shared (occ_shared.h) */
    occ_map_clear(map);
    return OCC_OK;
}

void occ_map_clear(occ_map_t *const map)
{
    if (map == NULL) {
        return;
    }
    const occ_pool_t empty = {0u, 0u, 0u, 0u, {OCC_NONE}};
    map->inner = empty;
    map->leaf = empty;
    map->oom_count = 0u;
    occ_root_set_child(map, OCC_NONE);
    map->priv.root_value = OCC_VALUE_UNOBSERVED;
    occ_root_set_flags(map, (uint8_t)OCC_NODE_HAS_UNKNOWN);
    map->write_gen++; /* every handle on the old content is stale */
    occi_shared_written(map);
}

occ_err_t occ_map_key(const occ_map_t *const map, const occ_vec3_t p, occ_key_t *const key)
{
    if (map == NULL || key == NULL || !occ_finite3(p)) {
        return OCC_ERR_ARG;
    }
    occ_key_t k;
    if (!occ_coord_to_key(map, p.x, &k.k[0]) || !occ_coord_to_key(map, p.y, &k.k[1]) ||
        !occ_coord_to_key(map, p.z, &k.k[2])) {
        return OCC_ERR_RANGE;
    }
    *key = k;
    return OCC_OK;
}

occ_key_t occ_key_at_level(occ_key_t key, const unsigned level)
{
    const uint32_t mask = level >= 32u ? 0u : ~(((uint32_t)1 << level) - 1u);
    for (unsigned i = 0; i < 3u; i++) {
        key.k[i] &= mask;
    }
    return key;
}

/* Levels above the root saturate to the root's: no shift by a caller value reaches 32. */
static unsigned node_level(const occ_map_t *const map, const unsigned level)
{
    return level > map->cfg.depth_levels ? map->cfg.depth_levels : level;
}

float occ_map_node_size(const occ_map_t *const map, const unsigned level)
{
    if (map == NULL) {
        return 0.0f;
    }
    return map->cfg.resolution_m * (float)((uint32_t)1 << node_level(map, level));
}

occ_err_t occ_map_key_range(const occ_map_t *const map, const float lo_m, const float hi_m,
                            uint32_t *const lo, uint32_t *const hi)
{
    if (map == NULL || lo == NULL || hi == NULL || !occ_finite(lo_m) || !occ_finite(hi_m) ||
        lo_m > hi_m) {
        return OCC_ERR_ARG;
    }
    uint32_t l;
    uint32_t h;
    if (!occi_geom_key_range(map, lo_m, hi_m, (occ_real_t)0, &l, &h)) {
        return OCC_ERR_RANGE;
    }
    *lo = l;
    *hi = h;
    return OCC_OK;
}

occ_vec3_t occ_map_key_center(const occ_map_t *const map, const occ_key_t key, const unsigned level)
{
    /* Above depth_levels both the key mask and the level saturate: the root's centre. */
    const unsigned lv = node_level(map, level);
    const occ_key_t base = occ_key_at_level(key, lv);
    const uint32_t kmax = (uint32_t)1 << map->cfg.depth_levels;
    occ_vec3_t c;
    if (base.k[0] < kmax && base.k[1] < kmax && base.k[2] < kmax) {
        return occ_geom_center(map, base, lv);
    }
    /* A caller key off the map (up to 2^32 - 1) gets the centre it would have, outside the map,
     * in 64-bit key arithmetic so that nothing overflows. */
    const int64_t half = (int64_t)1 << (map->cfg.depth_levels - 1u);
    const float res = map->cfg.resolution_m;
    const float offset = 0.5f * occ_map_node_size(map, lv);
    c.x = (float)((int64_t)base.k[0] - half) * res + offset;
    c.y = (float)((int64_t)base.k[1] - half) * res + offset;
    c.z = (float)((int64_t)base.k[2] - half) * res + offset;
    return c;
}
