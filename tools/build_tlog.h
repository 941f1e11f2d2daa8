/* SPDX-License-Identifier: BSD-3-Clause */
/* build_tlog.h - `occmap build --tlog FILE` (build_tlog.c): the range readings of a MAVLink
 * telemetry log into the map, with the log's own poses. */
#ifndef OCC_TOOLS_BUILD_TLOG_H_INCLUDED
#define OCC_TOOLS_BUILD_TLOG_H_INCLUDED

#include "occmap/occmap.h"

/* Integrate `tlog` into `map` (made by cmd_build from --res / --arena-bytes), print what it did
 * (text or --json) and save it to out_path when not NULL. 0, or 1 after a message. */
int build_tlog(occ_map_t *map, const char *tlog, bool json, const char *out_path);

#endif
