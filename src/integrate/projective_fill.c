/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_fill.c - single-pixel gaps of the depth image closed for the free test: a pixel
 * with no reading takes the smallest depth among its four neighbours that have one (left,
 * right, up, down; none: it stays without). Depth cameras leave speckle holes where ray casting
 * still frees the voxel by the neighbouring rays; the smallest neighbour is the conservative
 * choice. End points (hits) come from real readings only (projective_pixels.c). */
#include <math.h>

#include "projective_internal.h"

size_t occi_proj_fill_bytes(const uint32_t w)
{
    return 3u * (((size_t)w + 2u) * 4u + 12u); /* three padded rows, 16-byte steps */
}

static inline float lo_of(const float a, const float b)
{
    return b < a ? b : a;
}

/* One row: up, cur, down are padded candidate rows (index i + 1 is column i; a reading as
 * itself, no reading and the pads as +inf, so that the smallest of four is a plain min). The
 * neighbours are read through offset pointers with one index: with cur[i + 2u] GCC must allow
 * for a wrapping 32-bit index and loads those lanes one by one. */
OCC_PROJ_LANES static void fill_lanes(const uint32_t w, const float *restrict up,
                                      const float *restrict cur, const float *restrict down,
                                      float *restrict out)
{
    const float *const left = cur, *const mid = cur + 1, *const right = cur + 2;
    const float *const above = up + 1, *const below = down + 1;
    for (size_t i = 0; i < w; i++) {
        const float m = lo_of(lo_of(left[i], right[i]), lo_of(above[i], below[i]));
        const float c = mid[i];
        out[i] = c < INFINITY ? c : (m < INFINITY ? m : -INFINITY);
    }
}

/* Level-0 row j as candidates: a reading as itself, no reading as +inf. */
OCC_PROJ_LANES static void candidate_lanes(const uint32_t w, const float *restrict d0,
                                           float *restrict row)
{
    for (uint32_t i = 0; i < w; i++) {
        row[i] = d0[i] > 0.0f ? d0[i] : INFINITY;
    }
}

/* Copy level-0 row j (or nothing past the image) into a padded candidate row. */
static void padded_row(const occ_proj_t *const x, const uint32_t j, float *const row)
{
    const uint32_t w = x->im->width;
    row[0] = INFINITY;
    row[w + 1u] = INFINITY;
    if (j < x->im->height) {
        candidate_lanes(w, x->d0 + (size_t)j * w, row + 1);
        return;
    }
    for (uint32_t i = 1; i <= w; i++) {
        row[i] = INFINITY;
    }
}

void occi_proj_fill(occ_proj_t *const x, float *const mem)
{
    const uint32_t w = x->im->width, h = x->im->height;
    const size_t stride = (((size_t)w + 2u) * 4u + 12u) / 4u; /* floats per padded row */
    float *up = mem, *cur = mem + stride, *down = mem + 2u * stride;
    padded_row(x, h, up); /* above row 0: nothing */
    padded_row(x, 0u, cur);
    for (uint32_t j = 0; j < h; j++) {
        padded_row(x, j + 1u, down);
        fill_lanes(w, up, cur, down, x->d0 + (size_t)j * w);
        float *const t = up; /* the original rows move up */
        up = cur;
        cur = down;
        down = t;
    }
}
