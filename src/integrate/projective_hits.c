/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_hits.c - the frame's end points after the pixel pass: radix sorted and collapsed
 * at the start of the output (the walk asks them in code order; the tree pass merges them). */
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
