/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_evict.h - bounded memory in flight: making room in a fixed arena by evicting map content
 * far from the vehicle. Part of the manual; include it directly (occmap.h does not).
 *
 * The arena is fixed at build time and a flight is longer than the arena. Eviction returns
 * blocks to the pools by collapsing detailed subtrees far from a centre (the vehicle):
 *
 *  - OCC_EVICT_ROBOT (robot-centric window, ROG-Map style): an evicted node becomes UNOBSERVED,
 *    so everything below it reads OCC_STATE_UNKNOWN.
 *  - OCC_EVICT_COARSEN (keep coarse knowledge outside the window): an evicted node at level L
 *    loses its children and keeps one value for its whole cube, chosen so no voxel reads FREE
 *    that was not FREE before and no OCCUPIED voxel reads anything but OCCUPIED (until the
 *    fallback below forgets it):
 *      * max of the voxels below is OCCUPIED           -> the cube reads OCCUPIED (conservative);
 *      * max is FREE and every voxel below was FREE    -> the cube reads FREE (value = the max,
 *                                                         the least certain free voxel);
 *      * max is FREE but some voxel below was UNKNOWN (unobserved, or observed in the band
 *        between free_max and occupied_min)            -> the cube becomes UNOBSERVED (unknown);
 *      * max is in the unknown band                    -> the cube reads UNKNOWN (value = max).
 *    Collapsing starts at level policy.coarse_min_level (cubes of res * 2^L) and, when that
 *    is not enough, goes one level coarser at a time up to coarse_max_level; beyond that the
 *    policy falls back to ROBOT (forgetting). Coarse nodes are ordinary uniform nodes: a later
 *    update inside one splits it (its value is the starting value of every voxel below).
 *
 * In both modes evicted space is never FREE unless all of it was FREE, and the protected
 * region around the centre (a ball of keep_radius_m, or a box of half extents keep_half_m) is
 * never touched: only nodes whose cube lies entirely outside it (by a margin of about
 * res/1000 plus float rounding of the centre's coordinates) are collapsed, so every voxel whose
 * cube meets the region keeps its value.
 *
 * Order: approximately farthest first. A sweep runs passes with a distance threshold T that
 * starts beyond the farthest detailed content and shrinks by 1/4 per pass down to 0; a pass
 * walks the tree in Morton order and collapses every node whose cube lies entirely beyond T
 * (distance measured from the protected region's surface: Euclidean for SPHERE, Chebyshev for
 * BOX). It stops as soon as the pools can supply the target. COARSEN runs one sweep per level
 * from coarse_min_level to coarse_max_level, then a ROBOT sweep. The COARSEN level is sticky:
 * it only grows during a flight (a fresh sweep starts at the level the last one reached, so
 * exhausted levels are not swept again on every call); occ_evict_out_init() resets it.
 *
 * Slices: a call visits at most policy.budget_blocks blocks (0 = no limit; plus at most one
 * block, the root's, per pass started), so eviction can run a slice per control cycle. The
 * sweep position is kept in the caller-owned occ_evict_out_t as a Morton code and a level (not
 * as block indices), so the map may be changed freely between calls; the next call continues
 * the sweep where the last one stopped when the budget ran out, and starts a new sweep (from
 * the far end, around the centre it is given) after one reached its target or ended. Without
 * a budget, a sweep that began in an earlier call is only believed "exhausted" after a second,
 * complete sweep in the same call. Every call leaves the map consistent (occ_map_check()
 * holds after every call).
 *
 * Memory and work: no heap, no recursion; the walk's stack (about 300 bytes) lives in
 * occ_evict_out_t. Work per call is O(budget_blocks + depth) block visits; without a budget it
 * is O(passes * blocks), passes <= about log(map size / resolution) / log(4/3) per sweep.
 */
#ifndef OCC_OCC_EVICT_H_INCLUDED
#define OCC_OCC_EVICT_H_INCLUDED

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    OCC_EVICT_ROBOT = 0,   /* forget far subtrees: they read UNKNOWN */
    OCC_EVICT_COARSEN = 1  /* collapse far subtrees to one conservative value, then forget */
} occ_evict_mode_t;

typedef enum {
    OCC_EVICT_SPHERE = 0,  /* protected ball of keep_radius_m around the centre */
    OCC_EVICT_BOX = 1      /* protected axis-aligned box centre +- keep_half_m */
} occ_evict_shape_t;

typedef struct occ_evict_policy {
    occ_evict_mode_t mode;
    occ_evict_shape_t shape;
    float keep_radius_m;      /* SPHERE: protected radius, metres, >= 0 and finite */
    occ_vec3_t keep_half_m;   /* BOX: protected half extents per axis, metres, >= 0, finite */
    uint32_t budget_blocks;   /* blocks visited per call at most; 0 = no limit */
    uint8_t coarse_min_level; /* COARSEN: finest collapse level, 1..depth_levels */
    uint8_t coarse_max_level; /* COARSEN: coarsest collapse level, >= min; clamped to depth */
} occ_evict_policy_t;

/* ROBOT, SPHERE, keep 3 m, box 3 m each axis, no budget, coarse levels 2..5. */
occ_evict_policy_t occ_evict_policy_default(void);

/* Where a sweep stands (internal: do not touch, layout may change; zero is "no sweep in
 * progress"). */
typedef struct {
    uint8_t phase;        /* 0 idle, 1 running, 2 a sweep to continue */
    uint8_t coarse_level; /* current collapse level (COARSEN), depth+1 = forgetting */
    uint8_t depth;        /* map depth the sweep was started for */
    uint8_t resume_level; /* level of the next node to visit */
    occ_code_t resume_code;
    float threshold_m;    /* current pass threshold T */
    float farthest_m;     /* bound on the distance of detailed content left, this pass */
    /* The walk stack: frame i is the node at level depth - i. */
    uint8_t sp;
    uint8_t next[OCC_MAX_DEPTH + 1];
    uint8_t dirty[OCC_MAX_DEPTH + 1];
    uint32_t block[OCC_MAX_DEPTH + 1];
    occ_code_t base[OCC_MAX_DEPTH + 1];
} occ_evict_cursor_t;

/* Caller-owned eviction state and statistics. Zero it (or call occ_evict_out_init) once and
 * pass the same struct to every call for one map; the totals accumulate. */
typedef struct occ_evict_out {
    /* totals since init */
    uint64_t calls;
    uint64_t evictions;       /* nodes collapsed (forgotten or coarsened) */
    uint64_t blocks_freed;    /* inner + leaf blocks returned to the pools */
    uint64_t bytes_freed;
    uint64_t sweeps;          /* sweeps started */
    /* the last call */
    uint32_t last_evictions;
    uint32_t last_blocks_freed;
    uint32_t last_visited;    /* blocks visited (<= budget_blocks when a budget is set) */
    bool target_reached;      /* the pools can supply the target now */
    bool exhausted;           /* nothing outside the protected region is left to evict */
    bool resumable;           /* stopped by the budget (target not reached yet) */
    bool sweep_active;        /* a sweep is in progress: the next call continues it */
    /* the map's pools after the last call */
    size_t bytes_used;
    size_t bytes_peak;        /* the pools' peak since the map's init/clear */
    occ_evict_cursor_t priv;  /* internal: the sweep's cursor; do not touch, layout may change */
} occ_evict_out_t;

void occ_evict_out_init(occ_evict_out_t *out);

/* Evict (see above) until the pools could hand out `target_free_blocks` inner blocks AND
 * `target_free_blocks` leaf blocks at once (occi_pool_can_supply), or the budget is spent, or
 * nothing evictable is left. `center` is the vehicle position (map frame, metres).
 * Returns OCC_OK (see out->target_reached / exhausted / resumable for which happened),
 * OCC_ERR_ARG (NULL, non-finite centre, negative or non-finite radius/half extents, bad mode,
 * shape or coarse levels). Never allocates; only frees blocks. occ_map_check() holds after. */
occ_err_t occ_map_evict(occ_map_t *map, const occ_vec3_t *center,
                        const occ_evict_policy_t *policy, uint32_t target_free_blocks,
                        occ_evict_out_t *out);

/* The automatic mode of an integrator: evict, ignoring policy->budget_blocks, until the pools
 * can supply `n_inner` inner and `n_leaf` leaf blocks at once. OCC_OK when they can (also when
 * nothing had to be evicted), OCC_ERR_NOMEM when everything evictable outside the protected
 * region was evicted and they still cannot (oom_count is not bumped: the failing write does
 * that), OCC_ERR_ARG as occ_map_evict. */
occ_err_t occ_map_evict_for(occ_map_t *map, const occ_vec3_t *center,
                            const occ_evict_policy_t *policy, uint32_t n_inner, uint32_t n_leaf,
                            occ_evict_out_t *out);

/* occ_map_observe_need() (occmap.h) tells an integrator how much to ask for. */

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_map_evict: stack <= 768 / 768 B; work: <= budget_blocks + depth block visits per call (no
 *       budget: a whole sweep)
 *   occ_map_evict_for: stack <= 768 / 768 B; work: a whole sweep if needed (ignores budget_blocks)
 *   occ_evict_out_init, occ_evict_policy_default: stack <= 64 / 64 B; work: O(1)
 */

#ifdef __cplusplus
}
#endif
#endif
