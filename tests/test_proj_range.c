/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_proj_range.c - the projective integrator's footprint query (occi_proj_range over the
 * min/max pyramid and its windows) against brute force over the same depths: on random images
 * of many shapes (odd sides, one row, one column) with "no reading" pixels, for random
 * footprints of every size, the answer bounds the footprint's true min and max, and comes from
 * pixels near it (within twice the footprint's size). A query that reads a window too small
 * for the footprint (a wrong level), the wrong rows or a stale table fails here even where the
 * oracle test's frames happen not to notice. Random seed: printed, overridable with OCC_SEED.
 * Also linked against the release library (test_proj_range_rel: the AVX-512 or AVX2 clones).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "occmap/occmap.h"
#include "integrate/projective_internal.h"
#include "support/seeded_rng.h"

#define QUERIES_PER_SHAPE 5000u

static uint32_t rng_below(const uint32_t n)
{
    return (uint32_t)(rng_next() % n);
}

static int setup_seed(void **state)
{
    (void)state;
    rng_seed("test_proj_range");
    return 0;
}

/* Depths in blocks of random size (surfaces), noise on top, some pixels and some blocks
 * without a reading (-inf, as the pixel pass leaves them). */
static void random_depths(float *d, const uint32_t w, const uint32_t h)
{
    const uint32_t bw = 1u + rng_below(40u), bh = 1u + rng_below(40u);
    for (uint32_t j = 0; j < h; j++) {
        for (uint32_t i = 0; i < w; i++) {
            uint64_t z = ((uint64_t)(i / bw) << 32) ^ (j / bh) ^ 0x51ED270B27A5C3ull;
            z = (z ^ (z >> 29)) * 0xBF58476D1CE4E5B9ull;
            const float base = 0.5f + (float)(z % 4000u) / 1000.0f;
            const float noise = (float)rng_below(1000u) / 20000.0f;
            const bool none = (z >> 40) % 7u == 0u || rng_below(10u) == 0u;
            d[(size_t)j * w + i] = none ? -INFINITY : base + noise;
        }
    }
}

typedef struct {
    float lo, hi;
} range_t;

static range_t brute(const float *d, const uint32_t w, const uint32_t i0, const uint32_t i1,
                     const uint32_t j0, const uint32_t j1)
{
    range_t r = {INFINITY, -INFINITY};
    for (uint32_t j = j0; j <= j1; j++) {
        for (uint32_t i = i0; i <= i1; i++) {
            const float v = d[(size_t)j * w + i];
            r.lo = v < r.lo ? v : r.lo;
            r.hi = v > r.hi ? v : r.hi;
        }
    }
    return r;
}

/* [lo, hi] of a footprint inside [0, n): sizes spread over every pyramid level. */
static void random_span(const uint32_t n, uint32_t *lo, uint32_t *hi)
{
    uint32_t cap = (uint32_t)1 << rng_below(occ_bit_length32(n) + 1u);
    cap = cap < n ? cap : n;
    const uint32_t len = rng_below(cap); /* < n */
    *lo = rng_below(n - len);
    *hi = *lo + len;
}

static uint32_t grow_down(const uint32_t v, const uint32_t by)
{
    return v > by ? v - by : 0u;
}

static uint32_t grow_up(const uint32_t v, const uint32_t by, const uint32_t n)
{
    return v + by < n ? v + by : n - 1u;
}

static void check_shape(const uint32_t w, const uint32_t h)
{
    occ_proj_image_t im;
    memset(&im, 0, sizeof im);
    im.width = w;
    im.height = h;
    occ_proj_t *x = calloc(1u, sizeof *x);
    float *d0 = malloc((4u * (size_t)w * h + 16u) * sizeof(float));
    float *pyr = malloc(occi_proj_pyramid_bytes(w, h) + 16u);
    unsigned char *const raw = malloc(occi_proj_pixels_bytes(w) + 15u);
    assert_non_null(raw);
    unsigned char *const tables = raw + ((16u - ((uintptr_t)raw & 15u)) & 15u); /* 16-aligned */
    assert_non_null(x);
    assert_non_null(d0);
    assert_non_null(pyr);
    x->im = &im;
    x->d0 = d0;
    occi_proj_pixels_carve(x, tables);
    random_depths(d0, w, h);
    occi_proj_build(x, pyr); /* fills single-pixel gaps in d0 first: brute force reads that */
    const range_t all = brute(d0, w, 0u, w - 1u, 0u, h - 1u);
    assert_false(x->dmax < all.hi || x->dmax > all.hi); /* equal, also -inf */
    for (unsigned q = 0; q < QUERIES_PER_SHAPE; q++) {
        uint32_t i0, i1, j0, j1;
        random_span(w, &i0, &i1);
        random_span(h, &j0, &j1);
        float mn = NAN, mx = NAN;
        occi_proj_range(x, i0, i1, j0, j1, &mn, &mx);
        const range_t t = brute(d0, w, i0, i1, j0, j1);
        if (!(mn <= t.lo && mx >= t.hi)) {
            fail_msg("%ux%u [%u, %u] x [%u, %u]: query %g..%g, true %g..%g", w, h, i0, i1, j0,
                     j1, (double)mn, (double)mx, (double)t.lo, (double)t.hi);
        }
        /* the documented over-approximation: cells of one level (chosen by the longer side)
         * near the footprint */
        const uint32_t span = i1 - i0 > j1 - j0 ? i1 - i0 : j1 - j0;
        const uint32_t gi = 2u * span + 2u, gj = gi;
        const range_t near = brute(d0, w, grow_down(i0, gi), grow_up(i1, gi, w),
                                   grow_down(j0, gj), grow_up(j1, gj, h));
        if (!(mn >= near.lo && mx <= near.hi)) {
            fail_msg("%ux%u [%u, %u] x [%u, %u]: query %g..%g outside the pixels near it %g..%g",
                     w, h, i0, i1, j0, j1, (double)mn, (double)mx, (double)near.lo,
                     (double)near.hi);
        }
    }
    free(raw);
    free(pyr);
    free(d0);
    free(x);
}

static void test_range_bounds_every_shape(void **state)
{
    (void)state;
    static const uint32_t shapes[][2] = {{640u, 480u}, {1u, 1u},  {1u, 37u},  {37u, 1u},
                                         {8u, 8u},     {161u, 97u}, {1000u, 3u}, {3u, 700u},
                                         {320u, 240u}, {129u, 257u}};
    for (size_t s = 0; s < sizeof shapes / sizeof shapes[0]; s++) {
        check_shape(shapes[s][0], shapes[s][1]);
    }
    for (unsigned r = 0; r < 6u; r++) {
        check_shape(1u + rng_below(900u), 1u + rng_below(700u));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_range_bounds_every_shape),
    };
    return cmocka_run_group_tests(tests, setup_seed, NULL);
}
