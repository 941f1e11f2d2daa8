/* SPDX-License-Identifier: BSD-3-Clause */
/* occ_tlog_ranges.h - the range readings of a MAVLink telemetry log into a map, with the log's
 * own poses (port/posix/tlog_ranges.c; host only: malloc). Clock: the log stamps (occ_tlog.h).
 */
#ifndef OCC_TLOG_RANGES_H_INCLUDED
#define OCC_TLOG_RANGES_H_INCLUDED

#include "occmap/host/occ_tlog.h"
#include "occmap/occ_mavlink_ranges.h"
#include "occmap/occ_ranges.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- range readings of a log into a map ----------------------------------------------------- */
typedef struct {
    uint8_t autopilot_sysid, autopilot_compid; /* poses only from here; default 1, 1 */
    uint8_t own_sysid, own_compid;  /* our own messages, never integrated; default 1, 196 (what
                                     * `occmap feed` sends as) */
    uint64_t max_gap_us;            /* pose history: samples further apart do not interpolate;
                                     * default 1 s */
    uint64_t max_extrapolate_us;    /* readings after the last pose; default 0.2 s */
} occ_tlog_ranges_config_t;

typedef struct {
    uint64_t records, frames_ok, frames_bad;
    uint32_t attitudes;             /* ATTITUDE frames from the autopilot */
    uint32_t positions;             /* LOCAL_POSITION_NED / GLOBAL_POSITION_INT from it */
    uint32_t poses;                 /* poses in the history (attitude + position) */
    uint32_t position_source;       /* 0 none, 32 LOCAL_POSITION_NED, 33 GLOBAL_POSITION_INT */
    bool no_horizontal_fix;         /* GLOBAL_POSITION_INT had lat = lon = 0 (no estimate): the
                                     * vehicle is taken as horizontally still at the origin */
    uint32_t range_msgs;            /* range messages translated */
    uint32_t no_pose;               /* ... refused: no pose at their time (not integrated) */
    uint32_t insert_errors;         /* ... refused by the insert (nothing integrated) */
    uint32_t integrated;            /* ... integrated */
    uint64_t t_first_us, t_last_us; /* log stamps of the first and last integrated reading */
    occ_mav_ranges_counters_t tr;   /* the translator's counters */
    occ_ranges_result_t sum;        /* the inserts' results, summed (sum.insert: the
                                     * integrator's counters) */
} occ_tlog_ranges_stats_t;

/* Called for every integrated reading (may be NULL): its stamp, beams and sensor pose. */
typedef void (*occ_tlog_beams_fn)(void *user, uint64_t stamp_us, const occ_mav_beams_t *beams,
                                  const occ_pose_t *map_from_sensor);

occ_tlog_ranges_config_t occ_tlog_ranges_config_default(void);

/* Integrate the DISTANCE_SENSOR / OBSTACLE_DISTANCE / OBSTACLE_DISTANCE_3D readings of a log
 * into `map` with the vehicle's poses from the same log. Two passes: first every pose -
 * ATTITUDE (roll, pitch, yaw) with the latest position (LOCAL_POSITION_NED when the log has it,
 * else GLOBAL_POSITION_INT: north/east from the first fix, down = -relative_alt) - into a pose
 * history sized for the whole log (malloc); then each reading at its log stamp, its pose
 * interpolated between the attitudes around it, through occ_map_insert_ranges() (`params`,
 * scratch malloc'ed to occ_ranges_scratch_bytes(), grown when a message needs more). OCC_ERR_IO (cannot read), OCC_ERR_NOMEM, or the first
 * error other than a refused reading (each refusal is counted in `st`). */
occ_err_t occ_tlog_integrate_ranges(occ_map_t *map, const char *path,
                                    const occ_tlog_ranges_config_t *cfg,
                                    const occ_insert_params_t *params, occ_tlog_beams_fn on_beams,
                                    void *user, occ_tlog_ranges_stats_t *st, char *msg,
                                    size_t msg_len);

#ifdef __cplusplus
}
#endif
#endif
