/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_collide_ccd.h - collision of any convex shape with the map through libccd (GJK or MPR on a
 * support function). Host builds only: src/map/collide_ccd.c links -lccd and is listed apart
 * (OCC_CCD_SRC in src/sources.mk) so firmware without libccd keeps the analytic checks of
 * occ_query.h. The shape is the caller's `const void *`; libccd's own allocation-free entry
 * points (ccdGJKIntersect, ccdMPRIntersect) are the only ones used.
 */
#ifndef OCC_COLLIDE_CCD_H_INCLUDED
#define OCC_COLLIDE_CCD_H_INCLUDED

#include "occmap/occmap.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Support function: the point of `shape` farthest along `dir` (map frame, metres; dir need not
 * be unit and is never zero). */
typedef void (*occ_support_fn)(const void *shape, const occ_vec3_t *dir, occ_vec3_t *out);

typedef struct {
    const void *shape;      /* caller-owned, only passed to `support` */
    occ_support_fn support;
    occ_vec3_t center;      /* a point strictly inside the shape (MPR starts from it) */
    occ_vec3_t bmin, bmax;  /* an axis-aligned box holding the shape (prunes the tree walk) */
} occ_convex_t;

typedef enum { OCC_CCD_GJK = 0, OCC_CCD_MPR = 1 } occ_ccd_algo_t;

/* Is the convex shape free of OCCUPIED voxels (and UNKNOWN ones / off-map space under
 * OCC_UNKNOWN_UNSAFE)? The tree is walked over the box bmin..bmax with the blocking predicate;
 * every blocking node found there is tested against the shape with libccd (tolerance: libccd's
 * default epsilon, so shapes within ~1e-6 m of a node may go either way).
 * OCC_ERR_ARG for NULL, a NULL support, NaN, bmin > bmax, a bad policy or algo; OCC_ERR_STATE
 * when the support function wrote the map during the check. `out` (when non-NULL) reads unsafe
 * on every error: safe is set false on entry and true only once every blocking node was tested. */
occ_err_t occ_collide_convex(const occ_map_t *map, const occ_convex_t *shape,
                             occ_unknown_policy_t policy, occ_ccd_algo_t algo,
                             occ_collision_t *out);

#ifdef __cplusplus
}
#endif
#endif
