/* SPDX-License-Identifier: BSD-3-Clause */
/* run_link.h - the link side of `occmap run` (main thread): MAVLink in (poses into the history,
 * TIMESYNC, the feed's autopilot bookkeeping), out (OBSTACLE_DISTANCE from the live map,
 * HEARTBEAT with the loop's status, SET_MESSAGE_INTERVAL, TIMESYNC, STATUSTEXT), the feed log
 * and the telemetry lines. */
#ifndef OCC_TOOLS_RUN_LINK_H_INCLUDED
#define OCC_TOOLS_RUN_LINK_H_INCLUDED

#include "run.h"
#include "run_3d.h"
#include "occmap/occ_mavlink_ranges.h"

typedef struct {
    uint64_t sent;                  /* OBSTACLE_DISTANCE sent */
    uint64_t last_us;               /* local time of the last one */
    uint32_t *interval_us;          /* every period between two, in order */
    size_t n, cap;
} run_feed_timing_t;

typedef struct run_link_s {
    const run_opts_t *opt;
    run_state_t *st;
    run_mapguard_t *guard;
    const run_depth_t *depth;       /* NULL without --depth-dir */
    occ_link_t *link;
    occ_mav_feed_t *feed;
    occ_mav_parser_t parser;        /* our own pass over the bytes (poses, TIMESYNC) */
    occ_mav_pose_rx_t prx;
    occ_mav_ranges_t ranges_tr;     /* range messages of other components -> beams */
    occ_mav_sender_t tx;            /* TIMESYNC and STATUSTEXT (the feed has its own) */
    FILE *stats, *feed_log;
    uint64_t t0, next_stats, next_timesync;
    uint32_t timesync_sent, refusals_logged, statustexts;
    bool ever_sent, stale, autopilot_logged;
    const char *stale_why;          /* what went stale last: "pose" or an input's name */
    uint64_t od_seq;
    run_feed_timing_t ft;
    bool done_seen;                 /* the mapper finished: */
    uint64_t done_sent, done_us;    /* obstacle count and time then (--exit-after-depth) */
    occ_nearest_entry_t *nearest;   /* --3d: the search's scratch (NULL without --3d) */
    size_t nearest_cap;
    run_3d_t last_3d;               /* --3d: what went out with the last OBSTACLE_DISTANCE */
    uint64_t sent_3d;               /* OBSTACLE_DISTANCE_3D sent */
    struct run_can_s *can;          /* --can: the DroneCAN node (run_can.h), else NULL */
} run_link_t;

/* Until stop, --duration or --exit-after-depth. 0, or 1 after a link error. */
int run_link_loop(run_link_t *l);

/* Telemetry (run_stats.c): the config line, one line a second, the final line. */
void run_stats_config(run_link_t *l);
void run_stats_line(run_link_t *l, uint64_t now, const char *key, bool map_check_ok);

#endif
