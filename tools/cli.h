/* SPDX-License-Identifier: BSD-3-Clause */
/* cli.h - what the occmap subcommands share: the command table, argument helpers, JSON output. */
#ifndef OCC_TOOLS_CLI_H_INCLUDED
#define OCC_TOOLS_CLI_H_INCLUDED

#include <stdio.h>
#include "occmap/occmap.h"

/* One subcommand: returns the process exit status (0 ok, 1 runtime error, 2 usage error). */
typedef int (*cli_cmd_fn)(int argc, char **argv);

int cmd_stats(int argc, char **argv);     /* cmd_stats.c    foundation */
int cmd_build(int argc, char **argv);     /* cmd_build.c    integration */
int cmd_query(int argc, char **argv);     /* cmd_query.c    queries */
int cmd_info(int argc, char **argv);      /* cmd_info.c     files */
int cmd_convert(int argc, char **argv);   /* cmd_convert.c  files */
int cmd_feed(int argc, char **argv);      /* cmd_feed.c     MAVLink */
int cmd_can_feed(int argc, char **argv);  /* cmd_can_feed.c DroneCAN */
int cmd_run(int argc, char **argv);       /* cmd_run.c      the onboard loop */

/* Parse "a,b,c,..." into exactly n floats; false on any malformed or non-finite entry. */
int cli_parse_floats(const char *s, float *out, int n);
/* Parse one float in [lo, hi] (cli_parse_floats rules); false, *out unchanged, otherwise. */
bool cli_parse_float_in(const char *s, float lo, float hi, float *out);
/* Parse a decimal integer in [lo, hi] (no sign, no suffix); false, *out unchanged, otherwise. */
bool cli_parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out);
/* Parse a positive size with optional K/M/G suffix (powers of 1024). */
int cli_parse_size(const char *s, size_t *out);
/* Print an error "occmap <cmd>: <msg>" to stderr. */
void cli_error(const char *cmd, const char *fmt, ...);

/* JSON number text that reads back as exactly `v`: the shortest "%.*g" that round-trips (at most
 * 17 significant digits for a double, 9 for a float). `buf` must hold CLI_NUM_CHARS; returns
 * it. Non-finite values print as null (JSON has no NaN/Inf). */
#define CLI_NUM_CHARS 32
const char *cli_json_double(char *buf, double v);
const char *cli_json_float(char *buf, float v);

/* Print the map statistics keys (without braces) as JSON members:
 * "resolution_m", "depth_levels", "inner_nodes", "leaf_nodes", "occupied_leaves", "free_leaves",
 * "occupied_voxels", "free_voxels", "occupied_volume_m3", "free_volume_m3", "memory_bytes",
 * "bbox_min", "bbox_max". Every number round-trips (cli_json_double / cli_json_float). */
void cli_print_stats_json(FILE *f, const occ_map_t *map, const occ_map_stats_t *st);
/* The same as human-readable lines. */
void cli_print_stats_text(FILE *f, const occ_map_t *map, const occ_map_stats_t *st);

/* A DroneCAN unique id stable per host and node: FNV-1a of the host name and the node id
 * (can-feed and run). */
void cli_host_unique_id(uint8_t id[16], uint32_t node_id);

#endif
