/*
 * occ_file.h - map files on a POSIX host (port/posix/file_io.c). SKELETON: the files issue owns
 * and completes this header. Formats by extension: .bt (OctoMap compact), .ot (OctoMap full),
 * .occ (occmap snapshot).
 */
#ifndef OCC_FILE_H_INCLUDED
#define OCC_FILE_H_INCLUDED

#include "occmap/occmap.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Load `path` into `map`, which this call initializes on the caller's arena with the file's
 * resolution and depth and the other parameters of `base_cfg` (NULL: defaults). On error the
 * map is left as it was (if it was initialized) and `msg` (may be NULL) gets a one-line reason
 * with the byte offset where known. */
occ_err_t occ_file_load(const char *path, const occ_map_config_t *base_cfg, occ_map_t *map,
                        void *arena, size_t arena_bytes, char *msg, size_t msg_len);
/* Save atomically (temporary file, fsync, rename). */
occ_err_t occ_file_save(const char *path, const occ_map_t *map, char *msg, size_t msg_len);

#ifdef __cplusplus
}
#endif
#endif
