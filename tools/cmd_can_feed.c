/* cmd_can_feed.c - occmap can-feed: a DroneCAN node that publishes a map's obstacles. */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "occmap/occ_can.h"
#include "occmap/host/occ_file.h"
#include "occmap/occ_mavlink.h"

#define CMD "can-feed"

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static uint64_t now_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

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

static int open_udp_listen(const char *hostport)
{
    char host[64];
    const char *colon = strrchr(hostport, ':');
    if (colon == NULL || (size_t)(colon - hostport) >= sizeof host) {
        return -1;
    }
    memcpy(host, hostport, (size_t)(colon - hostport));
    host[colon - hostport] = '\0';
    const long port = strtol(colon + 1, NULL, 10);
    if (port <= 0 || port > 65535) {
        return -1;
    }
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, host[0] != '\0' ? host : "0.0.0.0", &a.sin_addr) != 1) {
        return -1;
    }
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        return -1;
    }
    if (bind(fd, (struct sockaddr *)&a, sizeof a) < 0) {
        (void)close(fd);
        return -1;
    }
    return fd;
}

static bool parse_uint(const char *s, unsigned long lo, unsigned long hi, unsigned long *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long v = strtoul(s, &end, 10);
    if (end == s || *end != '\0' || errno != 0 || s[0] == '-' || v < lo || v > hi) {
        return false;
    }
    *out = v;
    return true;
}

int cmd_can_feed(int argc, char **argv)
{
    const char *map_path = NULL, *socketcan_if = NULL, *mav_udp = NULL;
    long mcast_bus = -1;
    unsigned long node_id = 0, sensor_id = 0, sectors = 72, priority = 24;
    float pose_v[4] = {0, 0, 0, 0};
    bool have_pose = false, map_ned = false;
    float rate_hz = 10.0f, duration_s = -1.0f, min_m = 0.2f, max_m = 20.0f;
    size_t arena_extra = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
        unsigned long u = 0;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        }
        if (v == NULL) {
            cli_error(CMD, "%s needs a value (or unknown option)", a);
            return 2;
        }
        i++;
        bool ok = true;
        if (strcmp(a, "--map") == 0) {
            map_path = v;
        } else if (strcmp(a, "--socketcan") == 0) {
            socketcan_if = v;
        } else if (strcmp(a, "--mcast") == 0) {
            ok = parse_uint(v, 0, 255, &u);
            mcast_bus = (long)u;
        } else if (strcmp(a, "--node-id") == 0) {
            ok = parse_uint(v, 1, 127, &node_id);
        } else if (strcmp(a, "--sensor-id") == 0) {
            ok = parse_uint(v, 0, 255, &sensor_id);
        } else if (strcmp(a, "--priority") == 0) {
            ok = parse_uint(v, 0, 31, &priority);
        } else if (strcmp(a, "--sectors") == 0) {
            ok = parse_uint(v, 4, OCC_SECTORS_MAX, &sectors);
        } else if (strcmp(a, "--pose") == 0) {
            ok = cli_parse_floats(v, pose_v, 4) != 0;
            have_pose = ok;
        } else if (strcmp(a, "--mavlink-udp") == 0) {
            mav_udp = v;
        } else if (strcmp(a, "--rate-hz") == 0) {
            ok = cli_parse_floats(v, &rate_hz, 1) != 0 && rate_hz >= 0.1f && rate_hz <= 100.0f;
        } else if (strcmp(a, "--duration-s") == 0) {
            ok = cli_parse_floats(v, &duration_s, 1) != 0 && duration_s >= 0.0f;
        } else if (strcmp(a, "--min-m") == 0) {
            ok = cli_parse_floats(v, &min_m, 1) != 0 && min_m >= 0.01f;
        } else if (strcmp(a, "--max-m") == 0) {
            ok = cli_parse_floats(v, &max_m, 1) != 0 && max_m <= 655.0f;
        } else if (strcmp(a, "--map-frame") == 0) {
            ok = strcmp(v, "enu") == 0 || strcmp(v, "ned") == 0;
            map_ned = strcmp(v, "ned") == 0;
        } else if (strcmp(a, "--arena-extra") == 0) {
            ok = cli_parse_size(v, &arena_extra) != 0;
        } else {
            cli_error(CMD, "unknown option %s", a);
            usage(stderr);
            return 2;
        }
        if (!ok) {
            cli_error(CMD, "bad value for %s: '%s'", a, v);
            return 2;
        }
    }
    if (map_path == NULL || node_id == 0u || ((socketcan_if != NULL) == (mcast_bus >= 0)) ||
        (have_pose == (mav_udp != NULL)) || min_m >= max_m) {
        cli_error(CMD, "need --map, --node-id, one of --socketcan/--mcast and one of "
                       "--pose/--mavlink-udp (min < max)");
        usage(stderr);
        return 2;
    }

    /* The map. */
    occ_map_t map;
    void *arena = NULL;
    char msg[256] = "";
    occ_err_t e = occ_file_load_alloc(map_path, NULL, &map, arena_extra, &arena, NULL, msg,
                                      sizeof msg);
    if (e != OCC_OK) {
        cli_error(CMD, "cannot load %s: %s (%s)", map_path, msg, occ_err_str(e));
        return 1;
    }

    occ_sectors_config_t scfg = occ_sectors_config_default();
    scfg.n_sectors = (uint8_t)sectors;
    scfg.increment_deg = 360.0f / (float)sectors;
    scfg.angle_offset_deg = 0.0f;
    scfg.min_distance_cm = (uint16_t)lroundf(min_m * 100.0f);
    scfg.max_distance_cm = (uint16_t)lroundf(max_m * 100.0f);
    scfg.map_ned = map_ned;
    if (occ_sectors_config_check(&scfg) != OCC_OK) {
        cli_error(CMD, "bad sector settings (sectors %lu, %.2f..%.2f m)", sectors, (double)min_m,
                  (double)max_m);
        free(arena);
        return 2;
    }

    /* The pose: fixed, or live from MAVLink. */
    occ_pose_t pose;
    memset(&pose, 0, sizeof pose);
    const float deg = 3.14159265358979f / 180.0f;
    if (have_pose) {
        if (map_ned) {
            pose.x = pose_v[0];
            pose.y = pose_v[1];
            pose.z = pose_v[2];
            pose.yaw_rad = pose_v[3] * deg;
        } else {
            pose = occ_pose_from_ned(pose_v[0], pose_v[1], pose_v[2], pose_v[3] * deg);
        }
    }
    static occ_mav_feed_t mav; /* ~5 KB of sector scratch: keep it off the stack */
    int mav_fd = -1;
    if (mav_udp != NULL) {
        occ_mav_feed_config_t mcfg = occ_mav_feed_config_default();
        mcfg.map_frame = map_ned ? OCC_MAP_FRAME_NED : OCC_MAP_FRAME_ENU;
        mcfg.sectors = scfg;
        mcfg.pose_interval_us = 0; /* this link only listens: the streams must be set up */
        if (occ_mav_feed_init(&mav, &mcfg) != OCC_OK || (mav_fd = open_udp_listen(mav_udp)) < 0) {
            cli_error(CMD, "cannot listen for MAVLink on %s: %s", mav_udp, strerror(errno));
            free(arena);
            return 1;
        }
    }

    /* The bus. */
    static bus_t bus;
    memset(&bus, 0, sizeof bus);
    occ_can_iface_t iface;
    if (socketcan_if != NULL) {
        e = occ_socketcan_open(&bus.sc, socketcan_if, false, msg, sizeof msg);
        iface = occ_socketcan_iface(&bus.sc);
    } else {
        bus.use_mcast = true;
        e = occ_can_mcast_open(&bus.mc, (unsigned)mcast_bus, true, msg, sizeof msg);
        iface = occ_can_mcast_iface(&bus.mc);
    }
    if (e != OCC_OK) {
        cli_error(CMD, "cannot open the CAN bus: %s", msg);
        free(arena);
        if (mav_fd >= 0) {
            (void)close(mav_fd);
        }
        return 1;
    }
    const occ_can_filter_t all_ext = {0, 0, true};
    if (!bus.use_mcast) {
        (void)occ_socketcan_set_filters(&bus.sc, &all_ext, 1);
    }

    /* The node. */
    static occ_dronecan_node_t node;
    occ_dronecan_config_t ncfg = occ_dronecan_config_default();
    ncfg.node_id = (uint8_t)node_id;
    ncfg.sensor_id = (uint8_t)sensor_id;
    ncfg.priority = (uint8_t)priority;
    ncfg.proximity_period_us = (uint32_t)lroundf(1e6f / rate_hz);
    uint32_t h = 2166136261u; /* unique id: FNV-1a of host name and node id, stable per host */
    char hostname[64] = "";
    (void)gethostname(hostname, sizeof hostname - 1u);
    const size_t hl = strlen(hostname);
    for (size_t k = 0; k < 16u; k++) {
        const unsigned c = k < hl ? (unsigned)(unsigned char)hostname[k] : (unsigned)(k + node_id);
        h = (h ^ c) * 16777619u;
        ncfg.unique_id[k] = (uint8_t)(h >> 24);
    }
    e = occ_dronecan_init(&node, &ncfg, &iface);
    if (e != OCC_OK) {
        cli_error(CMD, "node init: %s", occ_err_str(e));
        free(arena);
        return 1;
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);

    const uint64_t t_start = now_us();
    const uint64_t t_end = duration_s >= 0.0f ? t_start + (uint64_t)(duration_s * 1e6f) : UINT64_MAX;
    uint32_t sector_errors = 0, send_errors = 0;
    while (!stop_requested) {
        const uint64_t t = now_us();
        if (t >= t_end) {
            break;
        }
        uint64_t pose_stamp = t;
        if (mav_fd >= 0) {
            uint8_t buf[2048];
            ssize_t r;
            while ((r = recv(mav_fd, buf, sizeof buf, 0)) > 0) {
                occ_mav_feed_rx(&mav, buf, (size_t)r, t);
            }
            if (!occ_mav_feed_pose(&mav, t, &pose)) {
                pose_stamp = 0; /* no fresh pose: the node reports NO_DATA */
            }
        }
        e = occ_dronecan_poll_map(&node, t, &map, t, &pose, pose_stamp, &scfg);
        if (e == OCC_ERR_RANGE || e == OCC_ERR_ARG) {
            sector_errors++; /* vehicle off the map: the node said NO_DATA */
        } else if (e == OCC_ERR_IO) {
            send_errors++;
        }
        /* Serve the bus until the next publication is due (at most 10 ms per wait). */
        occ_can_frame_t f;
        bool got = true;
        while (got && !stop_requested) {
            const uint64_t t2 = now_us();
            const uint64_t due = node.next_proximity_us < node.next_status_us
                                     ? node.next_proximity_us : node.next_status_us;
            if (t2 >= due || t2 >= t_end) {
                break;
            }
            int wait_ms = (int)((due - t2) / 1000u);
            wait_ms = wait_ms > 10 ? 10 : wait_ms;
            if (bus_recv(&bus, &f, wait_ms, &got) != OCC_OK) {
                break;
            }
            if (got) {
                (void)occ_dronecan_ingest(&node, &f, now_us());
            }
            got = got || wait_ms > 0; /* keep waiting until due */
        }
    }
    const occ_dronecan_stats_t *st = &node.stats;
    printf("{\"proximity_sent\": %u, \"tx_frames\": %u, \"tx_transfers\": %u, \"tx_full\": %u, "
           "\"tx_errors\": %u, \"rx_frames\": %u, \"node_info_answered\": %u, "
           "\"bus_off\": %u, \"sector_errors\": %u, \"send_errors\": %u, \"last_obstacles\": %u, "
           "\"seconds\": %.2f}\n",
           st->proximity_sent, st->tx_frames, st->tx_transfers, st->tx_full, st->tx_errors,
           st->rx_frames, st->node_info_answered, st->bus_off, sector_errors, send_errors,
           (unsigned)node.last_obstacles, (double)(now_us() - t_start) / 1e6);
    fflush(stdout);
    if (bus.use_mcast) {
        occ_can_mcast_close(&bus.mc);
    } else {
        occ_socketcan_close(&bus.sc);
    }
    if (mav_fd >= 0) {
        (void)close(mav_fd);
    }
    free(arena);
    return 0;
}
