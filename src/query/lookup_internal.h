/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * lookup_internal.h - the lookup index's table format and its walk over the tree (lookup_index.c,
 * lookup_index_build.c): what a cell holds, and the one fixed-stack walk that visits the nodes
 * the table is made of.
 */
#ifndef OCC_LOOKUP_INTERNAL_H_INCLUDED
#define OCC_LOOKUP_INTERNAL_H_INCLUDED

#include "query_internal.h"

/* A cell of a level >= 1 table: a block index (the cell's node has children: an inner block at
 * level >= 2, a leaf block at level 1), or OCC_IDX_TAG | state when the cell lies in a node
 * without children. Block indices stay below OCC_IDX_TAG (the build checks the pools). */
#define OCC_IDX_TAG 0xFFFFFFFCu

/* A level-0 table: 16 voxel states of 2 bits per 32-bit word, voxel i at bits 2 (i mod 16). */
#define OCC_IDX_PER_WORD 16u

/* A node the walk reports: without children (observed only), or at the stop level. */
typedef struct {
    occ_key_t key;   /* first voxel (low `level` bits clear) */
    unsigned level;
    uint32_t child;  /* child block, OCC_NONE when uniform */
    occ_value_t value;
} occ_idx_node_t;

/* Preorder walk down to `stop`: blk[L] is the block entered at level L (its entries sit at
 * L - 1), next[L] the next slot to visit there; top = depth + 1 when empty. */
typedef struct {
    uint32_t blk[OCC_MAX_DEPTH + 1u];
    uint8_t next[OCC_MAX_DEPTH + 1u];
    occ_key_t key;
    unsigned top, stop;
    bool root_pending;
} occ_idx_walk_t;

void occi_idx_walk_begin(occ_idx_walk_t *w, const occ_map_t *m, unsigned stop);
bool occi_idx_walk_next(occ_idx_walk_t *w, const occ_map_t *m, occ_idx_node_t *out);

/* Cells per axis and first keys of the table at `level` over the observed space (n = 0 when
 * nothing is observed). */
void occi_idx_box(const occ_map_t *m, unsigned level, uint32_t lo[3], uint32_t n[3]);
/* Table bytes for n cells per axis at `level` (SIZE_MAX when it does not fit). */
size_t occi_idx_bytes(unsigned level, const uint32_t n[3]);

#endif
