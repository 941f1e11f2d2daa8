/* SPDX-License-Identifier: BSD-3-Clause */
/* morton.c - 3 x 21-bit key <-> 63-bit Morton code (x in bit 0, y in bit 1, z in bit 2). */
#include "occmap/occmap.h"
#include "morton_internal.h"

/* Bit b of the index at bit 3 b (the table behind occi_morton_spread21; also in BMI2 builds,
 * where the projective pass still reads it). */
#define SP7(v)                                                                                    \
    ((uint32_t)(((v) & 1u) | (((v) & 2u) << 2) | (((v) & 4u) << 4) | (((v) & 8u) << 6) |          \
                (((v) & 16u) << 8) | (((v) & 32u) << 10) | (((v) & 64u) << 12)))
#define SP7_4(b) SP7(b), SP7((b) + 1u), SP7((b) + 2u), SP7((b) + 3u)
#define SP7_16(b) SP7_4(b), SP7_4((b) + 4u), SP7_4((b) + 8u), SP7_4((b) + 12u)
#define SP7_64(b) SP7_16(b), SP7_16((b) + 16u), SP7_16((b) + 32u), SP7_16((b) + 48u)
const uint32_t occi_morton_spread7[128] = {SP7_64(0u), SP7_64(64u)};

#if OCC_USE_BMI2
#include <immintrin.h>

static const uint64_t mask_x = 0x1249249249249249ull;

occ_code_t occ_morton_encode(const occ_key_t key)
{
    return _pdep_u64(key.k[0], mask_x) | _pdep_u64(key.k[1], mask_x << 1) |
           _pdep_u64(key.k[2], mask_x << 2);
}

occ_key_t occ_morton_decode(const occ_code_t code)
{
    occ_key_t key;
    key.k[0] = (uint32_t)_pext_u64(code, mask_x);
    key.k[1] = (uint32_t)_pext_u64(code, mask_x << 1);
    key.k[2] = (uint32_t)_pext_u64(code, mask_x << 2);
    return key;
}
#else
static uint32_t compact3(const uint64_t code)
{
    uint64_t x = code & 0x1249249249249249ull;
    x = (x | (x >> 2)) & 0x10C30C30C30C30C3ull;
    x = (x | (x >> 4)) & 0x100F00F00F00F00Full;
    x = (x | (x >> 8)) & 0x001F0000FF0000FFull;
    x = (x | (x >> 16)) & 0x001F00000000FFFFull;
    x = (x | (x >> 32)) & 0x1FFFFFull;
    return (uint32_t)x;
}

occ_code_t occ_morton_encode(const occ_key_t key)
{
    return occi_morton_spread21(key.k[0]) | (occi_morton_spread21(key.k[1]) << 1) |
           (occi_morton_spread21(key.k[2]) << 2);
}

occ_key_t occ_morton_decode(const occ_code_t code)
{
    occ_key_t key;
    key.k[0] = compact3(code);
    key.k[1] = compact3(code >> 1);
    key.k[2] = compact3(code >> 2);
    return key;
}
#endif
