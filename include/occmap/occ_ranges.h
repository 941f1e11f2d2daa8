/* occ_ranges.h - range beams (rangefinders, sonar, proximity arrays, time-of-flight zones) into
 * the map: one beam per reading, in the sensor's frame, integrated with the sensor's pose.
 *
 * Semantics of one beam (distance d, limits [min, max)):
 *  - min <= d < max: free space up to d, a hit at d (the voxel at the end point is occupied);
 *  - d >= max ("no return within max"): free space up to max, no hit;
 *  - d < min, NaN/Inf, or valid == false: skipped, counted, nothing integrated for it.
 * Work is bounded per call: beams x rays per beam x (max / resolution + 2) voxels.
 * Interface fixed by the lead; the implementation lives in src/sensors/ranges.c.
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

#ifdef __cplusplus
}
#endif
#endif
