/* SPDX-License-Identifier: BSD-3-Clause */
/* occ_depth.h - depth images (depth cameras, multizone time-of-flight arrays) into the map.
 *
 * occ_map_insert_depth() takes a depth image as the sensor gives it, the camera's pinhole
 * intrinsics and its pose at the frame's time, and integrates it with the ray-casting
 * integrators of occ_integrate.h. Its result is, voxel for voxel, what back-projecting the
 * valid pixels (below, in this exact float arithmetic) and calling occ_map_insert_cloud() with
 * the same method gives; the call takes the image (not a cloud) so that an integrator that reads
 * the image itself (projection, issue 19) plugs into the same call.
 *
 * Camera optical frame: x right, y down, z forward (the image's u to the right, v down).
 * Pixel (u, v) (column u, row v, integer indices from the top left; cx, cy in the same indices)
 * with depth d (metres along the optical axis, z) back-projects to
 *     c = ( (u - cx) * d / fx,  (v - cy) * d / fy,  d )        (float, left to right)
 * and the map point is occ_pose_apply(map_from_camera, c); the ray's origin is
 * map_from_camera->p. The range of a pixel is |c| (Euclidean, not d).
 *
 * Pixels, each one on the step grid (u = 0, step, 2 step, ... < width; the same in v):
 *  - no reading: raw 0 (U16); 0, NaN, negative or -Inf (F32); a pixel whose |c| overflows
 *    float (absurd intrinsics): skipped, pixels_no_reading;
 *  - |c| < min_range_m: skipped, pixels_too_close (the sensor's blind zone: no free space);
 *  - |c| > max_range_m: cleared up to max range along the pixel's ray, no hit (OctoMap's
 *    max-range rule, insert_cloud's max_range_m), pixels_beyond_max; an F32 +Inf (REP 117 "no
 *    return within range") is such a pixel: it, and any depth beyond 1024 max_range_m (float
 *    overflow), is placed at depth d = 2 max_range_m on its ray;
 *  - otherwise: free up to the end point, the end point's voxel hit (hits win in one call).
 * The beyond-max decision in the map is insert_cloud's (|p - origin| in the map frame); the
 * counter uses |c| and can differ from insert's rays_clipped by a pixel within float rounding
 * of max range.
 *
 * OCC_INSERT_PROJECTIVE (insert->method): the frame is integrated by projection instead
 * (occ_map_insert_projective(), occ_integrate.h, whose rule then decides the map, not
 * insert_cloud's): the step grid is its image (its pixel (i, j) is this image's (i step, j step),
 * the intrinsics divided by the step), the pose its rotation matrix (occ_pose_rotate of the
 * axes) and position, insert->proj_noise_rel its depth noise; the counters as above (points =
 * sampled - no reading - too close; scratch_points 0; insert: the projective call's). Scratch:
 * occ_depth_scratch_bytes() with that method returns OCC_PROJ_SCRATCH_BYTES for the step grid
 * with OCC_PROJ_OUT_DEFAULT slots. The default method stays occ_insert_params_default()'s SIMPLE
 * (shared with occ_map_insert_cloud, which has no image); for depth images pass PROJECTIVE: the
 * fastest here (make bench: bench/projective), at the price of centre-based decisions (see
 * occ_integrate.h: a voxel free by projection, not by a crossing ray).
 *
 * Memory: no heap. The back-projected points (12 bytes per valid pixel, after up to 3 bytes of
 * alignment) are written at the start of `scratch`; the rest of it is insert_cloud's scratch.
 * Work: (pixels on the step grid) x (voxels per ray, at most 3 (ceil(max_range / res) + 2) + 2)
 * for traversal, plus insert_cloud's tree update; O(1) stack.
 */
#ifndef OCC_DEPTH_H_INCLUDED
#define OCC_DEPTH_H_INCLUDED

#include "occmap/occ_core.h"
#include "occmap/occ_integrate.h"
#include "occmap/occ_pose.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Largest width or height accepted (keeps every count and the scratch formula in 32 bits of
 * pixels). */
#define OCC_DEPTH_MAX_SIDE 65535u

typedef enum {
    OCC_DEPTH_U16 = 0, /* uint16_t per pixel, metres = raw * depth_scale_m, 0 = no reading */
    OCC_DEPTH_F32 = 1  /* float per pixel, metres (depth_scale_m unused) */
} occ_depth_format_t;

/* A depth image in the caller's memory (read only, any alignment, host byte order). */
typedef struct {
    const void *data;          /* pixel (0, 0); row v starts at data + v * row_stride_bytes */
    occ_depth_format_t format;
    uint32_t width, height;    /* pixels, 1..OCC_DEPTH_MAX_SIDE */
    size_t row_stride_bytes;   /* >= width * bytes per pixel (2 or 4) */
    float depth_scale_m;       /* U16: metres per raw unit (TUM PNG: 1 / 5000), finite > 0 */
} occ_depth_image_t;

/* Pinhole intrinsics in pixels (no distortion: pass a rectified / registered image). */
typedef struct {
    float fx, fy;  /* focal lengths, finite > 0 */
    float cx, cy;  /* principal point, finite (pixel indices, as above) */
} occ_pinhole_t;

typedef struct {
    occ_pinhole_t intrinsics;
    float min_range_m;    /* finite, >= 0: closer readings are skipped */
    float max_range_m;    /* finite, > min_range_m: farther readings clear to it, no hit */
    uint32_t pixel_step;  /* >= 1: every step-th pixel in u and in v (1 = all) */
} occ_depth_params_t;

typedef struct {
    size_t pixels_sampled;     /* pixels on the step grid */
    size_t pixels_no_reading;  /* 0 / NaN / negative / -Inf: skipped */
    size_t pixels_too_close;   /* range < min_range_m: skipped */
    size_t pixels_beyond_max;  /* range > max_range_m: cleared to max range, no hit */
    size_t points;             /* back-projected and passed on (sampled - no reading - close) */
    size_t scratch_points;     /* scratch bytes the points took (alignment included) */
    occ_insert_result_t insert; /* insert_cloud's counters for those points (scratch_used is
                                 * its own part; the whole call wrote scratch_points more) */
} occ_depth_result_t;

/* ---- scratch sizing ----------------------------------------------------------------------
 * OCC_DEPTH_PIXELS(w, h, step): pixels on the step grid, ceil(w / step) * ceil(h / step).
 * OCC_DEPTH_SCRATCH_BYTES(w, h, step, max_ray_voxels): enough scratch for SIMPLE, DISCRETE and
 * SUPER_RAYS (and FAST_DISCRETE with d = 0), for a w x h image at that step whose rays are
 * clipped to a max range R at resolution res: pass max_ray_voxels = ceil(R / res) + 2. The
 * points (3 + 12 per pixel) plus OCC_INSERT_SCRATCH_BYTES for that many points. Integer
 * constant expressions when the arguments are (firmware: `static uint8_t scratch[...]`);
 * OCC_DEPTH_SCRATCH_FITS says whether the product fits a size_t. Example: an 8x8 ToF array at
 * step 1, 4 m at 0.1 m: OCC_DEPTH_SCRATCH_BYTES(8, 8, 1, 42). */
#define OCC_DEPTH_PIXELS(w, h, step)                                   \
    ((((size_t)(w) + (size_t)(step) - 1u) / (size_t)(step)) *         \
     (((size_t)(h) + (size_t)(step) - 1u) / (size_t)(step)))
#define OCC_DEPTH_SCRATCH_BYTES(w, h, step, max_ray_voxels)            \
    (3u + 12u * OCC_DEPTH_PIXELS(w, h, step) +                         \
     OCC_INSERT_SCRATCH_BYTES(OCC_DEPTH_PIXELS(w, h, step), max_ray_voxels))
#define OCC_DEPTH_SCRATCH_FITS(w, h, step, max_ray_voxels)                                  \
    (OCC_INSERT_SCRATCH_FITS(OCC_DEPTH_PIXELS(w, h, step), max_ray_voxels) &&              \
     OCC_DEPTH_PIXELS(w, h, step) <=                                                       \
         (SIZE_MAX - OCC_INSERT_SCRATCH_BYTES(OCC_DEPTH_PIXELS(w, h, step), max_ray_voxels) - \
          3u) / 12u)

/* The same bound at run time for this map's resolution: OCC_DEPTH_SCRATCH_BYTES(width, height,
 * pixel_step, ceil(max_range_m / res) + 2) with this build's fixed term; FAST_DISCRETE with
 * d > 0 needs more (its coarse set, occ_insert_scratch_bytes_scan()). Returns 0 for NULL, zero
 * sizes or step, sides above OCC_DEPTH_MAX_SIDE or a max range that is not finite > 0;
 * saturates at SIZE_MAX. O(1). */
size_t occ_depth_scratch_bytes(const occ_map_t *map, uint32_t width, uint32_t height,
                               uint32_t pixel_step, float max_range_m,
                               const occ_insert_params_t *insert);

/* Integrate one depth frame taken at pose map_from_camera (camera optical frame, see above).
 * `insert` chooses the method and its knobs and the automatic eviction exactly as for
 * occ_map_insert_cloud(); its max_range_m is ignored (depth->max_range_m is used).
 * `scratch` (any alignment, used only while the call runs) as above; `out` may be NULL and gets
 * the counters, also on error.
 * Errors (the map unchanged for all of them; auto_evict as in insert_cloud):
 *  - OCC_ERR_ARG: NULL map / image / data / depth / pose / insert; width or height 0 or above
 *    OCC_DEPTH_MAX_SIDE; row stride below width * bytes per pixel; bad format; U16 scale not
 *    finite > 0; fx, fy not finite > 0; cx, cy not finite; min range not finite >= 0; max range
 *    not finite or <= min range; step 0; a pose occ_pose_check() refuses; what insert_cloud
 *    refuses as OCC_ERR_ARG (bad method, fast_d).
 *  - OCC_ERR_RANGE: the camera outside the map.
 *  - OCC_ERR_SCRATCH: the scratch cannot hold the points or insert_cloud's sets (oom_count not
 *    bumped); OCC_ERR_NOMEM: the pools cannot hold the result (oom_count bumped).
 * Work and memory: see the top of this header. */
occ_err_t occ_map_insert_depth(occ_map_t *map, const occ_depth_image_t *image,
                               const occ_depth_params_t *depth,
                               const occ_pose_t *map_from_camera,
                               const occ_insert_params_t *insert, void *scratch,
                               size_t scratch_bytes, occ_depth_result_t *out);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_map_insert_depth: stack <= 1,472 / 1,536 B; work: ray-cast methods: pixels on the step
 *       grid x <= 3 (ceil(max_range / res) + 2) + 2 voxels each, then the tree update (one path
 *       per distinct voxel); OCC_INSERT_PROJECTIVE: occ_map_insert_projective's (occ_integrate.h)
 *   occ_depth_scratch_bytes: stack <= 128 / 128 B; work: O(1)
 */

#ifdef __cplusplus
}
#endif
#endif
