/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * shadow_grid.h - a dense reference model of an occmap map over a cubic volume of voxels, for
 * the randomized tree tests. It applies the same operations as the map with the arithmetic the
 * header documents (OctoMap's update rule on quantized values), derives every node's expected
 * max, state, indicators and answering level, the expected pool use and statistics, and the
 * blocks a write needs. Host test code: allocates with malloc.
 */
#ifndef OCC_SHADOW_GRID_H_INCLUDED
#define OCC_SHADOW_GRID_H_INCLUDED

#include "occmap/occmap.h"

typedef struct {
    occ_value_t max;    /* max of observed voxels (unobserved value if none) */
    occ_value_t first;  /* value of the first voxel (the uniform value when uniform) */
    uint8_t flags;      /* OCC_NODE_HAS_* of the region */
    bool observed;
    bool uniform;       /* every voxel below has the same raw value */
} shadow_node_t;

typedef struct {
    unsigned depth;        /* the map's depth_levels */
    unsigned vol_log2;     /* the volume's edge is 2^vol_log2 voxels, vol_log2 <= depth */
    uint32_t base[3];      /* first voxel key of the volume, aligned to its edge */
    uint32_t edge;
    occ_value_t *vox;      /* edge^3 values, x fastest */
    shadow_node_t *lvl[OCC_MAX_DEPTH + 1]; /* pyramid, levels 0..vol_log2 */
    bool dirty;
    /* Quantized model parameters (from the config through occ_value_from_logodds). */
    occ_value_t q_hit, q_miss, q_cmin, q_cmax, q_free_max, q_occ_min;
} shadow_grid_t;

/* Model of `map` (config only) over the volume at `base` (aligned) of edge 2^vol_log2. */
bool shadow_init(shadow_grid_t *s, const occ_map_t *map, unsigned vol_log2, const uint32_t base[3]);
void shadow_free(shadow_grid_t *s);
void shadow_clear(shadow_grid_t *s);
/* Copy the voxel values (same geometry). */
void shadow_copy(shadow_grid_t *dst, const shadow_grid_t *src);

/* The reference update rule on raw values (OctoMap's updateNode on quantized numbers). */
/* A delta in value steps: wider than an 8-bit value (OCC_VALUE_BITS 8 takes int16 deltas). */
#if OCC_VALUE_FLOAT
typedef float shadow_delta_t;
#else
typedef int32_t shadow_delta_t;
#endif
occ_value_t shadow_apply_delta(const shadow_grid_t *s, occ_value_t v, shadow_delta_t d);
occ_state_t shadow_state(const shadow_grid_t *s, occ_value_t v);

/* Operations; keys are absolute voxel keys inside the volume, levels <= vol_log2. Return true
 * when some voxel value changed. */
bool shadow_update(shadow_grid_t *s, occ_key_t key, shadow_delta_t q_delta);
bool shadow_set(shadow_grid_t *s, occ_key_t key, unsigned level, occ_value_t v);
bool shadow_forget(shadow_grid_t *s, occ_key_t key, unsigned level);
occ_value_t shadow_get(const shadow_grid_t *s, occ_key_t key);

/* Blocks the write needs from the pools (splits of uniform ancestors). */
void shadow_need_update(shadow_grid_t *s, occ_key_t key, occ_value_t q_delta, uint32_t *n_inner,
                        uint32_t *n_leaf);
void shadow_need_set(shadow_grid_t *s, occ_key_t key, unsigned level, occ_value_t v,
                     uint32_t *n_inner, uint32_t *n_leaf);

/* Expected read of the node at `level` containing `key` (any key of the map). */
void shadow_expect_read(shadow_grid_t *s, occ_key_t key, unsigned level, occ_node_info_t *out);

/* Expected statistics (pool use, leaf and voxel counts, nodes, bbox). */
typedef struct {
    uint32_t inner_used, leaf_used;
    uint64_t nodes, occupied_leaves, free_leaves, band_leaves, occupied_voxels, free_voxels;
    bool has_known;
    uint32_t kmin[3], kmax[3];
} shadow_stats_t;
void shadow_expect_stats(shadow_grid_t *s, shadow_stats_t *out);

/* Compare everything readable against the map: every node of every level inside the volume,
 * the chain above it, `n_outside` random keys outside (uses rand()), and the stats. Returns the
 * number of mismatches (each printed to stderr with `what`, at most 20 lines). */
unsigned shadow_compare(shadow_grid_t *s, const occ_map_t *map, unsigned n_outside,
                        const char *what);

/* Pools able to supply n_inner + n_leaf blocks now (the byte model of the two-ended arena). */
bool shadow_pool_fits(const occ_map_t *map, uint32_t n_inner, uint32_t n_leaf);

#endif
