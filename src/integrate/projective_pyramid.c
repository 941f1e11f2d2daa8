/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_pyramid.c - the frame's depths (one float per pixel, "no reading" as -inf) and
 * their min/max pyramid, and the footprint query the walk asks it. */
#include <math.h>
#include <string.h>

#include "projective_internal.h"

/* No NaN in the pyramid (no reading is -inf): plain compares, no libm call. */
static inline float lo_of(const float a, const float b)
{
    return b < a ? b : a;
}

static inline float hi_of(const float a, const float b)
{
    return b > a ? b : a;
}

static uint32_t half_up(const uint32_t n)
{
    return (n + 1u) / 2u;
}

size_t occi_proj_pyramid_bytes(const uint32_t w, const uint32_t h)
{
    size_t cells = 0;
    uint32_t lw = w, lh = h;
    while (lw > 1u || lh > 1u) {
        lw = half_up(lw);
        lh = half_up(lh);
        cells += (size_t)lw * lh;
    }
    return 8u * cells;
}

/* Level l from level l - 1 (src min / max; at level 1 both are d0). */
static void reduce(const float *smn, const float *smx, const uint32_t sw, const uint32_t sh,
                   float *dmn, float *dmx, const uint32_t dw, const uint32_t dh)
{
    for (uint32_t j = 0; j < dh; j++) {
        const uint32_t j0 = 2u * j, j1 = j0 + 1u < sh ? j0 + 1u : j0;
        for (uint32_t i = 0; i < dw; i++) {
            const uint32_t i0 = 2u * i, i1 = i0 + 1u < sw ? i0 + 1u : i0;
            const size_t a = (size_t)j0 * sw + i0, b = (size_t)j0 * sw + i1,
                         c = (size_t)j1 * sw + i0, e = (size_t)j1 * sw + i1;
            const float m0 = lo_of(lo_of(smn[a], smn[b]), lo_of(smn[c], smn[e]));
            const float m1 = hi_of(hi_of(smx[a], smx[b]), hi_of(smx[c], smx[e]));
            dmn[(size_t)j * dw + i] = m0;
            dmx[(size_t)j * dw + i] = m1;
        }
    }
}

void occi_proj_build(occ_proj_t *const x, float *const mem)
{
    const uint32_t w = x->im->width, h = x->im->height;
    x->mn[0] = x->d0;
    x->mx[0] = x->d0;
    x->lw[0] = w;
    x->lh[0] = h;
    float *next = mem;
    unsigned l = 0;
    while (x->lw[l] > 1u || x->lh[l] > 1u) {
        OCC_ASSERT(l + 1u < OCC_PROJ_MAX_LEVELS);
        const uint32_t dw = half_up(x->lw[l]), dh = half_up(x->lh[l]);
        x->mn[l + 1u] = next;
        x->mx[l + 1u] = next + (size_t)dw * dh;
        next += 2u * (size_t)dw * dh;
        reduce(x->mn[l], x->mx[l], x->lw[l], x->lh[l], x->mn[l + 1u], x->mx[l + 1u], dw, dh);
        x->lw[l + 1u] = dw;
        x->lh[l + 1u] = dh;
        l++;
    }
    x->levels = l + 1u;
    x->dmax = x->mx[l][0]; /* -inf: no reading at all */
}

void occi_proj_range(const occ_proj_t *const x, const uint32_t i0, const uint32_t i1,
                     const uint32_t j0, const uint32_t j1, float *const mn, float *const mx)
{
    unsigned l = 0;
    while (((i1 >> l) - (i0 >> l)) > 2u || ((j1 >> l) - (j0 >> l)) > 2u) {
        l++;
    }
    OCC_ASSERT(l < x->levels);
    const uint32_t a0 = i0 >> l, a1 = i1 >> l, b0 = j0 >> l, b1 = j1 >> l;
    const uint32_t lw = x->lw[l];
    const float *const pmn = x->mn[l], *const pmx = x->mx[l];
    float lo = INFINITY, hi = -INFINITY;
    for (uint32_t b = b0; b <= b1; b++) {
        for (uint32_t a = a0; a <= a1; a++) {
            const size_t k = (size_t)b * lw + a;
            lo = lo_of(lo, pmn[k]);
            hi = hi_of(hi, pmx[k]);
        }
    }
    *mn = lo;
    *mx = hi;
}
