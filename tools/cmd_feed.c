/* cmd_feed.c - occmap feed: OBSTACLE_DISTANCE over MAVLink from a map and the autopilot's pose. */
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "occmap/occ_file.h"
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
            "                   [--timeout-ms 300] [--autopilot ardupilot|px4] [--map-frame enu|ned]\n"
            "                   [--min-m 0.2] [--max-m 20] [--band-m 0.5] [--unknown-as-distance]\n"
            "                   [--duration-s S] [--verbose]\n"
            "Reads the autopilot's pose (LOCAL_POSITION_NED + ATTITUDE, ODOMETRY or\n"
            "ATTITUDE_QUATERNION) and sends MAVLink 2 OBSTACLE_DISTANCE (72 x 5 deg, MAV_FRAME_BODY_FRD)\n"
            "at --rate-hz plus a 1 Hz HEARTBEAT (MAV_TYPE_ONBOARD_CONTROLLER). Nothing is sent while the\n"
            "pose is older than --timeout-ms. --udp sends to HOST:PORT and takes poses from whoever\n"
            "answers (an autopilot or SITL listening there); --udp-listen waits for the autopilot to\n"
            "send first. The map file is fixed for the run, so it never goes stale. Ends after\n"
            "--duration-s (default: at SIGINT/SIGTERM) and prints statistics as one JSON line.\n");
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

int cmd_feed(int argc, char **argv)
{
    const char *map_path = NULL, *udp = NULL, *udp_listen = NULL, *serial = NULL;
    occ_mav_feed_config_t cfg = occ_mav_feed_config_default();
    uint32_t rate_hz = 10, timeout_ms = 300, sysid = cfg.sysid, compid = cfg.compid;
    float duration_s = 0.0f, min_m = 0.2f, max_m = 20.0f, band_m = 0.5f;
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
        } else if (strcmp(a, "--unknown-as-distance") == 0) {
            cfg.sectors.unknown_as_distance = true;
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
    cfg.sectors.min_distance_cm = (uint16_t)(min_m * 100.0f + 0.5f);
    cfg.sectors.max_distance_cm = (uint16_t)(max_m * 100.0f + 0.5f);
    cfg.sectors.band_below_m = band_m;
    cfg.sectors.band_above_m = band_m;
    static occ_mav_feed_t feed;
    if (occ_mav_feed_init(&feed, &cfg) != OCC_OK) {
        cli_error(CMD, "bad feed configuration (min %.2f m must be < max %.2f m)", (double)min_m,
                  (double)max_m);
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
           "\"ignored_rx\": %u, \"stale_skips\": %u, \"sector_errors\": %u, \"frames_ok\": %u, "
           "\"bad_crc\": %u, \"bad_len\": %u, \"unknown_id\": %u, \"bad_flags\": %u, "
           "\"junk_bytes\": %u, \"tx_dropped\": %u, \"update_us_mean\": %.1f, "
           "\"update_us_max\": %llu}\n",
           c->obstacle_tx, c->heartbeat_tx, c->positions_rx, c->attitudes_rx, c->ignored_rx,
           c->stale_skips, c->sector_errors, pc->frames_ok, pc->bad_crc, pc->bad_len,
           pc->unknown_id, pc->bad_flags, pc->junk_bytes, link.tx_dropped,
           tm.n > 0u ? (double)tm.sum_us / (double)tm.n : 0.0, (unsigned long long)tm.max_us);
    fflush(stdout);
    occ_link_close(&link);
    free(arena);
    return status;
}
