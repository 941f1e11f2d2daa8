/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_hits.c - the frame's end points after the pixel pass: radix sorted and collapsed
 * at the start of the output, and dropped from the walk's free voxels (hits win). */
#include <string.h>

#include "projective_internal.h"

void occi_proj_hits_sort(occ_proj_t *const x)
{
    const size_t n = x->nh;
    occ_code_t *const sorted = occi_keyset_sort(x->out, x->out + n, n, x->hist);
    if (sorted != x->out) {
        memcpy(x->out, sorted, n * sizeof *sorted);
    }
    x->hwm = 2u * n;
    x->nh = occi_keyset_unique(x->out, n);
}

size_t occi_proj_drop_hits(occ_code_t *const free_codes, const size_t nv,
                           const occ_code_t *const hits, const size_t nh)
{
    size_t o = 0, j = 0;
    for (size_t i = 0; i < nv; i++) {
        const occ_code_t c = free_codes[i];
        while (j < nh && (hits[j] & ~OCC_CODE_HIT_BIT) < c) {
            j++;
        }
        if (j < nh && (hits[j] & ~OCC_CODE_HIT_BIT) == c) {
            continue; /* hits win */
        }
        free_codes[o++] = c;
    }
    return o;
}
