/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_query.h - reading the map through volumes: iteration with state predicates, voxel counts,
 * nearest-first search, collision checks, ray casts, line of sight, information gain.
 * Included by occmap.h. Implemented in src/map/volume.c (volumes), query.c (iterator, counts),
 * lookup.c, lookup_index.c + lookup_index_build.c (the lookup index), nearest.c, collide.c,
 * castray.c, infogain.c (core: no heap, no recursion, float
 * math). Convex shapes through libccd
 * are in occ_collide_ccd.h (host builds only).
 *
 * Geometry: every volume and node is a closed set in the map frame (metres). A node at `level`
 * is the axis-aligned cube of edge resolution * 2^level holding voxel keys
 * [key, key + 2^level) per axis. "A node intersects a volume" means the closed cube and the
 * closed volume share a point (exact tests, float arithmetic: separating axes for OBB and
 * frustum, exact segment-to-box distance for capsules). Space outside the map volume holds no
 * node: iteration never reports it; collision checks treat it as UNKNOWN.
 *
 * Cost: iteration skips whole branches that miss the volume or cannot match the predicate
 * (inner max value for "occupied", indicator flags for "free"/"unknown"), so it is proportional
 * to the nodes touched near the volume's boundary and the nodes reported, not to the volume.
 */
#ifndef OCC_QUERY_H_INCLUDED
#define OCC_QUERY_H_INCLUDED

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Volumes (caller-owned values; constructors validate and precompute) -------------------- */
typedef enum {
    OCC_VOL_AABB = 0,
    OCC_VOL_OBB = 1,
    OCC_VOL_SPHERE = 2,
    OCC_VOL_CAPSULE = 3, /* the points within r of segment [a, b] (a swept sphere) */
    OCC_VOL_FRUSTUM = 4, /* a view frustum (truncated pyramid); near 0 gives a pyramid */
    OCC_VOL_SEGMENT = 5  /* the segment [a, b] itself */
} occ_volume_kind_t;

typedef struct {
    occ_volume_kind_t kind;
    occ_vec3_t bmin, bmax; /* axis-aligned bounds of the volume (the AABB itself for OCC_VOL_AABB) */
    union {
        struct { occ_vec3_t c; float r; } sphere;
        struct { occ_vec3_t c; occ_vec3_t axis[3]; float half[3]; } obb;
        struct { occ_vec3_t a, b; float r; } capsule; /* also the segment (r = 0) */
        struct {
            occ_vec3_t n[6];      /* outward plane normals (unit); inside: n.p <= d */
            float d[6];
            occ_vec3_t corner[8]; /* 0..3 near face, 4..7 far face (same order) */
            occ_vec3_t left, up;  /* the camera's lateral axes (edges of near and far faces) */
            occ_vec3_t origin;    /* the apex (sensor position) */
        } frustum;
    } u;
} occ_volume_t;

/* Each returns OCC_ERR_ARG (volume untouched) for a NULL pointer or any NaN/Inf input. O(1). */
/* min <= max per axis (a flat box is valid). */
occ_err_t occ_volume_aabb(occ_volume_t *v, occ_vec3_t min, occ_vec3_t max);
/* radius >= 0 (0: the point). */
occ_err_t occ_volume_sphere(occ_volume_t *v, occ_vec3_t center, float radius_m);
/* Box of half extents half[i] >= 0 along axes[i]; the axes must be unit length and mutually
 * orthogonal within 1e-3 (else OCC_ERR_ARG: degenerate axes). Either handedness. */
occ_err_t occ_volume_obb(occ_volume_t *v, occ_vec3_t center, const float half_m[3],
                         const occ_vec3_t axes[3]);
/* OBB rotated by yaw (rad, about z) then shown as axes (cos,sin,0), (-sin,cos,0), (0,0,1). */
occ_err_t occ_volume_obb_yaw(occ_volume_t *v, occ_vec3_t center, const float half_m[3],
                             float yaw_rad);
/* Capsule: radius >= 0; a == b gives a sphere. */
occ_err_t occ_volume_capsule(occ_volume_t *v, occ_vec3_t a, occ_vec3_t b, float radius_m);
occ_err_t occ_volume_segment(occ_volume_t *v, occ_vec3_t a, occ_vec3_t b);
/* View frustum at `origin` looking along axes[0] with axes[1] = left, axes[2] = up (unit,
 * orthogonal within 1e-3), full fields of view 0 < hfov, vfov < pi (rad), 0 <= near < far (m).
 * OCC_ERR_ARG otherwise. */
occ_err_t occ_volume_frustum(occ_volume_t *v, occ_vec3_t origin, const occ_vec3_t axes[3],
                             float hfov_rad, float vfov_rad, float near_m, float far_m);

/* Exact tests of a node cube (centre c, half edge h) against a volume (used by the iterator;
 * exposed for tests and for callers with their own grids). O(1). */
bool occ_volume_hits_box(const occ_volume_t *v, occ_vec3_t c, float h);
/* True when the whole cube lies inside the volume (never for segments). */
bool occ_volume_holds_box(const occ_volume_t *v, occ_vec3_t c, float h);

/* ---- Predicates ------------------------------------------------------------------------------ */
#define OCC_PRED_OCCUPIED 0x01u
#define OCC_PRED_FREE 0x02u
#define OCC_PRED_UNKNOWN 0x04u /* unobserved, or observed in the band free_max..occupied_min */
#define OCC_PRED_ANY 0x07u

/* Split uniform nodes that lie partly in the volume down to min_level (virtually: the tree is not
 * touched), so that the reported nodes cover exactly the volume's cells at min_level; uniform
 * nodes wholly inside stay whole (occ_query_node_t.inside). Without it a uniform (pruned) node is
 * reported once, whatever its size. */
#define OCC_ITER_SPLIT 0x01u

typedef struct {
    uint8_t states;    /* OR of OCC_PRED_*: report nodes in one of these states (0 = any) */
    uint8_t min_level; /* do not descend below this level (0 = voxels). A node that has children
                        * but sits at min_level is reported when it CONTAINS a wanted state
                        * (indicators / max value); its `state` is then the state of its max. */
    uint8_t options;   /* OCC_ITER_* */
} occ_pred_t;

/* One reported node. */
typedef struct {
    occ_key_t key;       /* first voxel of the node (lowest `level` bits clear) */
    uint8_t level;
    bool uniform;        /* no children below (all voxels share `logodds`/`state`) */
    bool inside;         /* the whole node lies in the volume (computed with OCC_ITER_SPLIT only) */
    bool observed;
    occ_state_t state;
    uint8_t flags;       /* OCC_NODE_HAS_* (and OCC_NODE_UNIFORM) */
    float logodds;       /* max of the observed voxels below (0 if unobserved) */
    occ_vec3_t center;   /* metres */
    float size_m;        /* edge */
} occ_query_node_t;

/* The iterator: caller-owned, fixed-size (no heap), valid while `map` and `vol` are unchanged
 * (a write to the map is detected: see occ_query_status).
 * Visits nodes depth first in Morton order (children 0..7), so reported nodes come sorted by
 * Morton code of their first voxel. It does not start at the root: the volume's bounds fall in
 * at most 2x2x2 nodes of the smallest level that can hold them, and the walk starts at those
 * (reached by direct descent), so a small volume costs O(depth) plus the nodes near it.
 * Fields are private. */
typedef struct {
    const occ_map_t *map;
    const occ_volume_t *vol;
    occ_pred_t pred;
    uint8_t sp;            /* entries on the stack */
    uint8_t base;          /* first stack entry of the current start node */
    uint8_t virt_sp;       /* entries >= virt_sp are virtual (split of a uniform node) */
    uint8_t start_level;   /* level of the start nodes */
    uint8_t nstart, istart;
    occ_value_t virt_value;
    occ_key_t path;        /* key bits of the current node at each stack level */
    occ_key_t start[8];    /* the start nodes, in Morton order */
    uint32_t block[OCC_MAX_DEPTH]; /* block[D-L]: child block of the path node at level L */
    uint8_t mask[OCC_MAX_DEPTH];  /* children of block[i] still to visit (match and touch) */
    uint32_t gen;          /* map->write_gen at occ_query_begin() */
} occ_query_iter_t;

/* Start iterating the nodes of `map` that intersect `vol` and match `pred`. OCC_ERR_ARG for
 * NULL, bad states bits, min_level > depth_levels; a refused iterator reports nothing
 * (occ_query_next false, occ_query_status OCC_ERR_ARG). O(1). */
occ_err_t occ_query_begin(occ_query_iter_t *it, const occ_map_t *map, const occ_volume_t *vol,
                          occ_pred_t pred);
/* Next node; false when done. Amortized O(depth) per node touched. Also false, without reading
 * the tree, when the map was written (or cleared) since occ_query_begin(): a caller that draws a
 * safety answer from the nodes seen must then check occ_query_status(). */
bool occ_query_next(occ_query_iter_t *it, occ_query_node_t *out);
/* OCC_OK while the iterator is valid, OCC_ERR_STATE once the map was written since
 * occ_query_begin() (the nodes reported may then be incomplete), OCC_ERR_ARG for NULL or an
 * iterator occ_query_begin() refused. O(1). */
occ_err_t occ_query_status(const occ_query_iter_t *it);

/* Voxels (level 0) of the map inside `vol`, by state. Whole nodes inside the volume count
 * 8^level voxels without being split. `outside` is true when the volume reaches beyond the map. */
typedef struct {
    uint64_t occupied, free, unknown;
    bool outside;
} occ_query_counts_t;
occ_err_t occ_query_count(const occ_map_t *map, const occ_volume_t *vol, occ_query_counts_t *out);

/* ---- Point lookups with a path cache ----------------------------------------------------------
 * For streams of nearby points (a trajectory, a sensor footprint): the cursor keeps the path of
 * the last voxel and re-descends only below the highest key bit that changed, so a lookup next to
 * the previous one touches one or two blocks instead of depth_levels. Caller-owned, no heap;
 * valid while the map is not modified (re-init after any write: a write or occ_map_clear() is
 * detected through occ_map_t.write_gen, and the cursor then answers UNKNOWN). */
typedef struct {
    const occ_map_t *map;
    occ_key_t key;        /* last voxel looked up */
    uint8_t lu;           /* level of the uniform node (or voxel) holding it */
    bool valid;
    occ_value_t val;
    uint32_t blk[OCC_MAX_DEPTH + 1u]; /* blk[L]: child block of the path node at level L > lu */
    uint32_t gen;         /* map->write_gen at occ_lookup_init() */
} occ_lookup_t;

/* Start a cursor on `map`. O(1). */
void occ_lookup_init(occ_lookup_t *lk, const occ_map_t *map);
/* State of the voxel at `p`: exactly occ_map_state_at(map, p) (UNKNOWN for NaN or off-map).
 * UNKNOWN, without reading the tree, when the map was written (or cleared) since
 * occ_lookup_init() (occ_lookup_status() then says OCC_ERR_STATE) or lk is NULL.
 * O(levels below the highest key bit that differs from the previous lookup). */
occ_state_t occ_lookup_state(occ_lookup_t *lk, occ_vec3_t p);
/* Same answer, with its error: OCC_OK, OCC_ERR_STATE (stale cursor), OCC_ERR_ARG (NULL, NaN or
 * Inf), OCC_ERR_RANGE (off the map); *state (when non-NULL) is UNKNOWN on every error. */
occ_err_t occ_lookup_read(occ_lookup_t *lk, occ_vec3_t p, occ_state_t *state);
/* OCC_OK while the cursor is valid, OCC_ERR_STATE once the map was written since
 * occ_lookup_init(), OCC_ERR_ARG for NULL. O(1). */
occ_err_t occ_lookup_status(const occ_lookup_t *lk);

/* Many points in one call: states_out[i] = occ_map_state_at(map, pts[i]) for i < n (an
 * occ_state_t value, UNKNOWN 0, FREE 1, OCCUPIED 2, stored in one byte: a fixed size whatever the
 * compiler's enum size, for bindings (numpy uint8) and large batches). Points in metres, map
 * frame; a NaN, Inf or off-map point answers UNKNOWN, as the single call does (no error). The
 * points go through one lookup cursor started by this call, so a point next to the previous one
 * (a grid slice row, a trajectory, a sensor footprint) re-descends only the levels below the
 * highest key bit that changed; a random order costs one descent per point.
 * Errors: OCC_ERR_ARG for a NULL map, or NULL pts / states_out with n > 0; then every
 * states_out[i] is UNKNOWN when states_out is non-NULL (fail closed). n = 0 is OCC_OK.
 * Reads only; as any reader, not safe against a concurrent writer of the same map (occ_shared.h).
 * O(n x levels below the highest changed key bit), <= n x depth_levels blocks read. */
occ_err_t occ_map_states_at(const occ_map_t *map, const occ_vec3_t *pts, size_t n,
                            uint8_t *states_out);

/* ---- Exact lookup index for random points (issue 22) ---------------------------------------------
 * A table over the key bounding box of the map's observed space, built by the caller into
 * caller-given memory (no heap), that answers occ_map_state_at exactly with two table loads
 * (level 0) or a table load plus `level` block loads (level >= 1) instead of a descent from the
 * root (depth_levels dependent loads).
 *  - level 0: the box in bricks of 8x8x8 voxels (aligned to keys that are multiples of 8): a
 *    directory of one 4-byte brick number per brick, then 3 constant bricks (all UNKNOWN, all
 *    FREE, all OCCUPIED) and one 128-byte brick (2 bits per voxel: its state) per mixed brick,
 *    a brick whose voxels do not all read the same state. A brick of one state (whatever the
 *    log-odds of its voxels) costs only its directory entry:
 *    bytes = 4 x bricks of the box + 128 x (3 + mixed bricks) (0 when nothing is observed).
 *  - level L >= 1: 4 bytes per level-L cell of the box (the cell's child block, or its state when
 *    the cell lies in a node without children): bytes ~ voxels / 8^L * 4; the lookup then walks
 *    the last L levels of the tree (<= L block reads).
 * Points outside the box hold no observed voxel: they answer UNKNOWN, as occ_map_state_at
 * (which also says UNKNOWN off the map and for NaN / Inf). The key of a point is occ_map_key's
 * (the map's one conversion), so the answer equals occ_map_state_at for every point, voxel
 * borders included.
 * Staleness: the index records the map's write_gen, arena and root block; after any write (or
 * clear, or a re-load into the struct) it answers UNKNOWN with OCC_ERR_STATE without reading
 * the table or the tree (fail closed: a stale index never says FREE). Rebuild it then.
 * The caller's memory and the map must outlive the index; the index is not thread-safe against
 * writers (as the map); concurrent readers of an unchanged map are fine (lookups only read). */
typedef struct {
    const occ_map_t *map; /* the map it was built on (NULL: not built) */
    uint8_t level;        /* table level: 0 = bricks of 2-bit voxel states, >= 1 = cell references */
    uint32_t lo[3];       /* first voxel key of the box per axis (low max(level, 3 at level 0)
                             bits clear) */
    uint32_t n[3];        /* cells per axis, bricks at level 0 (0 when nothing is observed) */
    size_t bytes;         /* table bytes used of the caller's memory */
    struct {              /* internal: do not touch, layout may change */
        const uint32_t *cells;   /* the table (in the caller's memory); level 0: the directory */
        const uint32_t *bricks;  /* level 0: the bricks after the directory, else NULL */
        size_t stride_y, stride_x; /* cells per y step / per x step: n[2], n[1] * n[2] */
        uint8_t shift;           /* a cell is 2^shift voxels per axis: 3 at level 0, else level */
        uint32_t gen;            /* map->write_gen at build */
        uint32_t root;           /* the map's root block at build */
        const void *arena;       /* the map's arena at build */
    } priv;
} occ_lookup_index_t;

/* Table bytes for an index at `level` (0..depth_levels) over `map`'s observed space:
 * *bytes = 0 when nothing is observed, SIZE_MAX when the size does not fit a size_t.
 * OCC_ERR_ARG for NULL or level > depth_levels. O(nodes) (a walk for the bounding box, at
 * level 0 one more down to the voxels to count the mixed bricks), read only. */
occ_err_t occ_lookup_index_need(const occ_map_t *map, unsigned level, size_t *bytes);
/* The finest level whose table fits in `budget_bytes` (level 0, at most 4 + 128 bytes per 512
 * voxels + 384, is below level 1's 256 bytes per 512 voxels but on the smallest maps). OCC_ERR_ARG
 * for NULL, OCC_ERR_NOMEM when not even the coarsest level fits (*level unchanged). O(nodes) per
 * level tried. */
occ_err_t occ_lookup_index_pick(const occ_map_t *map, size_t budget_bytes, unsigned *level);
/* Build the index at `level` on `mem` (any alignment: the table starts at the next 4-byte
 * boundary, so give occ_lookup_index_need()'s bytes + 3 unless mem is 4-aligned). Writes only
 * [mem, mem + mem_bytes). OCC_ERR_ARG for NULL idx or map, level > depth_levels, or NULL mem
 * with a non-empty table; OCC_ERR_NOMEM when mem_bytes is too small (nothing written to mem);
 * OCC_ERR_UNSUPPORTED when a block index collides with the table's state tags (a pool of
 * > 4 G - 4 blocks) or a level-0 table would hold >= 4 G - 3 mixed bricks. On error the index is
 * left unbuilt (lookups answer UNKNOWN + OCC_ERR_STATE). O(nodes + cells of the table); level 0
 * walks the tree down to the voxels twice (count, then fill) and writes every voxel of a mixed
 * brick once. Stack: a fixed walk (<= depth_levels frames). */
occ_err_t occ_lookup_index_build(occ_lookup_index_t *idx, const occ_map_t *map, unsigned level,
                                 void *mem, size_t mem_bytes);
/* OCC_OK while the index matches its map, OCC_ERR_STATE when it was never built (or its build
 * failed) or the map was written, cleared or re-loaded since, OCC_ERR_ARG for NULL. O(1). */
occ_err_t occ_lookup_index_status(const occ_lookup_index_t *idx);
/* State of the voxel at `p`: exactly occ_map_state_at(map, p) while the index is valid; UNKNOWN
 * (without reading table or tree) when it is stale, unbuilt or NULL. O(1 + level). */
occ_state_t occ_lookup_index_state(const occ_lookup_index_t *idx, occ_vec3_t p);
/* Same answer, with its error: OCC_OK, OCC_ERR_STATE (stale or unbuilt), OCC_ERR_ARG (NULL,
 * NaN or Inf), OCC_ERR_RANGE (off the map); *state (when non-NULL) is UNKNOWN on every error. */
occ_err_t occ_lookup_index_read(const occ_lookup_index_t *idx, occ_vec3_t p, occ_state_t *state);
/* out[i] = occ_lookup_index_state(idx, pts[i]) for i < n, with the table loads of a few points
 * started ahead (prefetch), so random points overlap their cache misses. OCC_ERR_STATE when
 * stale or unbuilt (every out[i] UNKNOWN), OCC_ERR_ARG for NULL idx, or NULL pts / out with
 * n > 0 (then nothing is written). Points that are NaN or off the map answer UNKNOWN (no error).
 * O(n (1 + level)). */
occ_err_t occ_lookup_index_states(const occ_lookup_index_t *idx, const occ_vec3_t *pts, size_t n,
                                  occ_state_t *out);

/* ---- Nearest-first iteration -------------------------------------------------------------------- */
typedef struct {
    float dist2;       /* squared distance from the query point to the node cube */
    uint32_t child;    /* child block, OCC_NONE if uniform */
    occ_key_t key;
    occ_value_t value;
    uint8_t level;
    uint8_t flags;
} occ_nearest_entry_t;

typedef struct {
    const occ_map_t *map;
    occ_vec3_t p;
    float max_dist2;
    occ_pred_t pred;
    occ_nearest_entry_t *heap; /* caller buffer: a binary min-heap on dist2 */
    size_t cap, n;
    uint32_t gen;              /* map->write_gen at occ_nearest_begin() */
} occ_nearest_t;

/* Start a nearest-first search from `p` over nodes within `max_dist_m` (>= 0) that match `pred`
 * (OCC_ITER_SPLIT is ignored: uniform nodes come whole, at their distance). `buf` holds `cap`
 * entries (a few hundred suffice for max_dist of a few metres; each entry is a node waiting to
 * be opened). OCC_ERR_ARG for NULL, NaN, negative distance, cap == 0 (occ_nearest_next on a
 * refused iterator answers OCC_ERR_ARG). p may lie outside the map. */
occ_err_t occ_nearest_begin(occ_nearest_t *it, const occ_map_t *map, occ_vec3_t p,
                            float max_dist_m, occ_pred_t pred, occ_nearest_entry_t *buf,
                            size_t cap);
/* Next node by increasing distance (ties in any order): *found false when none is left.
 * OCC_ERR_NOMEM when `buf` overflowed (the search stops; results so far were exact);
 * OCC_ERR_STATE when the map was written (or cleared) since occ_nearest_begin() (nothing is
 * read from the tree); *found is false on every error.
 * O(log cap) per heap operation. `dist_m` (may be NULL) gets the point-to-cube distance. */
occ_err_t occ_nearest_next(occ_nearest_t *it, occ_query_node_t *out, float *dist_m, bool *found);

/* ---- Collision checks --------------------------------------------------------------------------- */
typedef enum {
    OCC_UNKNOWN_UNSAFE = 0, /* default: unknown and off-map space block (never flown through) */
    OCC_UNKNOWN_SAFE = 1    /* unknown counts as free */
} occ_unknown_policy_t;

/* Every collision check below sets `safe` false (and `outside` false) on entry, before any
 * argument check when `out` is non-NULL, so that a caller ignoring an error reads "unsafe". */
typedef struct {
    bool safe;             /* no blocking node intersects the volume */
    bool outside;          /* blocked (policy unsafe) because the volume leaves the map */
    occ_query_node_t node; /* first blocking node in Morton order when !safe && !outside and the
                            * call returned OCC_OK; an unobserved, UNKNOWN node on error */
} occ_collision_t;

/* Is the volume free of OCCUPIED voxels (and of UNKNOWN ones and off-map space under
 * OCC_UNKNOWN_UNSAFE)? Stops at the first blocking node. OCC_ERR_ARG for NULL, NaN/Inf, negative
 * radius, degenerate axes, a policy outside the enum. */
occ_err_t occ_collide_volume(const occ_map_t *map, const occ_volume_t *vol,
                             occ_unknown_policy_t policy, occ_collision_t *out);
occ_err_t occ_collide_sphere(const occ_map_t *map, occ_vec3_t center, float radius_m,
                             occ_unknown_policy_t policy, occ_collision_t *out);
occ_err_t occ_collide_aabb(const occ_map_t *map, occ_vec3_t min, occ_vec3_t max,
                           occ_unknown_policy_t policy, occ_collision_t *out);
occ_err_t occ_collide_obb(const occ_map_t *map, occ_vec3_t center, const float half_m[3],
                          const occ_vec3_t axes[3], occ_unknown_policy_t policy,
                          occ_collision_t *out);
/* A sphere of radius_m swept from a to b. */
occ_err_t occ_collide_capsule(const occ_map_t *map, occ_vec3_t a, occ_vec3_t b, float radius_m,
                              occ_unknown_policy_t policy, occ_collision_t *out);
/* The three answers of occ_distance_to_obstacle. */
typedef enum {
    OCC_OBSTACLE_UNDECIDED = 0, /* the search failed (see the error code): treat as an obstacle
                                 * at distance 0, never as clear */
    OCC_OBSTACLE_FOUND = 1,     /* *dist_m is the distance to the nearest blocking node */
    OCC_OBSTACLE_NONE = 2       /* nothing blocks within max_dist_m (*dist_m = max_dist_m) */
} occ_obstacle_t;

/* Distance from p (metres, map frame) to the nearest blocking node (policy as above, off-map
 * space excluded), searched up to max_dist_m (>= 0). *result says which of the three answers
 * holds. On every error *result is OCC_OBSTACLE_UNDECIDED and *dist_m is 0 (for each that is
 * non-NULL): OCC_ERR_ARG (NULL, NaN/Inf, negative distance, cap 0, bad policy), OCC_ERR_NOMEM
 * when `buf` (cap entries, as occ_nearest_begin) cannot hold the search: nothing nearer than the
 * nodes searched so far blocks, but what lies beyond is not known. No writes; O(nodes opened *
 * log cap). */
occ_err_t occ_distance_to_obstacle(const occ_map_t *map, occ_vec3_t p, float max_dist_m,
                                   occ_unknown_policy_t policy, occ_nearest_entry_t *buf,
                                   size_t cap, float *dist_m, occ_obstacle_t *result);

/* ---- Ray casts ---------------------------------------------------------------------------------- */
typedef enum {
    OCC_RAY_HIT = 0,       /* stopped on an occupied voxel */
    OCC_RAY_MAX_RANGE = 1, /* the next voxel centre was beyond max_range */
    OCC_RAY_UNKNOWN = 2,   /* entered an unknown voxel with ignore_unknown false */
    OCC_RAY_MAP_EDGE = 3   /* reached the border of the map */
} occ_ray_stop_t;

typedef struct {
    bool hit;           /* OctoMap's return value */
    occ_ray_stop_t stop;
    occ_key_t key;      /* the voxel the ray stopped in */
    occ_vec3_t end;     /* its centre (OctoMap's `end`) */
} occ_ray_result_t;

/* OctoMap's castRay: walk the voxels from the one holding `origin` along `direction` (need not
 * be unit) by 3D-DDA, voxel by voxel, and stop at the first OCCUPIED one (hit = true, its centre
 * in end). An UNKNOWN voxel stops the ray with hit = false unless ignore_unknown; max_range_m > 0
 * stops it (hit = false) at the first voxel whose centre is farther than max_range_m from the
 * origin (<= 0: unbounded, up to the map border). The origin's own voxel is tested first.
 * Same voxels, same ties and the same double arithmetic as OctoMap when OCC_RAY_DOUBLE.
 * OCC_ERR_ARG: NULL, NaN/Inf, zero direction; OCC_ERR_RANGE: origin outside the map. Fail
 * closed: on any error (out non-NULL) *out reads an obstacle at the origin: hit = true,
 * stop = OCC_RAY_HIT, end = origin as given, key = OCC_NONE on every axis (no voxel).
 * O(voxels crossed); no lookup while the ray is inside a node whose indicators say nothing below
 * can stop it (no OCCUPIED voxel, nor UNKNOWN one unless ignore_unknown), pruned or not. */
occ_err_t occ_cast_ray(const occ_map_t *map, occ_vec3_t origin, occ_vec3_t direction,
                       bool ignore_unknown, float max_range_m, occ_ray_result_t *out);

/* Line of sight from a to b: the voxels the segment crosses (3D-DDA from a's voxel to b's, both
 * included) hold nothing OCCUPIED (nor UNKNOWN under OCC_UNKNOWN_UNSAFE). `blocker` (may be NULL)
 * gets the first blocking voxel (visible: its hit is false, the rest unspecified). OCC_ERR_ARG
 * (NULL, NaN, bad policy), OCC_ERR_RANGE (a or b outside the map). Fail closed: *visible (if
 * non-NULL) is false on every error, and blocker (if non-NULL) then reads as occ_cast_ray's error
 * result (an obstacle at a, key OCC_NONE). O(voxels crossed), passing whole nodes that hold nothing blocking. */
occ_err_t occ_line_of_sight(const occ_map_t *map, occ_vec3_t a, occ_vec3_t b,
                            occ_unknown_policy_t policy, bool *visible,
                            occ_ray_result_t *blocker);

/* ---- Information gain (UFOMap's exploration example) --------------------------------------------- */
#define OCC_GAIN_OCCLUSION 0x01u /* count a cell only if the line of sight from the sensor origin
                                  * (frustum apex / sphere centre) to its centre is not blocked by
                                  * an occupied voxel (unknown does not block) */
typedef struct {
    uint64_t unknown_cells; /* cells at `level` intersecting the volume whose state is UNKNOWN */
    float entropy_bits;     /* sum over those cells of H(p), p = sigmoid(max log-odds);
                             * an unobserved cell contributes 1 bit */
} occ_info_gain_t;

/* Information gain of a sensor volume (typically a frustum or a sphere; any kind works) at cells
 * of `level` (0 = voxels). A cell's state is the state of its max value, as occ_map_read_key.
 * Cells outside the map are not counted. OCC_ERR_ARG for NULL, level > depth_levels, bad options;
 * on every error `out` (when non-NULL) reads 0 cells and 0 bits (nothing to gain there).
 * O(cells reported) (with OCC_GAIN_OCCLUSION times the ray length in voxels). */
occ_err_t occ_info_gain(const occ_map_t *map, const occ_volume_t *vol, unsigned level,
                        unsigned options, occ_info_gain_t *out);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_collide_sphere, occ_collide_aabb, occ_collide_obb: stack <= 960 / 960 B; work: the
 *       volume in O(1), then <= 8 start cells, each one descent, then the blocking blocks
 *       touching the volume (the obb's children tested one by one), stopping at the first hit
 *   occ_collide_capsule: stack <= 960 / 960 B; work: the volume in O(1), then <= 8 start cells,
 *       each one descent, then the blocking blocks touching the capsule (children tested one
 *       by one), stopping at the first hit
 *   occ_collide_volume: stack <= 640 / 640 B; work: <= 8 start cells, each one descent, then
 *       the blocking blocks touching the volume, stopping at the first hit
 *   occ_cast_ray, occ_line_of_sight: stack <= 512 / 512 B; work: voxels crossed, <= 3 (range / res
 *       + 2) + 2 (range: max_range_m, else to the map border), each looked up unless its node holds
 *       nothing blocking
 *   occ_distance_to_obstacle: stack <= 512 / 512 B; work: O(nodes opened x log cap)
 *   occ_nearest_*: stack <= 320 / 320 B; work: O(nodes opened x log cap)
 *   occ_query_count: stack <= 960 / 1,024 B; work: amortized O(depth) per node touched
 *   occ_query_next: stack <= 640 / 704 B; work: amortized O(depth) per node touched
 *   occ_info_gain: stack <= 1,024 / 1,024 B; work: the cells reported (x the ray length in voxels
 *       with OCC_GAIN_OCCLUSION)
 *   occ_lookup_index_state, occ_lookup_index_read: stack <= 192 / 256 B; work: one table load +
 *       one brick word (level 0) or <= level block reads
 *   occ_lookup_index_states: stack <= 320 / 384 B; work: per point one table load + one brick
 *       word (level 0) or <= level block reads
 *   occ_lookup_index_need: stack <= 448 / 448 B; work: every node down to the level once (level
 *       0: down to level 3, then every node)
 *   occ_lookup_index_pick: stack <= 448 / 448 B; work: every node once per level tried
 *   occ_lookup_index_build: stack <= 576 / 576 B; work: every node down to the level twice (level
 *       0: down to level 3 once, every node twice) + every table cell once
 *   occ_lookup_index_status: stack <= 192 / 256 B; work: O(1)
 *   occ_lookup_read, occ_lookup_state: stack <= 256 / 256 B; work: the levels below the highest key
 *       bit that differs from the last lookup
 *   occ_map_states_at: stack <= 320 / 320 B; work: per point the levels below the highest key bit
 *       that differs from the previous point's, <= n x depth_levels blocks read
 *   occ_query_begin: stack <= 256 / 320 B; work: <= 8 start cells, one key range each
 *   occ_query_status, occ_lookup_init, occ_lookup_status: stack <= 256 / 256 B; work: O(1)
 *   occ_volume_frustum: stack <= 704 / 832 B; work: O(1), no map access
 *   occ_volume_obb_yaw: stack <= 640 / 704 B; work: O(1), no map access
 *   occ_volume_hits_box: stack <= 256 / 320 B; work: O(1), no map access
 *   occ_volume_aabb, occ_volume_sphere, occ_volume_obb: stack <= 192 / 256 B; work: O(1), no
 *       map access
 *   occ_volume_capsule, occ_volume_segment: stack <= 192 / 256 B; work: O(1), no map access
 *   occ_volume_holds_box: stack <= 192 / 256 B; work: O(1), no map access
 */

#ifdef __cplusplus
}
#endif

#endif /* OCC_QUERY_H_INCLUDED */
