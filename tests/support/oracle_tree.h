/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * oracle_tree.h - an octomap::OcTree behind a C API, the reference the tree tests and the memory
 * bench compare occmap against. Host only (links Debian's liboctomap). Keys are OctoMap keys
 * (16 bits per axis, depth 16): the same numbers as occmap keys at depth_levels 16.
 */
#ifndef OCC_ORACLE_TREE_H_INCLUDED
#define OCC_ORACLE_TREE_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct oracle_tree oracle_tree_t;

/* A new OcTree of the decimal a user writes for (float)resolution_m (OcTree(0.1) for 0.1f,
 * oracle_res.hpp) with OctoMap's default sensor model. NULL on failure.
 * Free with oracle_tree_free(). */
oracle_tree_t *oracle_tree_new(double resolution_m);
void oracle_tree_free(oracle_tree_t *t);
void oracle_tree_clear(oracle_tree_t *t);

/* The sensor model in use (log-odds): hit, miss, clamp min/max, occupancy threshold. */
void oracle_tree_params(const oracle_tree_t *t, float *hit, float *miss, float *clamp_min,
                        float *clamp_max, float *occ_thres);

/* OcTree::updateNode(key, occupied) (lazy_eval false: inner nodes and pruning kept current). */
void oracle_tree_update_key(oracle_tree_t *t, uint32_t kx, uint32_t ky, uint32_t kz,
                            bool occupied);
/* OcTree::updateNode(key, log_odds_delta). */
void oracle_tree_update_key_logodds(oracle_tree_t *t, uint32_t kx, uint32_t ky, uint32_t kz,
                                    float delta);
/* OcTree::coordToKeyChecked(x, y, z): true and the key if inside the tree's volume. */
bool oracle_tree_coord_to_key(const oracle_tree_t *t, double x, double y, double z,
                              uint32_t key[3]);

/* OcTree::size() (all nodes, root included), memoryUsage(), getNumLeafNodes(). */
size_t oracle_tree_size(const oracle_tree_t *t);
size_t oracle_tree_memory_usage(const oracle_tree_t *t);
size_t oracle_tree_num_leaf_nodes(const oracle_tree_t *t);

/* Leaf iterator counts: leaves whose log-odds is >= the occupancy threshold, and the others. */
void oracle_tree_leaf_counts(const oracle_tree_t *t, uint64_t *occupied, uint64_t *free_);

/* Visit every leaf (leaf iterator order). `key` is the leaf's first voxel (lowest `level` bits
 * clear), `level` = 16 - OctoMap depth (0 = voxel). Returns the number of leaves. */
typedef void (*oracle_tree_leaf_fn)(void *ctx, const uint32_t key[3], unsigned level,
                                    float logodds, bool occupied);
size_t oracle_tree_for_each_leaf(const oracle_tree_t *t, oracle_tree_leaf_fn fn, void *ctx);

/* Search the node containing voxel `key` at `level` (0 = voxel). Returns true when a node
 * exists there or above (a pruned leaf); *found_level gets the level of the node found,
 * *logodds its value, *has_children whether it has children. */
bool oracle_tree_search(const oracle_tree_t *t, const uint32_t key[3], unsigned level,
                        unsigned *found_level, float *logodds, bool *has_children);

#ifdef __cplusplus
}
#endif
#endif
