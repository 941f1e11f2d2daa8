/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_core.h - the map (chapter 1 of occmap.h): a pool-backed tri-state occupancy octree. This header is the manual.
 *
 * Model (UFOMap / OctoMap):
 *  - The world is cut into cubic voxels of edge `resolution_m` metres. A voxel's occupancy is a
 *    log-odds value (natural log of p/(1-p)), clamped to [clamp_min, clamp_max].
 *  - A voxel that was never observed is UNOBSERVED and reads OCC_STATE_UNKNOWN. An observed voxel
 *    is OCCUPIED when logodds >= occupied_min, FREE when logodds < free_max, and UNKNOWN in the
 *    band between (empty with the defaults, which equal OctoMap's single 0.5 threshold).
 *  - The octree has `depth_levels` levels above the voxels. Levels are counted from the voxels up:
 *    level 0 is a voxel, level 1 a node of 2x2x2 voxels, ..., level depth_levels the root.
 *    An inner node's value is the max of its observed children (as OctoMap's inner nodes).
 *  - Indicators per node: contains-free, contains-unknown; "all children equal" is a node that
 *    has no child block (pruned or never split). Eight equal children are always pruned.
 *
 * Frames and units: the map frame is right-handed, metres, z up (OctoMap's data is ENU).
 * Log-odds are natural-log odds. Keys follow OctoMap: key = floor(x * (1 / res)) + 2^(depth_levels-1)
 * where res is the shortest decimal that rounds to cfg.resolution_m (0.1f means 0.1, 0.08f 0.08),
 * so a voxel here is the same voxel in the octomap::OcTree(res) a user writes (OcTree(0.1) for
 * 0.1f) or reads from a file whose header says that resolution, at depth 16. Every call (keys,
 * reads, lookups, integration, rays, volumes, collision, nearest, sectors, eviction, readers)
 * uses this one conversion. Float-only builds (OCC_RAY_DOUBLE=0) use the same formulas in float.
 *
 * Memory: no heap. occ_map_init() carves a caller arena into two pools that grow towards each
 * other: leaf blocks (8 voxel values, 16 bytes) from the bottom, inner blocks (8 nodes with
 * child index, value and indicator bits, 56 bytes) from the top; each has an intrusive free list.
 * Every allocation and free is O(1). Running out of blocks is normal: the call returns
 * OCC_ERR_NOMEM, bumps oom_count, and the map is exactly as before the call.
 *
 * Threads: a map is not thread-safe unless shared (occ_shared.h: one writer, many wait-free
 * readers on views); otherwise serialize access per map. Distinct maps are independent.
 * Recursion: none; every walk uses a fixed stack of at most OCC_MAX_DEPTH entries.
 */
#ifndef OCC_OCC_CORE_H_INCLUDED
#define OCC_OCC_CORE_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

#ifdef OCC_CONFIG_HEADER
#include OCC_CONFIG_HEADER
#endif

/* ---- Compile-time knobs (one block; each documented). ---------------------------------------
 * OCC_VALUE_FLOAT   0: node values are 16-bit fixed-point log-odds, step 1/OCC_FIXED_ONE
 *                      (1/1024 = 0.000977); rounding error per update <= 0.00049, so after k
 *                      unclamped updates a value differs from float by <= k * 0.00049.
 *                      Range +-31.99 log-odds. Leaf block 16 B, inner block 56 B.
 *                   1: float values (leaf block 32 B, inner block 72 B). Changes block sizes,
 *                      not the public structs' field names.
 * OCC_VALUE_BITS   16: (with OCC_VALUE_FLOAT 0) the fixed-point width above (default).
 *                   8: compact int8 log-odds, step 1/OCC_FIXED_ONE = 1/36 (0.0278). Leaf block
 *                      8 B, inner block 35 B (24-bit child indices: a pool holds at most
 *                      OCC_POOL_MAX_BLOCKS = 2^24 - 1 blocks, the map uses at most 128 MiB of
 *                      arena). Raw range [-127, +127] = [-3.53, +3.53] log-odds,
 *                      -128 is reserved for "unobserved". OctoMap's defaults land exactly or
 *                      nearly on the grid: clamp_min -2.0 -> -72 (exact), clamp_max 3.511 ->
 *                      126 (3.500, -0.011), occupancy threshold 0 -> 0 (exact, so the occupied /
 *                      free split of any value is the float build's), hit 0.847 -> 31 (0.861,
 *                      +0.014 per hit), miss -0.405 -> -15 (-0.417, -0.011 per miss). After k
 *                      unclamped updates a value differs from float by <= k * 0.014; updates
 *                      saturate at the clamps (deltas are added in int32, never wrap); a
 *                      config whose values fall outside +-3.53 is saturated to it. A .occ file
 *                      records its value kind; the 8-bit build refuses 16-bit / float
 *                      snapshots (and they refuse its) with OCC_ERR_UNSUPPORTED; .bt/.ot load
 *                      converts float log-odds with rounding and saturation.
 *                   Any other value is rejected with #error.
 * OCC_RAY_DOUBLE    1: key and ray arithmetic in double, bit-for-bit the arithmetic OctoMap
 *                      uses (host default). 0: float only (firmware default, no soft-double);
 *                      keys can then differ from OctoMap's for points within ~1e-7 relative
 *                      of a voxel border.
 * OCC_USE_BMI2      1: Morton interleave with the x86 BMI2 pdep/pext instructions.
 * OCC_ASSERT(x)     internal-invariant check (memory-guarding invariants: an allocation result, a
 *                   block index below its pool's high-water mark before every dereference, level
 *                   and slot ranges, walk stack depths). Never for caller mistakes: those are
 *                   error codes. Default: nothing (x is not evaluated, only type-checked by
 *                   sizeof, so release and firmware code is unchanged and variables that only
 *                   an assert reads do not warn). x has no side effects.
 *                   Tests (the ASan build, OCC_TESTING) define it in the OCC_CONFIG_HEADER
 *                   tests/support/occ_test_config.h as CMocka's mock_assert(), so a broken
 *                   invariant fails the test and expect_assert_failure() can prove one fires.
 *                   A firmware build maps it in its own OCC_CONFIG_HEADER, e.g. to a trap that
 *                   stops the vehicle's map task at the fault (the debugger or the HardFault
 *                   handler then has the PC of the failed check):
 *                     #define OCC_ASSERT(x) ((x) ? (void)0 : __builtin_trap())
 *                   or to the RTOS's own assert hook. The map is then no longer trusted:
 *                   occ_map_check() tells whether it can be kept.
 */
#ifndef OCC_VALUE_FLOAT
#define OCC_VALUE_FLOAT 0
#endif
#ifndef OCC_VALUE_BITS
#define OCC_VALUE_BITS 16
#endif
#if OCC_VALUE_BITS != 16 && OCC_VALUE_BITS != 8
#error "OCC_VALUE_BITS must be 16 or 8"
#endif
#if OCC_VALUE_FLOAT && OCC_VALUE_BITS != 16
#error "OCC_VALUE_BITS 8 needs OCC_VALUE_FLOAT 0"
#endif
#ifndef OCC_RAY_DOUBLE
#if defined(__arm__) || defined(__thumb__)
#define OCC_RAY_DOUBLE 0
#else
#define OCC_RAY_DOUBLE 1
#endif
#endif
#ifndef OCC_USE_BMI2
#define OCC_USE_BMI2 0
#endif
#ifndef OCC_ASSERT
#define OCC_ASSERT(x) ((void)sizeof((x) ? 1 : 0))
#endif

#define OCC_MAX_DEPTH 21u         /* 3 x 21 bits of key fit a 63-bit Morton code. */
#if OCC_VALUE_BITS == 8
#define OCC_FIXED_ONE 36          /* fixed-point log-odds: value = round(logodds * 36). */
#else
#define OCC_FIXED_ONE 1024        /* fixed-point log-odds: value = round(logodds * 1024). */
#endif

#if OCC_VALUE_FLOAT
typedef float occ_value_t;
#elif OCC_VALUE_BITS == 8
typedef int8_t occ_value_t;
#else
typedef int16_t occ_value_t;
#endif

/* ---- Errors --------------------------------------------------------------------------------- */
typedef enum {
    OCC_OK = 0,
    OCC_ERR_ARG = -1,         /* NULL pointer, NaN/Inf, bad size or config */
    OCC_ERR_RANGE = -2,       /* coordinate or key outside the map volume */
    OCC_ERR_NOMEM = -3,       /* a pool (or a caller buffer other than an integrator's
                                 scratch) too small; nothing was changed */
    OCC_ERR_FORMAT = -4,      /* corrupt or malformed input bytes */
    OCC_ERR_IO = -5,          /* a caller stream or OS call failed (port layer) */
    OCC_ERR_STATE = -6,       /* call not valid in the object's current state */
    OCC_ERR_UNSUPPORTED = -7, /* valid input this build does not handle */
    OCC_ERR_CORRUPT = -8,     /* occ_map_check() found broken invariants */
    OCC_ERR_SCRATCH = -9,     /* the caller's scratch is too small for this call (oom_count is
                                 not bumped: it counts the pools); nothing was changed */
    OCC_ERR_TIME = -10        /* no pose for that time (pose history: empty, too old, too new,
                                 a gap) or a sample out of time order; nothing was changed */
} occ_err_t;

/* Short constant English text for an error code (never NULL). */
const char *occ_err_str(occ_err_t err);

typedef enum {
    OCC_STATE_UNKNOWN = 0,
    OCC_STATE_FREE = 1,
    OCC_STATE_OCCUPIED = 2
} occ_state_t;

/* ---- Geometry, keys and Morton codes ---------------------------------------------------------- */
typedef struct { float x, y, z; } occ_vec3_t;        /* metres, map frame */
typedef struct { uint32_t k[3]; } occ_key_t;         /* voxel key per axis, < 2^depth_levels */
typedef uint64_t occ_code_t;                          /* Morton code of a voxel key, 63 bits */

/* Interleave key bits: bit 3i of the code is x bit i, 3i+1 is y bit i, 3i+2 is z bit i, so
 * bits [3L, 3L+2] of a voxel's code are its child index inside its level-(L+1) ancestor, in
 * OctoMap's child order (bit 0 = x, bit 1 = y, bit 2 = z). Keys must be < 2^21. O(1). */
occ_code_t occ_morton_encode(occ_key_t key);
occ_key_t occ_morton_decode(occ_code_t code);

/* ---- Configuration ---------------------------------------------------------------------------- */
typedef struct {
    float resolution_m;    /* voxel edge, metres, > 0 and finite */
    uint8_t depth_levels;  /* levels above the voxels, 1..21 (OctoMap: 16) */
    float hit;             /* log-odds added on a hit, > 0 (OctoMap: logit(0.7) = 0.847) */
    float miss;            /* log-odds added on a miss, < 0 (OctoMap: logit(0.4) = -0.405) */
    float clamp_min;       /* log-odds clamp, < clamp_max (OctoMap: logit(0.1192) = -2.0) */
    float clamp_max;       /* (OctoMap: logit(0.971) = 3.511) */
    float free_max;        /* observed and < free_max: FREE (default 0, OctoMap) */
    float occupied_min;    /* observed and >= occupied_min: OCCUPIED (default 0); needs
                            * free_max <= occupied_min; values between read UNKNOWN */
} occ_map_config_t;

/* octomap::OcTree's defaults: res 0.1 m, depth 16, hit logit(0.7) = 0.847, miss logit(0.4) =
 * -0.405, clamp logit(0.1192) = -2.0 / logit(0.971) = 3.511, occupancy threshold 0.5 (0). */
occ_map_config_t occ_map_config_default(void);

/* ---- Pools and the map ------------------------------------------------------------------------ */
#define OCC_LEAF_BLOCK_BYTES ((size_t)(8u * sizeof(occ_value_t)))
#if OCC_VALUE_BITS == 8
/* 8 x (3-byte child index + value) + 3 bytes of indicator bits (3 per entry). */
#define OCC_INNER_BLOCK_BYTES ((size_t)35u)
/* Blocks one pool can hold: the 24-bit indices keep 0xFFFFFF for "no child". occ_map_init()
 * uses at most OCC_POOL_MAX_BLOCKS * OCC_LEAF_BLOCK_BYTES (128 MiB) of a larger arena. */
#define OCC_POOL_MAX_BLOCKS 0xFFFFFFu
#else
#define OCC_INNER_BLOCK_BYTES ((size_t)(8u * (4u + sizeof(occ_value_t) + 1u)))
/* Blocks one pool can hold (an index is a uint32_t, OCC_NONE is "no child"). */
#define OCC_POOL_MAX_BLOCKS 0xFFFFFFFEu
#endif
#define OCC_ARENA_ALIGN 8u
/* Bytes of arena that hold at least n_inner inner blocks and n_leaf leaf blocks at once
 * (plus alignment slack, so any pointer the caller passes works). */
#define OCC_ARENA_BYTES(n_inner, n_leaf) \
    ((size_t)(n_inner) * OCC_INNER_BLOCK_BYTES + (size_t)(n_leaf) * OCC_LEAF_BLOCK_BYTES + \
     OCC_ARENA_ALIGN)

/* How many leaf blocks fit in `arena_bytes` next to `n_inner` inner blocks (0 if none). */
uint32_t occ_arena_blocks_for_bytes(size_t arena_bytes, uint32_t n_inner);

/* One pool's counters. A caller may read used, peak, hwm and free_count (never write them). */
typedef struct {
    uint32_t used;       /* blocks handed out now */
    uint32_t peak;       /* max of used since init/clear */
    uint32_t hwm;        /* blocks ever carved from the arena (free list + used) */
    uint32_t free_count; /* blocks on the free list */
    struct {             /* internal: do not touch, layout may change */
        uint32_t free_head; /* first block of the intrusive free list, OCC_NONE if empty */
    } priv;
} occ_pool_t;

#define OCC_NONE UINT32_MAX

/* A map: caller-allocated (static is fine: its size is fixed at compile time), set up by
 * occ_map_init() and changed only through the API. A caller may read the fields above `priv`
 * (never write them); `priv` is the map's own state: do not touch, its layout may change. */
typedef struct {
    occ_map_config_t cfg;     /* the configuration occ_map_init() accepted */
    size_t arena_bytes;       /* usable bytes of the arena (after alignment) */
    occ_pool_t inner, leaf;   /* inner blocks grow down from the top, leaves up from the bottom */
    uint32_t oom_count;       /* operations refused with OCC_ERR_NOMEM since init/clear */
    /* Write generation: +1 (mod 2^32) on every call that may change the tree (update, observe,
     * insert and integrate, set, forget, evict, clear, read into the map). Handles that keep
     * block indices between calls (occ_lookup_t, occ_query_iter_t, occ_nearest_t, occ_walk_t,
     * occ_node_t) record it when made and answer OCC_ERR_STATE once it moved. occ_map_init()
     * (and occ_io_load(), which initializes) restarts it: handles taken before a re-init of the
     * same struct are not detected, so drop them with the old map. */
    uint32_t write_gen;
    struct {
        /* Quantized copies of the config. */
        occ_value_t q_hit, q_miss, q_clamp_min, q_clamp_max, q_free_max, q_occ_min;
        uint8_t *arena;           /* aligned start of the arena */
        uint32_t block_budget;    /* arena_bytes / OCC_LEAF_BLOCK_BYTES: leaf-sized units */
        /* Voxel geometry, set once by occ_map_init(): the resolution as the shortest decimal
         * that rounds to cfg.resolution_m (0.1f -> 0.1, what OcTree(0.1) holds) and its
         * inverse, in double when OCC_RAY_DOUBLE (0 in the float build), and as floats. */
        double geo_res, geo_inv;
        float geo_res_f, geo_inv_f;
        /* The root node (level depth_levels) lives here, not in a block. */
#if OCC_VALUE_BITS == 8
        /* Packed as in an inner block: a 24-bit index, the indicator bits one per byte. */
        uint8_t root_child[3];
        occ_value_t root_value;
        uint8_t root_flags[3];
#else
        uint32_t root_child;
        occ_value_t root_value;
        uint8_t root_flags;
#endif
        void *shared;             /* occ_shared.h state once occ_map_share() ran, else NULL */
    } priv;                   /* internal: do not touch, layout may change */
} occ_map_t;

/* Initialize `map` on the caller's arena (any alignment; the map uses the aligned part).
 * The arena is owned by the map until the caller stops using `map`; no deinit is needed.
 * Returns OCC_ERR_ARG for NULL, non-finite or inconsistent config (resolution <= 0,
 * depth 0 or > 21, hit <= 0, miss >= 0, clamp_min >= clamp_max, free_max > occupied_min,
 * a value outside the fixed-point range). Any arena size is accepted, even 0 (then NULL is
 * allowed): a map whose arena holds no block can only hold a uniform root, and every write that
 * needs a block returns OCC_ERR_NOMEM. O(1). On error `map` is not usable. */
occ_err_t occ_map_init(occ_map_t *map, const occ_map_config_t *cfg, void *arena,
                       size_t arena_bytes);

/* Forget all content: every voxel is unobserved again, pools empty, peaks and oom_count reset.
 * Bumps write_gen (handles on the old content answer OCC_ERR_STATE). O(1). */
void occ_map_clear(occ_map_t *map);

/* ---- Coordinates and keys --------------------------------------------------------------------- */
/* Voxel key of a point, per axis OctoMap's coordToKeyChecked: floor(p * (1 / res)) + 2^(D-1),
 * res the decimal resolution (see the top of this header), in double when OCC_RAY_DOUBLE
 * (bit-for-bit OcTree(res).coordToKey), else in float (a point within ~1e-7 relative of a voxel
 * border may then get the neighbour's key, the same in every call of this build).
 * OCC_ERR_ARG for NULL or NaN/Inf, OCC_ERR_RANGE outside the map volume [-2^(D-1) res,
 * 2^(D-1) res) per axis. O(1), no writes. */
occ_err_t occ_map_key(const occ_map_t *map, occ_vec3_t p, occ_key_t *key);
/* Keys [*lo, *hi] on one axis (all axes are alike) of the voxels that hold a coordinate of the
 * closed interval [lo_m, hi_m], clamped to the map: the keys occ_map_key gives lo_m and hi_m
 * when they are inside it. OCC_ERR_ARG for NULL, NaN or lo_m > hi_m, OCC_ERR_RANGE when the
 * interval misses the map (outputs then unchanged). O(1). */
occ_err_t occ_map_key_range(const occ_map_t *map, float lo_m, float hi_m, uint32_t *lo,
                            uint32_t *hi);
/* Centre (metres) of the node at `level` that contains voxel `key`: per axis OctoMap's
 * keyToCoord, ((first key - 2^(D-1)) + 2^level / 2) * res in double when OCC_RAY_DOUBLE, rounded
 * to float. A level above depth_levels saturates to depth_levels: the root's centre, the map
 * origin (0, 0, 0). A key >= 2^depth_levels (no voxel of the map) gets the centre it would
 * have, outside the map volume. */
occ_vec3_t occ_map_key_center(const occ_map_t *map, occ_key_t key, unsigned level);
/* Edge length (metres) of a node at `level`: resolution * 2^level. A level above depth_levels
 * saturates to depth_levels (the root's edge, the whole map); NULL map: 0. */
float occ_map_node_size(const occ_map_t *map, unsigned level);
/* The key with its lowest `level` bits cleared: the first voxel of the level-`level` node.
 * Any level is valid: 32 and above clear every bit (key 0, 0, 0). */
occ_key_t occ_key_at_level(occ_key_t key, unsigned level);

/* ---- Reading ----------------------------------------------------------------------------------- */
#define OCC_NODE_HAS_FREE 0x01u     /* some voxel below is FREE */
#define OCC_NODE_HAS_UNKNOWN 0x02u  /* some voxel below is UNKNOWN (incl. unobserved) */
#define OCC_NODE_HAS_OCCUPIED 0x04u /* some voxel below is OCCUPIED (max >= occupied_min) */
#define OCC_NODE_UNIFORM 0x08u      /* no children: every voxel below has this node's value */

typedef struct {
    float logodds;     /* max of observed voxels below (0 when nothing below is observed) */
    bool observed;     /* false: no voxel below was ever observed (logodds then 0) */
    occ_state_t state; /* state of the node's value (max): OCCUPIED if any voxel below is */
    uint8_t flags;     /* OCC_NODE_* */
    uint8_t level;     /* level of the node that answered: >= the level asked for when the
                        * region is uniform above it (pruned), so the answer holds for all of it */
} occ_node_info_t;

/* Read the node at `level` (0 = voxel) containing voxel `key`. A coarse read returns the max of
 * the voxels below it (OctoMap's inner value) and indicator flags. O(depth), no writes. On any
 * error `out` (when non-NULL) reads an unobserved UNKNOWN node (fail closed), OCC_ERR_ARG for
 * NULL or level > depth_levels, OCC_ERR_RANGE for a key outside the map. */
occ_err_t occ_map_read_key(const occ_map_t *map, occ_key_t key, unsigned level,
                           occ_node_info_t *out);
/* Same for a point in metres. OCC_ERR_ARG / OCC_ERR_RANGE as occ_map_key(). */
occ_err_t occ_map_read(const occ_map_t *map, occ_vec3_t p, unsigned level, occ_node_info_t *out);
/* State of the voxel at `p`; UNKNOWN for invalid or out-of-map points (never FREE by error).
 * For many points in one call: occ_map_states_at() (occ_query.h). */
occ_state_t occ_map_state_at(const occ_map_t *map, occ_vec3_t p);
/* State of a log-odds value under this map's thresholds (observed values only). */
occ_state_t occ_map_state_of(const occ_map_t *map, float logodds);

/* ---- Writing (all-or-nothing: on any error the map is unchanged) ------------------------------- */
/* Add `delta_logodds` to voxel `key` (an unobserved voxel starts at 0), clamp to
 * [clamp_min, clamp_max], keep inner maxima and indicators, prune equal siblings. As OctoMap's
 * updateNode: a voxel already at a clamp bound is left as is when the delta pushes outward.
 * Needs at most depth_levels-1 inner blocks and 1 leaf block. O(depth).
 * OCC_ERR_ARG (NaN delta), OCC_ERR_RANGE (key >= 2^D), OCC_ERR_NOMEM. */
occ_err_t occ_map_update_key(occ_map_t *map, occ_key_t key, float delta_logodds);
/* Same for a point (metres). */
occ_err_t occ_map_update(occ_map_t *map, occ_vec3_t p, float delta_logodds);
/* Integrate an observation of voxel `key`: adds cfg.hit if `occupied`, else cfg.miss. */
occ_err_t occ_map_observe_key(occ_map_t *map, occ_key_t key, bool occupied);

/* Set the whole node at `level` containing `key` to `logodds` (clamped to the fixed-point range,
 * not to [clamp_min, clamp_max]); its subtree is released. Used by readers of pruned files.
 * O(depth). Errors as occ_map_update_key. */
occ_err_t occ_map_set_key(occ_map_t *map, occ_key_t key, unsigned level, float logodds);
/* Make the node at `level` containing `key` unobserved (releases its subtree). Never fails for
 * lack of memory... except when it must split a uniform observed parent: OCC_ERR_NOMEM then. */
occ_err_t occ_map_forget_key(occ_map_t *map, occ_key_t key, unsigned level);

/* Batch update: codes[i] are voxel Morton codes, strictly ascending, each at most once; bit 63 of
 * an entry set means hit (cfg.hit), clear means miss (cfg.miss). Either all are applied or, if
 * the pools cannot hold the result, none (OCC_ERR_NOMEM). Walks the tree once in Morton order,
 * so memory is touched coherently. Result equals applying occ_map_observe_key() per entry in
 * any order. O(n * depth) worst case, O(n) for clustered codes. `n_changed` (may be NULL) gets
 * the number of voxels whose value changed. */
#define OCC_CODE_HIT_BIT ((occ_code_t)1 << 63)
occ_err_t occ_map_observe_codes(occ_map_t *map, const occ_code_t *codes, size_t n,
                                size_t *n_changed);

/* Blocks occ_map_observe_codes(map, codes, n) would allocate now (an upper bound: pruning on
 * the way only frees), so an integrator can ask occ_map_evict_for() for exactly that. Codes as
 * for occ_map_observe_codes (ascending, hit bit 63); OCC_ERR_ARG for NULL or unsorted codes.
 * O(n * depth), read only. */
occ_err_t occ_map_observe_need(const occ_map_t *map, const occ_code_t *codes, size_t n,
                               uint32_t *n_inner, uint32_t *n_leaf);

/* ---- Diagnostics -------------------------------------------------------------------------------- */
typedef struct {
    uint32_t inner_used, inner_peak, leaf_used, leaf_peak;
    uint32_t inner_capacity;  /* inner blocks that fit if no more leaf blocks are taken */
    uint32_t leaf_capacity;   /* leaf blocks that fit if no more inner blocks are taken */
    uint32_t oom_count;
    size_t bytes_used;        /* (inner_used * inner block + leaf_used * leaf block) bytes */
    size_t bytes_peak;        /* max bytes_used since init/clear */
    size_t arena_bytes;
    /* Leaves after pruning, as OctoMap's leaf iterator counts them (a pruned node is one leaf). */
    uint64_t occupied_leaves, free_leaves, unknown_band_leaves;
    uint64_t occupied_voxels, free_voxels; /* voxels at level 0 (pruned nodes expanded) */
    uint64_t nodes;           /* observed nodes, root included: OctoMap's size() */
    uint64_t inner_nodes;     /* observed nodes with children */
    uint64_t leaf_nodes;      /* observed nodes without children (OctoMap's leaves) */
    /* Voxels x resolution^3 in double, with the resolution a user writes (the shortest decimal
     * that round-trips resolution_m: 0.1f -> 0.1), so they equal octomap::OcTree(0.1)'s sums of
     * its leaves' volumes to ~1e-15 relative (a float sum was off in the 7th digit). */
    double occupied_volume_m3, free_volume_m3;
    bool has_known;           /* false: nothing observed, the bbox is empty */
    occ_vec3_t bbox_min, bbox_max; /* metres, of the observed space */
} occ_map_stats_t;

/* Pool counters only: O(1). */
void occ_map_pool_stats(const occ_map_t *map, occ_map_stats_t *out);
/* Everything, with a walk over the tree: O(nodes). */
void occ_map_stats(const occ_map_t *map, occ_map_stats_t *out);

/* Self-check (O(nodes + free blocks)): pool accounting (used + free == carved), free lists
 * without cycles or foreign indices, every block reachable exactly once (no leak, no sharing),
 * every inner value the max of its children, indicators equal to the children's, no prunable
 * block left. OCC_OK or OCC_ERR_CORRUPT. Never writes. */
occ_err_t occ_map_check(const occ_map_t *map);

/* ---- Depth-first walk (Morton preorder: a node, then its children 0..7) ------------------------ */
typedef struct {
    occ_key_t key;      /* first voxel of the node (lowest `level` bits clear) */
    uint8_t level;      /* 0 = voxel */
    bool has_children;
    occ_value_t value;  /* raw value (max of children for inner nodes) */
    bool observed;
    uint8_t flags;      /* OCC_NODE_* */
} occ_walk_node_t;

typedef struct {
    const occ_map_t *map;
    uint8_t sp;
    occ_code_t code;  /* Morton code of the node last returned (internal) */
    struct { uint32_t block; uint8_t level; uint8_t next; } stack[OCC_MAX_DEPTH + 1];
    bool started;
    bool pushed;  /* the node last returned pushed its children's frame */
    uint32_t gen; /* map->write_gen at occ_walk_begin() */
} occ_walk_t;

/* Start a walk over the observed nodes (unobserved subtrees are never reported). The walk is
 * valid until the next write to the map (see occ_map_t.write_gen). */
void occ_walk_begin(occ_walk_t *w, const occ_map_t *map);
/* Next node, true while there is one. Complexity O(1) amortized per node. False without
 * reading the tree when the map was written (or cleared) since occ_walk_begin():
 * occ_walk_status() then says OCC_ERR_STATE. */
bool occ_walk_next(occ_walk_t *w, occ_walk_node_t *node);
/* OCC_OK while the walk is valid, OCC_ERR_STATE once the map was written since
 * occ_walk_begin() (a walk that ended early for that reason did not visit every node),
 * OCC_ERR_ARG for NULL. O(1). */
occ_err_t occ_walk_status(const occ_walk_t *w);
/* Do not descend into the children of the node last returned. */
void occ_walk_skip_children(occ_walk_t *w);

/* ---- Top-down node access (for walkers that pick their own order: sector scans, custom queries) --
 * A node handle holds what a reader needs and where its children are; it stays valid until the
 * next write to the map (it records occ_map_t.write_gen). Each call reads one block: O(1). */
typedef struct {
    occ_key_t key;      /* first voxel of the node (lowest `level` bits clear) */
    uint8_t level;      /* 0 = voxel */
    bool observed;      /* false: nothing below was ever observed */
    uint8_t flags;      /* OCC_NODE_* (incl. OCC_NODE_UNIFORM when it has no children) */
    occ_state_t state;  /* state of the node's value (the max below) */
    float logodds;      /* max of observed voxels below (0 when unobserved) */
    uint32_t children;  /* internal: the child block, OCC_NONE when uniform */
    uint32_t gen;       /* internal: map->write_gen when the handle was made */
} occ_node_t;

/* The root (level depth_levels). */
void occ_map_node_root(const occ_map_t *map, occ_node_t *out);
/* Child `slot` (0..7: bit 0 = +x half, bit 1 = +y, bit 2 = +z) of `parent`. A uniform parent's
 * children are reported with the parent's value (as if expanded). OCC_ERR_ARG for NULL, a
 * parent level of 0 or above depth_levels, a slot > 7, or a child block the map never carved;
 * OCC_ERR_STATE when the map was written (or cleared) since `parent` was made. On either error
 * nothing is read from the tree and `out` (when non-NULL) gets an unobserved, UNKNOWN node
 * without children that is itself stale. */
occ_err_t occ_map_node_child(const occ_map_t *map, const occ_node_t *parent, unsigned slot,
                             occ_node_t *out);

/* Log-odds <-> node value. */
float occ_value_to_logodds(occ_value_t v);
occ_value_t occ_value_from_logodds(float logodds);
bool occ_value_observed(occ_value_t v);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_map_read, occ_map_read_key: stack <= 192 / 192 B; work: one descent, <= depth_levels blocks
 *       read
 *   occ_map_state_at: stack <= 128 / 192 B; work: one descent, <= depth_levels blocks read
 *   occ_map_update, occ_map_update_key: stack <= 768 / 768 B; work: one path: <= depth_levels
 *       blocks, allocates <= depth-1 inner + 1 leaf
 *   occ_map_observe_key: stack <= 640 / 704 B; work: as occ_map_update_key
 *   occ_map_observe_codes: stack <= 640 / 704 B; work: n codes x <= depth_levels blocks (about n
 *       when clustered)
 *   occ_map_observe_need: stack <= 640 / 704 B; work: n codes x <= depth_levels blocks, read only
 *   occ_map_set_key, occ_map_forget_key: stack <= 704 / 704 B; work: one path + the blocks of the
 *       subtree it releases
 *   occ_map_stats: stack <= 448 / 512 B; work: every node once
 *   occ_map_check: stack <= 384 / 448 B; work: every node + every free block once
 *   occ_walk_next: stack <= 128 / 128 B; work: O(1) amortized per node
 *   occ_map_node_root, occ_map_node_child: stack <= 128 / 128 B; work: one block read
 *   occ_map_init, occ_map_clear, occ_map_config_default: stack <= 128 / 192 B; work: O(1): the
 *       pools and the root are reset, the arena is not touched (a shared map: + one publish,
 *       occ_shared.h)
 *   occ_map_pool_stats, occ_walk_begin, occ_walk_status: stack <= 128 / 128 B; work: O(1), no
 *       tree walk
 *   occ_walk_skip_children: stack <= 128 / 128 B; work: O(1), no tree walk
 *   occ_map_key, occ_map_key_range, occ_map_key_center: stack <= 192 / 192 B; work: O(1): one
 *       key conversion per axis, no map access
 *   occ_key_at_level, occ_map_node_size, occ_morton_*: stack <= 128 / 128 B; work: O(1), no map
 *       access
 *   occ_value_*, occ_arena_blocks_for_bytes, occ_err_str: stack <= 64 / 64 B; work: O(1), no map
 *       access
 *   occ_map_state_of: stack <= 128 / 192 B; work: O(1), no map access
 */

#ifdef __cplusplus
}
#endif


#endif /* OCC_OCC_CORE_H_INCLUDED */
