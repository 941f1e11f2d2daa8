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

/* A level-0 table is a directory of 8x8x8-voxel bricks (one 32-bit brick number per brick of the
 * box, x major) and the bricks it names: 512 voxel states of 2 bits = 32 words each, voxel
 * (x, y, z) of the brick (low 3 key bits) at index 64 x + 8 y + z, 16 per word at bits 2 (i mod
 * 16). Bricks 0, 1, 2 are constant (all UNKNOWN, FREE, OCCUPIED: brick number = state), so a
 * brick of one state costs only its directory entry; the mixed bricks follow. */
#define OCC_IDX_BRICK_SHIFT 3u
#define OCC_IDX_BRICK_WORDS 32u
#define OCC_IDX_CONST_BRICKS 3u
#define OCC_IDX_PER_WORD 16u

/* Word and shift of key k's voxel in brick b. */
static inline size_t occi_idx_brick_word(const uint32_t b, const occ_key_t *const k,
                                         unsigned *const shift)
{
    const uint32_t v = ((k->k[0] & 7u) << 6) | ((k->k[1] & 7u) << 3) | (k->k[2] & 7u);
    *shift = 2u * (v % OCC_IDX_PER_WORD);
    return (size_t)b * OCC_IDX_BRICK_WORDS + v / OCC_IDX_PER_WORD;
}

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

/* Cells per axis and first keys of the table with cells of 2^shift voxels per axis over the
 * observed space (n = 0 when nothing is observed). */
void occi_idx_box(const occ_map_t *m, unsigned shift, uint32_t lo[3], uint32_t n[3]);
/* Table bytes for n cells per axis at `level` (SIZE_MAX when it does not fit); `mixed` bricks at
 * level 0. */
size_t occi_idx_bytes(unsigned level, const uint32_t n[3], size_t mixed);
/* The cube of span^3 table entries from entry c0 (the table's strides) set to `word`: a uniform
 * node's cells, or its bricks' directory entries. */
void occi_idx_fill_cube(const occ_lookup_index_t *ix, uint32_t *table, size_t c0, uint32_t span,
                        uint32_t word);

/* Level 0 (lookup_index_bricks.c): the bricks that hold more than one state, and the fill of
 * the directory (ix->priv.cells) and of `mixed` bricks after the constant ones. */
size_t occi_idx_mixed(const occ_map_t *m);
void occi_idx_fill_bricks(const occ_lookup_index_t *ix, const occ_map_t *m, uint32_t *dir,
                          uint32_t *bricks, size_t mixed);

#endif
