/* SPDX-License-Identifier: BSD-3-Clause */
/* run.h - what the parts of `occmap run` share (issue 21): the options, the state the link
 * thread (main: MAVLink in and out, telemetry) and the mapping thread (sensor replay, the map's
 * one writer) exchange, and each part's entry points. Host only (POSIX threads, stdio, malloc).
 *
 * Locks: the map through run_mapguard.h only; everything else in run_state_t under `lock`
 * (held for copies and counter updates, never across an integration or an i/o call). */
#ifndef OCC_TOOLS_RUN_H_INCLUDED
#define OCC_TOOLS_RUN_H_INCLUDED

#include <pthread.h>
#include <stdio.h>

#include "feed_args.h"
#include "run_mapguard.h"
#include "occmap/occ_depth.h"
#include "occmap/occ_dronecan.h"
#include "occmap/occ_evict.h"
#include "occmap/occ_mavlink_run.h"
#include "occmap/host/occ_tum.h"

/* ---- options (run_args.c) ------------------------------------------------------------------ */
#define RUN_CAN_MOUNTS 8u
typedef struct {
    feed_args_t fa;                  /* --map, --min-m, --max-m, --rate, --duration */
    occ_mav_feed_config_t feed;      /* sector settings (band, ground, angle, unknown) */
    const char *udp, *udp_listen, *serial;
    uint32_t sysid, compid, target_sysid, target_compid;
    const char *depth_dir;
    bool have_intrinsics;
    float intrinsics[4];             /* fx, fy, cx, cy (pixels) */
    float mount[6];                  /* x, y, z (m), roll, pitch, yaw (deg): body FLU <- mount */
    uint32_t stride;
    bool depth_projective; /* --depth-method projective, or simple (default) */
    uint32_t max_frames;             /* 0: all */
    float depth_min_m, depth_max_m;
    float res_m;
    size_t arena_bytes;
    const char *out_path;
    float save_every_s;              /* 0: only at exit */
    float pose_rate_hz;
    uint32_t pose_timeout_ms, sensor_timeout_ms;
    uint32_t max_lag_ms;             /* recorded timing: a frame due longer ago is dropped (late) */
    const char *stats_path, *feed_log_path;
    bool exit_after_depth;
    bool mavlink_ranges;             /* integrate range messages of other components */
    bool obstacle_3d;                /* --3d: OBSTACLE_DISTANCE_3D above / below (run_3d.h) */
    uint32_t replay_speed;           /* 1: recorded timing; 0: as fast as the poses allow */
    float keep_radius_m;             /* eviction: protected ball around the camera */
    const char *can;                 /* --can IFACE or mcast:BUS (run_can.h); NULL: off */
    uint32_t can_node_id;            /* --can-node-id, 1..127 */
    occ_dronecan_range_mount_t can_mounts[RUN_CAN_MOUNTS]; /* --can-range-mount, by sensor_id */
    size_t n_can_mounts;
} run_opts_t;

/* Parse argv. RUN: go on; else the exit status (0 after --help, 2 after a message). */
#define RUN_ARGS_GO (-1)
int run_args_parse(run_opts_t *o, int argc, char **argv);
void run_args_usage(FILE *f);
/* A run option that takes no value (--3d ...). */
bool run_args_is_flag(const char *opt);

/* --config FILE (run_config.c): argv with each `key = value` line of FILE as "--key" "value"
 * ("--key" alone for a flag set true; false leaves it out) placed before the command line's
 * own options (the command line wins), --config FILE removed. 0, or 2 after a message
 * (file:line). The new argv lives until exit. */
int run_config_expand(int argc, char **argv, int *out_argc, char ***out_argv);

/* ---- the depth directory (run_depth.c) ------------------------------------------------------- */
typedef struct {
    size_t index;                    /* line index among depth.txt's entries (from 0) */
    uint64_t remote_us;              /* autopilot time: t - T_REF, T_REF = first entry - 1 s */
    char file[96];
} run_frame_t;

typedef struct {
    const char *dir;
    run_frame_t *frames;             /* entries whose PNG exists, in file order */
    size_t n, n_listed;              /* frames here; entries in depth.txt */
    occ_depth_params_t params;       /* intrinsics, min/max range, pixel step */
    float depth_scale_m;             /* metres per raw unit (TUM: 1 / 5000) */
    occ_pose_t body_from_camera;     /* mount composed with optical <- FLU */
} run_depth_t;

/* 0, or 1 after a message. */
int run_depth_open(run_depth_t *d, const run_opts_t *o);
void run_depth_close(run_depth_t *d);

/* ---- shared state ---------------------------------------------------------------------------- */
/* The sensor inputs, each with its own staleness (--sensor-timeout-ms). */
enum { RUN_SRC_DEPTH, RUN_SRC_MAVLINK, RUN_SRC_CAN, RUN_SOURCES };

/* Whether the options configure input `src` (--depth-dir; --mavlink-ranges; --can with a
 * --can-range-mount), and its name in the telemetry. */
bool run_source_on(const run_opts_t *o, int src);
const char *run_source_name(int src);

enum { RUN_DROP_EMPTY, RUN_DROP_TOO_OLD, RUN_DROP_TOO_NEW, RUN_DROP_GAP, RUN_DROP_NOMEM,
       RUN_DROP_ERROR, RUN_DROP_LATE, RUN_DROP_REASONS };

typedef struct {
    size_t *idx;
    uint32_t *version;               /* integrated: the version that holds it; dropped: unused */
    occ_pose_t *pose;                /* integrated: map_from_camera used; dropped: identity */
    size_t n, cap;
} run_list_t;

typedef struct {
    uint64_t frames_done;            /* integrated (in whole or part) + dropped */
    uint64_t integrated, partial;    /* partial: only the nearest part fitted (also integrated) */
    uint64_t dropped[RUN_DROP_REASONS];
    uint64_t points;                 /* back-projected points integrated */
    uint32_t *integrate_us;          /* every integration's time, in order */
    size_t n_integrate, cap_integrate;
    uint64_t saves, save_errors;
    bool done;                       /* the mapping thread has finished the directory */
} run_map_counters_t;

typedef struct {
    pthread_mutex_t lock;
    /* link thread -> mapping thread */
    occ_pose_history_t hist;         /* remote (autopilot) time */
    occ_pose_sample_t *hist_ring;
    uint64_t last_pose_local_us;     /* receive time of the newest pose pushed */
    occ_timesync_t ts;
    bool have_arrival;
    int64_t arrival_offset_us;       /* max(remote stamp - local arrival): offset without TIMESYNC */
    /* mapping thread -> link thread */
    run_map_counters_t mc;
    uint64_t last_sample_local_us[RUN_SOURCES]; /* each input's newest integration; 0: none */
    run_list_t integrated, dropped;  /* since the last feed-log line */
    occ_evict_out_t evict;           /* written by the mapper under lock after each frame */
    occ_map_stats_t pool;            /* the pools after the last frame (occ_map_pool_stats) */
    struct run_ranges_s *ranges;     /* range messages of other components (run_ranges.h) */
    volatile int stop;               /* either thread asks the other to end */
} run_state_t;

/* Clock offset remote - local: TIMESYNC when it answered, else the arrival estimate. false when
 * neither is known. Caller holds st->lock. */
bool run_state_offset(const run_state_t *st, int64_t *offset_us, const char **source);

/* Append (realloc'd; false when out of memory). */
bool run_list_push(run_list_t *l, size_t idx, uint32_t version, const occ_pose_t *pose);
void run_list_free(run_list_t *l);

/* ---- the mapping thread (run_mapper.c) --------------------------------------------------------- */
typedef struct {
    const run_opts_t *opt;
    struct run_camera_s *cam;        /* NULL: no depth input (run_camera.h) */
    run_state_t *st;
    run_mapguard_t *guard;
    occ_evict_policy_t policy;
} run_mapper_t;

void *run_mapper_main(void *arg);

/* Save o->out_path atomically (the writer's thread, or after it ended). 0 or 1 (message). */
int run_save(const run_opts_t *o, const occ_map_t *map);

/* ---- telemetry (run_stats.c) ----------------------------------------------------------------- */
/* p in [0, 1] of n values (sorted copy); 0 for n == 0. */
double run_percentile_u32(const uint32_t *v, size_t n, double p);

#endif
