/*
 * occ_scan.h - reading recorded point clouds on a POSIX host (port/posix). Host side only:
 * these functions allocate the returned arrays with malloc; free them with free().
 */
#ifndef OCC_SCAN_H_INCLUDED
#define OCC_SCAN_H_INCLUDED

#include "occmap/occmap.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Read a plain-text point file: one "x y z" per line (metres; OctoMap's scan.dat). Blank lines
 * and lines starting with '#' are skipped; OctoMap's "NODE x y z roll pitch yaw" pose lines are
 * rejected (use the graph reader). On success *points (malloc'd) holds *n points.
 * OCC_ERR_IO (cannot open/read), OCC_ERR_FORMAT (a malformed line: `msg` names the line number),
 * OCC_ERR_NOMEM. */
occ_err_t occ_scan_read_xyz(const char *path, occ_vec3_t **points, size_t *n, char *msg,
                            size_t msg_len);

#ifdef __cplusplus
}
#endif
#endif
