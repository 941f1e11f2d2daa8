/* SPDX-License-Identifier: BSD-3-Clause */
/* iotest.h - helpers shared by the file tests and fuzz regression tests (prefix iotest_). */
#ifndef OCC_IOTEST_H_INCLUDED
#define OCC_IOTEST_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#include "occmap/occmap.h"
#include "oracle_io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Whole file into a malloc'd buffer (NULL if unreadable). */
uint8_t *iotest_read_file(const char *path, size_t *len);
/* FNV-1a over every node the walk reports (key, level, value, flags, children) and the pool
 * counters: equal digests = the same map. */
uint64_t iotest_map_digest(const occ_map_t *map);
/* occ_map_config_default() with OctoMap's exact sensor model (logodds of 0.7, 0.4, 0.1192,
 * 0.971 as OctoMap computes them), so .bt leaves and clamped values match OctoMap's. */
occ_map_config_t iotest_octomap_cfg(void);
/* Load bytes into a malloc'd arena sized by occ_io_probe (plus `extra` bytes). Returns the
 * arena (free() it) or NULL with *err set. */
void *iotest_load(occ_map_t *map, const uint8_t *buf, size_t len, size_t extra, occ_err_t *err,
                  occ_io_info_t *info);
/* Serialize into a malloc'd buffer. */
uint8_t *iotest_write(const occ_map_t *map, occ_format_t fmt, size_t *len);
/* The occmap map and the OctoMap tree describe the same voxels with values within `tol`. */
bool iotest_equivalent(const occ_map_t *map, const oracle_io_t *t, float tol, char *why,
                       size_t why_len);

#ifdef __cplusplus
}
#endif
#endif
