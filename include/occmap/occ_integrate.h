/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_integrate.h - integrating point clouds (ray casting) into the map. Part of the manual.
 *
 * Semantics are OctoMap's insertPointCloud() exactly: within one call every voxel is updated at
 * most once; a voxel that is both traversed by some ray and contains some end point is updated
 * as occupied (cfg.hit), every other traversed voxel as free (cfg.miss). A ray longer than the
 * max range clears up to max range along its direction and marks no hit. Traversal is the 3D-DDA
 * of Amanatides & Woo with OctoMap's computeRayKeys arithmetic (float direction, double tMax
 * when OCC_RAY_DOUBLE=1) on the map's decimal resolution (occmap.h), so the keys are bit-for-bit
 * OctoMap's for the octomap::OcTree(0.1) a user writes for cfg.resolution_m = 0.1f.
 *
 * Memory: no heap. The per-scan key sets live in the caller's scratch buffer: the voxels the
 * rays cross as a voxel set (below), or as sorted Morton codes (radix sort) when the set does
 * not fit; either way they are de-duplicated and applied with occ_map_observe_codes(), which
 * touches the tree in Morton order. If the scratch cannot hold them the call returns
 * OCC_ERR_SCRATCH; if the pools cannot hold the result, OCC_ERR_NOMEM; either way the map is
 * exactly as before (automatic eviction aside, see auto_evict). The voxel set goes to the tree
 * by 4x4x4 bricks in Morton order, without codes, when the blocks its update can allocate (as
 * if none of its nodes existed) fit the pools (not after FAST_DISCRETE's coarse pass); else as
 * codes, below. Both give the same map and counts.
 *
 * The voxel set (SIMPLE, DISCRETE, SUPER_RAYS and FAST_DISCRETE's voxel rays): one bit per voxel
 * in 32^3-voxel chunks (4 KiB, aligned to keys), taken from the scratch when a ray first enters
 * one, so it grows with the chunks the scan crosses, not with its voxel visits. It is used when
 * it surely fits (room for every chunk of the scan's bounding box) or when the sorted codes
 * would not fit one batch (16 bytes per code of the rays' bound after the fixed term); else the
 * sorted codes run as one batch, and no traversal is risked on a set that could run full.
 * After the one traversal of the scan the set is read back in Morton order, merged with the end
 * voxels (hit wins), into the room the chunks left: in one batch when it fits there, else in
 * pieces of that room (SIMPLE and DISCRETE). All or nothing still holds for pieces: before any
 * write, the blocks each piece's update can allocate as if none of its nodes existed (so the
 * pruning of one piece cannot starve the next) are counted on the set and summed, and checked
 * against the pools (evicting for the sum first with auto_evict; what was evicted then stays
 * evicted); when they do not fit: OCC_ERR_NOMEM, map unchanged - a conservative check: it may
 * refuse where one batch with more scratch would succeed. The map equals the one-batch result
 * voxel for voxel. One traversal needs (n = n_points, C = the 32^3-voxel chunks the rays cross, at most those of
 * the scan's bounding box):
 *   OCC_INSERT_SCRATCH_FIXED_BYTES + (DISCRETE) 8 n + 8 (n + 1)
 *     + max(8 (n + 1), 8192, SUPER_RAYS: its tables, 24 n + 278,600 on a 64-bit host) + 4,160 C
 * (tests/test_integrate_chunks.c checks it to the byte).
 * scan.dat at 0.05 m (88,206 points; 14.2 M voxel visits, 3.9 M voxels, C = 605): 4,239,415 B
 * for SIMPLE. By bricks the call then writes ~4.0 MB of scratch (scratch_used) and nothing
 * more, unbounded or in 8 MiB alike (make bench-scratch; README, Performance); one batch of
 * codes would want ~34 MB, and where the pools are too tight for the bricks' bound, 8 MiB
 * runs in 7 pieces of codes with the instructions of one batch (callgrind: 1,616 M against
 * 1,617 M).
 * Bounded scratch below that (SIMPLE and DISCRETE, issue 22): when the set runs full, the scan is
 * traced again as sorted codes in Morton-range windows instead of failing. The first pass keeps
 * the lowest codes that fit and narrows its window to them (codes above are dropped by every
 * later ray); each further pass traces the whole scan again for the next window. Windows are
 * disjoint key ranges, so each voxel is updated once and hits win exactly as in one batch; the
 * pools are checked first for the sum over the windows, as for pieces. Cost: 2 x windows
 * traversals of the scan (windows ~ unique voxels / (scratch / 32)); scan.dat at 0.05 m in
 * 4 MiB (45 KB short of the set): ~10 s, 80-100x one batch.
 * Minimum scratch: the fixed term, plus (DISCRETE) 8 bytes per point, plus 16 bytes per code
 * for c = max(longest ray's keys + 2, DISCRETE: n_points) codes, where a ray's keys are
 * |dk|_1 + 4 (occ_insert_scratch_bytes_scan() of that one point is 8 + 16 (keys + 1)); below
 * it OCC_ERR_SCRATCH, map unchanged. SUPER_RAYS and FAST_DISCRETE take the set only when it
 * fits one batch (else they trace again as sorted codes) and are not windowed: short scratch
 * is OCC_ERR_SCRATCH as before.
 *
 * Work: O(sum over rays of the voxels each ray crosses) for traversal, bounded per ray by
 * 3 * (max_range / resolution + 2) + 2 voxels (the whole map's edge with unlimited range), plus
 * O(unique voxels * depth) for the tree update. Firmware budgets rays x voxels per ray.
 */
#ifndef OCC_INTEGRATE_H_INCLUDED
#define OCC_INTEGRATE_H_INCLUDED

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Radix digit width (bits) of the key-set sort: its histogram takes 2^bits * 4 bytes of scratch
 * per pass. Filter: a direct-mapped table of 2^bits recently emitted codes (8 bytes each) that
 * drops repeated visits before the sort; exact (a code is dropped only if it was emitted before
 * in this call). */
#ifndef OCC_INSERT_RADIX_BITS
#if defined(__arm__) || defined(__thumb__)
#define OCC_INSERT_RADIX_BITS 8
#else
#define OCC_INSERT_RADIX_BITS 11
#endif
#endif
#ifndef OCC_INSERT_FILTER_BITS
#if defined(__arm__) || defined(__thumb__)
#define OCC_INSERT_FILTER_BITS 8
#else
#define OCC_INSERT_FILTER_BITS 15
#endif
#endif
/* Radix passes over the 63 key bits: 6 with 11-bit digits (host), 8 with 8-bit digits (ARM). */
#define OCC_INSERT_RADIX_PASSES ((63u + OCC_INSERT_RADIX_BITS - 1u) / OCC_INSERT_RADIX_BITS)

/* ---- Scratch sizing at compile time (firmware: `static uint8_t scratch[...]`) ----------------
 * OCC_INSERT_SCRATCH_FIXED_BYTES: what every call takes whatever the scan: up to 7 bytes to
 * align the scratch, the filter (2^FILTER_BITS * 8) and the sort's histograms (RADIX_PASSES *
 * 2^RADIX_BITS * 4): 311,303 bytes on a host, 10,247 on ARM.
 * OCC_INSERT_SCRATCH_BYTES(n_points, max_ray_voxels): enough scratch for SIMPLE, DISCRETE,
 * SUPER_RAYS and FAST_DISCRETE with d = 0, for up to n_points points whose rays (after clipping
 * to max range) span at most max_ray_voxels keys on each axis between the origin's voxel and
 * the end's: per point 8 bytes (its end voxel) and 16 per code its ray can emit (3 v + 4 keys
 * and its hit: the codes and the sort's temporary). For a max range R at resolution res pass
 * ceil(R / res) + 2 (rounding of the keys). Integer constant expressions: both arguments must
 * be integer constants; the product must fit a size_t (OCC_INSERT_SCRATCH_FITS says so, for a
 * compile-time check). The bound is exact for one point with a ray that long on every axis: one
 * byte less is refused with OCC_ERR_SCRATCH (tests/test_integrate.c). Not covered:
 * FAST_DISCRETE with d > 0 (its coarse set, see occ_insert_scratch_bytes_scan). */
#define OCC_INSERT_SCRATCH_FIXED_BYTES                                                        \
    (7u + ((size_t)1 << OCC_INSERT_FILTER_BITS) * 8u +                                       \
     (size_t)OCC_INSERT_RADIX_PASSES * ((size_t)1 << OCC_INSERT_RADIX_BITS) * 4u)
#define OCC_INSERT_SCRATCH_PER_POINT(max_ray_voxels) \
    (8u + 16u * (3u * (size_t)(max_ray_voxels) + 5u))
#define OCC_INSERT_SCRATCH_BYTES(n_points, max_ray_voxels) \
    (OCC_INSERT_SCRATCH_FIXED_BYTES +                      \
     (size_t)(n_points) * OCC_INSERT_SCRATCH_PER_POINT(max_ray_voxels))
#define OCC_INSERT_SCRATCH_FITS(n_points, max_ray_voxels)                                   \
    ((size_t)(max_ray_voxels) <= (SIZE_MAX / 16u - 5u) / 3u &&                                 \
     (size_t)(n_points) <= (SIZE_MAX - OCC_INSERT_SCRATCH_FIXED_BYTES) /                      \
                               OCC_INSERT_SCRATCH_PER_POINT(max_ray_voxels))

typedef enum {
    /* One exact ray per point (OctoMap insertPointCloud, discretize = false). */
    OCC_INSERT_SIMPLE = 0,
    /* Points first reduced to one per voxel, rays to voxel centres (discretize = true). */
    OCC_INSERT_DISCRETE = 1,
    /* UFOMap's fast discrete integrator (approximate): DISCRETE's end voxels; free space is
     * sampled from the origin in steps of a level-`fast_d` node's edge (res * 2^d) until
     * `fast_n` such steps before the end, from where the exact voxel DDA runs to the end voxel
     * (n = 0: no voxel DDA; the end's level-d node is cleared too). Every voxel below each
     * sampled level-d node gets cfg.miss / (2d+1) once per scan; then the voxel updates (hits,
     * fine free voxels) are applied on top, as UFOMap does (an end voxel's node is both
     * cleared coarsely and hit). fast_d = 0 is DISCRETE exactly. The all-or-nothing pool check
     * is conservative here: it may refuse (OCC_ERR_NOMEM) when fewer free blocks remain than
     * the distinct nodes on the updated paths, even if existing blocks would have sufficed. */
    OCC_INSERT_FAST_DISCRETE = 2,
    /* Super rays (Kim et al. 2017): points whose rays cross the same voxels (decided per end
     * voxel by the grid edges inside the bundle in the three axis-plane projections, the
     * paper's mapping lines) share one traversal. Same map as SIMPLE, voxel for voxel: rays
     * within 1e-9 (relative) of a decision or ending within 1e-4 voxel of a face are cast
     * singly, and so are end voxels with fewer than super_k points and bundles split into more
     * than a third as many super rays as rays. Needs the voxel set and its tables in the
     * scratch (see the top), else each ray is cast alone, as SIMPLE; memory as SIMPLE.
     * When to use it: SIMPLE's exact map from a dense depth camera at coarse voxels, where
     * several points end in one voxel. Measured (`make bench-insert`, bench/insert.cpp: 10 TUM
     * fr2 pioneer frames 640x480, 5 interleaved rounds, CPU ms per frame, medians; ratio = median
     * of the per-round SIMPLE / SUPER_RAYS): 0.2 m 34.9 -> 22.2 ms, 1.57x [1.54, 1.58], 2.9
     * points per traversal; 0.1 m 63.9 -> 57.8 ms, 1.13x [1.08, 1.15], 1.7 points; 0.05 m
     * 121.1 -> 118.9 ms, 1.02x, 1.2 points (two more runs: 1.56x / 1.12x / 1.02x and 1.56x /
     * 1.14x / 1.04x). Since SIMPLE's walk got faster (issue 22: per octant, Morton stepping,
     * the set to the tree by bricks) the gain is smaller: make bench on nine commits from
     * 29878c6 to 4f0089c (AMD EPYC, then Intel Xeon from 28c6fa7) gave 1.24x to 1.39x at 0.2 m
     * and 0.98x to 1.03x at 0.1 m; on 2af980b 1.30x [1.27, 1.33] and 1.02x [1.02, 1.05],
     * on d80dd40 1.31x [1.31, 1.32] and 1.03x [1.02, 1.04]; with the 8-lane walk (AVX-512,
     * raycast_lanes.c) on 539017a 1.31x [1.30, 1.32] and 1.00x [0.989, 1.00] (README,
     * Performance).
     * When not: at 0.1 m or finer, and for laser scans (scan.dat, spherical_scan.graph at
     * 0.2 / 0.1 / 0.05 m: 0.95x to 1.11x over three runs, 1.0 to 1.8 points per traversal),
     * it buys nothing over SIMPLE. If OctoMap's discretize = true map will do, DISCRETE is
     * faster still (TUM: 6.6 / 9.2 / 20.5 ms per frame at 0.2 / 0.1 / 0.05 m), and for depth
     * images PROJECTIVE (approximate) is faster than both. */
    OCC_INSERT_SUPER_RAYS = 3,
    /* Depth images only (occ_map_insert_depth, occ_map_insert_projective below): free space by
     * projecting octree nodes into the image, no rays. occ_map_insert_cloud refuses it. */
    OCC_INSERT_PROJECTIVE = 4
} occ_insert_method_t;

typedef struct {
    occ_insert_method_t method;
    float max_range_m;  /* <= 0: unlimited. Compared like OctoMap: |p - origin| <= max range */
    uint8_t fast_n;     /* FAST_DISCRETE: coarse nodes before the end where fine marching starts */
    uint8_t fast_d;     /* FAST_DISCRETE: level of the coarse nodes, 0..depth_levels-1 */
    uint16_t super_k;   /* SUPER_RAYS: end voxels with fewer points are cast singly (paper: 20) */
    /* Automatic eviction (occ_evict.h), NULL = off. When the pools are short for the scan's
     * voxel updates, evict with this policy around `origin` (occ_map_evict_for, which never
     * touches the protected region) and retry. If the whole scan still does not fit at once,
     * its sorted updates are applied in Morton-ordered chunks, evicting before each chunk that
     * needs it: the result equals one batch, but the call is then no longer all-or-nothing
     * (on OCC_ERR_NOMEM the chunks before the failing one stay applied; out->voxels_updated
     * says how many). `auto_evict_state` (required with a policy) accumulates the statistics.
     * FAST_DISCRETE with d > 0: its coarse pass and the voxel updates are checked together
     * against a bound as if none of their nodes existed; when the pools are short of it, the
     * call evicts for that bound first and fails with OCC_ERR_NOMEM if even that cannot be
     * met (the coarse pass is not chunked; what was evicted stays evicted). */
    const struct occ_evict_policy *auto_evict;  /* occ_evict_policy_t */
    struct occ_evict_out *auto_evict_state;     /* occ_evict_out_t */
    float proj_noise_rel; /* PROJECTIVE: depth noise as a fraction of depth, [0, 0.5] (0) */
} occ_insert_params_t;

/* SIMPLE, unlimited range, n = 0, d = 2, k = 4, no automatic eviction. */
occ_insert_params_t occ_insert_params_default(void);

typedef struct {
    size_t points_integrated; /* points that produced a ray or a hit */
    size_t points_skipped;    /* bad points: NaN / Inf, or (within max range) outside the map */
    size_t rays_clipped;      /* rays longer than max range: cleared up to max range, no hit */
    size_t rays_no_hit;       /* occ_map_insert_rays: no-hit points within max range (cleared
                               * up to the point, end voxel not marked) */
    size_t rays_cast;         /* traversals run (DISCRETE: distinct end voxels; super rays) */
    size_t voxel_visits;      /* keys produced by traversals, before de-duplication */
    size_t voxels_updated;    /* distinct voxels updated (= voxels_free + voxels_occupied) */
    size_t voxels_free;       /* ... of which as free */
    size_t voxels_occupied;   /* ... of which as occupied */
    size_t voxels_changed;    /* voxels whose stored value changed */
    size_t coarse_updated;    /* FAST_DISCRETE: coarse nodes updated as free */
    size_t scratch_used;      /* scratch bytes this call wrote (filter, histograms, its sets and
                               * the high-water of its code arrays; what it reserved but never
                               * wrote is not counted), also on error. <= scratch_bytes; not a
                               * size that would suffice: use the bounds below for that. */
} occ_insert_result_t;

/* Scratch bytes that make occ_map_insert_cloud() run in one batch whatever the scan (less is
 * enough when the scan's voxel set fits; less still runs SIMPLE and DISCRETE in windows, see
 * the top of this header), for up to
 * `n_points` points whose rays are at most `max_ray_m` long (pass max(max_range, farthest point
 * distance); <= 0 or non-finite means "the whole map": a huge number). Formula:
 *   OCC_INSERT_SCRATCH_BYTES(n_points, ceil(max_ray_m / res) + 2)
 * (the fixed term is this build's: OCC_INSERT_RADIX_PASSES differs between host and ARM).
 * SUPER_RAYS needs no more than SIMPLE; FAST_DISCRETE with d > 0 needs in addition 32 bytes
 * per 4x4x4 block of level-d nodes of the scan's bounding box and 16 bytes per coarse sample
 * (occ_insert_scratch_bytes_scan() counts both; this function does not). Saturates at
 * SIZE_MAX. O(1). */
size_t occ_insert_scratch_bytes(const occ_map_t *map, size_t n_points, float max_ray_m,
                                const occ_insert_params_t *params);

/* The same bound computed for one scan: per ray the keys the DDA can emit (|dk|_1 + 4), summed
 * (FAST_DISCRETE: plus its coarse set over the scan's box). Bad points count 0. O(n). Returns
 * 0 if an argument is NULL. With at least this much scratch the call never returns
 * OCC_ERR_SCRATCH. Saturates at SIZE_MAX (a box too big for any scratch). */
size_t occ_insert_scratch_bytes_scan(const occ_map_t *map, const occ_vec3_t *origin,
                                     const occ_vec3_t *points, size_t n_points,
                                     const occ_insert_params_t *params);

/* Integrate one scan taken from sensor position `origin` (map frame, metres). `points` are in
 * the map frame. `scratch` (any alignment, owned by the call only while it runs) holds the
 * per-scan sets; less than the bound above may still work: the sets are compacted when full,
 * and SIMPLE / DISCRETE then run in Morton-range windows (slower, same map; see the top).
 * `out` (may be NULL) gets the counters, also on error (then nothing was applied).
 * Scratch beyond 32 GiB is not used (the sort counts codes in 32 bits).
 * Errors: OCC_ERR_ARG (NULL map/origin/params, points NULL with n > 0, origin NaN/Inf, bad
 * method or fast_d >= depth_levels), OCC_ERR_RANGE (origin outside the map), OCC_ERR_SCRATCH
 * (the scratch cannot hold the scan's sets: the map is unchanged, oom_count is not bumped),
 * OCC_ERR_NOMEM (the pools cannot hold the result: the map is unchanged, oom_count is bumped).
 * Bad points are not an error: they are skipped and counted.
 * Differences to OctoMap: an origin outside the map is an error (OctoMap would still mark the
 * end points); with discretize=true OctoMap wraps out-of-map points into the map, here they
 * are skipped. */
occ_err_t occ_map_insert_cloud(occ_map_t *map, const occ_vec3_t *origin,
                               const occ_vec3_t *points, size_t n_points,
                               const occ_insert_params_t *params, void *scratch,
                               size_t scratch_bytes, occ_insert_result_t *out);

/* occ_map_insert_cloud() with a per-point hit flag: hit[i] == false makes point i the end of
 * a ray that only clears - the voxels up to the point (to max range if it lies beyond) are
 * updated as free and the point's own voxel is not marked, exactly what insert_cloud does for a
 * point beyond max range (OctoMap insertRay() with a max range the end exceeds). hit == NULL:
 * every point is a hit (this is then occ_map_insert_cloud()). Rangefinders (occ_ranges.h) use
 * it for "no return within the sensor's own max range", which a single max_range_m cannot say.
 * A no-hit point is traced the way the method traces rays: SIMPLE and SUPER_RAYS exactly to
 * the point; DISCRETE and FAST_DISCRETE take it apart from the discretised end voxels, to the
 * point itself (FAST_DISCRETE: with its coarse march). Counted in out->rays_no_hit (within max
 * range) or rays_clipped (beyond it) and in points_integrated. The sets, scratch (the same
 * bounds), errors, all-or-nothing rule and work are occ_map_insert_cloud()'s; `hit` is read,
 * never kept. */
occ_err_t occ_map_insert_rays(occ_map_t *map, const occ_vec3_t *origin, const occ_vec3_t *points,
                              const bool *hit, size_t n_points,
                              const occ_insert_params_t *params, void *scratch,
                              size_t scratch_bytes, occ_insert_result_t *out);

/* ---- Exact ray keys ----------------------------------------------------------------------- */
/* The voxels OctoMap's computeRayKeys(origin, end) visits, in its order: the origin's voxel
 * first, every voxel crossed after it, the end point's voxel excluded; none when both are in the
 * same voxel. `keys` gets up to `cap` keys, `*n_keys` the count (also the count needed when
 * OCC_ERR_NOMEM is returned; then keys hold the first cap). OCC_ERR_ARG (NULL, NaN/Inf),
 * OCC_ERR_RANGE (origin or end outside the map, as OctoMap's false). At most
 * |dk_x| + |dk_y| + |dk_z| + 4 keys (occ_ray_max_keys). O(keys). No map access. */
occ_err_t occ_ray_keys(const occ_map_t *map, occ_vec3_t origin, occ_vec3_t end,
                       occ_key_t *keys, size_t cap, size_t *n_keys);
/* Upper bound of the keys occ_ray_keys() returns between two points (0 if invalid). */
size_t occ_ray_max_keys(const occ_map_t *map, occ_vec3_t origin, occ_vec3_t end);

/* ---- Depth images by projection (OCC_INSERT_PROJECTIVE) -----------------------------------
 * D-Map style (Cai et al. 2023): no rays. A min/max pyramid of the image is built once in the
 * scratch, then a virtual octree (no tree reads) is walked top-down from the root; each node's
 * box is projected into the image and compared with the pyramid over its footprint.
 *
 * The rule, per voxel (exact; the walk only decides whole nodes where every voxel below would
 * get the same answer, so the result equals applying it to every voxel of the map):
 *  - pixel depth d (metres along z): U16 raw * depth_scale_m (raw 0: no reading); F32 as given
 *    (0, NaN, negative, -Inf: no reading; +Inf or > 1024 max_range_m: d = 2 max_range_m). Pixel
 *    (i, j) has the ray a_i = (i - cx) / fx, b_j = (j - cy) / fy and the camera-frame point
 *    c = (a_i d, b_j d, d) with |c|^2 = (d d) (a_i a_i + (b_j b_j + 1)) (float, as written);
 *    |c|^2 not finite: no reading; |c|^2 < min_range_m^2: no reading (blind zone);
 *  - the voxel's centre C (OctoMap's float centre per axis) goes to the camera frame:
 *    w = C - t, q_k = r[0][k] w_0 + r[1][k] w_1 + r[2][k] w_2 (float, left to right), and its
 *    pixel, with iz = 1 / q_2 (float), is i = floor(fx * (q_0 iz) + cx + 0.5),
 *    j = floor(fy * (q_1 iz) + cy + 0.5);
 *  - the free test's depth of a pixel: its reading d; a pixel with no reading takes the
 *    smallest reading among its four neighbours (left, right, up, down) that have one, so that a
 *    single-pixel gap (a speckle of the sensor) is decided by the readings around it as ray
 *    casting decides it by the neighbouring rays; with none it stays without;
 *  - the voxel is FREE (cfg.miss) iff q_2 > 0, (i, j) is inside the image, that pixel has a
 *    free-test depth d, q_2 < T(d) = (1 - noise_rel) * d (float) and
 *    q_0^2 + q_1^2 + q_2^2 <= max_range_m^2 (float): strictly in front of the surface by the
 *    margin m(d) = noise_rel * d, the caller's depth noise as a fraction of d
 *    (occ_insert_params_t.proj_noise_rel). There is no resolution term: a voxel that holds the
 *    surface holds end points and is OCCUPIED (hits win), and the voxel in front of it is free,
 *    as ray casting makes it (a half-voxel margin left a shell of unknown voxels in front of
 *    every surface, which an obstacle feed reports as "no data");
 *  - near field: it is FREE too when one of the near rays crosses it: from the camera t along
 *    every step-th pixel of each row and column and the last one (step = min(fx, fy) / 32
 *    truncated, at least 1: a ray every ~1.8 degrees) that has a free-test depth d, to depth
 *    z = min(T(d), 4 voxels, R) with R = max_range_m / sqrtf(a_i a_i + (b_j b_j + 1)) (max range
 *    along the pixel's ray: far off the optical axis, in a very wide field of view, 4 voxels of
 *    depth are a long ray, and a reading beyond max range frees no further than max range; the
 *    end e = (r (a_i, b_j, 1)) z + t, float), the voxels occ_ray_keys(t, e) gives (the camera's
 *    voxel first, the end's excluded; none when e is off the map). Within a few voxels of the
 *    camera a voxel is large against the frustum, so most voxels there have their centre
 *    outside the image though the camera's rays cross them;
 *  - the voxel is OCCUPIED (cfg.hit) iff it is the end voxel of some pixel with a reading and
 *    |c|^2 <= max_range_m^2: the voxel of the point t + r c, computed from the camera's voxel
 *    in float so that every pixel costs a few vector operations: per map axis a,
 *    key_a = kt_a + floor(d (U_a(i) + V_a(j)) + F_a) with U_a(i) = (r[a][0] a_i) rf,
 *    V_a(j) = (r[a][1] b_j + r[a][2]) rf, rf = (float)(1 / res), kt the camera's key and
 *    F_a = (float)(t_a / res - floor(t_a / res)) (the map's key arithmetic: double on hosts).
 *    That is the map key of t + r c up to float rounding relative to the distance (below 1e-6
 *    of a voxel per voxel of distance); an end point outside the map, or farther than 2^22
 *    voxels, marks nothing (points_skipped). Hits win over FREE (OctoMap's rule);
 *  - every other voxel is unchanged: behind or within the margin of its pixel's surface, at
 *    pixels without a free-test depth (never free: unknown stays unknown), outside the image
 *    (the border is the pixel grid: centre rounding to a pixel outside [0, width) x [0, height))
 *    and not crossed by a near ray, behind the camera, beyond max range. At a depth discontinuity each voxel follows its own centre's
 *    pixel: a voxel whose centre projects onto the far side is free even if a near pixel's end
 *    point is next to it (unless it holds that end point: then it is hit).
 *  A pixel beyond max range (|c| > max_range_m) marks no hit and frees up to max range.
 * Differences to ray casting (OctoMap insertPointCloud): beyond the near field voxels are
 * decided by their centres, not by the rays crossing them: a voxel crossed by a ray but whose
 * centre's pixel reads nearer (grazing surfaces, discontinuities) or has no reading (gaps wider
 * than a pixel), and the frustum's boundary voxels whose centres lie outside the image, stay
 * unchanged; a voxel no ray crosses whose centre is in front of its pixel's surface is free.
 * Measured against OctoMap in `make bench` (bench/projective.cpp) and in the loop demo.
 *
 * Writes: hits, free voxels and whole free nodes (every voxel below gets cfg.miss once) in one
 * pass over the tree in Morton order; each voxel is updated at most once per call. The pool
 * check comes first (a bound as if no node on the paths existed, so it may refuse with
 * OCC_ERR_NOMEM when a tight pool would have sufficed); any error: the map is unchanged.
 *
 * Scratch (caller's, any alignment): a fixed part (OCC_PROJ_FIXED_BYTES: alignment, an 8 KiB
 * cache of the end points' level-2 nodes, the radix sort's histograms, the call's context, the walk's
 * per-level constants and stack and the 64-voxel rule's lane arrays (6 KiB, kept off the
 * stack)), 4 bytes per pixel (the
 * depths), 8 bytes per pyramid cell (min and max, levels 1.. of halved sides, and from level 2
 * on per cell the min and max over the 8 x 8 cells from it: at most OCC_PROJ_CELLS(w, h) =
 * 5 w h / 12 + 3 (w + h) / 2 + 40 cells), 52 bytes per image column (the pixel
 * pass's per-column tables and row buffers, OCC_PROJ_COLUMN_BYTES) and the output, in 8-byte
 * slots: the end points as records of 2 slots, a level-2 node's code and the bits of its voxels
 * that hold one (one record per node, more when the cache dropped it between two of its end
 * points: ~1,300 records for a pioneer frame; twice while they are sorted), the near
 * rays' voxels (twice while sorted; ~5,000 for a 640 x 480 Kinect frame), then the updates:
 * 4 per level-2 node (4 x 4 x 4 voxels) holding a free voxel or an end point (its voxels by
 * the miss and by the hit) and 1 per whole free node above level 2. OCC_PROJ_SCRATCH_BYTES(w,
 * h, n_out) sizes it for n_out slots; OCC_PROJ_OUT_DEFAULT(w, h) = w h / 2 + 16384 slots covers
 * the TUM frames in `make bench` (bench/projective.cpp prints what they used) and an 8x8 ToF
 * array at 0.05 m to 3 m (tests/test_projective.c). For 640 x 480 the whole formula is 12.1
 * bytes per pixel, of which a frame of the pioneer sequence used at most 8.5. A small image
 * with a very wide field of view (fx or fy below 32: a near ray at every pixel) can need more
 * (tests/test_projective_fuzz.c draws such cameras). A frame that needs more slots is refused
 * with OCC_ERR_SCRATCH (map unchanged): pass more.
 * out->insert.scratch_used says what a call used.
 *
 * Work, bounded per call: O(pixels) for the pixel pass (depths, end points), the gap filling
 * and the pyramid; the near rays (about (32 w / f) (32 h / f) rays, each of at most
 * sqrt(3) L / res + 4 voxels, L = z sqrt(1 + a^2 + b^2) <= min(4 res sqrt(1 + a^2 + b^2),
 * max_range_m) its length: 11 on the optical axis, 13 at a Kinect's corners, more in a very
 * wide field of view); the walk tests a node in O(1) (8 corner projections, at most 3 x 3 pyramid
 * cells or 2 x 2 windows) and descends only where its answer is mixed, down to level 2, whose
 * 64 voxels it decides at once (a level-2 node in the frustum and within range gets no
 * footprint: the rule at once): at most 8 D + 8 (undecided nodes) nodes, in the worst case (a
 * noisy surface filling the frustum) every voxel of the frustum within max range. Typical:
 * proportional to the surface's voxels, not pixels x ray length. Then one pass over the tree.
 * Stack: O(D), no recursion. */
#define OCC_PROJ_CELLS(w, h) \
    (5u * (size_t)(w) * (size_t)(h) / 12u + 3u * ((size_t)(w) + (size_t)(h)) / 2u + 40u)
#define OCC_PROJ_LEVELS_BYTES 2048u /* the walk's per-level constants (kept off the stack) */
#define OCC_PROJ_CTX_BYTES 2304u    /* the call's context and walk stack (kept off the stack) */
#define OCC_PROJ_BULK_BYTES 2048u   /* the 64-voxel rule's lane arrays (kept off the stack) */
#define OCC_PROJ_FIXED_BYTES                                                               \
    (8u + 8192u + (size_t)OCC_INSERT_RADIX_PASSES * ((size_t)1 << OCC_INSERT_RADIX_BITS) * 4u + \
     OCC_PROJ_LEVELS_BYTES + OCC_PROJ_CTX_BYTES + OCC_PROJ_BULK_BYTES)
#define OCC_PROJ_COLUMN_BYTES(w) (52u * (size_t)(w) + 256u)
#define OCC_PROJ_SCRATCH_BYTES(w, h, n_out)                                                 \
    (OCC_PROJ_FIXED_BYTES + 48u + 4u * (size_t)(w) * (size_t)(h) + 8u * OCC_PROJ_CELLS(w, h) + \
     OCC_PROJ_COLUMN_BYTES(w) + 8u * (size_t)(n_out))
#define OCC_PROJ_OUT_DEFAULT(w, h) ((size_t)(w) * (size_t)(h) / 2u + 16384u)

typedef enum {
    OCC_PROJ_U16 = 0, /* uint16_t, metres = raw * depth_scale_m, 0 = no reading */
    OCC_PROJ_F32 = 1  /* float metres */
} occ_proj_format_t;

/* A depth image in the caller's memory (read only, any alignment, host byte order). Pixel
 * (i, j) is at data + j * row_stride_bytes + i * pixel_stride_bytes (a subsampled view of a
 * bigger image is a larger pixel stride). */
typedef struct {
    const void *data;
    occ_proj_format_t format;
    uint32_t width, height;    /* 1..65535 */
    size_t row_stride_bytes;   /* >= width * pixel_stride_bytes */
    size_t pixel_stride_bytes; /* >= 2 (U16) or 4 (F32) */
    float depth_scale_m;       /* U16: finite > 0 */
} occ_proj_image_t;

/* The camera: pinhole intrinsics in pixels of this image (optical frame x right, y down,
 * z forward), the rigid map_from_camera transform (r orthonormal within 1e-3, t the camera's
 * position in the map frame, metres), min/max range and the depth noise. */
typedef struct {
    float fx, fy, cx, cy;       /* fx, fy finite > 0; cx, cy finite */
    float r[3][3];              /* map_from_camera rotation: map = r * camera + t */
    occ_vec3_t t;
    float min_range_m;          /* finite >= 0 */
    float max_range_m;          /* finite > min_range_m */
    float noise_rel;            /* [0, 0.5]: margin in front of a surface m(d) = noise_rel * d */
} occ_proj_camera_t;

typedef struct {
    size_t pixels;            /* width * height */
    size_t pixels_no_reading; /* no reading (incl. non-finite |c|) */
    size_t pixels_too_close;  /* |c| < min_range_m */
    size_t pixels_beyond_max; /* |c| > max_range_m: no hit */
    size_t nodes_tested;      /* nodes the walk projected */
    occ_insert_result_t insert; /* points_integrated: pixels with a hit inside the map;
                                 * points_skipped: end points outside the map; rays_clipped:
                                 * pixels_beyond_max; voxels_*: voxel-level updates;
                                 * coarse_updated: whole free nodes; scratch_used */
} occ_proj_result_t;

/* Integrate one depth image by the rule above. `out` may be NULL; it gets the counters, also on
 * error. Errors (the map unchanged for all): OCC_ERR_ARG (NULL map/image/camera/data, bad size,
 * stride, format, scale, intrinsics, ranges, noise, a non-orthonormal r or non-finite t),
 * OCC_ERR_RANGE (camera outside the map), OCC_ERR_SCRATCH (scratch NULL or short: oom_count not
 * bumped), OCC_ERR_NOMEM (pools short: oom_count bumped). No automatic eviction. */
occ_err_t occ_map_insert_projective(occ_map_t *map, const occ_proj_image_t *image,
                                    const occ_proj_camera_t *camera, void *scratch,
                                    size_t scratch_bytes, occ_proj_result_t *out);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_map_insert_cloud, occ_map_insert_rays: stack <= 1,408 / 1,472 B; work: n_points rays x <= 3
 *       (ceil(max_ray / res) + 2) + 2 voxels, then one path per distinct voxel
 *   occ_map_insert_projective: stack <= 1,088 / 1,152 B (its context, tables, walk stack and
 *       lane arrays are in the scratch; the deepest chain is the tree pass updating a whole
 *       node's subtree); work: O(pixels) for the pixel pass, gap filling and pyramid, the near
 *       rays, the walk as stated above (at most every voxel of the frustum within max range),
 *       then one pass over the tree
 *   occ_ray_keys: stack <= 384 / 448 B; work: <= occ_ray_max_keys() keys, no map access
 *   occ_insert_scratch_bytes_scan: stack <= 256 / 320 B; work: O(n_points) (FAST_DISCRETE: + its
 *       coarse box)
 *   occ_insert_scratch_bytes: stack <= 256 / 320 B; work: O(1)
 *   occ_ray_max_keys, occ_insert_params_default: stack <= 128 / 192 B; work: O(1)
 */

#ifdef __cplusplus
}
#endif
#endif
