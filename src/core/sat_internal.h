/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * sat_internal.h - saturating size arithmetic for the map (scratch sizes, brick counts, strides,
 * n * sizeof, capacity sums, arena splits). A result that does not fit is SIZE_MAX, which no
 * buffer holds, so on a 32-bit size_t "too big" becomes an error and never a wrapped small size.
 */
#ifndef OCC_SAT_INTERNAL_H_INCLUDED
#define OCC_SAT_INTERNAL_H_INCLUDED

#include <stddef.h>
#include <stdint.h>

static inline size_t occ_sat_add(const size_t a, const size_t b)
{
    return a > SIZE_MAX - b ? SIZE_MAX : a + b;
}

static inline size_t occ_sat_mul(const size_t a, const size_t b)
{
    return (a != 0u && b > SIZE_MAX / a) ? SIZE_MAX : a * b;
}

/* a - b, or 0 when b > a. */
static inline size_t occ_sat_sub(const size_t a, const size_t b)
{
    return a > b ? a - b : 0u;
}

/* A 64-bit count as a size (SIZE_MAX when it does not fit). */
static inline size_t occ_sat_size(const uint64_t v)
{
    return (uint64_t)(size_t)v == v ? (size_t)v : SIZE_MAX;
}

#endif
