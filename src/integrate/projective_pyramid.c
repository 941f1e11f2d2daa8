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

/* Vertical step: per column the min of two rows' minima and the max of their maxima. */
OCC_PROJ_LANES static void rows_minmax(const uint32_t n, const float *restrict amn,
                                       const float *restrict bmn, const float *restrict amx,
                                       const float *restrict bmx, float *restrict tmn,
                                       float *restrict tmx)
{
    for (uint32_t i = 0; i < n; i++) {
        tmn[i] = lo_of(amn[i], bmn[i]);
        tmx[i] = hi_of(amx[i], bmx[i]);
    }
}

/* Horizontal step: pairs of columns. The index is a size_t: with a 32-bit one, 2 i could wrap,
 * and GCC loads the lanes one by one instead of two vectors it deinterleaves. */
OCC_PROJ_LANES static void pairs_minmax(const uint32_t n, const float *restrict tmn,
                                        const float *restrict tmx, float *restrict dmn,
                                        float *restrict dmx)
{
    for (size_t i = 0; i < n; i++) {
        dmn[i] = lo_of(tmn[2u * i], tmn[2u * i + 1u]);
        dmx[i] = hi_of(tmx[2u * i], tmx[2u * i + 1u]);
    }
}

/* Level l + 1 from level l (src min / max; at level 1 both are d0): per destination row the
 * two source rows' column-wise min / max (tmn / tmx: sw cells, one more when sw is odd, for the
 * repeated last column), then pairs of columns. */
static void reduce(const float *smn, const float *smx, const uint32_t sw, const uint32_t sh,
                   float *dmn, float *dmx, const uint32_t dw, const uint32_t dh, float *tmn,
                   float *tmx)
{
    for (uint32_t j = 0; j < dh; j++) {
        const uint32_t j0 = 2u * j, j1 = j0 + 1u < sh ? j0 + 1u : j0;
        rows_minmax(sw, smn + (size_t)j0 * sw, smn + (size_t)j1 * sw, smx + (size_t)j0 * sw,
                    smx + (size_t)j1 * sw, tmn, tmx);
        if ((sw & 1u) != 0u) { /* the last pair repeats the odd column */
            tmn[sw] = tmn[sw - 1u];
            tmx[sw] = tmx[sw - 1u];
        }
        pairs_minmax(dw, tmn, tmx, dmn + (size_t)j * dw, dmx + (size_t)j * dw);
    }
}

void occi_proj_build(occ_proj_t *const x, float *const mem)
{
    const uint32_t w = x->im->width, h = x->im->height;
    /* the pixel pass's tables are free now: the gap filling's rows, then the reduction's */
    OCC_ASSERT(occi_proj_fill_bytes(w) <= occi_proj_pixels_bytes(w));
    occi_proj_fill(x, x->px.asq);
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
        reduce(x->mn[l], x->mx[l], x->lw[l], x->lh[l], x->mn[l + 1u], x->mx[l + 1u], dw, dh,
               x->px.u[0], x->px.u[1]);
        x->lw[l + 1u] = dw;
        x->lh[l + 1u] = dh;
        l++;
    }
    x->levels = l + 1u;
    x->dmax = x->mx[l][0]; /* -inf: no reading at all */
}

/* The lowest level at which pixels i0..i1 fall in at most 3 cells, without a loop whose exit
 * mispredicts: with f = floor(log2 (i1 - i0)) they fall in at most 3 at level f and in at
 * least 5 at f - 2 (a cell count is monotone in the level), so it is f - 1 or f. */
static uint32_t span_level(const uint32_t i0, const uint32_t i1)
{
    const uint32_t w = i1 - i0;
    const uint32_t f = occ_bit_length32(w | 1u) - 1u; /* floor(log2 w), w >= 1 */
    const uint32_t c = f > 0u ? f - 1u : 0u;
    const uint32_t l = ((i1 >> c) - (i0 >> c)) <= 2u ? c : f;
    return w <= 2u ? 0u : l;
}

void occi_proj_range(const occ_proj_t *const x, const uint32_t i0, const uint32_t i1,
                     const uint32_t j0, const uint32_t j1, float *const mn, float *const mx)
{
    const uint32_t li = span_level(i0, i1), lj = span_level(j0, j1);
    const unsigned l = li > lj ? li : lj;
    OCC_ASSERT(l < x->levels);
    /* The 1..3 cells per axis as a fixed 3 x 3 window (the middle one repeated where a span
     * has fewer: min and max do not mind), so that no loop bound depends on the footprint
     * (their exits mispredicted); written out as two trees of nine, without a serial chain
     * (gcc kept the 3 x 3 loops rolled, one dependent min and max per cell). */
    const uint32_t a0 = i0 >> l, a1 = i1 >> l, b0 = j0 >> l, b1 = j1 >> l;
    const uint32_t am = a0 + 1u < a1 ? a0 + 1u : a1, bm = b0 + 1u < b1 ? b0 + 1u : b1;
    const size_t lw = x->lw[l];
    const size_t r0 = (size_t)b0 * lw, r1 = (size_t)bm * lw, r2 = (size_t)b1 * lw;
    const float *const n = x->mn[l], *const p = x->mx[l];
    const float lo = lo_of(lo_of(lo_of(n[r0 + a0], n[r0 + am]), lo_of(n[r0 + a1], n[r1 + a0])),
                           lo_of(lo_of(n[r1 + am], n[r1 + a1]),
                                 lo_of(lo_of(n[r2 + a0], n[r2 + am]), n[r2 + a1])));
    const float hi = hi_of(hi_of(hi_of(p[r0 + a0], p[r0 + am]), hi_of(p[r0 + a1], p[r1 + a0])),
                           hi_of(hi_of(p[r1 + am], p[r1 + a1]),
                                 hi_of(hi_of(p[r2 + a0], p[r2 + am]), p[r2 + a1])));
    *mn = lo;
    *mx = hi;
}
