/* SPDX-License-Identifier: BSD-3-Clause */
/* coarse_internal.h - whole-node updates for FAST_DISCRETE (coarse.c), src/integrate only. */
#ifndef OCC_COARSE_INTERNAL_H_INCLUDED
#define OCC_COARSE_INTERNAL_H_INCLUDED

#include "../core/tree_internal.h"

/* Upper bound of the blocks that updating the nodes at `level` named by `codes` (sorted voxel
 * codes of their first voxels; hit bit ignored) can allocate: one child block per distinct node
 * above `level` on their paths, as if none existed. O(n). */
void occi_coarse_need(const occ_code_t *codes, size_t n, unsigned level, unsigned depth,
                      uint64_t *inner, uint64_t *leaf);

/* Add `delta` to every voxel below each level-`level` (>= 1) node named by `codes` (sorted,
 * unique). The caller checked with occi_coarse_need() + occi_pool_can_supply() that the pools
 * can supply the blocks. Keeps maxima, indicators and pruning. Returns n. */
size_t occi_coarse_apply(occ_map_t *m, const occ_code_t *codes, size_t n, unsigned level,
                         occ_value_t delta);

#endif
