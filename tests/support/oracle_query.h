/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * oracle_query.h - brute-force references for the query tests (tests/support/oracle_query.cpp).
 * Shapes are built and tested with Eigen in double precision, sharing no code with the core's
 * float geometry; cells are enumerated one by one. Cell tests answer 1 (intersects), 0 (misses)
 * or -1 (within ORACLE_Q_EPS of touching: either answer is acceptable).
 * Also OctoMap itself for castRay (a .bt loaded through liboctomap).
 */
#ifndef OCC_ORACLE_QUERY_H_INCLUDED
#define OCC_ORACLE_QUERY_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>
#include "occmap/occmap.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ORACLE_Q_EPS 1e-4

typedef struct oracle_q_shape oracle_q_shape_t;

/* Shapes (free with oracle_q_free). Rotations from Z-Y-X Euler angles (yaw, pitch, roll, rad);
 * oracle_q_axes() gives the rotated axes (columns) so the test can hand them to the core. */
oracle_q_shape_t *oracle_q_aabb(const double mn[3], const double mx[3]);
oracle_q_shape_t *oracle_q_sphere(const double c[3], double r);
oracle_q_shape_t *oracle_q_obb(const double c[3], const double half[3], double yaw, double pitch,
                               double roll);
oracle_q_shape_t *oracle_q_capsule(const double a[3], const double b[3], double r);
oracle_q_shape_t *oracle_q_segment(const double a[3], const double b[3]);
/* Frustum looking along the rotated x axis (left = rotated y, up = rotated z). */
oracle_q_shape_t *oracle_q_frustum(const double origin[3], double yaw, double pitch, double roll,
                                   double hfov, double vfov, double near_m, double far_m);
void oracle_q_axes(const oracle_q_shape_t *s, float axes[9]); /* axis i = axes[3i..3i+2] */
void oracle_q_free(oracle_q_shape_t *s);

/* Does the cube at `level` holding voxel `key` of `map` intersect the shape? 1 / 0 / -1. */
int oracle_q_cell(const oracle_q_shape_t *s, const occ_map_t *map, occ_key_t key, unsigned level);

/* Brute force: every cell at `level` of the map that intersects the shape (or is ambiguous) and
 * holds a voxel whose state (read voxel by voxel with occ_map_read_key) is in `states`
 * (OCC_PRED_* bits). Writes up to `cap` Morton codes of the cells' first voxels (sorted) and
 * their ambiguity (1 if the geometric test was -1); returns the number found (may exceed cap). */
size_t oracle_q_collect(const occ_map_t *map, const oracle_q_shape_t *s, unsigned states,
                        unsigned level, uint64_t *codes, uint8_t *ambiguous, size_t cap);

/* Voxels intersecting the shape by state (occupied, free, unknown), definite ones only, and
 * the number of ambiguous voxels. */
void oracle_q_count(const occ_map_t *map, const oracle_q_shape_t *s, uint64_t counts[3],
                    uint64_t *ambiguous);

/* The shape's axis-aligned bounds. */
void oracle_q_bounds(const oracle_q_shape_t *s, double mn[3], double mx[3]);

/* Cells at `level` intersecting the shape none of whose voxels was ever observed (the
 * information gain under the default thresholds): definite and ambiguous counts. */
void oracle_q_gain(const occ_map_t *map, const oracle_q_shape_t *s, unsigned level,
                   uint64_t *definite, uint64_t *ambiguous);

/* Nearest: squared distance from p to the nearest voxel whose state is in `states`, searching
 * every voxel of the map (small maps). Returns -1 when none. */
double oracle_q_nearest_d2(const occ_map_t *map, const double p[3], unsigned states);

/* Fill an initialized (empty) map with a random scene in the middle half of its key range:
 * free and occupied blocks at levels 1..3 (pruned nodes), scattered voxels updated 1-3 times,
 * forgotten holes; only public calls (occ_map_set_key, occ_map_update_key, occ_map_forget_key). */
occ_err_t oracle_q_random_map(occ_map_t *map, uint64_t seed, unsigned n_voxels);

/* ---- OctoMap ---------------------------------------------------------------------------------- */
typedef struct oracle_q_octo oracle_q_octo_t;
/* Load a .bt/.ot through liboctomap; NULL if the file cannot be read. */
oracle_q_octo_t *oracle_q_octo_load(const char *path);
void oracle_q_octo_free(oracle_q_octo_t *o);
/* A random OcTree (resolution res_m, depth 16) around the origin: free boxes (pruned into large
 * nodes), unknown gaps between them, occupied boxes and scattered occupied voxels inside. */
oracle_q_octo_t *oracle_q_octo_random(uint64_t seed, double res_m);
double oracle_q_octo_resolution(const oracle_q_octo_t *o);
size_t oracle_q_octo_leaves(const oracle_q_octo_t *o);
/* Metric bounding box of the known space. */
void oracle_q_octo_bbox(const oracle_q_octo_t *o, double mn[3], double mx[3]);
/* Copy every leaf into `map` (initialized, same resolution, depth 16) with occ_map_set_key at the
 * leaf's level. Returns OCC_OK or the first error; *state_mismatch counts leaves whose occmap
 * state differs from OctoMap's isNodeOccupied after the copy. */
occ_err_t oracle_q_octo_copy(const oracle_q_octo_t *o, occ_map_t *map, size_t *state_mismatch);
/* OcTree::castRay(origin, dir, end, ignore_unknown, max_range). */
bool oracle_q_octo_cast(const oracle_q_octo_t *o, const float origin[3], const float dir[3],
                        bool ignore_unknown, double max_range, float end[3]);
/* OcTree::search(x, y, z): 1 occupied, 0 free, -1 unknown. */
int oracle_q_octo_search(const oracle_q_octo_t *o, const float p[3]);

#ifdef __cplusplus
}
#endif
#endif
