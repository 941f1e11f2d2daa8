/* SPDX-License-Identifier: BSD-3-Clause */
/* oracle_rays.h - OctoMap as the reference for ray keys and point-cloud integration (C API of
 * oracle_rays.cpp). Resolution: pass (double)cfg.resolution_m; the tree is built with the decimal
 * a user writes for that float (OcTree(0.1) for 0.1f, tests/support/oracle_res.hpp). */
#ifndef OCC_ORACLE_RAYS_H_INCLUDED
#define OCC_ORACLE_RAYS_H_INCLUDED

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* computeRayKeys(o, e): returns its bool; *n = keys in the ray, the first cap go to keys
 * (3 per key). */
int oracle_ray_keys(double res, const float o[3], const float e[3], uint32_t *keys, size_t cap,
                    size_t *n);

/* An octomap::OcTree of resolution res (depth 16, default sensor model). */
void *oracle_ins_new(double res);
void oracle_ins_delete(void *t);
/* insertPointCloud(points, origin, max_range, lazy_eval = false, discretize). */
void oracle_ins_cloud(void *t, const float *xyz, size_t n, const float origin[3],
                      double max_range, int discretize);
/* Leaves (after OctoMap's pruning): first key of each (low `level` bits clear), its level above
 * the voxels and log-odds. Returns the count; fills the first cap. */
size_t oracle_ins_leaves(void *t, uint32_t *keys, uint8_t *levels, float *logodds, size_t cap);
/* The deepest existing node containing voxel `key`: 1 and its log-odds and level, 0 if the
 * voxel is unknown to OctoMap. */
int oracle_ins_search(void *t, const uint32_t key[3], float *logodds, unsigned *level);
size_t oracle_ins_memory(void *t);

#ifdef __cplusplus
}
#endif
#endif
