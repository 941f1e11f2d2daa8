/* SPDX-License-Identifier: BSD-3-Clause */
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

/* The last end point's voxel: its key, code and box shrunk by a rounding margin (a point
 * strictly inside has that key whatever the key arithmetic's rounding). */
typedef struct {
    occ_code_t code;
    uint32_t k[3];
    float lo[3], hi[3];
    bool valid;
} last_voxel_t;

/* Morton code bits of axis 0 (axis a: shifted by a). */
#define MORTON_AXIS0 0x1249249249249249ull

/* The code of key k (with the hit bit): from the last voxel's code when each axis moved by at
 * most one (masked add / subtract on that axis' bits, the same code), else the full encode. */
static occ_code_t code_of(const last_voxel_t *v, const uint32_t k[3])
{
    if (v->valid) {
        occ_code_t c = v->code;
        unsigned a = 0;
        for (; a < 3u; a++) {
            const occ_code_t m = (occ_code_t)MORTON_AXIS0 << a, one = (occ_code_t)1 << a;
            if (k[a] == v->k[a] + 1u) {
                c = (((c | ~m) + one) & m) | (c & ~m);
            } else if (k[a] + 1u == v->k[a]) {
                c = (((c & m) - one) & m) | (c & ~m);
            } else if (k[a] != v->k[a]) {
                break;
            }
        }
        if (a == 3u) {
            return c;
        }
    }
    const occ_key_t key = {{k[0], k[1], k[2]}};
    return occ_morton_encode(key) | OCC_CODE_HIT_BIT;
}

static bool in_last(const last_voxel_t *v, const float p[3])
{
    return v->valid && p[0] > v->lo[0] && p[0] < v->hi[0] && p[1] > v->lo[1] &&
           p[1] < v->hi[1] && p[2] > v->lo[2] && p[2] < v->hi[2];
}

static void set_last(const occ_proj_t *x, const uint32_t k[3], const occ_code_t code,
                     last_voxel_t *v)
{
    const float m = 1e-3f * (float)x->g.res;
    for (unsigned a = 0; a < 3u; a++) {
        const float lo = (float)(((occ_rr_t)k[a] - x->g.tmv_r) * x->g.res);
        v->lo[a] = lo + m;
        v->hi[a] = lo + (float)x->g.res - m;
    }
    v->code = code;
    v->k[0] = k[0];
    v->k[1] = k[1];
    v->k[2] = k[2];
    v->valid = true;
}

/* The end point of pixel (i, j) at depth d within max range, or false. */
static bool end_point(const occ_proj_t *x, const uint32_t i, const uint32_t j, const float d,
                      float p[3])
{
    const occ_proj_camera_t *const k = x->cam;
    float c[3];
    occ_proj_back(k, i, j, d, c);
    if (!(d * d < x->far2) && c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > x->max2) {
        return false; /* beyond max range: frees up to it, marks nothing */
    }
    p[0] = k->r[0][0] * c[0] + k->r[0][1] * c[1] + k->r[0][2] * c[2] + k->t.x;
    p[1] = k->r[1][0] * c[0] + k->r[1][1] * c[1] + k->r[1][2] * c[2] + k->t.y;
    p[2] = k->r[2][0] * c[0] + k->r[2][1] * c[1] + k->r[2][2] * c[2] + k->t.z;
    return true;
}

bool occi_proj_hits(occ_proj_t *const x)
{
    const uint32_t w = x->im->width, h = x->im->height;
    occ_code_t *const filt = x->filter;
    for (size_t i = 0; i < OCC_PROJ_FILTER_N; i++) {
        filt[i] = 0u; /* a hit code always has bit 63: 0 is never one */
    }
    last_voxel_t last = {0u, {0}, {0}, {0}, false};
    size_t n = 0;
    for (uint32_t j = 0; j < h; j++) {
        const float *const row = x->d0 + (size_t)j * w;
        for (uint32_t i = 0; i < w; i++) {
            float p[3];
            if (!(row[i] > 0.0f) || !end_point(x, i, j, row[i], p) || in_last(&last, p)) {
                continue; /* no hit, or the previous pixel's voxel again */
            }
            uint32_t kk[3];
            if (!occi_raygeo_key(&x->g, p, kk)) {
                x->r->insert.points_skipped++; /* outside the map */
                continue;
            }
            const occ_code_t code = code_of(&last, kk);
            const occ_key_t key = {{kk[0], kk[1], kk[2]}}; /* the check's only (tests) */
            OCC_ASSERT(code == (occ_morton_encode(key) | OCC_CODE_HIT_BIT));
            set_last(x, kk, code, &last);
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
