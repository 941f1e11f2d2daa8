/* SPDX-License-Identifier: BSD-3-Clause */
/* occ_ranges.h - range beams (rangefinders, sonar, proximity arrays, time-of-flight zones) into
 * the map: one beam per reading, in the sensor's frame, integrated with the sensor's pose.
 *
 * Semantics of one beam (distance d, limits [min, max)):
 *  - min <= d < max: free space up to d, a hit at d (the voxel at the end point is occupied);
 *  - d >= max ("no return within max"): free space up to max, no hit;
 *  - d < min, NaN/Inf, or valid == false: skipped, counted, nothing integrated for it.
 * Work is bounded per call: beams x rays per beam x (3 (max / resolution + 2) + 2) voxels
 * (src/sensors/ranges.c; the call's contract below).
 *
 * Inf is not "no return" (ROS REP 117 reads +Inf so): a non-finite distance is skipped, so
 * that a broken computation never clears space (fail closed). A driver that knows "nothing
 * within max" passes distance = max_m (or more).
 *
 * Cones (cone_half_rad > 0: sonar, a wide time-of-flight zone) are sampled by
 * OCC_RANGES_CONE_RAYS fixed rays: the axis and a ring of OCC_RANGES_CONE_RING rays at the
 * half-angle. With unit axis a, let e be the sensor axis (x, y, z) on which a has its smallest
 * |component| (the first on ties), u = normalise(a x e), v = a x u; ring ray j (0..RING-1) is
 *   cos(h) a + sin(h) (cos(2 pi j / RING) u + sin(2 pi j / RING) v).
 * (For a = +x: e = y, u = +z, v = -y: the ring starts at +z and turns towards -y.) Every ray of
 * the cone gets the beam's distance: all clear up to d (max for no return), and on a return
 * ALL of them mark their end as occupied. A cone's return says only that something lies at d
 * somewhere on the cap; marking every sample of the cap keeps an off-axis obstacle in the map
 * (fail closed for avoidance) at the price of over-marking the cap, which later readings from
 * other poses clear. Space between the samples is not touched (it stays what it was).
 */
#ifndef OCC_OCC_RANGES_H_INCLUDED
#define OCC_OCC_RANGES_H_INCLUDED

#include "occmap/occ_core.h"
#include "occmap/occ_integrate.h"
#include "occmap/occ_pose.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    occ_vec3_t dir;          /* sensor frame, unit length (normalised by the call if not) */
    float distance_m;        /* measured distance along dir */
    float min_m, max_m;      /* the sensor's valid interval, 0 <= min < max */
    float cone_half_rad;     /* 0: a thin beam; > 0: a cone, sampled (see occ_map_insert_ranges) */
    bool valid;              /* false: the sensor flagged the reading invalid (skipped) */
} occ_range_beam_t;

/* The cone sampling (see the top): the axis plus a ring at the half-angle. */
#define OCC_RANGES_CONE_RING 8u
#define OCC_RANGES_CONE_RAYS (1u + OCC_RANGES_CONE_RING)
/* Largest cone half-angle accepted (86 degrees: a cone opens forward). */
#define OCC_RANGES_CONE_MAX_RAD 1.5f

/* ---- scratch at compile time (firmware: `static uint8_t scratch[...]`) ----------------------
 * OCC_RANGES_SCRATCH_BYTES(n_beams, rays_per_beam, max_ray_voxels): enough scratch for any call
 * with up to n_beams beams, rays_per_beam = 1 when no beam is a cone, else OCC_RANGES_CONE_RAYS,
 * and max_ray_voxels = ceil(largest max_m / resolution) + 2. It is the integrator's bound for
 * the rays (occ_integrate.h) plus the rays' end points and hit flags (and 3 bytes of
 * alignment). Integer constant expressions when the arguments are; check the product with
 * OCC_INSERT_SCRATCH_FITS(n_beams * rays_per_beam, max_ray_voxels). SIMPLE, DISCRETE,
 * SUPER_RAYS, FAST_DISCRETE with d = 0 (as OCC_INSERT_SCRATCH_BYTES). */
#define OCC_RANGES_SCRATCH_PER_RAY (sizeof(occ_vec3_t) + sizeof(bool))
#define OCC_RANGES_SCRATCH_BYTES(n_beams, rays_per_beam, max_ray_voxels)                    \
    (3u + (size_t)(n_beams) * (size_t)(rays_per_beam) * OCC_RANGES_SCRATCH_PER_RAY +       \
     OCC_INSERT_SCRATCH_BYTES((size_t)(n_beams) * (size_t)(rays_per_beam), max_ray_voxels))

/* What one occ_map_insert_ranges() call did. Every beam lands in exactly one beams_ counter. */
typedef struct {
    size_t beams_hit;        /* min <= d < max: cleared up to d, hit at d */
    size_t beams_no_return;  /* d >= max: cleared up to max, no hit */
    size_t beams_invalid;    /* valid == false: skipped */
    size_t beams_too_close;  /* d < min: skipped */
    size_t beams_bad;        /* d NaN or +-Inf: skipped */
    size_t rays;             /* rays handed to the integrator (1 per thin beam, CONE_RAYS per
                              * cone) */
    occ_insert_result_t insert; /* the integrator's counters for those rays (a ray whose end
                                 * lies outside the map is skipped there: insert.points_skipped) */
} occ_ranges_result_t;

/* Scratch that makes occ_map_insert_ranges() never fail for lack of it for these beams (what
 * the macro gives for the beams that will cast rays and their largest max_m). 0 for NULL map
 * or params or beams == NULL with n > 0; saturates at SIZE_MAX. O(n). */
size_t occ_ranges_scratch_bytes(const occ_map_t *map, const occ_range_beam_t *beams,
                                size_t n_beams, const occ_insert_params_t *params);

/* Integrate n_beams readings of one sensor taken at one time: beams in the sensor frame, the
 * sensor's pose map_from_sensor (occ_pose.h; the rays start at its origin). Each beam becomes
 * rays as the top of this header says; all rays of the call are one scan of
 * occ_map_insert_rays() (occ_integrate.h: each voxel updated at most once, a hit wins over
 * free, the method and options of `params`, whose max_range_m - when > 0 - clips every ray
 * further, as insert_cloud does). A beam's hit equals occ_map_insert_cloud() of its end point
 * map_from_sensor(dir * d); a no-return beam equals insert_cloud of a point beyond max_m along
 * dir with max_range_m = max_m (up to float rounding of the clipped end: here the end is
 * map_from_sensor(dir * max_m)).
 * Beams with valid == false are skipped unread. For the others the configuration must hold:
 * dir finite and |dir| >= 1e-6 (normalised here), min_m and max_m finite with
 * 0 <= min_m < max_m, cone_half_rad finite in [0, OCC_RANGES_CONE_MAX_RAD].
 * `scratch` (any alignment, used only during the call) holds the rays' ends and flags, then
 * the integrator's sets: see OCC_RANGES_SCRATCH_BYTES / occ_ranges_scratch_bytes(). `out`
 * (may be NULL) gets the counters, also on error.
 * Errors, each leaving the map exactly as it was: OCC_ERR_ARG (NULL map / pose / params,
 * beams NULL with n_beams > 0, a bad pose (occ_pose_check), a bad beam configuration, bad
 * params as insert_cloud), OCC_ERR_RANGE (the sensor origin outside the map), OCC_ERR_SCRATCH,
 * OCC_ERR_NOMEM (as insert_cloud; with params->auto_evict as insert_cloud says).
 * Work: O(n_beams) to build the rays, then insert_cloud's for at most n_beams x
 * OCC_RANGES_CONE_RAYS rays of at most 3 (max_m / resolution + 2) + 2 voxels each. No heap. */
occ_err_t occ_map_insert_ranges(occ_map_t *map, const occ_pose_t *map_from_sensor,
                                const occ_range_beam_t *beams, size_t n_beams,
                                const occ_insert_params_t *params, void *scratch,
                                size_t scratch_bytes, occ_ranges_result_t *out);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_map_insert_ranges: stack <= 1,472 / 1,536 B; work: beams x rays per beam x <= 3 (max / res
 *       + 2) + 2 voxels, then one path per distinct voxel
 *   occ_ranges_scratch_bytes: stack <= 128 / 192 B; work: O(n_beams)
 */

#ifdef __cplusplus
}
#endif
#endif
