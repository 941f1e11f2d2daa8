/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_feed.c - occmap feed: OBSTACLE_DISTANCE over MAVLink from a map and the autopilot's pose.
 * The options it shares with can-feed (--map, --map-frame, --min-m, --max-m, --rate-hz,
 * --duration-s) and the link, map and stop signal: feed_args.c. */
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "feed_args.h"

#define CMD "feed"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: occmap feed --map MAP (--udp HOST:PORT | --udp-listen [HOST:]PORT |\n"
            "                   --serial DEV:BAUD) [--rate-hz 10] [--sysid 1] [--compid 196]\n"
            "                   [--autopilot-sysid N] [--autopilot-compid 1] [--pose-interval-ms 50]\n"
            "                   [--timeout-ms 300] [--autopilot ardupilot|px4] [--map-frame enu|ned]\n"
            "                   [--min-m 0.2] [--max-m 20] [--angle-offset-deg -20]\n"
            "                   [--band-below-m 0.5] [--band-above-m 0.5] [--band-m B]\n"
            "                   [--ground-clearance-m 0.1] [--no-ignore-ground]\n"
            "                   [--unknown no-data|distance] [--duration-s S] [--verbose]\n"
            "Reads the autopilot's pose (LOCAL_POSITION_NED + ATTITUDE, ODOMETRY or\n"
            "ATTITUDE_QUATERNION) and sends MAVLink 2 OBSTACLE_DISTANCE (72 x 5 deg, MAV_FRAME_BODY_FRD)\n"
            "at --rate-hz plus a 1 Hz HEARTBEAT (MAV_TYPE_ONBOARD_CONTROLLER). Nothing is sent while the\n"
            "pose is older than --timeout-ms. --udp sends to HOST:PORT (an autopilot or SITL listening\n"
            "there); --udp-listen waits for the autopilot to send first. The map file is fixed for the run, so it never goes stale. Ends after\n"
            "--duration-s (default: at SIGINT/SIGTERM) and prints statistics as one JSON line.\n"
            "\n"
            "The autopilot: poses are taken only from system --autopilot-sysid (default: the first\n"
            "HEARTBEAT of an autopilot, i.e. not MAV_AUTOPILOT_INVALID and not a GCS), component\n"
            "--autopilot-compid. The feed asks it for LOCAL_POSITION_NED and ATTITUDE every\n"
            "--pose-interval-ms (MAV_CMD_SET_MESSAGE_INTERVAL), once a second while a stream is\n"
            "missing, and again after it stops (an autopilot reboot); refusals are logged.\n"
            "--pose-interval-ms 0: never ask (streams configured on the autopilot).\n"
            "\n"
            "What each element says (ArduPilot PRX1_TYPE=2 keeps the nearest valid element of each of\n"
            "its 8 faces of 45 deg; PX4 bins them into 36 x 10 deg):\n"
            "  obstacle  distance in cm, clamped to [min, max]: an obstacle to both.\n"
            "  free      max + 1 (MAVLink's \"no obstacle\"): ArduPilot drops it, an all-free face reads\n"
            "            \"no obstacle\"; PX4 reads free.\n"
            "  unknown   --unknown no-data (default): 65535; ArduPilot skips it, so a face of only\n"
            "            unknown reads \"no obstacle\" (it will fly and arm there); PX4: no data.\n"
            "            --unknown distance: the distance to the unknown space, an obstacle to both:\n"
            "            the vehicle stops short of unexplored space, and ArduPilot's arming check\n"
            "            (> 0.6 m in every face) fails while unknown space is within 0.6 m.\n"
            "--angle-offset-deg: body angle of element 0's centre; -20 makes each of ArduPilot's faces\n"
            "one run of 9 elements (with 0 its forward face is overwritten by elements 68-71).\n"
            "The band: voxels from --band-below-m under the vehicle to --band-above-m over it count;\n"
            "the ground under the vehicle (the first occupied voxel down its own column) and\n"
            "anything less than --ground-clearance-m above it do not, so the floor it stands on or\n"
            "flies over is no obstacle; --no-ignore-ground reports it.\n");
}

/* The options only `occmap feed` takes, read into the feed's configuration. */
typedef struct {
    occ_mav_feed_config_t cfg; /* ids, autopilot, map frame, sectors: filled by configure() */
    uint32_t timeout_ms, sysid, compid, ap_sysid, ap_compid, pose_interval_ms;
    const char *udp, *udp_listen, *serial; /* exactly one: the link */
    bool verbose;
} feed_opts_t;

static const char *const feed_flags[] = {"--verbose", "--unknown-as-distance",
                                         "--no-ignore-ground", NULL};

static void feed_opts_init(feed_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->cfg = occ_mav_feed_config_default();
    o->timeout_ms = 300;
    o->sysid = o->cfg.sysid;
    o->compid = o->cfg.compid;
    o->ap_sysid = o->cfg.autopilot_sysid;
    o->ap_compid = o->cfg.autopilot_compid;
    o->pose_interval_ms = o->cfg.pose_interval_us / 1000u;
}

/* Who is who on the MAVLink side: our ids, the autopilot's, its streams and its kind. */
static int mavlink_option(feed_opts_t *o, const char *a, const char *v)
{
    bool ok = true;
    if (strcmp(a, "--sysid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->sysid);
    } else if (strcmp(a, "--compid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->compid);
    } else if (strcmp(a, "--timeout-ms") == 0) {
        ok = cli_parse_u32(v, 1, 60000, &o->timeout_ms);
    } else if (strcmp(a, "--autopilot-sysid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->ap_sysid);
    } else if (strcmp(a, "--autopilot-compid") == 0) {
        ok = cli_parse_u32(v, 1, 255, &o->ap_compid);
    } else if (strcmp(a, "--pose-interval-ms") == 0) {
        ok = cli_parse_u32(v, 0, 60000, &o->pose_interval_ms);
    } else if (strcmp(a, "--autopilot") == 0) {
        ok = strcmp(v, "ardupilot") == 0 || strcmp(v, "px4") == 0;
        if (ok) {
            o->cfg.autopilot = strcmp(v, "px4") == 0 ? OCC_AUTOPILOT_PX4 : OCC_AUTOPILOT_ARDUPILOT;
        }
    } else if (strcmp(a, "--udp") == 0) {
        o->udp = v;
    } else if (strcmp(a, "--udp-listen") == 0) {
        o->udp_listen = v;
    } else if (strcmp(a, "--serial") == 0) {
        o->serial = v;
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

/* feed_opt_fn: the flags (v == NULL), then the sector and MAVLink options. */
static int feed_option(void *ctx, const char *a, const char *v)
{
    feed_opts_t *const o = ctx;
    if (v == NULL) {
        if (strcmp(a, "--verbose") == 0) {
            o->verbose = true;
        } else if (strcmp(a, "--unknown-as-distance") == 0) { /* the old spelling */
            o->cfg.sectors.unknown_as_distance = true;
        } else {
            o->cfg.sectors.ignore_ground = false; /* --no-ignore-ground */
        }
        return FEED_OPT_OK;
    }
    const int r = feed_args_sector_option(&o->cfg.sectors, a, v);
    return r != FEED_OPT_UNKNOWN ? r : mavlink_option(o, a, v);
}

/* The options into the feed's configuration and the feed; 0, or 2 after a message. */
static int configure(occ_mav_feed_t *feed, feed_opts_t *o, const feed_args_t *fa)
{
    occ_mav_feed_config_t *const cfg = &o->cfg;
    cfg->sysid = (uint8_t)o->sysid;
    cfg->compid = (uint8_t)o->compid;
    cfg->period_us = (uint32_t)(1e6 / (double)fa->rate_hz);
    cfg->pose_timeout_us = o->timeout_ms * 1000u;
    cfg->autopilot_sysid = (uint8_t)o->ap_sysid;
    cfg->autopilot_compid = (uint8_t)o->ap_compid;
    cfg->pose_interval_us = o->pose_interval_ms * 1000u;
    cfg->map_frame = fa->map_ned ? OCC_MAP_FRAME_NED : OCC_MAP_FRAME_ENU;
    feed_args_apply_range(fa, &cfg->sectors);
    if (occ_mav_feed_init(feed, cfg) != OCC_OK) {
        cli_error(CMD, "bad feed configuration (min %.2f m must be < max %.2f m; the band "
                  "below + above must be > 0)", (double)fa->min_m, (double)fa->max_m);
        return 2;
    }
    return 0;
}

static int open_link(const feed_opts_t *o, occ_link_t *link)
{
    if (o->udp != NULL) {
        return feed_link_open(CMD, "--udp", OCC_LINK_UDP_CLIENT, o->udp, link);
    }
    if (o->udp_listen != NULL) {
        return feed_link_open(CMD, "--udp-listen", OCC_LINK_UDP_LISTEN, o->udp_listen, link);
    }
    return feed_link_open(CMD, "--serial", OCC_LINK_SERIAL, o->serial, link);
}

typedef struct {
    uint64_t n, sum_us, max_us;
} timing_t;

/* Write every frame the feed has due at `now`, timing each OBSTACLE_DISTANCE it computes.
 * 0, or 1 after a message. */
static int send_due(occ_mav_feed_t *feed, const occ_map_t *map, occ_link_t *link,
                    const uint64_t now, timing_t *tm)
{
    for (;;) {
        uint8_t out[OCC_MAV_FRAME_MAX];
        const uint32_t before = feed->counters.obstacle_tx;
        const uint64_t a = occ_port_clock_us();
        const size_t len = occ_mav_feed_poll(feed, map, now, out, sizeof out);
        if (len == 0u) {
            return 0;
        }
        if (feed->counters.obstacle_tx != before) {
            const uint64_t dt = occ_port_clock_us() - a;
            tm->n++;
            tm->sum_us += dt;
            tm->max_us = dt > tm->max_us ? dt : tm->max_us;
        }
        if (occ_link_write(link, out, len) != OCC_OK) {
            cli_error(CMD, "write failed");
            return 1;
        }
    }
}

/* The autopilot the feed listens to, once; every refused SET_MESSAGE_INTERVAL. */
static void log_autopilot(const occ_mav_feed_t *feed, bool *named, uint32_t *refusals)
{
    if (!*named && feed->have_autopilot) {
        *named = true;
        fprintf(stderr, "feed: poses from the autopilot at system %u component %u\n",
                feed->ap_sysid, feed->ap_compid);
    }
    if (feed->counters.request_refusals != *refusals) {
        *refusals = feed->counters.request_refusals;
        fprintf(stderr, "feed: the autopilot refused SET_MESSAGE_INTERVAL (MAV_RESULT %u, %u "
                "refusals); set its stream rates for LOCAL_POSITION_NED and ATTITUDE by hand\n",
                feed->counters.last_refusal_result, *refusals);
    }
}

/* --verbose, once a second: the pose and the counters. */
static void log_progress(const occ_mav_feed_t *feed, const uint64_t now, const uint64_t t0)
{
    occ_pose_t p = occ_pose_identity();
    const bool fresh = occ_mav_feed_pose(feed, now, &p);
    fprintf(stderr, "feed: t=%.1fs pose %s (%.2f %.2f %.2f yaw %.1f deg) tx %u obstacle %u hb"
            ", rx ok %u bad %u\n", (double)(now - t0) * 1e-6, fresh ? "fresh" : "stale",
            (double)p.p.x, (double)p.p.y, (double)p.p.z, (double)occ_pose_yaw(&p) * 57.29578,
            feed->counters.obstacle_tx, feed->counters.heartbeat_tx,
            feed->parser.counters.frames_ok,
            feed->parser.counters.bad_crc + feed->parser.counters.bad_len);
}

/* Sleep until the feed's next message is due or input arrives (at most 50 ms). */
static void wait_next(const occ_mav_feed_t *feed, occ_link_t *link)
{
    const uint64_t due = occ_mav_feed_next_due(feed);
    const uint64_t now = occ_port_clock_us();
    uint64_t wait = due > now ? due - now : 0u;
    wait = wait > 50000u ? 50000u : wait;
    if (wait > 0u) {
        (void)occ_link_wait(link, wait);
    }
}

/* Read, send, log and wait until --duration-s or a stop signal. 0, or 1 after an i/o error. */
static int run(occ_mav_feed_t *feed, const occ_map_t *map, occ_link_t *link,
               const feed_args_t *fa, const bool verbose, timing_t *tm)
{
    const uint64_t t0 = occ_port_clock_us();
    const uint64_t t_end = feed_args_end_us(fa, t0);
    uint64_t next_report = t0 + 1000000u;
    uint32_t refusals_logged = 0;
    bool autopilot_logged = false;
    while (!feed_stop_requested()) {
        const uint64_t now = occ_port_clock_us();
        if (now >= t_end) {
            break;
        }
        if (feed_link_drain(link, feed, now) != OCC_OK) {
            cli_error(CMD, "read failed");
            return 1;
        }
        if (send_due(feed, map, link, now, tm) != 0) {
            return 1;
        }
        log_autopilot(feed, &autopilot_logged, &refusals_logged);
        if (verbose && now >= next_report) {
            next_report += 1000000u;
            log_progress(feed, now, t0);
        }
        wait_next(feed, link);
    }
    return 0;
}

static void print_stats(const occ_mav_feed_t *feed, const occ_link_t *link, const timing_t *tm)
{
    const occ_mav_feed_counters_t *c = &feed->counters;
    const occ_mav_counters_t *pc = &feed->parser.counters;
    printf("{\"obstacle_tx\": %u, \"heartbeat_tx\": %u, \"positions_rx\": %u, \"attitudes_rx\": %u, "
           "\"ignored_rx\": %u, \"foreign_rx\": %u, \"requests_tx\": %u, \"request_acks\": %u, "
           "\"request_refusals\": %u, \"stale_skips\": %u, \"sector_errors\": %u, \"frames_ok\": %u, "
           "\"bad_crc\": %u, \"bad_len\": %u, \"unknown_id\": %u, \"bad_flags\": %u, "
           "\"junk_bytes\": %u, \"tx_dropped\": %u, \"update_us_mean\": %.1f, "
           "\"update_us_max\": %llu}\n",
           c->obstacle_tx, c->heartbeat_tx, c->positions_rx, c->attitudes_rx, c->ignored_rx,
           c->foreign_rx, c->requests_tx, c->request_acks, c->request_refusals, c->stale_skips,
           c->sector_errors, pc->frames_ok, pc->bad_crc, pc->bad_len, pc->unknown_id,
           pc->bad_flags, pc->junk_bytes, link->tx_dropped,
           tm->n > 0u ? (double)tm->sum_us / (double)tm->n : 0.0, (unsigned long long)tm->max_us);
    fflush(stdout);
}

int cmd_feed(int argc, char **argv)
{
    feed_opts_t o;
    feed_opts_init(&o);
    feed_args_t fa;
    const feed_cmd_t cmd = {CMD, usage, feed_flags, feed_option, &o};
    const int parsed = feed_args_parse(&fa, &cmd, argc, argv);
    if (parsed != FEED_ARGS_RUN) {
        return parsed;
    }
    const int n_links = (o.udp != NULL) + (o.udp_listen != NULL) + (o.serial != NULL);
    if (fa.map_path == NULL || n_links != 1) {
        cli_error(CMD, "needs --map and exactly one of --udp, --udp-listen, --serial");
        usage(stderr);
        return 2;
    }
    static occ_mav_feed_t feed; /* sector scratch: keep it off the stack */
    if (configure(&feed, &o, &fa) != 0) {
        return 2;
    }
    occ_map_t map;
    void *arena = NULL;
    if (feed_load_map(CMD, &fa, 0, &map, &arena) != 0) {
        return 1;
    }
    occ_link_t link;
    int status = open_link(&o, &link);
    if (status == 0) {
        feed_stop_install();
        timing_t tm = {0, 0, 0};
        status = run(&feed, &map, &link, &fa, o.verbose, &tm);
        print_stats(&feed, &link, &tm);
        occ_link_close(&link);
    }
    free(arena);
    return status;
}
