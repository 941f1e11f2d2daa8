/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * denseset.c - the per-scan fine voxel set read back in Morton order. Rays zero and list a 32^3
 * chunk when they first enter it (occ_denseset_enter, raycast.c), so nothing is kept per visit
 * and only entered chunks are ever written; here the listed chunks are sorted by their Morton
 * code (a chunk's voxels are one contiguous code range) and their words read in order.
 */
#include "integrate_internal.h"

/* The entered chunks' codes (chunk key = key >> 5), sorted; returns where they are. */
static const uint64_t *sorted_chunks(occ_bitset_t *const bs, uint32_t *const hist)
{
    const size_t ncx = bs->nb[0] >> 3, ncy = bs->nb[1] >> 3;
    for (size_t i = 0; i < bs->n_chunks; i++) {
        const size_t ci = (size_t)bs->clist[i];
        occ_key_t k;
        k.k[0] = (bs->b0[0] >> 3) + (uint32_t)(ci % ncx);
        k.k[1] = (bs->b0[1] >> 3) + (uint32_t)((ci / ncx) % ncy);
        k.k[2] = (bs->b0[2] >> 3) + (uint32_t)(ci / (ncx * ncy));
        bs->clist[i] = occ_morton_encode(k);
    }
    return occi_keyset_sort(bs->clist, bs->ctmp, bs->n_chunks, hist);
}

/* Words of the chunk whose code is `cc`. */
static const uint64_t *chunk_words(const occ_bitset_t *const bs, const uint64_t cc)
{
    const occ_key_t k = occ_morton_decode(cc);
    const size_t ci = (size_t)(k.k[0] - (bs->b0[0] >> 3)) +
                      bs->stride_y * (size_t)(k.k[1] - (bs->b0[1] >> 3)) +
                      bs->stride_z * (size_t)(k.k[2] - (bs->b0[2] >> 3));
    return bs->words + (ci << 9);
}

size_t occi_denseset_extract(occ_bitset_t *const bs, const occ_code_t *const hits,
                             const size_t n_hits, occ_code_t *const out, const size_t cap,
                             uint32_t *const hist)
{
    const uint64_t *const chunks = sorted_chunks(bs, hist);
    size_t n = 0, h = 0;
    for (size_t i = 0; i < bs->n_chunks; i++) {
        const uint64_t *const words = chunk_words(bs, chunks[i]);
        const occ_code_t base = (occ_code_t)chunks[i] << 15;
        for (unsigned wi = 0; wi < 512u; wi++) {
            uint64_t w = words[wi];
            while (w != 0u) {
                const occ_code_t c = base | ((occ_code_t)wi << 6) | (unsigned)__builtin_ctzll(w);
                w &= w - 1u;
                while (h < n_hits && (hits[h] & ~OCC_CODE_HIT_BIT) < c) {
                    if (n == cap) {
                        return SIZE_MAX;
                    }
                    out[n++] = hits[h++];
                }
                if (n == cap) {
                    return SIZE_MAX;
                }
                if (h < n_hits && (hits[h] & ~OCC_CODE_HIT_BIT) == c) {
                    out[n++] = hits[h++];
                } else {
                    out[n++] = c;
                }
            }
        }
    }
    while (h < n_hits) {
        if (n == cap) {
            return SIZE_MAX;
        }
        out[n++] = hits[h++];
    }
    return n;
}
