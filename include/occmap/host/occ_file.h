/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_file.h - map files on a POSIX host (port/posix/file_io.c), on top of occ_io.h.
 * Formats: .bt (OctoMap compact), .ot (OctoMap full), .occ (occmap snapshot). Loading detects
 * the format from the file's content (the magic), so a misnamed file still loads; saving picks
 * it from the extension (case-insensitive). Host only: these functions use malloc and stdio.
 */
#ifndef OCC_FILE_H_INCLUDED
#define OCC_FILE_H_INCLUDED

#include "occmap/occmap.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Format named by the extension of `path` (.bt, .ot, .occ), else OCC_FORMAT_UNKNOWN. */
occ_format_t occ_file_format_of(const char *path);

/* Read the whole file into a malloc'd buffer (free() it). OCC_ERR_IO (msg says why),
 * OCC_ERR_NOMEM. */
occ_err_t occ_file_read_all(const char *path, uint8_t **data, size_t *len, char *msg,
                            size_t msg_len);

/* Validate `path` without loading it (occ_io_probe): format, resolution, node count and the
 * arena bytes a load needs (info->arena_bytes_needed). `base_cfg` NULL: defaults. */
occ_err_t occ_file_probe(const char *path, const occ_map_config_t *base_cfg, occ_io_info_t *info,
                         char *msg, size_t msg_len);

/* Load `path` into `map`, which this call initializes on the caller's arena with the file's
 * resolution and depth and the other parameters of `base_cfg` (NULL: defaults; snapshots carry
 * their own config). On error the map is left as it was (if it was initialized) and `msg` (may
 * be NULL) gets a one-line reason with the byte offset where known. `info` may be NULL.
 * Errors: OCC_ERR_IO, OCC_ERR_FORMAT, OCC_ERR_UNSUPPORTED, OCC_ERR_NOMEM (does not fit).
 * Never on a shared map (occ_shared.h): an init unshares it under its readers; read the file
 * with occ_file_read_all() and load it with occ_io_read() instead (one version). */
occ_err_t occ_file_load(const char *path, const occ_map_config_t *base_cfg, occ_map_t *map,
                        void *arena, size_t arena_bytes, char *msg, size_t msg_len);
/* The same, also returning what the reader found (warnings, node count). */
occ_err_t occ_file_load_info(const char *path, const occ_map_config_t *base_cfg, occ_map_t *map,
                             void *arena, size_t arena_bytes, occ_io_info_t *info, char *msg,
                             size_t msg_len);

/* Load into a freshly malloc'd arena sized for the file plus `extra_bytes` of headroom for
 * later updates. *arena_out receives the arena (free() it when the map is no longer used). */
occ_err_t occ_file_load_alloc(const char *path, const occ_map_config_t *base_cfg, occ_map_t *map,
                              size_t extra_bytes, void **arena_out, occ_io_info_t *info,
                              char *msg, size_t msg_len);

/* Save atomically in the format of the extension: write "<path>.tmp.<pid>", fsync it, rename
 * it over `path`, fsync the directory. A crash at any point leaves either the old file or the
 * new one, never a torn one; on error the temporary file is removed. OCC_ERR_ARG (unknown
 * extension), OCC_ERR_UNSUPPORTED (OctoMap format and depth != 16), OCC_ERR_IO. */
occ_err_t occ_file_save(const char *path, const occ_map_t *map, char *msg, size_t msg_len);
/* The same in an explicit format; `bytes` (may be NULL) gets the file size. */
occ_err_t occ_file_save_as(const char *path, const occ_map_t *map, occ_format_t format,
                           size_t *bytes, char *msg, size_t msg_len);

#ifdef __cplusplus
}
#endif
#endif
