/* SPDX-License-Identifier: BSD-3-Clause */
/* run_ranges.h - range messages other components send on the link (DISTANCE_SENSOR,
 * OBSTACLE_DISTANCE, OBSTACLE_DISTANCE_3D; occ_mavlink_ranges.h) into `occmap run`'s map: the
 * link thread translates them and queues them stamped on the autopilot's clock - with their own
 * time_boot_ms / time_usec when it is a time on that clock (TIMESYNC known, and the stamp mapped
 * to our clock through its offset, as the poses are, is at most --sensor-timeout-ms before the
 * arrival and not after it), else with their arrival (local receive time + clock offset: a
 * companion sensor's own time_boot is not the autopilot's clock; DroneCAN readings always); the
 * mapping thread integrates each with the pose at that time. */
#ifndef OCC_TOOLS_RUN_RANGES_H_INCLUDED
#define OCC_TOOLS_RUN_RANGES_H_INCLUDED

#include "run.h"
#include "occmap/occ_mavlink_ranges.h"

#define RUN_RANGES_QUEUE 64u

typedef struct {
    occ_mav_beams_t beams;
    uint64_t remote_us, local_us;    /* autopilot time of the reading; local arrival */
    int source;                      /* RUN_SRC_MAVLINK or RUN_SRC_CAN (its staleness) */
} run_range_msg_t;

typedef struct run_ranges_s {
    run_range_msg_t q[RUN_RANGES_QUEUE];
    size_t head, n;
    uint64_t own_window_us;          /* --sensor-timeout-ms: how old an own stamp may be */
    uint64_t queued, queue_full, no_clock; /* link side */
    uint64_t stamped_own, stamped_arrival; /* queued with their own stamp / their arrival */
    uint64_t integrated, no_pose, nomem, errors; /* mapping side */
} run_ranges_t;

/* Link thread: a parsed frame from another component; true if it was a range message (queued
 * or counted). Takes st->lock. */
bool run_ranges_take(run_state_t *st, run_ranges_t *r, occ_mav_ranges_t *tr,
                     const occ_mav_frame_t *f, uint64_t now);

/* Link thread: queue beams of input `source` (RUN_SRC_MAVLINK, or another front end's, e.g.
 * RUN_SRC_CAN) that arrived at local `now`, stamped with the autopilot's time then. Takes
 * st->lock. */
void run_ranges_queue(run_state_t *st, run_ranges_t *r, const occ_mav_beams_t *beams,
                      uint64_t now, int source);

/* Mapping thread: integrate every queued message whose pose is known (or give it up after
 * --pose-timeout-ms). */
void run_ranges_service(run_mapper_t *m);
/* Mapping thread, at the end of the run (the link stopped): integrate what has its pose, and
 * count what is still waiting for a pose after its time as dropped (no_pose): none left queued. */
void run_ranges_finish(run_mapper_t *m);

/* Telemetry members ("ranges": {...}); caller holds st->lock. */
void run_ranges_print(FILE *f, const run_ranges_t *r, const occ_mav_ranges_t *tr);

#endif
