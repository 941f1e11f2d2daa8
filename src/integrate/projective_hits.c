/* projective_hits.c - the frame's end points: each pixel with a reading within range marks the
 * voxel of its back-projected point (hits win over the walk's free voxels). Codes are filtered
 * (repeats from neighbouring pixels), radix sorted and collapsed at the start of the output. */
#include <string.h>

#include "projective_internal.h"

/* Slot of a code in the repeat filter. */
static size_t filter_slot(const occ_code_t c)
{
    return (size_t)((c ^ (c >> 17) ^ (c >> 31)) & (OCC_PROJ_FILTER_N - 1u));
}

bool occi_proj_hits(occ_proj_t *const x)
{
    const occ_proj_camera_t *const k = x->cam;
    const uint32_t w = x->im->width, h = x->im->height;
    occ_code_t *const filt = x->filter;
    for (size_t i = 0; i < OCC_PROJ_FILTER_N; i++) {
        filt[i] = 0u; /* a hit code always has bit 63: 0 is never one */
    }
    size_t n = 0;
    for (uint32_t j = 0; j < h; j++) {
        const float *const row = x->d0 + (size_t)j * w;
        for (uint32_t i = 0; i < w; i++) {
            const float d = row[i];
            if (!(d > 0.0f)) {
                continue;
            }
            float c[3];
            occ_proj_back(k, i, j, d, c);
            if (c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > x->max2) {
                continue; /* beyond max range: frees up to it, marks nothing */
            }
            const float p[3] = {k->r[0][0] * c[0] + k->r[0][1] * c[1] + k->r[0][2] * c[2] + k->t.x,
                                k->r[1][0] * c[0] + k->r[1][1] * c[1] + k->r[1][2] * c[2] + k->t.y,
                                k->r[2][0] * c[0] + k->r[2][1] * c[1] + k->r[2][2] * c[2] + k->t.z};
            uint32_t kk[3];
            if (!occi_raygeo_key(&x->g, p, kk)) {
                x->r->insert.points_skipped++; /* outside the map */
                continue;
            }
            const occ_key_t key = {{kk[0], kk[1], kk[2]}};
            const occ_code_t code = occ_morton_encode(key) | OCC_CODE_HIT_BIT;
            const size_t s = filter_slot(code);
            if (filt[s] == code) {
                continue;
            }
            filt[s] = code;
            if (2u * (n + 1u) > x->cap) {
                return false; /* the codes and the sort's temporary */
            }
            x->out[n++] = code;
        }
    }
    occ_code_t *const sorted = occi_keyset_sort(x->out, x->out + n, n, x->hist);
    if (sorted != x->out) {
        memcpy(x->out, sorted, n * sizeof *sorted);
    }
    x->hwm = 2u * n;
    x->nh = occi_keyset_unique(x->out, n);
    return true;
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
