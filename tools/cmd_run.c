/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_run.c - `occmap run`, the onboard loop (issue 21): the map, the threads, the end.
 * Options: run_args.c; the depth directory: run_depth.c; the mapping thread: run_mapper.c;
 * the link, feed and feed log: run_link.c; telemetry: run_stats.c; map access: run_mapguard.c. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "run_camera.h"
#include "run_can.h"
#include "run_link.h"
#include "run_ranges.h"
#include "occmap/occ_port.h"
#include "occmap/host/occ_file.h"

#define NEAREST_CAP 16384u /* --3d: nodes waiting in the nearest-first search (24 B each) */
#define HISTORY_CAP 8192u /* poses: 160 s at 50 Hz, the whole TUM ground truth at 100 Hz */

/* The map in one arena of --arena-bytes, empty or loaded from --map. 0, or 1 after a message. */
static int make_map(const run_opts_t *o, occ_map_t *map, void **arena)
{
    char msg[256] = "";
    *arena = malloc(o->arena_bytes);
    if (*arena == NULL) {
        cli_error("run", "cannot allocate --arena-bytes %zu", o->arena_bytes);
        return 1;
    }
    occ_err_t e;
    if (o->fa.map_path != NULL) {
        e = occ_file_load(o->fa.map_path, NULL, map, *arena, o->arena_bytes, msg, sizeof msg);
    } else {
        occ_map_config_t cfg = occ_map_config_default();
        cfg.resolution_m = o->res_m;
        e = occ_map_init(map, &cfg, *arena, o->arena_bytes);
        (void)snprintf(msg, sizeof msg, "bad --res or --arena-bytes");
    }
    if (e != OCC_OK) {
        cli_error("run", "%s%s%s (%s)", o->fa.map_path != NULL ? o->fa.map_path : "",
                  o->fa.map_path != NULL ? ": " : "", msg, occ_err_str(e));
        free(*arena);
        *arena = NULL;
        return 1;
    }
    return 0;
}

static int make_feed(const run_opts_t *o, occ_mav_feed_t *feed)
{
    occ_mav_feed_config_t c = o->feed;
    c.sysid = (uint8_t)o->sysid;
    c.compid = (uint8_t)o->compid;
    c.period_us = (uint32_t)(1e6 / (double)o->fa.rate_hz);
    c.pose_timeout_us = o->pose_timeout_ms * 1000u;
    c.autopilot_sysid = (uint8_t)o->target_sysid;
    c.autopilot_compid = (uint8_t)o->target_compid;
    c.pose_interval_us = o->pose_rate_hz > 0.0f ? (uint32_t)(1e6 / (double)o->pose_rate_hz) : 0u;
    c.map_frame = o->fa.map_ned ? OCC_MAP_FRAME_NED : OCC_MAP_FRAME_ENU;
    feed_args_apply_range(&o->fa, &c.sectors);
    if (occ_mav_feed_init(feed, &c) != OCC_OK) {
        cli_error("run", "bad feed configuration (--min-m must be < --max-m; band > 0)");
        return 2;
    }
    return 0;
}

static int make_state(run_state_t *st)
{
    memset(st, 0, sizeof *st);
    st->hist_ring = calloc(HISTORY_CAP, sizeof *st->hist_ring);
    const occ_pose_history_cfg_t hc = {OCC_TUM_MAX_GAP_US, 0};
    if (st->hist_ring == NULL || pthread_mutex_init(&st->lock, NULL) != 0 ||
        occ_pose_history_init(&st->hist, st->hist_ring, HISTORY_CAP, &hc) != OCC_OK ||
        occ_timesync_init(&st->ts, 500000u) != OCC_OK) {
        free(st->hist_ring);
        return 1;
    }
    occ_evict_out_init(&st->evict);
    return 0;
}

static void free_state(run_state_t *st)
{
    (void)pthread_mutex_destroy(&st->lock);
    free(st->hist_ring);
    free(st->mc.integrate_us);
    run_list_free(&st->integrated);
    run_list_free(&st->dropped);
}

static FILE *open_out(const char *path, FILE *dflt)
{
    if (path == NULL) {
        return dflt;
    }
    FILE *const f = fopen(path, "w");
    if (f == NULL) {
        cli_error("run", "cannot write %s", path);
    }
    return f;
}

static int open_link(const run_opts_t *o, occ_link_t *link)
{
    if (o->udp != NULL) {
        return feed_link_open("run", "--udp", OCC_LINK_UDP_CLIENT, o->udp, link);
    }
    if (o->udp_listen != NULL) {
        return feed_link_open("run", "--udp-listen", OCC_LINK_UDP_LISTEN, o->udp_listen, link);
    }
    return feed_link_open("run", "--serial", OCC_LINK_SERIAL, o->serial, link);
}

/* The two threads, then the last save and the map's self-check. 0, or 1. */
static int run_threads(run_link_t *l, run_mapper_t *m)
{
    pthread_t th;
    if (pthread_create(&th, NULL, run_mapper_main, m) != 0) {
        cli_error("run", "cannot start the mapping thread");
        return 1;
    }
    int status = run_link_loop(l);
    l->st->stop = 1;
    (void)pthread_join(th, NULL);
    if (l->opt->out_path != NULL && run_save(l->opt, l->guard->map) != 0) {
        status = 1;
    }
    const bool check_ok = occ_map_check(l->guard->map) == OCC_OK;
    run_stats_line(l, occ_port_clock_us(), "final", check_ok);
    return check_ok ? status : 1;
}

/* The link's MAVLink state: parser, the autopilot's pose filter, range translator, our ids. */
static void init_mavlink(run_link_t *l, const run_opts_t *o)
{
    occ_mav_parser_init(&l->parser);
    occ_mav_pose_rx_config_t pc = occ_mav_pose_rx_config_default();
    pc.sysid = (uint8_t)o->target_sysid;
    pc.compid = (uint8_t)o->target_compid;
    (void)occ_mav_pose_rx_init(&l->prx, &pc);
    (void)occ_mav_ranges_init(&l->ranges_tr, (uint8_t)o->sysid, (uint8_t)o->compid);
    l->tx.sysid = (uint8_t)o->sysid;
    l->tx.compid = (uint8_t)o->compid;
}

/* The link is open: camera, mapper and CAN set up, the two threads run. 0 or 1. */
static int run_open(run_link_t *l, run_opts_t *o, run_depth_t *depth)
{
    static run_camera_t cam; /* the TUM replay; a live camera driver plugs in here */
    static run_camera_tum_t tum;
    if (depth != NULL) {
        run_camera_tum(&cam, &tum, depth);
    }
    run_mapper_t m = {o, depth != NULL ? &cam : NULL, l->st, l->guard, occ_evict_policy_default()};
    m.policy.keep_radius_m = o->keep_radius_m;
    static run_can_t can;
    int status = 0;
    if (o->can != NULL) {
        status = run_can_open(&can, o);
        l->can = status == 0 ? &can : NULL;
    }
    feed_stop_install();
    l->t0 = occ_port_clock_us();
    l->next_stats = l->t0 + 1000000u;
    run_stats_config(l);
    status = status == 0 ? run_threads(l, &m) : status;
    if (l->can != NULL) {
        run_can_close(l->can);
    }
    return status;
}

/* Everything opened, the loop run; what was opened closed. */
static int run_all(run_opts_t *o, occ_map_t *map, run_depth_t *depth)
{
    static occ_mav_feed_t feed; /* sector scratch: off the stack */
    static run_state_t st;
    static run_ranges_t ranges;
    run_mapguard_t guard;
    int status = make_feed(o, &feed);
    if (status != 0 || make_state(&st) != 0 || run_mapguard_init(&guard, map) != 0) {
        return status != 0 ? status : 1;
    }
    memset(&ranges, 0, sizeof ranges);
    ranges.own_window_us = (uint64_t)o->sensor_timeout_ms * 1000u;
    st.ranges = &ranges;
    occ_link_t link;
    static run_link_t l;
    memset(&l, 0, sizeof l);
    l.opt = o;
    l.st = &st;
    l.guard = &guard;
    l.depth = depth;
    l.link = &link;
    l.feed = &feed;
    init_mavlink(&l, o);
    if (o->obstacle_3d) { /* the 3D search's heap: ample for --max-m 20 at 0.1 m */
        l.nearest_cap = NEAREST_CAP;
        l.nearest = malloc(NEAREST_CAP * sizeof *l.nearest);
        if (l.nearest == NULL) {
            cli_error("run", "cannot allocate the --3d search");
            return 1;
        }
    }
    l.stats = open_out(o->stats_path, stderr);
    l.feed_log = open_out(o->feed_log_path, NULL);
    status = l.stats == NULL || (o->feed_log_path != NULL && l.feed_log == NULL) ? 1
             : open_link(o, &link);
    if (status == 0) {
        status = run_open(&l, o, depth);
        occ_link_close(&link);
    }
    if (l.stats != NULL && l.stats != stderr) {
        (void)fclose(l.stats);
    }
    if (l.feed_log != NULL) {
        (void)fclose(l.feed_log);
    }
    free(l.ft.interval_us);
    free(l.nearest);
    run_mapguard_destroy(&guard);
    free_state(&st);
    return status;
}

int cmd_run(int argc, char **argv)
{
    static run_opts_t o;
    const int parsed = run_args_parse(&o, argc, argv);
    if (parsed != RUN_ARGS_GO) {
        return parsed;
    }
    run_depth_t depth;
    if (o.depth_dir != NULL && run_depth_open(&depth, &o) != 0) {
        return 1;
    }
    occ_map_t map;
    void *arena = NULL;
    int status = make_map(&o, &map, &arena);
    if (status == 0) {
        status = run_all(&o, &map, o.depth_dir != NULL ? &depth : NULL);
    }
    free(arena);
    if (o.depth_dir != NULL) {
        run_depth_close(&depth);
    }
    return status;
}
