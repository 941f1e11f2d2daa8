/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * rayorder.c - the dense path's rays in the order of their directions. The walk's costly
 * branches are OctoMap's axis choices; rays from one origin with nearly equal directions take
 * nearly the same choices, and the branch predictor learns them from ray to ray when such rays
 * come one after the other (in scan order they do only along a scan line). The dense set is a
 * union and the counts are sums, so the order changes nothing else.
 */
#include "integrate_internal.h"

/* The low 16 bits of x spread to the even bits. */
static uint32_t spread2(uint32_t x)
{
    x &= 0xFFFFu;
    x = (x | (x << 8)) & 0x00FF00FFu;
    x = (x | (x << 4)) & 0x0F0F0F0Fu;
    x = (x | (x << 2)) & 0x33333333u;
    return (x | (x << 1)) & 0x55555555u;
}

/* A point's direction from o on the cube: its dominant axis and sign, then the two other
 * coordinates over the dominant one, quantized to 128 steps and interleaved (near directions,
 * near keys). 17 bits: two radix passes; rays of one cell keep their scan order. Finer cells
 * measured no better on scan.dat. */
static uint64_t dir_key(const float o[3], const occ_vec3_t p)
{
    if (!occ_finite3(p)) {
        return 0u; /* skipped by the walk anyway */
    }
    const float v[3] = {p.x - o[0], p.y - o[1], p.z - o[2]};
    const float m[3] = {v[0] < 0.0f ? -v[0] : v[0], v[1] < 0.0f ? -v[1] : v[1],
                        v[2] < 0.0f ? -v[2] : v[2]};
    const unsigned a = m[0] >= m[1] ? (m[0] >= m[2] ? 0u : 2u) : (m[1] >= m[2] ? 1u : 2u);
    if (!(m[a] > 0.0f) || !occ_finite(m[a])) {
        return 0u;
    }
    const float q = 63.0f / m[a];
    const uint32_t u = (uint32_t)(v[(a + 1u) % 3u] * q + 63.5f); /* 0 .. 126 */
    const uint32_t w = (uint32_t)(v[(a + 2u) % 3u] * q + 63.5f);
    const uint64_t face = 2u * a + (v[a] < 0.0f ? 1u : 0u);
    return (face << 14) | spread2(u) | (spread2(w) << 1);
}

const uint32_t *occi_ray_order(occ_ictx_t *const x, const occ_vec3_t *const points,
                               const size_t n)
{
    /* keys, their sort temporary (8 B each), indices and theirs (4 B each): 3 codes a point */
    if (x->bs == NULL || n < 2u || n >= UINT32_MAX || x->b_cap / 3u < n) {
        return NULL;
    }
    uint64_t *const keys = x->b, *const tkeys = keys + n;
    uint32_t *const vals = (uint32_t *)(void *)(tkeys + n), *const tvals = vals + n;
    for (size_t i = 0; i < n; i++) {
        keys[i] = dir_key(x->o, points[i]);
        vals[i] = (uint32_t)i;
    }
    occ_ictx_note(x, 0, 3u * n);
    const uint64_t *const sorted = occi_keyset_sort_pairs(keys, vals, tkeys, tvals, n, x->hist);
    return sorted == keys ? vals : tvals;
}
