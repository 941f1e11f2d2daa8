/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * raycast_lanes.c - occi_dda_mark's walk over 8 rays at once, one per lane of AVX-512 vectors of
 * doubles (x86-64 GCC, where the CPU has it: OCC_MARK_LANES and occi_mwalk_lanes_ok). The
 * scalar walk's time is its axis branch, which the CPU mispredicts at random. Here every lane
 * picks its axis by three compares (OctoMap's rule: the smallest tMax, ties to the higher axis)
 * and steps its tMax and its Morton code under that mask. In the vector loop too:
 *  - a lane whose ray passes its length or reaches its end voxel adds its steps (its visits)
 *    and takes the batch's next ray, set up beforehand (expanding loads);
 *  - a lane whose code enters another 32^3 chunk finds the chunk's words in a small cache of
 *    chunks (gathers); only a miss, or a step off the map, leaves the loop for the scalar
 *    walk's chunk entry (occi_mwalk_enter).
 * The voxels are marked from the lanes' codes one at a time: two lanes may share a word. The
 * same IEEE operations and the scalar walk's order (length, chunk, end, mark), so the same set,
 * chunks, overflow and visits (test_integrate, the OctoMap comparisons, bench/ab_split's
 * digests).
 */
#include "integrate_internal.h"

#if OCC_MARK_LANES
#include <immintrin.h>
#include <string.h>

#define LANES 8u
#define DILATED_X 0x1249249249249249ull /* axis 0's bits of a code */

/* The batch's rays, set up (their origins marked), in the lanes' layout; the walk's loads take
 * them in order from `next`. */
typedef struct {
    double t[3][OCC_MARK_BATCH], d[3][OCC_MARK_BATCH], len[OCC_MARK_BATCH];
    uint64_t c[OCC_MARK_BATCH], ce[OCC_MARK_BATCH], cw[OCC_MARK_BATCH];
    uint64_t add[3][OCC_MARK_BATCH];
    size_t n, next;
} rays_t;

/* The lanes between vector loops, per lane as the vectors hold them. */
typedef struct {
    double t[3][LANES], d[3][LANES], len[LANES];
    uint64_t c[LANES], ce[LANES], cw[LANES], add[3][LANES], steps[LANES];
    unsigned live; /* lanes holding a ray */
} lanes_t;

/* A code's step on axis a adds -m (+1: x - m) or all ones (-1: x - 1) to the axis' bits
 * x = c & m (occ_code_step). */
static void ray_put(rays_t *const r, const occi_mwalk_t *const w, const uint64_t *const cw)
{
    const size_t i = r->n++;
    for (unsigned a = 0; a < 3u; a++) {
        r->t[a][i] = w->dd.tmax[a];
        r->d[a][i] = w->dd.tdelta[a];
        r->add[a][i] = w->dd.step[a] < 0 ? ~(uint64_t)0 : (uint64_t)0 - (DILATED_X << a);
    }
    r->len[i] = w->len;
    r->c[i] = w->c;
    r->ce[i] = w->ce;
    r->cw[i] = (uint64_t)(uintptr_t)cw;
}

/* Lane l takes the next ray, or goes idle. */
static void lane_take(lanes_t *const s, const unsigned l, rays_t *const r)
{
    if (r->next == r->n) {
        s->live &= ~(1u << l);
        return;
    }
    const size_t i = r->next++;
    for (unsigned a = 0; a < 3u; a++) {
        s->t[a][l] = r->t[a][i];
        s->d[a][l] = r->d[a][i];
        s->add[a][l] = r->add[a][i];
    }
    s->len[l] = r->len[i];
    s->c[l] = r->c[i];
    s->ce[l] = r->ce[i];
    s->cw[l] = r->cw[i];
    s->steps[l] = 0u;
    s->live |= 1u << l;
}

/* The chunk cache's slot of chunk code k (the code's bits from 15 up). */
static size_t cache_slot(const uint64_t k)
{
    return (size_t)((k ^ (k >> 8) ^ (k >> 16)) & (OCC_MARK_CACHE - 1u));
}

/* Lane l's step entered a chunk the cache does not hold, or left the map: the scalar walk's
 * chunk entry (which ends the ray on a miss off the map or in a full set), then its end test
 * and its mark. Returns the visits of a ray that ended (the lane then takes the next ray). */
static size_t lane_enter(lanes_t *const s, const unsigned l, const bool end, rays_t *const r,
                         occi_mwalk_cache_t *const cache, occ_vset_t *const vs)
{
    const uint64_t c = s->c[l];
    const occ_key_t k = occ_morton_decode(c);
    occi_mwalk_t w;
    for (unsigned a = 0; a < 3u; a++) {
        w.cc[a] = k.k[a] >> 5;
    }
    w.ce = s->ce[l];
    uint64_t *const cw = occi_mwalk_enter(&w, vs, c);
    if (cw != NULL) {
        const size_t slot = cache_slot(c >> 15);
        cache->key[slot] = (c >> 15) + 1u;
        cache->ptr[slot] = (uint64_t)(uintptr_t)cw;
        s->cw[l] = cache->ptr[slot];
        if (!end) {
            cw[(c >> 6) & 511u] |= (uint64_t)1 << (c & 63u);
            return 0;
        }
    }
    const size_t visits = s->steps[l];
    lane_take(s, l, r);
    return visits;
}

/* The vector loop (no call in it: every vector register would be saved around one). Returns
 * when every lane is idle (0) or with the lanes that need lane_enter; *end says which of them
 * are at their end voxel. Adds the visits of the rays that ended to *visits. */
__attribute__((target("avx512f"))) static unsigned
walk_lanes(lanes_t *const s, rays_t *const r, const occi_mwalk_cache_t *const cache,
           const uint64_t off_map, unsigned *const end_out, size_t *const visits)
{
    const __m512i one = _mm512_set1_epi64(1), zero = _mm512_setzero_si512();
    const __m512i m0x = _mm512_set1_epi64((long long)DILATED_X);
    const __m512i m1x = _mm512_slli_epi64(m0x, 1), m2x = _mm512_slli_epi64(m0x, 2);
    const __m512i words = _mm512_set1_epi64(511), bits = _mm512_set1_epi64(63);
    const __m512i off = _mm512_set1_epi64((long long)off_map);
    const __m512i slots = _mm512_set1_epi64((long long)(OCC_MARK_CACHE - 1u));
    __m512d t0 = _mm512_loadu_pd(s->t[0]), t1 = _mm512_loadu_pd(s->t[1]);
    __m512d t2 = _mm512_loadu_pd(s->t[2]), d0 = _mm512_loadu_pd(s->d[0]);
    __m512d d1 = _mm512_loadu_pd(s->d[1]), d2 = _mm512_loadu_pd(s->d[2]);
    __m512d len = _mm512_loadu_pd(s->len);
    __m512i c = _mm512_loadu_si512(s->c), ce = _mm512_loadu_si512(s->ce);
    __m512i cw = _mm512_loadu_si512(s->cw), a0 = _mm512_loadu_si512(s->add[0]);
    __m512i a1 = _mm512_loadu_si512(s->add[1]), a2 = _mm512_loadu_si512(s->add[2]);
    __m512i steps = _mm512_loadu_si512(s->steps), acc = zero;
    unsigned live = s->live, slow = 0, end = 0;
    /* a step's marks are written one step later, from what the step stored: read right after
     * the vector stores, the words' addresses wait on them */
    uint64_t adr[2][LANES], bit[2][LANES];
    unsigned pend = 0, cur = 0;
    while (live != 0u) {
        const __mmask8 lt12 = _mm512_cmp_pd_mask(t1, t2, _CMP_LT_OQ);
        const __mmask8 m0 = _mm512_cmp_pd_mask(t0, t1, _CMP_LT_OQ) &
                            _mm512_cmp_pd_mask(t0, t2, _CMP_LT_OQ);
        const __mmask8 m1 = (__mmask8)(~m0 & lt12), m2 = (__mmask8)(~m0 & ~lt12);
        t0 = _mm512_mask_add_pd(t0, m0, t0, d0);
        t1 = _mm512_mask_add_pd(t1, m1, t1, d1);
        t2 = _mm512_mask_add_pd(t2, m2, t2, d2);
        const __m512i m = _mm512_mask_blend_epi64(m2, _mm512_mask_blend_epi64(m1, m0x, m1x), m2x);
        const __m512i add = _mm512_mask_blend_epi64(m2, _mm512_mask_blend_epi64(m1, a0, a1), a2);
        const __m512i x = _mm512_and_si512(c, m);
        const __m512i cn =
            _mm512_add_epi64(c, _mm512_sub_epi64(_mm512_and_si512(_mm512_add_epi64(x, add), m), x));
        const __mmask8 lv = (__mmask8)live;
        steps = _mm512_mask_add_epi64(steps, lv, steps, one);
        const unsigned past = (unsigned)(_mm512_mask_cmp_pd_mask(lv, t0, len, _CMP_GT_OQ) &
                                         _mm512_cmp_pd_mask(t1, len, _CMP_GT_OQ) &
                                         _mm512_cmp_pd_mask(t2, len, _CMP_GT_OQ));
        const __m512i moved = _mm512_srli_epi64(_mm512_xor_si512(cn, c), 15); /* chunk bits */
        const unsigned chunk = (unsigned)_mm512_mask_test_epi64_mask(lv, moved, moved) & ~past;
        c = cn;
        end = (unsigned)_mm512_mask_cmpeq_epi64_mask(lv, c, ce) & ~past;
        if (chunk != 0u) { /* its words from the cache; a miss or off the map: lane_enter */
            const __m512i key = _mm512_srli_epi64(c, 15);
            const __m512i fold = _mm512_xor_si512(key, _mm512_srli_epi64(key, 8));
            const __m512i slot = /* cache_slot() */
                _mm512_and_si512(_mm512_xor_si512(fold, _mm512_srli_epi64(key, 16)), slots);
            const __mmask8 on = (__mmask8)(chunk & ~(unsigned)_mm512_test_epi64_mask(c, off));
            const __m512i got = _mm512_mask_i64gather_epi64(zero, on, slot, cache->key, 8);
            const __mmask8 hit = _mm512_mask_cmpeq_epi64_mask(on, got, _mm512_add_epi64(key, one));
            cw = _mm512_mask_i64gather_epi64(cw, hit, slot, cache->ptr, 8);
            slow = chunk & ~(unsigned)hit;
        }
        const unsigned fin = (past | end) & ~slow;
        const __m512i word = _mm512_and_si512(_mm512_srli_epi64(c, 6), words);
        _mm512_storeu_si512(adr[cur], _mm512_add_epi64(cw, _mm512_slli_epi64(word, 3)));
        _mm512_storeu_si512(bit[cur], _mm512_sllv_epi64(one, _mm512_and_si512(c, bits)));
        cur ^= 1u;
        if (pend == (1u << LANES) - 1u) { /* the common case, unrolled */
            for (unsigned l = 0; l < LANES; l++) {
                *(uint64_t *)(uintptr_t)adr[cur][l] |= bit[cur][l];
            }
        } else {
            for (unsigned mk = pend; mk != 0u; mk &= mk - 1u) {
                const unsigned l = (unsigned)__builtin_ctz(mk);
                *(uint64_t *)(uintptr_t)adr[cur][l] |= bit[cur][l];
            }
        }
        pend = live & ~fin & ~slow;
        if (fin != 0u) { /* their visits, then the next rays into those lanes, in order */
            acc = _mm512_mask_add_epi64(acc, (__mmask8)fin, acc, steps);
            unsigned take = fin;
            const size_t left = r->n - r->next;
            while ((size_t)__builtin_popcount(take) > left) {
                take &= ~(1u << (31 - __builtin_clz(take))); /* the last lanes go idle */
            }
            live &= ~(fin & ~take);
            const __mmask8 k = (__mmask8)take;
            const size_t i = r->next;
            t0 = _mm512_mask_expandloadu_pd(t0, k, &r->t[0][i]);
            t1 = _mm512_mask_expandloadu_pd(t1, k, &r->t[1][i]);
            t2 = _mm512_mask_expandloadu_pd(t2, k, &r->t[2][i]);
            d0 = _mm512_mask_expandloadu_pd(d0, k, &r->d[0][i]);
            d1 = _mm512_mask_expandloadu_pd(d1, k, &r->d[1][i]);
            d2 = _mm512_mask_expandloadu_pd(d2, k, &r->d[2][i]);
            len = _mm512_mask_expandloadu_pd(len, k, &r->len[i]);
            c = _mm512_mask_expandloadu_epi64(c, k, &r->c[i]);
            ce = _mm512_mask_expandloadu_epi64(ce, k, &r->ce[i]);
            cw = _mm512_mask_expandloadu_epi64(cw, k, &r->cw[i]);
            a0 = _mm512_mask_expandloadu_epi64(a0, k, &r->add[0][i]);
            a1 = _mm512_mask_expandloadu_epi64(a1, k, &r->add[1][i]);
            a2 = _mm512_mask_expandloadu_epi64(a2, k, &r->add[2][i]);
            steps = _mm512_mask_mov_epi64(steps, k, zero);
            r->next = i + (size_t)__builtin_popcount(take);
        }
        if (slow != 0u) {
            break;
        }
    }
    cur ^= 1u;
    for (unsigned mk = pend; mk != 0u; mk &= mk - 1u) {
        const unsigned l = (unsigned)__builtin_ctz(mk);
        *(uint64_t *)(uintptr_t)adr[cur][l] |= bit[cur][l];
    }
    _mm512_storeu_pd(s->t[0], t0);
    _mm512_storeu_pd(s->t[1], t1);
    _mm512_storeu_pd(s->t[2], t2);
    _mm512_storeu_pd(s->d[0], d0);
    _mm512_storeu_pd(s->d[1], d1);
    _mm512_storeu_pd(s->d[2], d2);
    _mm512_storeu_pd(s->len, len);
    _mm512_storeu_si512(s->c, c);
    _mm512_storeu_si512(s->ce, ce);
    _mm512_storeu_si512(s->cw, cw);
    _mm512_storeu_si512(s->add[0], a0);
    _mm512_storeu_si512(s->add[1], a1);
    _mm512_storeu_si512(s->add[2], a2);
    _mm512_storeu_si512(s->steps, steps);
    *visits += (size_t)_mm512_reduce_add_epi64(acc);
    s->live = live;
    *end_out = end;
    return slow;
}

bool occi_mwalk_lanes_ok(const unsigned depth)
{
    return depth < 21u && __builtin_cpu_supports("avx512f");
}

size_t occi_mwalk_batch(const occ_raygeo_t *const g, const float o[3], const uint32_t ko[3],
                        const occi_ray_end_t *const ends, const size_t n, occ_vset_t *const vs,
                        occi_mwalk_cache_t *const cache)
{
    rays_t r;
    r.n = 0u;
    r.next = 0u;
    for (size_t i = 0; i < n; i++) { /* set up, origins marked: the scalar walk's start */
        occi_mwalk_t w;
        uint64_t *cw = NULL;
        if (occi_mwalk_start(&w, &cw, g, o, ends[i].e, ko, ends[i].ke, vs)) {
            ray_put(&r, &w, cw);
        }
    }
    lanes_t s;
    memset(&s, 0, sizeof s); /* an idle lane's zeros: harmless in the vector loop, never used */
    for (unsigned l = 0; l < LANES; l++) {
        lane_take(&s, l, &r);
    }
    /* a key at or past 2^depth, or below 0 (all 21 bits), sets a code bit from 3 depth up */
    const uint64_t off_map = ~(((uint64_t)1 << (3u * g->depth)) - 1u);
    size_t visits = 0;
    while (s.live != 0u) {
        unsigned end = 0;
        for (unsigned ev = walk_lanes(&s, &r, cache, off_map, &end, &visits); ev != 0u;
             ev &= ev - 1u) {
            const unsigned l = (unsigned)__builtin_ctz(ev);
            visits += lane_enter(&s, l, ((end >> l) & 1u) != 0u, &r, cache, vs);
        }
    }
    return visits;
}
#else
typedef int occi_raycast_lanes_unused; /* ISO C: no empty translation unit */
#endif
