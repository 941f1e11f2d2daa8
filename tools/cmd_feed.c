/* cmd_feed.c - occmap feed: OBSTACLE_DISTANCE over MAVLink from a map and the autopilot's pose. */
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "occmap/host/occ_file.h"
#include "occmap/occ_mavlink.h"
#include "occmap/occ_port.h"

#define CMD "feed"

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

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

static bool parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    char *end = NULL;
    const unsigned long v = strtoul(s, &end, 10);
    if (s[0] == '\0' || s[0] == '-' || end == NULL || *end != '\0' || v < lo || v > hi) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

static bool parse_float(const char *s, float lo, float hi, float *out)
{
    float v;
    if (!cli_parse_floats(s, &v, 1) || v < lo || v > hi) {
        return false;
    }
    *out = v;
    return true;
}

/* "HOST:PORT" -> host (copied) and port; for --udp-listen "PORT" alone is accepted too. */
static bool split_host_port(const char *s, char *host, size_t host_len, uint32_t *port,
                            bool host_optional)
{
    const char *colon = strrchr(s, ':');
    if (colon == NULL) {
        if (!host_optional) {
            return false;
        }
        host[0] = '\0';
        return parse_u32(s, 1, 65535, port);
    }
    const size_t n = (size_t)(colon - s);
    if (n >= host_len || (n == 0 && !host_optional)) {
        return false;
    }
    memcpy(host, s, n);
    host[n] = '\0';
    return parse_u32(colon + 1, 1, 65535, port);
}

typedef struct {
    uint64_t n, sum_us, max_us;
} timing_t;

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

int cmd_feed(int argc, char **argv)
{
    const char *map_path = NULL, *udp = NULL, *udp_listen = NULL, *serial = NULL;
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    uint32_t rate_hz = 10, timeout_ms = 300, sysid = cfg.sysid, compid = cfg.compid;
    uint32_t ap_sysid = cfg.autopilot_sysid, ap_compid = cfg.autopilot_compid;
    uint32_t pose_interval_ms = cfg.pose_interval_us / 1000u;
    float duration_s = 0.0f, min_m = 0.2f, max_m = 20.0f, band_m = 0.0f;
    occ_sectors_config_t *const sc = &cfg.sectors;
    bool verbose = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok = true;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            return 0;
        } else if (strcmp(a, "--verbose") == 0) {
            verbose = true;
            continue;
        } else if (strcmp(a, "--unknown-as-distance") == 0) { /* the old spelling */
            sc->unknown_as_distance = true;
            continue;
        } else if (strcmp(a, "--no-ignore-ground") == 0) {
            sc->ignore_ground = false;
            continue;
        }
        if (v == NULL) {
            cli_error(CMD, "%s needs a value", a);
            usage(stderr);
            return 2;
        }
        i++;
        if (strcmp(a, "--map") == 0) {
            map_path = v;
        } else if (strcmp(a, "--udp") == 0) {
            udp = v;
        } else if (strcmp(a, "--udp-listen") == 0) {
            udp_listen = v;
        } else if (strcmp(a, "--serial") == 0) {
            serial = v;
        } else if (strcmp(a, "--rate-hz") == 0) {
            ok = parse_u32(v, 1, 100, &rate_hz);
        } else if (strcmp(a, "--sysid") == 0) {
            ok = parse_u32(v, 1, 255, &sysid);
        } else if (strcmp(a, "--compid") == 0) {
            ok = parse_u32(v, 1, 255, &compid);
        } else if (strcmp(a, "--timeout-ms") == 0) {
            ok = parse_u32(v, 1, 60000, &timeout_ms);
        } else if (strcmp(a, "--duration-s") == 0) {
            ok = parse_float(v, 0.0f, 1e7f, &duration_s);
        } else if (strcmp(a, "--min-m") == 0) {
            ok = parse_float(v, 0.01f, 600.0f, &min_m);
        } else if (strcmp(a, "--max-m") == 0) {
            ok = parse_float(v, 0.02f, 655.0f, &max_m);
        } else if (strcmp(a, "--band-m") == 0) {
            ok = parse_float(v, 0.01f, 100.0f, &band_m);
            sc->band_below_m = sc->band_above_m = band_m;
        } else if (strcmp(a, "--band-below-m") == 0) {
            ok = parse_float(v, 0.0f, 100.0f, &sc->band_below_m);
        } else if (strcmp(a, "--band-above-m") == 0) {
            ok = parse_float(v, 0.0f, 100.0f, &sc->band_above_m);
        } else if (strcmp(a, "--ground-clearance-m") == 0) {
            ok = parse_float(v, 0.0f, 100.0f, &sc->ground_clearance_m);
        } else if (strcmp(a, "--angle-offset-deg") == 0) {
            ok = parse_float(v, -360.0f, 360.0f, &sc->angle_offset_deg);
        } else if (strcmp(a, "--unknown") == 0) {
            if (strcmp(v, "no-data") == 0) {
                sc->unknown_as_distance = false;
            } else if (strcmp(v, "distance") == 0) {
                sc->unknown_as_distance = true;
            } else {
                ok = false;
            }
        } else if (strcmp(a, "--autopilot-sysid") == 0) {
            ok = parse_u32(v, 1, 255, &ap_sysid);
        } else if (strcmp(a, "--autopilot-compid") == 0) {
            ok = parse_u32(v, 1, 255, &ap_compid);
        } else if (strcmp(a, "--pose-interval-ms") == 0) {
            ok = parse_u32(v, 0, 60000, &pose_interval_ms);
        } else if (strcmp(a, "--autopilot") == 0) {
            if (strcmp(v, "ardupilot") == 0) {
                cfg.autopilot = OCC_AUTOPILOT_ARDUPILOT;
            } else if (strcmp(v, "px4") == 0) {
                cfg.autopilot = OCC_AUTOPILOT_PX4;
            } else {
                ok = false;
            }
        } else if (strcmp(a, "--map-frame") == 0) {
            if (strcmp(v, "enu") == 0) {
                cfg.map_frame = OCC_MAP_FRAME_ENU;
            } else if (strcmp(v, "ned") == 0) {
                cfg.map_frame = OCC_MAP_FRAME_NED;
            } else {
                ok = false;
            }
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
    const int n_links = (udp != NULL) + (udp_listen != NULL) + (serial != NULL);
    if (map_path == NULL || n_links != 1) {
        cli_error(CMD, "needs --map and exactly one of --udp, --udp-listen, --serial");
        usage(stderr);
        return 2;
    }
    cfg.sysid = (uint8_t)sysid;
    cfg.compid = (uint8_t)compid;
    cfg.period_us = 1000000u / rate_hz;
    cfg.pose_timeout_us = timeout_ms * 1000u;
    cfg.autopilot_sysid = (uint8_t)ap_sysid;
    cfg.autopilot_compid = (uint8_t)ap_compid;
    cfg.pose_interval_us = pose_interval_ms * 1000u;
    sc->min_distance_cm = (uint16_t)(min_m * 100.0f + 0.5f);
    sc->max_distance_cm = (uint16_t)(max_m * 100.0f + 0.5f);
    static occ_mav_feed_t feed;
    if (occ_mav_feed_init(&feed, &cfg) != OCC_OK) {
        cli_error(CMD, "bad feed configuration (min %.2f m must be < max %.2f m; the band "
                  "below + above must be > 0)", (double)min_m, (double)max_m);
        return 2;
    }

    char msg[256] = "";
    occ_map_t map;
    void *arena = NULL;
    occ_err_t e = occ_file_load_alloc(map_path, NULL, &map, 0, &arena, NULL, msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error(CMD, "%s: %s (%s)", map_path, occ_err_str(e), msg);
        return 1;
    }

    occ_link_t link;
    char host[256];
    uint32_t port = 0;
    if (udp != NULL) {
        if (!split_host_port(udp, host, sizeof host, &port, false)) {
            cli_error(CMD, "--udp wants HOST:PORT, got '%s'", udp);
            free(arena);
            return 2;
        }
        e = occ_link_udp_connect(&link, host, (uint16_t)port, msg, sizeof msg);
    } else if (udp_listen != NULL) {
        if (!split_host_port(udp_listen, host, sizeof host, &port, true)) {
            cli_error(CMD, "--udp-listen wants [HOST:]PORT, got '%s'", udp_listen);
            free(arena);
            return 2;
        }
        e = occ_link_udp_listen(&link, host[0] != '\0' ? host : NULL, (uint16_t)port, msg,
                                sizeof msg);
    } else {
        if (!split_host_port(serial, host, sizeof host, &port, false)) {
            cli_error(CMD, "--serial wants DEV:BAUD, got '%s'", serial);
            free(arena);
            return 2;
        }
        e = occ_link_serial_open(&link, host, port, msg, sizeof msg);
    }
    if (e != OCC_OK) {
        cli_error(CMD, "%s", msg);
        free(arena);
        return e == OCC_ERR_ARG ? 2 : 1;
    }

    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    const uint64_t t0 = occ_port_clock_us();
    const uint64_t t_end = duration_s > 0.0f ? t0 + (uint64_t)(duration_s * 1e6f) : UINT64_MAX;
    timing_t tm = {0, 0, 0};
    uint64_t next_report = t0 + 1000000u;
    uint32_t refusals_logged = 0;
    bool autopilot_logged = false;
    int status = 0;
    while (!stop_requested) {
        uint64_t now = occ_port_clock_us();
        if (now >= t_end) {
            break;
        }
        uint8_t buf[2048];
        size_t n = 0;
        do {
            if (occ_link_read(&link, buf, sizeof buf, &n) != OCC_OK) {
                cli_error(CMD, "read failed");
                status = 1;
                break;
            }
            if (n > 0u) {
                occ_mav_feed_rx(&feed, buf, n, now);
            }
        } while (n > 0u);
        if (status != 0) {
            break;
        }
        for (;;) {
            uint8_t out[OCC_MAV_FRAME_MAX];
            const uint32_t before = feed.counters.obstacle_tx;
            const uint64_t a = occ_port_clock_us();
            const size_t len = occ_mav_feed_poll(&feed, &map, now, out, sizeof out);
            if (len == 0u) {
                break;
            }
            if (feed.counters.obstacle_tx != before) {
                const uint64_t dt = occ_port_clock_us() - a;
                tm.n++;
                tm.sum_us += dt;
                tm.max_us = dt > tm.max_us ? dt : tm.max_us;
            }
            if (occ_link_write(&link, out, len) != OCC_OK) {
                cli_error(CMD, "write failed");
                status = 1;
                break;
            }
        }
        if (status != 0) {
            break;
        }
        log_autopilot(&feed, &autopilot_logged, &refusals_logged);
        if (verbose && now >= next_report) {
            next_report += 1000000u;
            occ_pose_t p;
            const bool fresh = occ_mav_feed_pose(&feed, now, &p);
            fprintf(stderr, "feed: t=%.1fs pose %s (%.2f %.2f %.2f yaw %.1f deg) tx %u obstacle %u hb"
                    ", rx ok %u bad %u\n", (double)(now - t0) * 1e-6, fresh ? "fresh" : "stale",
                    (double)p.x, (double)p.y, (double)p.z, (double)p.yaw_rad * 57.29578,
                    feed.counters.obstacle_tx, feed.counters.heartbeat_tx,
                    feed.parser.counters.frames_ok,
                    feed.parser.counters.bad_crc + feed.parser.counters.bad_len);
        }
        const uint64_t due = occ_mav_feed_next_due(&feed);
        now = occ_port_clock_us();
        uint64_t wait = due > now ? due - now : 0u;
        wait = wait > 50000u ? 50000u : wait;
        if (wait > 0u) {
            (void)occ_link_wait(&link, wait);
        }
    }
    const occ_mav_feed_counters_t *c = &feed.counters;
    const occ_mav_counters_t *pc = &feed.parser.counters;
    printf("{\"obstacle_tx\": %u, \"heartbeat_tx\": %u, \"positions_rx\": %u, \"attitudes_rx\": %u, "
           "\"ignored_rx\": %u, \"foreign_rx\": %u, \"requests_tx\": %u, \"request_acks\": %u, "
           "\"request_refusals\": %u, \"stale_skips\": %u, \"sector_errors\": %u, \"frames_ok\": %u, "
           "\"bad_crc\": %u, \"bad_len\": %u, \"unknown_id\": %u, \"bad_flags\": %u, "
           "\"junk_bytes\": %u, \"tx_dropped\": %u, \"update_us_mean\": %.1f, "
           "\"update_us_max\": %llu}\n",
           c->obstacle_tx, c->heartbeat_tx, c->positions_rx, c->attitudes_rx, c->ignored_rx,
           c->foreign_rx, c->requests_tx, c->request_acks, c->request_refusals, c->stale_skips,
           c->sector_errors, pc->frames_ok, pc->bad_crc, pc->bad_len, pc->unknown_id, pc->bad_flags, pc->junk_bytes, link.tx_dropped,
           tm.n > 0u ? (double)tm.sum_us / (double)tm.n : 0.0, (unsigned long long)tm.max_us);
    fflush(stdout);
    occ_link_close(&link);
    free(arena);
    return status;
}
