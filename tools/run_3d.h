/* SPDX-License-Identifier: BSD-3-Clause */
/* run_3d.h - `occmap run --3d`: the nearest occupied space above and below the sectors' band,
 * sent as OBSTACLE_DISTANCE_3D (one message per side, MAV_FRAME_BODY_FRD) after each
 * OBSTACLE_DISTANCE, from the same map view and pose. Host only (a heap buffer for the search). */
#ifndef OCC_TOOLS_RUN_3D_H_INCLUDED
#define OCC_TOOLS_RUN_3D_H_INCLUDED

#include "occmap/occ_query.h"
#include "occmap/occ_sectors.h"

typedef struct {
    bool found;          /* an occupied point on this side within R */
    occ_vec3_t map_m;    /* that point (map frame, metres): the node's nearest point */
    occ_vec3_t frd_m;    /* the same from the vehicle in body FRD (full attitude), metres */
    float dist_m;
} run_3d_side_t;

typedef struct {
    run_3d_side_t above, below;
    occ_err_t err;       /* OCC_OK, or the search's error (both sides then fail closed) */
} run_3d_t;

/* Sides (map's up axis u: +z in an ENU map, -z in a NED one; vehicle at u0):
 *  above: occupied space with u >= u0 + band_above_m; below: u <= u0 - band_below_m (the
 *  configured band, without the ground rule: the floor under a vehicle higher than band_below
 *  is "below"). Each side reports the nearest point (Euclidean, from the vehicle) of an
 *  OCCUPIED node's part on that side, searched within R = max_distance_cm / 100 m by
 *  occ_nearest_*; unknown space is not reported (the message has no "unknown").
 * Exact: nodes come nearest-first and a node's part on one side is never nearer than the node.
 * Fail closed: on an error (bad pose, map written during the call, the search buffer full before
 * both sides were decided) both sides are found at min_distance_cm straight up / down.
 * `buf` of `cap` entries is the search's scratch. Reads the map only. */
void run_3d_nearest(const occ_map_t *map, const occ_pose_t *map_from_body,
                    const occ_sectors_config_t *cfg, occ_nearest_entry_t *buf, size_t cap,
                    run_3d_t *out);

#endif
