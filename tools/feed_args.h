/* SPDX-License-Identifier: BSD-3-Clause */
/* feed_args.h - what the two feed commands share, `occmap feed` (MAVLink, cmd_feed.c) and
 * `occmap can-feed` (DroneCAN, cmd_can_feed.c): the argument loop and the options both take,
 * the MAVLink link they open, the map they load, the stop signal and the end of the run.
 * Host only (POSIX links, stdio, malloc). */
#ifndef OCC_TOOLS_FEED_ARGS_H_INCLUDED
#define OCC_TOOLS_FEED_ARGS_H_INCLUDED

#include <stdio.h>

#include "occmap/occmap.h"
#include "occmap/occ_sectors.h"
#include "occmap/occ_mavlink.h"
#include "occmap/occ_port.h"
#include "occmap/host/occ_link_posix.h"

/* The options both commands take, with the same meaning and bounds. */
typedef struct {
    const char *map_path; /* --map MAP (required; checked by the command) */
    bool map_ned;         /* --map-frame enu|ned (default enu) */
    float min_m, max_m;   /* --min-m [0.01, 600] (0.2), --max-m [0.02, 655] (20): the range */
    float rate_hz;        /* --rate-hz [0.1, 100] (10): obstacle messages per second */
    float duration_s;     /* --duration-s [0, 1e7]; < 0 (default): until SIGINT/SIGTERM */
} feed_args_t;

/* A command's own options: called with the option and its value (NULL for a name listed in
 * `flags`, which takes none). Returns one of: */
enum { FEED_OPT_OK, FEED_OPT_BAD_VALUE, FEED_OPT_UNKNOWN };
typedef int (*feed_opt_fn)(void *ctx, const char *opt, const char *val);

typedef struct {
    const char *name;          /* "feed": messages read "occmap feed: ..." */
    void (*usage)(FILE *f);    /* the command's --help text */
    const char *const *flags;  /* its options without a value, NULL-terminated (or NULL) */
    feed_opt_fn option;        /* its other options */
    void *ctx;                 /* handed to option() */
} feed_cmd_t;

#define FEED_ARGS_RUN (-1)

/* Parse argv[1..] into `a` (defaults first) and the command's own options. Returns FEED_ARGS_RUN
 * to go on, or the exit status to return now: 0 after --help/-h (usage on stdout), 2 after a
 * message on stderr (a missing value or an unknown option, then the usage; a bad value). */
int feed_args_parse(feed_args_t *a, const feed_cmd_t *cmd, int argc, char **argv);

/* The sector options `occmap feed` and `occmap run` share: --band-m, --band-below-m,
 * --band-above-m, --ground-clearance-m, --angle-offset-deg, --unknown no-data|distance, into `sc`.
 * FEED_OPT_OK, FEED_OPT_BAD_VALUE or FEED_OPT_UNKNOWN (not one of them). */
int feed_args_sector_option(occ_sectors_config_t *sc, const char *opt, const char *val);

/* min_m, max_m in whole centimetres (rounded) into the sector settings. */
void feed_args_apply_range(const feed_args_t *a, occ_sectors_config_t *sc);

/* The clock time (occ_port_clock_us) the run ends at, started at t0: UINT64_MAX without
 * --duration-s. */
uint64_t feed_args_end_us(const feed_args_t *a, uint64_t t0);

/* Load a->map_path (occ_file_load_alloc, `arena_extra` bytes of room to grow; *arena is to be
 * freed). Returns 0, or 1 after a message. */
int feed_load_map(const char *cmd, const feed_args_t *a, size_t arena_extra, occ_map_t *map,
                  void **arena);

/* Open a MAVLink link of `kind` from the option `opt`'s value `spec`: OCC_LINK_UDP_CLIENT
 * "HOST:PORT", OCC_LINK_UDP_LISTEN "[HOST:]PORT", OCC_LINK_SERIAL "DEV:BAUD". Returns 0, or the
 * exit status after a message: 2 for a malformed spec or one the OS calls refuse as an argument
 * (OCC_ERR_ARG), 1 for an i/o error. */
int feed_link_open(const char *cmd, const char *opt, occ_link_kind_t kind, const char *spec,
                   occ_link_t *link);

/* Hand every datagram/byte run waiting on `link` to occ_mav_feed_rx at time `now`. Stops at the
 * first read error and returns it (OCC_ERR_IO), else OCC_OK. */
occ_err_t feed_link_drain(occ_link_t *link, occ_mav_feed_t *feed, uint64_t now);

/* SIGINT and SIGTERM set a flag instead of killing the process, so a feed can print its
 * statistics; feed_stop_requested() reads it. */
void feed_stop_install(void);
bool feed_stop_requested(void);

#endif
