/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * oracle_stats.h - OctoMap's own statistics of a tree, the reference for occ_map_stats():
 * the node and leaf counts of octomap::OcTree and the occupied / free volumes as OctoMap's leaf
 * iterator gives them (the sum of it.getSize()^3 over the leaves, isNodeOccupied() deciding).
 * Host only, extern "C".
 */
#ifndef OCC_ORACLE_STATS_H_INCLUDED
#define OCC_ORACLE_STATS_H_INCLUDED

#include <stddef.h>
#include <stdint.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double resolution_m;                   /* the tree's, as OctoMap holds it (double) */
    uint64_t nodes, leaf_nodes;            /* size(), getNumLeafNodes() */
    uint64_t occupied_leaves, free_leaves;
    double occupied_volume_m3, free_volume_m3;
} oracle_stats_t;

/* OcTree::readBinary on the bytes of a .bt file, prune(), then the statistics. False if OctoMap
 * refuses the bytes. */
bool oracle_stats_bt(const uint8_t *data, size_t len, oracle_stats_t *out);

#ifdef __cplusplus
}
#endif
#endif
