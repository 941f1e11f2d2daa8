/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * oracle_io.h - OctoMap (Debian liboctomap 1.9.7) as the reference for the file tests and the
 * I/O bench: its readers and writers on memory buffers, trees built from updates or from
 * OctoMap's example scans, and a leaf-for-leaf equivalence check. Host only, extern "C".
 * Keys are OctoMap keys (depth 16); `level` = 16 - OctoMap depth (0 = voxel).
 */
#ifndef OCC_ORACLE_IO_H_INCLUDED
#define OCC_ORACLE_IO_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct oracle_io oracle_io_t;

typedef enum { ORACLE_OCTREE = 0, ORACLE_COLOR = 1, ORACLE_STAMPED = 2 } oracle_io_kind_t;

/* A new empty tree of the given kind, of the decimal a user writes for (float)resolution_m. */
oracle_io_t *oracle_io_new(oracle_io_kind_t kind, double resolution_m);
void oracle_io_free(oracle_io_t *t);
/* OcTree::readBinary on the bytes (any id, as OctoMap does). NULL when OctoMap refuses. */
oracle_io_t *oracle_io_read_bt(const uint8_t *data, size_t len);
/* AbstractOcTree::read (.ot) on the bytes: an OcTree, ColorOcTree or OcTreeStamped. */
oracle_io_t *oracle_io_read_ot(const uint8_t *data, size_t len);
/* writeBinary (toMaxLikelihood + prune: modifies the tree, as OctoMap does) / write (.ot).
 * malloc'd bytes, free() them. */
uint8_t *oracle_io_write_bt(oracle_io_t *t, size_t *len);
uint8_t *oracle_io_write_ot(const oracle_io_t *t, size_t *len);
/* Whole-file helpers (timed by the bench). */
oracle_io_t *oracle_io_read_bt_file(const char *path);
bool oracle_io_write_bt_file(oracle_io_t *t, const char *path);

void oracle_io_prune(oracle_io_t *t);
size_t oracle_io_size(const oracle_io_t *t);
double oracle_io_resolution(const oracle_io_t *t);
/* updateNode(key, delta) (lazy_eval false); colour trees also get a colour from the key. */
void oracle_io_update(oracle_io_t *t, uint32_t kx, uint32_t ky, uint32_t kz, float delta);
/* setNodeValue(key, logodds) at the voxel. */
void oracle_io_set(oracle_io_t *t, uint32_t kx, uint32_t ky, uint32_t kz, float logodds);
/* insertPointCloud of the first `max_scans` scans of an OctoMap ScanGraph file (.graph).
 * False if the file cannot be read. */
bool oracle_io_insert_graph(oracle_io_t *t, const char *path, unsigned max_scans,
                            double max_range_m);

/* Visit every leaf; returns the count. */
/* insertPointCloud(points in the map frame, origin, max_range (<= 0: none), lazy_eval false,
 * discretize) on an ORACLE_OCTREE (the depth tests' reference). */
void oracle_io_insert_cloud(oracle_io_t *t, const float *xyz, size_t n, const float origin[3],
                            double max_range_m, bool discretize);
typedef void (*oracle_io_leaf_fn)(void *ctx, const uint32_t key[3], unsigned level,
                                  float logodds);
size_t oracle_io_for_each_leaf(const oracle_io_t *t, oracle_io_leaf_fn fn, void *ctx);
/* search(key, depth 16 - level): true when a node exists there or above; its level, value,
 * and whether it has children. */
bool oracle_io_search(const oracle_io_t *t, const uint32_t key[3], unsigned level,
                      unsigned *found_level, float *logodds, bool *has_children);

/* True when both trees describe the same voxels with values within `tol` (pruning may differ):
 * every leaf of one lies in a leaf of the other or above its finer leaves, values agree where
 * one is inside a leaf of the other, and the known volumes are equal. `why` gets the first
 * difference. */
bool oracle_io_equivalent(const oracle_io_t *a, const oracle_io_t *b, float tol, char *why,
                          size_t why_len);

#ifdef __cplusplus
}
#endif
#endif
