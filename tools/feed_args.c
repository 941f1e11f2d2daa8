/* SPDX-License-Identifier: BSD-3-Clause */
/* feed_args.c - the argument loop, options, link, map and stop signal of the feed commands. */
#include <math.h>
#include <signal.h>
#include <string.h>

#include "cli.h"
#include "feed_args.h"
#include "occmap/host/occ_file.h"

static void feed_args_defaults(feed_args_t *a)
{
    memset(a, 0, sizeof *a);
    a->map_ned = false;
    a->min_m = 0.2f;
    a->max_m = 20.0f;
    a->rate_hz = 10.0f;
    a->duration_s = -1.0f;
}

/* One of the shared options: FEED_OPT_OK, FEED_OPT_BAD_VALUE or FEED_OPT_UNKNOWN. */
static int shared_option(feed_args_t *a, const char *opt, const char *v)
{
    bool ok = true;
    if (strcmp(opt, "--map") == 0) {
        a->map_path = v;
    } else if (strcmp(opt, "--map-frame") == 0) {
        ok = strcmp(v, "enu") == 0 || strcmp(v, "ned") == 0;
        a->map_ned = ok ? strcmp(v, "ned") == 0 : a->map_ned;
    } else if (strcmp(opt, "--min-m") == 0) {
        ok = cli_parse_float_in(v, 0.01f, 600.0f, &a->min_m);
    } else if (strcmp(opt, "--max-m") == 0) {
        ok = cli_parse_float_in(v, 0.02f, 655.0f, &a->max_m);
    } else if (strcmp(opt, "--rate-hz") == 0) {
        ok = cli_parse_float_in(v, 0.1f, 100.0f, &a->rate_hz);
    } else if (strcmp(opt, "--duration-s") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 1e7f, &a->duration_s);
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

/* Which voxels count and what an element says: the band, the ground, angles, unknown space. */
int feed_args_sector_option(occ_sectors_config_t *sc, const char *a, const char *v)
{
    bool ok;
    if (strcmp(a, "--band-m") == 0) {
        float band_m = 0.0f;
        ok = cli_parse_float_in(v, 0.01f, 100.0f, &band_m);
        sc->band_below_m = sc->band_above_m = band_m;
    } else if (strcmp(a, "--band-below-m") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 100.0f, &sc->band_below_m);
    } else if (strcmp(a, "--band-above-m") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 100.0f, &sc->band_above_m);
    } else if (strcmp(a, "--ground-clearance-m") == 0) {
        ok = cli_parse_float_in(v, 0.0f, 100.0f, &sc->ground_clearance_m);
    } else if (strcmp(a, "--angle-offset-deg") == 0) {
        ok = cli_parse_float_in(v, -360.0f, 360.0f, &sc->angle_offset_deg);
    } else if (strcmp(a, "--unknown") == 0) {
        ok = strcmp(v, "no-data") == 0 || strcmp(v, "distance") == 0;
        sc->unknown_as_distance = ok ? strcmp(v, "distance") == 0 : sc->unknown_as_distance;
    } else {
        return FEED_OPT_UNKNOWN;
    }
    return ok ? FEED_OPT_OK : FEED_OPT_BAD_VALUE;
}

static bool is_flag(const feed_cmd_t *cmd, const char *opt)
{
    for (const char *const *f = cmd->flags; f != NULL && *f != NULL; f++) {
        if (strcmp(*f, opt) == 0) {
            return true;
        }
    }
    return false;
}

int feed_args_parse(feed_args_t *a, const feed_cmd_t *cmd, int argc, char **argv)
{
    feed_args_defaults(a);
    for (int i = 1; i < argc; i++) {
        const char *opt = argv[i];
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0) {
            cmd->usage(stdout);
            return 0;
        }
        if (is_flag(cmd, opt)) {
            (void)cmd->option(cmd->ctx, opt, NULL);
            continue;
        }
        if (i + 1 >= argc) {
            cli_error(cmd->name, "%s needs a value", opt);
            cmd->usage(stderr);
            return 2;
        }
        const char *v = argv[++i];
        int r = shared_option(a, opt, v);
        if (r == FEED_OPT_UNKNOWN) {
            r = cmd->option(cmd->ctx, opt, v);
        }
        if (r == FEED_OPT_UNKNOWN) {
            cli_error(cmd->name, "unknown option %s", opt);
            cmd->usage(stderr);
            return 2;
        }
        if (r == FEED_OPT_BAD_VALUE) {
            cli_error(cmd->name, "bad value for %s: '%s'", opt, v);
            return 2;
        }
    }
    return FEED_ARGS_RUN;
}

void feed_args_apply_range(const feed_args_t *a, occ_sectors_config_t *sc)
{
    sc->min_distance_cm = (uint16_t)lroundf(a->min_m * 100.0f);
    sc->max_distance_cm = (uint16_t)lroundf(a->max_m * 100.0f);
}

uint64_t feed_args_end_us(const feed_args_t *a, const uint64_t t0)
{
    return a->duration_s >= 0.0f ? t0 + (uint64_t)(a->duration_s * 1e6f) : UINT64_MAX;
}

int feed_load_map(const char *cmd, const feed_args_t *a, const size_t arena_extra,
                  occ_map_t *map, void **arena)
{
    char msg[256] = "";
    *arena = NULL;
    const occ_err_t e = occ_file_load_alloc(a->map_path, NULL, map, arena_extra, arena, NULL,
                                            msg, sizeof msg);
    if (e != OCC_OK) {
        cli_error(cmd, "cannot load %s: %s (%s)", a->map_path, msg, occ_err_str(e));
        return 1;
    }
    return 0;
}

/* "HOST:PORT" -> host (copied) and port (1..65535); with host_optional "PORT" alone and
 * ":PORT" give an empty host. */
static bool split_host_port(const char *s, char *host, size_t host_len, uint32_t *port,
                            bool host_optional)
{
    const char *colon = strrchr(s, ':');
    if (colon == NULL) {
        if (!host_optional) {
            return false;
        }
        host[0] = '\0';
        return cli_parse_u32(s, 1, 65535, port);
    }
    const size_t n = (size_t)(colon - s);
    if (n >= host_len || (n == 0 && !host_optional)) {
        return false;
    }
    memcpy(host, s, n);
    host[n] = '\0';
    return cli_parse_u32(colon + 1, 1, 65535, port);
}

int feed_link_open(const char *cmd, const char *opt, const occ_link_kind_t kind,
                   const char *spec, occ_link_t *link)
{
    char host[256], msg[256] = "";
    uint32_t port = 0;
    const bool listen = kind == OCC_LINK_UDP_LISTEN, serial = kind == OCC_LINK_SERIAL;
    /* the port of a serial spec is its baud rate, checked by occ_link_serial_open */
    if (!split_host_port(spec, host, sizeof host, &port, listen)) {
        cli_error(cmd, "%s wants %s, got '%s'", opt,
                  listen ? "[HOST:]PORT" : serial ? "DEV:BAUD" : "HOST:PORT", spec);
        return 2;
    }
    occ_err_t e;
    if (listen) {
        e = occ_link_udp_listen(link, host[0] != '\0' ? host : NULL, (uint16_t)port, msg,
                                sizeof msg);
    } else if (serial) {
        e = occ_link_serial_open(link, host, port, msg, sizeof msg);
    } else {
        e = occ_link_udp_connect(link, host, (uint16_t)port, msg, sizeof msg);
    }
    if (e != OCC_OK) {
        cli_error(cmd, "%s", msg);
        return e == OCC_ERR_ARG ? 2 : 1;
    }
    return 0;
}

occ_err_t feed_link_drain(occ_link_t *link, occ_mav_feed_t *feed, const uint64_t now)
{
    uint8_t buf[2048];
    size_t n = 0;
    do {
        if (occ_link_read(link, buf, sizeof buf, &n) != OCC_OK) {
            return OCC_ERR_IO;
        }
        if (n > 0u) {
            occ_mav_feed_rx(feed, buf, n, now);
        }
    } while (n > 0u);
    return OCC_OK;
}

static volatile sig_atomic_t stop_flag;

static void on_stop_signal(int sig)
{
    (void)sig;
    stop_flag = 1;
}

void feed_stop_install(void)
{
    struct sigaction sa; /* no SA_RESTART: a blocking call returns at once */
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
}

bool feed_stop_requested(void)
{
    return stop_flag != 0;
}
