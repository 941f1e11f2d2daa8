/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_sectors.h - what the vehicle is told: the nearest obstacle per horizontal sector (src/sectors/sectors.c).
 * Pure C99, no OS, no heap; uses the public map API only.
 *
 * Frames (the pose is the library's one pose type, occ_pose.h)
 *  - ENU map (default): x east, y north, z up (OctoMap's data); the pose is map_from_body with
 *    the body FLU (x forward, y left, z up). From an autopilot: occ_pose_from_ned(
 *    LOCAL_POSITION_NED x y z, ATTITUDE_QUATERNION or occ_quat_from_euler(ATTITUDE roll, pitch,
 *    yaw)).
 *  - NED map (cfg.map_ned; occmap feed --map-frame ned): the map is x north, y east, z down and
 *    the pose is read as map(NED) <- body(FRD): p = (north, east, down) as LOCAL_POSITION_NED
 *    sends it, q the autopilot's attitude as it sends it (ATTITUDE_QUATERNION q1..q4, or
 *    occ_quat_from_euler(ATTITUDE roll, pitch, yaw)); occ_pose_to_ned() of an ENU pose gives
 *    the same. The band's "above" side is then -z.
 *  - The heading is occ_pose_yaw(pose): the body x axis's direction seen from above (ENU:
 *    0 = east, counter-clockwise; NED: 0 = north, clockwise). Sectors are in the vehicle's
 *    heading frame, MAV_FRAME_BODY_FRD seen from above: body angle 0 is forward, angles grow
 *    clockwise. Sector i is centred on body angle angle_offset_deg + i * increment_deg and
 *    covers [centre - inc/2, centre + inc/2).
 *  - Roll and pitch do not tilt anything: the band is about the vehicle's position on the map's
 *    vertical axis and the sectors are horizontal slices (ArduPilot files OBSTACLE_DISTANCE in
 *    its 0-degree pitch layer, PX4 in its horizontal bins), so a rolled or pitched vehicle gets
 *    the sectors of the level vehicle with the same heading and position. (Pitched within
 *    ~0.06 deg of +-90 the heading is the one occ_quat_to_euler() states.)
 *
 * What a sector reports (the exact geometric definition the tests check by brute force)
 *  - The vertical band is [z - band_below_m, z + band_above_m) ("below" is -z in an ENU map, +z
 *    in a NED one); a voxel takes part when its z extent overlaps the band. Space outside the map
 *    volume counts as UNKNOWN.
 *  - The ground (ignore_ground, on by default; ArduPilot's proximity library has a rule of the
 *    same kind): walking down the vehicle's own voxel column from the voxel that holds the
 *    vehicle to the band's lower edge, the first OCCUPIED voxel is the ground the vehicle stands
 *    on or flies over. The band's lower edge then rises to ground_clearance_m above that voxel's
 *    top face, so the floor (and anything lower than ground_clearance_m above it) is not an
 *    obstacle, while a wall or a step higher than that is. If the lifted edge would reach the
 *    band's upper edge, the band stays as configured (the ground is then reported: fail safe).
 *    An unobserved column under the vehicle finds no ground: then the floor around the vehicle
 *    is inside the band when band_below_m reaches it.
 *  - For each sector: d_occ = the smallest horizontal distance from the vehicle to a point of an
 *    OCCUPIED voxel's footprint that lies inside the sector's wedge; d_unk the same for UNKNOWN
 *    voxels (never observed, or in the band between free_max and occupied_min).
 *    R = max_distance_cm / 100 m is the search radius.
 *  - d_occ <= d_unk and d_occ < R : obstacle: distance in cm (floor), clamped to
 *    [min_distance_cm, max_distance_cm].
 *  - d_unk < d_occ and d_unk < R  : the view is blocked by unknown space. Unknown space is never
 *    reported as free: unknown_as_distance = false reports UINT16_MAX (MAVLink's "unknown"),
 *    true reports d_unk clamped like an obstacle (conservative: unexplored space is a wall).
 *    What each autopilot does with them is in occ_mavlink.h and the README.
 *  - otherwise (everything within R observed free): max_distance_cm + 1, MAVLink's "no obstacle"
 *    (max_distance itself would be an obstacle at the range limit to ArduPilot).
 *  A value is never 0 (min_distance_cm >= 1). A vehicle standing in unknown space gets
 *  d_unk = 0 in every sector.
 *
 * Fail closed: on every error return of occ_sectors_compute() (bad arguments included, when
 * `out` is not NULL) all OCC_SECTORS_MAX values of out->distance_cm hold the unsafe answer, an
 * obstacle at cfg->min_distance_cm (1 cm when cfg is NULL or has min 0), d_occ_m / d_unk_m are 0
 * and out->n is 0. A caller that ignores the error code reads "obstacle", never "clear".
 */
#ifndef OCC_OCC_SECTORS_H_INCLUDED
#define OCC_OCC_SECTORS_H_INCLUDED

#include "occmap/occ_core.h"
#include "occmap/occ_pose.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OCC_SECTORS_MAX 72u
#define OCC_SECTORS_UNKNOWN UINT16_MAX

typedef struct {
    uint8_t n_sectors;             /* 1..72 */
    float increment_deg;           /* (0, 90], n_sectors * increment_deg <= 360 */
    float angle_offset_deg;        /* body angle of sector 0's centre, clockwise positive; 0 by
                                    * default (the MAVLink feed's default is -20: occ_mavlink.h) */
    float band_below_m, band_above_m; /* vertical band around the vehicle, metres >= 0, sum > 0 */
    uint16_t min_distance_cm, max_distance_cm; /* 1 <= min < max <= 65533 */
    bool unknown_as_distance;      /* see the header comment: false -> UINT16_MAX */
    bool map_ned;                  /* false: ENU map (default); true: NED map and pose */
    bool ignore_ground;            /* the ground rule above; default true */
    float ground_clearance_m;      /* >= 0, default 0.1: height above the ground not reported */
} occ_sectors_config_t;

/* Largest max_distance_cm: max + 1 ("no obstacle") stays below UINT16_MAX ("unknown"). */
#define OCC_SECTORS_MAX_DISTANCE_CM 65533u

/* Work space of one computation (internal): the depth-first stack of pending nodes (at most 7
 * per level plus the root) and per-sector state. Lives in occ_sectors_t so the call needs only
 * a small C stack frame. */
#define OCC_SECTORS_STACK (8u * (OCC_MAX_DEPTH + 2u))
typedef struct {
    occ_node_t node;   /* read when pushed: popping costs no tree descent */
    float dmin;
} occ_sectors_item_t;

typedef struct {
    uint8_t n;                              /* sectors filled */
    uint16_t distance_cm[OCC_SECTORS_MAX];  /* obstacle clamped to [min,max]; max + 1 = observed
                                             * free; UINT16_MAX = unknown; never 0 */
    /* Diagnostics of the last call. */
    uint32_t nodes_read;                    /* nodes visited (popped from the stack) */
    uint32_t leaves_used;                   /* uniform nodes folded into the sectors */
    /* Metres, per sector, of the last call (OCC_SECTORS_FAR when nothing within R). */
    float d_occ_m[OCC_SECTORS_MAX];
    float d_unk_m[OCC_SECTORS_MAX];
    /* Internal scratch. */
    float ray_c[OCC_SECTORS_MAX + 1], ray_s[OCC_SECTORS_MAX + 1];
    occ_sectors_item_t stack[OCC_SECTORS_STACK];
} occ_sectors_t;

#define OCC_SECTORS_FAR 1.0e30f

/* Defaults: 72 sectors of 5 degrees, offset 0 (the MAVLink feed uses -20, see occ_mavlink.h),
 * band +-0.5 m with the ground rule (clearance 0.1 m), 20..2000 cm, unknown -> UINT16_MAX. */
occ_sectors_config_t occ_sectors_config_default(void);

/* OCC_OK if `cfg` is usable, else OCC_ERR_ARG (ranges as documented on the fields). O(1). */
occ_err_t occ_sectors_config_check(const occ_sectors_config_t *cfg);

/* Fill out->distance_cm[0..n_sectors-1] (and out->n, d_occ_m, d_unk_m) for the vehicle at
 * `map_from_body` (see "Frames": ENU <- FLU, or NED <- FRD with cfg.map_ned).
 * Walks the octree top-down with occ_map_read_key(), nearest node first, and skips a node when
 * it lies outside the search cylinder, holds only free space, or is farther than what every
 * sector it spans already found (d_occ_m / d_unk_m are exact where they decide the result).
 * Cost grows with the nodes between the vehicle and the nearest non-free space per sector, not
 * with R^2 (what it costs on a real map: README, Limits); each read is an O(depth) descent from
 * the root.
 * Stack: < 512 bytes (the work space is in `out`). Never writes the map; reads no memory other
 * than map, pose, cfg and out.
 * The ground rule adds at most band_below_m / resolution + 1 voxel reads.
 * Errors: OCC_ERR_ARG (NULL, a pose occ_pose_check() refuses, bad cfg), OCC_ERR_RANGE (the vehicle outside the
 * map volume), OCC_ERR_NOMEM (the walk's stack in `out` is full: cannot happen with
 * OCC_SECTORS_STACK, checked anyway), or the error of occ_map_node_child() (a map written
 * during the call). On error `out` holds the unsafe answer (see "Fail closed" above). */
occ_err_t occ_sectors_compute(const occ_map_t *map, const occ_pose_t *map_from_body,
                              const occ_sectors_config_t *cfg, occ_sectors_t *out);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call. Callbacks (CAN tx, I/O
 * sinks) add their own stack. Instruction counts on a real map: README, Firmware.
 *   occ_sectors_compute: stack <= 832 / 896 B; work: nodes between the vehicle and the nearest
 *       non-free space per sector, each one descent (+ band_below / res + 1 voxel reads)
 *   occ_sectors_config_default, occ_sectors_config_check: stack <= 64 / 64 B; work: O(1)
 */

#ifdef __cplusplus
}
#endif
#endif
