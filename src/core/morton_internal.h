/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * morton_internal.h - a key's bits spread for its Morton code by table (src/ only): one 512-byte
 * table serves occ_morton_encode (without BMI2) and the projective pass's end-point codes.
 */
#ifndef OCC_MORTON_INTERNAL_H_INCLUDED
#define OCC_MORTON_INTERNAL_H_INCLUDED

#include <stdint.h>

/* Index bit b at bit 3 b, for the 128 values of seven bits. */
extern const uint32_t occi_morton_spread7[128];

/* The low 21 bits of v spread to every third bit (bit b to bit 3 b): three look-ups, about a
 * third of the magic-bits steps' instructions. */
static inline uint64_t occi_morton_spread21(const uint32_t v)
{
    return (uint64_t)occi_morton_spread7[v & 127u] |
           ((uint64_t)occi_morton_spread7[(v >> 7) & 127u] << 21) |
           ((uint64_t)occi_morton_spread7[(v >> 14) & 127u] << 42);
}

#endif
