/* SPDX-License-Identifier: BSD-3-Clause */
/* mavlink_obstacle3d.c - the OBSTACLE_DISTANCE_3D encoder (occ_mavlink_run.h). */
#include "occmap/occ_mavlink_run.h"

#include <math.h>
#include <string.h>

#include "ardupilotmega/mavlink.h"

size_t occ_mav_encode_obstacle_3d(occ_mav_sender_t *tx, const occ_mav_obstacle_3d_t *m,
                                  uint8_t *out, size_t cap)
{
    if (m == NULL || !isfinite(m->x) || !isfinite(m->y) || !isfinite(m->z) ||
        !isfinite(m->min_distance) || !isfinite(m->max_distance)) {
        return 0;
    }
    mavlink_obstacle_distance_3d_t s;
    memset(&s, 0, sizeof s);
    s.time_boot_ms = m->time_boot_ms;
    s.sensor_type = m->sensor_type;
    s.frame = m->frame;
    s.obstacle_id = m->obstacle_id;
    s.x = m->x;
    s.y = m->y;
    s.z = m->z;
    s.min_distance = m->min_distance;
    s.max_distance = m->max_distance;
    return occ_mav_finalize(tx, MAVLINK_MSG_ID_OBSTACLE_DISTANCE_3D, (const uint8_t *)&s,
                            MAVLINK_MSG_ID_OBSTACLE_DISTANCE_3D_LEN, out, cap);
}
