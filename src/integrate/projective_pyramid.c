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
    unsigned l = 0;
    while (lw > 1u || lh > 1u) {
        lw = half_up(lw);
        lh = half_up(lh);
        l++;
        /* the level's cells, and from OCC_PROJ_WIN_LEVEL on its windows too */
        cells += (size_t)lw * lh * (l >= OCC_PROJ_WIN_LEVEL ? 2u : 1u);
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

/* Per column, dmn / dmx = the min / max of themselves and of row (smn, smx) (another row). */
OCC_PROJ_LANES static void row_into(const uint32_t n, const float *restrict smn,
                                    const float *restrict smx, float *restrict dmn,
                                    float *restrict dmx)
{
    for (uint32_t i = 0; i < n; i++) {
        dmn[i] = lo_of(dmn[i], smn[i]);
        dmx[i] = hi_of(dmx[i], smx[i]);
    }
}

/* windows_first's column steps are written out for N = 8 (steps 1, 2, 4). */
typedef char occ_proj_win_steps[OCC_PROJ_WIN_SHIFT == 3u ? 1 : -1];

/* Over a row of n cells, dst cell i = min / max of src cells i and min(i + s, n - 1) (another
 * row: each step reads the old cells). */
OCC_PROJ_LANES static void cols_step(const uint32_t n, const uint32_t s, const float *restrict smn,
                                     const float *restrict smx, float *restrict dmn,
                                     float *restrict dmx)
{
    const size_t body = n > s ? n - s : 0u; /* size_t: a 32-bit i + s could wrap, and GCC
                                                * then loads the lanes one by one */
    for (size_t i = 0; i < body; i++) {
        dmn[i] = lo_of(smn[i], smn[i + s]);
        dmx[i] = hi_of(smx[i], smx[i + s]);
    }
    for (size_t i = body; i < n; i++) {
        dmn[i] = lo_of(smn[i], smn[n - 1u]);
        dmx[i] = hi_of(smx[i], smx[n - 1u]);
    }
}

/* The first windowed level v: per cell (a, b) the min and max over cells [a, a + N) x
 * [b, b + N) of the level (N = OCC_PROJ_WIN_CELLS, clipped at its last row and column), by
 * doubling: after step k a cell covers 2^(k+1) rows (in place, going down: row b + s is still
 * the old one when row b reads it), then the same over columns. */
static void windows_first(occ_proj_t *const x, const unsigned v)
{
    const uint32_t lw = x->lw[v], lh = x->lh[v];
    const size_t cells = (size_t)lw * lh;
    float *const wmn = x->wmn[v], *const wmx = x->wmx[v];
    memcpy(wmn, x->mn[v], cells * sizeof(float));
    memcpy(wmx, x->mx[v], cells * sizeof(float));
    for (uint32_t s = 1; s < OCC_PROJ_WIN_CELLS; s *= 2u) {
        for (uint32_t b = 0; b + 1u < lh; b++) {
            const size_t from = (size_t)(b + s < lh ? b + s : lh - 1u) * lw;
            row_into(lw, wmn + from, wmx + from, wmn + (size_t)b * lw, wmx + (size_t)b * lw);
        }
    }
    /* the columns through two row buffers (the pixel pass's, free now): row -> a -> b -> row */
    float *const amn = x->px.u[0], *const amx = x->px.u[1];
    float *const bmn = x->px.u[2], *const bmx = x->px.dr;
    for (uint32_t b = 0; b < lh; b++) {
        float *const rmn = wmn + (size_t)b * lw, *const rmx = wmx + (size_t)b * lw;
        cols_step(lw, 1u, rmn, rmx, amn, amx);
        cols_step(lw, 2u, amn, amx, bmn, bmx);
        cols_step(lw, 4u, bmn, bmx, rmn, rmx);
    }
}

/* Level v's windows from level v - 1's: its cells a .. a + N - 1 are the cells 2 a ..
 * 2 a + 2 N - 1 below, the windows there at 2 a and 2 a + N (clipped to the last). */
static void windows_up(occ_proj_t *const x, const unsigned v)
{
    const uint32_t lw = x->lw[v], lh = x->lh[v], sw = x->lw[v - 1u], sh = x->lh[v - 1u];
    const float *const smn = x->wmn[v - 1u], *const smx = x->wmx[v - 1u];
    for (uint32_t b = 0; b < lh; b++) {
        const size_t r0 = (size_t)(2u * b) * sw;
        const size_t r1 = (size_t)(2u * b + OCC_PROJ_WIN_CELLS < sh ? 2u * b + OCC_PROJ_WIN_CELLS
                                                                     : sh - 1u) * sw;
        for (uint32_t a = 0; a < lw; a++) {
            const uint32_t c0 = 2u * a;
            const uint32_t c1 = c0 + OCC_PROJ_WIN_CELLS < sw ? c0 + OCC_PROJ_WIN_CELLS : sw - 1u;
            x->wmn[v][(size_t)b * lw + a] = lo_of(lo_of(smn[r0 + c0], smn[r0 + c1]),
                                                  lo_of(smn[r1 + c0], smn[r1 + c1]));
            x->wmx[v][(size_t)b * lw + a] = hi_of(hi_of(smx[r0 + c0], smx[r0 + c1]),
                                                  hi_of(smx[r1 + c0], smx[r1 + c1]));
        }
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
    for (unsigned v = OCC_PROJ_WIN_LEVEL; v < x->levels && v < OCC_PROJ_MAX_LEVELS; v++) {
        x->wmn[v] = next;
        x->wmx[v] = next + (size_t)x->lw[v] * x->lh[v];
        next += 2u * (size_t)x->lw[v] * x->lh[v];
        if (v == OCC_PROJ_WIN_LEVEL) {
            windows_first(x, v);
        } else {
            windows_up(x, v);
        }
    }
}

/* The lowest level at which pixels i0..i1 (w = i1 - i0) span at most `most` + 1 cells, without
 * a loop whose exit mispredicts: with f = floor(log2 w) it is f - back or f - back + 1, for
 * the two uses below (a cell count is monotone in the level):
 *  - at most 3 cells (back 1, most 2): at level f they span at most 3, at f - 2 at least 5;
 *  - at most 2 N cells, N = 2^s (back s, most 2 N - 1): at f - s + 1 fewer than N plus one,
 *    at f - s - 1 at least 2 N + 1.
 * w <= 2: level 0 (c = 0 and the span fits). */
static uint32_t fit_level(const uint32_t i0, const uint32_t i1, const uint32_t back,
                          const uint32_t most)
{
    const uint32_t w = i1 - i0;
    const uint32_t f = occ_bit_length32(w | 1u) - 1u; /* floor(log2 w), w >= 1 */
    const uint32_t c = f > back ? f - back : 0u;
    return ((i1 >> c) - (i0 >> c)) <= most ? c : c + 1u;
}

/* Over the windows of level l (>= OCC_PROJ_WIN_LEVEL): two windows of N cells per axis cover
 * the footprint's at most 2 N there (the second starts N - 1 cells before its last). */
static void window_range(const occ_proj_t *const x, const unsigned l, const uint32_t i0,
                         const uint32_t i1, const uint32_t j0, const uint32_t j1,
                         float *const mn, float *const mx)
{
    OCC_ASSERT(l < x->levels);
    const uint32_t a0 = i0 >> l, a1 = i1 >> l, b0 = j0 >> l, b1 = j1 >> l;
    const uint32_t m = OCC_PROJ_WIN_CELLS - 1u;
    const uint32_t a2 = a1 > a0 + m ? a1 - m : a0, b2 = b1 > b0 + m ? b1 - m : b0;
    const size_t lw = x->lw[l];
    const float *const n = x->wmn[l], *const p = x->wmx[l];
    const size_t c00 = (size_t)b0 * lw + a0, c01 = (size_t)b0 * lw + a2;
    const size_t c10 = (size_t)b2 * lw + a0, c11 = (size_t)b2 * lw + a2;
    *mn = lo_of(lo_of(n[c00], n[c01]), lo_of(n[c10], n[c11]));
    *mx = hi_of(hi_of(p[c00], p[c01]), hi_of(p[c10], p[c11]));
}

void occi_proj_range(const occ_proj_t *const x, const uint32_t i0, const uint32_t i1,
                     const uint32_t j0, const uint32_t j1, float *const mn, float *const mx)
{
    /* at most 2 N cells per axis: two windows of N cover them */
    const uint32_t most = 2u * OCC_PROJ_WIN_CELLS - 1u;
    const uint32_t wi = fit_level(i0, i1, OCC_PROJ_WIN_SHIFT, most);
    const uint32_t wj = fit_level(j0, j1, OCC_PROJ_WIN_SHIFT, most);
    const unsigned wl = wi > wj ? wi : wj;
    if (wl >= OCC_PROJ_WIN_LEVEL) {
        window_range(x, wl, i0, i1, j0, j1, mn, mx);
        return;
    }
    const uint32_t li = fit_level(i0, i1, 1u, 2u), lj = fit_level(j0, j1, 1u, 2u); /* <= 3 cells */
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
