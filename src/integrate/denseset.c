/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * denseset.c - the per-scan fine voxel set read back in Morton order. Rays zero and list a 32^3
 * chunk when they first enter it (occ_denseset_enter, raycast.c), so nothing is kept per visit
 * and only entered chunks are ever written; here the listed chunks are sorted by their Morton
 * code (a chunk's voxels are one contiguous code range) and their words read in order.
 */
#include "integrate_internal.h"

/* Index of the chunk whose code is `cc`, relative to the box. */
static uint64_t chunk_index(const occ_bitset_t *const bs, const uint64_t cc)
{
    const occ_key_t k = occ_morton_decode(cc);
    return (uint64_t)(k.k[0] - (bs->b0[0] >> 3)) +
           (uint64_t)bs->stride_y * (k.k[1] - (bs->b0[1] >> 3)) +
           (uint64_t)bs->stride_z * (k.k[2] - (bs->b0[2] >> 3));
}

void occi_denseset_order(occ_bitset_t *const bs, uint32_t *const hist, occi_dense_t *const d)
{
    const size_t ncx = bs->nb[0] >> 3, ncy = bs->nb[1] >> 3;
    uint64_t *const list = bs->touched, *const tmp = bs->touched + occ_denseset_chunks(bs);
    for (size_t i = 0; i < bs->n_touched; i++) { /* chunk index -> its code (chunk key = key >> 5) */
        const size_t ci = (size_t)list[i];
        occ_key_t k;
        k.k[0] = (bs->b0[0] >> 3) + (uint32_t)(ci % ncx);
        k.k[1] = (bs->b0[1] >> 3) + (uint32_t)((ci / ncx) % ncy);
        k.k[2] = (bs->b0[2] >> 3) + (uint32_t)(ci / (ncx * ncy));
        list[i] = occ_morton_encode(k);
    }
    const uint64_t *const sorted = occi_keyset_sort(list, tmp, bs->n_touched, hist);
    uint64_t *const slots = sorted == list ? tmp : list;
    for (size_t i = 0; i < bs->n_touched; i++) {
        slots[i] = chunk_index(bs, sorted[i]);
    }
    d->words = bs->words;
    d->chunks = sorted;
    d->slots = slots;
    d->n_chunks = bs->n_touched;
}
