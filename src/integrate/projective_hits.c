/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_hits.c - the frame's end points after the pixel pass: their records (a level-2
 * node's code and the bits of its voxels holding one) radix sorted by node and merged, one per
 * node, at the start of the output (the walk asks them in code order and merges them into its
 * stream). */
#include "projective_internal.h"

void occi_proj_hits_sort(occ_proj_t *const x)
{
    const size_t n = x->nh;
    occ_code_t *const r = x->out;
    occ_code_t *const sorted = occi_keyset_sort_records(r, r + 2u * n, n, x->hist);
    size_t w = 0, voxels = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_code_t brick = sorted[2u * i];
        const uint64_t bits = sorted[2u * i + 1u];
        if (w > 0u && r[2u * (w - 1u)] == brick) {
            r[2u * w - 1u] |= bits;
            continue;
        }
        r[2u * w] = brick; /* w <= i: read before written, in place or from tmp */
        r[2u * w + 1u] = bits;
        w++;
    }
    for (size_t i = 0; i < w; i++) {
        voxels += occ_popcount64(r[2u * i + 1u]);
    }
    x->nh = 2u * w;
    x->nhv = voxels;
}
