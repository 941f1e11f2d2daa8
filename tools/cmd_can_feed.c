/* SPDX-License-Identifier: BSD-3-Clause */
/* cmd_can_feed.c - occmap can-feed: a DroneCAN node that publishes a map's obstacles.
 * The options it shares with feed (--map, --map-frame, --min-m, --max-m, --rate-hz,
 * --duration-s) and the MAVLink link, map and stop signal: feed_args.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "feed_args.h"
#include "occmap/occ_dronecan.h"
#include "occmap/host/occ_can_mcast.h"
#include "occmap/host/occ_socketcan.h"

#define CMD "can-feed"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: occmap can-feed --map MAP (--socketcan IF | --mcast BUS) --node-id N\n"
            "         [--sensor-id S] (--pose N,E,D,YAW_DEG | --mavlink-udp HOST:PORT)\n"
            "         [--rate-hz 10] [--duration-s S] [--sectors 72] [--min-m 0.2] [--max-m 20]\n"
            "         [--priority 24] [--map-frame enu|ned] [--arena-extra SIZE]\n"
            "A DroneCAN node: ardupilot.equipment.proximity_sensor.Proximity for every sector with an\n"
            "obstacle around the pose (body yaw degrees, 0 forward, clockwise), NodeStatus at 1 Hz,\n"
            "GetNodeInfo answered. --pose is the autopilot's NED pose (metres, yaw degrees from north);\n"
            "--mavlink-udp listens on HOST:PORT for the autopilot's MAVLink stream and takes live poses\n"
            "(only from the system of the first autopilot HEARTBEAT, component 1; it sends nothing, so\n"
            "the autopilot must stream LOCAL_POSITION_NED and ATTITUDE on that link by itself).\n"
            "--mcast BUS is pydronecan's / ArduPilot SITL's CAN over UDP multicast (239.65.82.BUS:57732,\n"
            "loopback only). Ends after --duration-s (default: until SIGINT) and prints statistics as\n"
            "one JSON line.\n");
}

/* The options only `occmap can-feed` takes. */
typedef struct {
    const char *socketcan_if;  /* --socketcan IF, or */
    bool have_mcast;           /* --mcast BUS */
    uint32_t mcast_bus;
    uint32_t node_id, sensor_id, sectors, priority;
    bool have_pose;            /* --pose N,E,D,YAW_DEG, or */
    float pose_v[4];
    const char *mav_udp;       /* --mavlink-udp HOST:PORT */
    size_t arena_extra;
} can_opts_t;

static void can_opts_init(can_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->sectors = 72;
    o->priority = 24;
}

/* feed_opt_fn for the options above (none is a flag). */
static int can_option(void *ctx, const char *a, const char *v)
{
    can_opts_t *const o = ctx;
    bool ok = true;
    if (strcmp(a, "--socketcan") == 0) {
        o->socketcan_if = v;
    } else if (strcmp(a, "--mcast") == 0) {
        ok = o->have_mcast = cli_parse_u32(v, 0, 255, &o->mcast_bus);
    } else if (strcmp(a, "--node-id") == 0) {
        ok = cli_parse_u32(v, 1, 127, &o->node_id);
    } else if (strcmp(a, "--sensor-id") == 0) {
        ok = cli_parse_u32(v, 0, 255, &o->sensor_id);
    } else if (strcmp(a, "--priority") == 0) {
        ok = cli_parse_u32(v, 0, 31, &o->priority);
    } else if (strcmp(a, "--sectors") == 0) {
        ok = cli_parse_u32(v, 4, OCC_SECTORS_MAX, &o->sectors);
    } else if (strcmp(a, "--pose") == 0) {
        ok = o->have_pose = cli_parse_floats(v, o->pose_v, 4) != 0;
    } else if (strcmp(a, "--mavlink-udp") == 0) {
        o->mav_udp = v;
    } else if (strcmp(a, "--arena-extra") == 0) {
        ok = cli_parse_size(v, &o->arena_extra) != 0;
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

/* The sectors of the Proximity messages; 0, or 2 after a message. */
static int sectors_config(const can_opts_t *o, const feed_args_t *fa, occ_sectors_config_t *sc)
{
    *sc = occ_sectors_config_default();
    sc->n_sectors = (uint8_t)o->sectors;
    sc->increment_deg = 360.0f / (float)o->sectors;
    sc->angle_offset_deg = 0.0f;
    feed_args_apply_range(fa, sc);
    sc->map_ned = fa->map_ned;
    if (occ_sectors_config_check(sc) != OCC_OK) {
        cli_error(CMD, "bad sector settings (sectors %lu, %.2f..%.2f m)", (unsigned long)o->sectors,
                  (double)fa->min_m, (double)fa->max_m);
        return 2;
    }
    return 0;
}

/* --pose (NED metres, yaw degrees from north, level) in the map's frame: map(ENU) <- body(FLU),
 * or with a NED map the NED <- FRD pose itself. A bad --pose leaves a zero quaternion, which
 * the sectors refuse (fail closed). */
static occ_pose_t fixed_pose(const can_opts_t *o, const bool map_ned)
{
    const float deg = 3.14159265358979f / 180.0f;
    const float *const v = o->pose_v;
    occ_pose_t pose;
    memset(&pose, 0, sizeof pose);
    if (!o->have_pose) {
        return pose;
    }
    const occ_vec3_t ned = {v[0], v[1], v[2]};
    const occ_quat_t heading = occ_quat_from_euler(0.0f, 0.0f, v[3] * deg);
    if (!map_ned) {
        (void)occ_pose_from_ned(ned, heading, &pose);
        return pose;
    }
    pose.p = ned;
    pose.q = heading;
    return pose;
}

/* --mavlink-udp: listen for the autopilot's poses (it sends nothing, so it never asks for
 * streams). 0, or the exit status after a message. */
static int mavlink_open(const occ_sectors_config_t *sc, const bool map_ned, const char *spec,
                        occ_mav_feed_t *mav, occ_link_t *link)
{
    occ_mav_feed_config_t mcfg = occ_mav_feed_config_default();
    mcfg.map_frame = map_ned ? OCC_MAP_FRAME_NED : OCC_MAP_FRAME_ENU;
    mcfg.sectors = *sc;
    mcfg.pose_interval_us = 0; /* this link only listens: the streams must be set up */
    if (occ_mav_feed_init(mav, &mcfg) != OCC_OK) {
        cli_error(CMD, "bad MAVLink pose settings");
        return 2;
    }
    return feed_link_open(CMD, "--mavlink-udp", OCC_LINK_UDP_LISTEN, spec, link);
}

typedef struct {
    bool use_mcast;
    occ_socketcan_t sc;
    occ_can_mcast_t mc;
} bus_t;

static occ_err_t bus_recv(bus_t *b, occ_can_frame_t *f, int timeout_ms, bool *got)
{
    return b->use_mcast ? occ_can_mcast_recv(&b->mc, f, timeout_ms, got)
                        : occ_socketcan_recv(&b->sc, f, timeout_ms, got);
}

/* --socketcan IF (every extended frame in) or --mcast BUS. 0, or 1 after a message. */
static int bus_open(bus_t *bus, const can_opts_t *o, occ_can_iface_t *iface)
{
    char msg[256] = "";
    occ_err_t e;
    memset(bus, 0, sizeof *bus);
    if (o->socketcan_if != NULL) {
        e = occ_socketcan_open(&bus->sc, o->socketcan_if, false, msg, sizeof msg);
        *iface = occ_socketcan_iface(&bus->sc);
    } else {
        bus->use_mcast = true;
        e = occ_can_mcast_open(&bus->mc, (unsigned)o->mcast_bus, true, msg, sizeof msg);
        *iface = occ_can_mcast_iface(&bus->mc);
    }
    if (e != OCC_OK) {
        cli_error(CMD, "cannot open the CAN bus: %s", msg);
        return 1;
    }
    const occ_can_filter_t all_ext = {0, 0, true};
    if (!bus->use_mcast) {
        (void)occ_socketcan_set_filters(&bus->sc, &all_ext, 1);
    }
    return 0;
}

static void bus_close(bus_t *bus)
{
    if (bus->use_mcast) {
        occ_can_mcast_close(&bus->mc);
    } else {
        occ_socketcan_close(&bus->sc);
    }
}

/* The DroneCAN node on `iface`; 0, or 1 after a message. */
static int node_open(occ_dronecan_node_t *node, const can_opts_t *o, const feed_args_t *fa,
                     const occ_can_iface_t *iface)
{
    occ_dronecan_config_t ncfg = occ_dronecan_config_default();
    ncfg.node_id = (uint8_t)o->node_id;
    ncfg.sensor_id = (uint8_t)o->sensor_id;
    ncfg.priority = (uint8_t)o->priority;
    ncfg.proximity_period_us = (uint32_t)lroundf(1e6f / fa->rate_hz);
    cli_host_unique_id(ncfg.unique_id, o->node_id);
    const occ_err_t e = occ_dronecan_init(node, &ncfg, iface);
    if (e != OCC_OK) {
        cli_error(CMD, "node init: %s", occ_err_str(e));
        return 1;
    }
    return 0;
}

/* What one run holds: the map, where the pose comes from, the bus and the node. */
typedef struct {
    const occ_map_t *map;
    occ_sectors_config_t sectors;
    occ_pose_t pose;           /* fixed, or the last live one */
    occ_link_t *mav_link;      /* NULL with --pose */
    occ_mav_feed_t *mav;       /* the live pose's parser (with mav_link) */
    bus_t *bus;
    occ_dronecan_node_t *node;
    uint32_t sector_errors, send_errors;
} can_run_t;

/* The pose's time stamp at t: t for a fixed or fresh pose, 0 when no live pose is fresh (the
 * node then reports NO_DATA). */
static uint64_t update_pose(can_run_t *r, const uint64_t t)
{
    if (r->mav_link == NULL) {
        return t;
    }
    (void)feed_link_drain(r->mav_link, r->mav, t); /* a read error leaves the pose to go stale */
    return occ_mav_feed_pose(r->mav, t, &r->pose) ? t : 0u;
}

/* Serve the bus until the next publication is due (at most 10 ms per wait). */
static void serve_bus(can_run_t *r, const uint64_t t_end)
{
    occ_dronecan_node_t *const node = r->node;
    occ_can_frame_t f;
    bool got = true;
    while (got && !feed_stop_requested()) {
        const uint64_t t2 = occ_port_clock_us();
        const uint64_t due = node->next_proximity_us < node->next_status_us
                                 ? node->next_proximity_us : node->next_status_us;
        if (t2 >= due || t2 >= t_end) {
            break;
        }
        int wait_ms = (int)((due - t2) / 1000u);
        wait_ms = wait_ms > 10 ? 10 : wait_ms;
        if (bus_recv(r->bus, &f, wait_ms, &got) != OCC_OK) {
            break;
        }
        if (got) {
            (void)occ_dronecan_ingest(node, &f, occ_port_clock_us());
        }
        got = got || wait_ms > 0; /* keep waiting until due */
    }
}

/* Publish and serve until t_end or a stop signal. */
static void run(can_run_t *r, const uint64_t t_end)
{
    while (!feed_stop_requested()) {
        const uint64_t t = occ_port_clock_us();
        if (t >= t_end) {
            break;
        }
        const uint64_t pose_stamp = update_pose(r, t);
        const occ_err_t e = occ_dronecan_poll_map(r->node, t, r->map, t, &r->pose, pose_stamp,
                                                  &r->sectors);
        if (e == OCC_ERR_RANGE || e == OCC_ERR_ARG) {
            r->sector_errors++; /* vehicle off the map: the node said NO_DATA */
        } else if (e == OCC_ERR_IO) {
            r->send_errors++;
        }
        serve_bus(r, t_end);
    }
}

static void print_stats(const can_run_t *r, const uint64_t t_start)
{
    const occ_dronecan_stats_t *st = &r->node->stats;
    printf("{\"proximity_sent\": %u, \"tx_frames\": %u, \"tx_transfers\": %u, \"tx_full\": %u, "
           "\"tx_errors\": %u, \"rx_frames\": %u, \"node_info_answered\": %u, "
           "\"bus_off\": %u, \"sector_errors\": %u, \"send_errors\": %u, \"last_obstacles\": %u, "
           "\"seconds\": %.2f}\n",
           st->proximity_sent, st->tx_frames, st->tx_transfers, st->tx_full, st->tx_errors,
           st->rx_frames, st->node_info_answered, st->bus_off, r->sector_errors, r->send_errors,
           (unsigned)r->node->last_obstacles, (double)(occ_port_clock_us() - t_start) / 1e6);
    fflush(stdout);
}

/* Everything after the map is loaded: the sectors, the pose source, the bus, the node, the
 * run. Returns the exit status; closes what it opened. */
static int serve(const can_opts_t *o, const feed_args_t *fa, const occ_map_t *map)
{
    static occ_mav_feed_t mav; /* ~5 KB of sector scratch: keep it off the stack */
    static bus_t bus;
    static occ_dronecan_node_t node;
    occ_link_t mav_link;
    can_run_t r;
    memset(&r, 0, sizeof r);
    r.map = map;
    r.bus = &bus;
    r.node = &node;
    int status = sectors_config(o, fa, &r.sectors);
    if (status != 0) {
        return status;
    }
    r.pose = fixed_pose(o, fa->map_ned);
    if (o->mav_udp != NULL) {
        status = mavlink_open(&r.sectors, fa->map_ned, o->mav_udp, &mav, &mav_link);
        if (status != 0) {
            return status;
        }
        r.mav_link = &mav_link;
        r.mav = &mav;
    }
    occ_can_iface_t iface;
    status = bus_open(&bus, o, &iface);
    if (status == 0) {
        status = node_open(&node, o, fa, &iface);
        if (status == 0) {
            feed_stop_install();
            const uint64_t t_start = occ_port_clock_us();
            run(&r, feed_args_end_us(fa, t_start));
            print_stats(&r, t_start);
        }
        bus_close(&bus);
    }
    if (r.mav_link != NULL) {
        occ_link_close(r.mav_link);
    }
    return status;
}

int cmd_can_feed(int argc, char **argv)
{
    can_opts_t o;
    can_opts_init(&o);
    feed_args_t fa;
    const feed_cmd_t cmd = {CMD, usage, NULL, can_option, &o};
    const int parsed = feed_args_parse(&fa, &cmd, argc, argv);
    if (parsed != FEED_ARGS_RUN) {
        return parsed;
    }
    if (fa.map_path == NULL || o.node_id == 0u || ((o.socketcan_if != NULL) == o.have_mcast) ||
        (o.have_pose == (o.mav_udp != NULL)) || fa.min_m >= fa.max_m) {
        cli_error(CMD, "need --map, --node-id, one of --socketcan/--mcast and one of "
                       "--pose/--mavlink-udp (min < max)");
        usage(stderr);
        return 2;
    }
    occ_map_t map;
    void *arena = NULL;
    if (feed_load_map(CMD, &fa, o.arena_extra, &map, &arena) != 0) {
        return 1;
    }
    const int status = serve(&o, &fa, &map);
    free(arena);
    return status;
}
