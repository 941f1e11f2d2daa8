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

/* The pieces of walk_lanes below are inlined into it (no call in its loop: every vector
 * register would be saved around one). */
#define LANES_FN OCC_ALWAYS_INLINE __attribute__((target("avx512f")))

/* The lanes as the vector loop holds them (lanes_t's fields, one vector each). */
typedef struct {
    __m512d t0, t1, t2, d0, d1, d2, len;
    __m512i c, ce, cw, a0, a1, a2, steps;
} vec_t;

LANES_FN static inline void vec_load(vec_t *const v, const lanes_t *const s)
{
    v->t0 = _mm512_loadu_pd(s->t[0]);
    v->t1 = _mm512_loadu_pd(s->t[1]);
    v->t2 = _mm512_loadu_pd(s->t[2]);
    v->d0 = _mm512_loadu_pd(s->d[0]);
    v->d1 = _mm512_loadu_pd(s->d[1]);
    v->d2 = _mm512_loadu_pd(s->d[2]);
    v->len = _mm512_loadu_pd(s->len);
    v->c = _mm512_loadu_si512(s->c);
    v->ce = _mm512_loadu_si512(s->ce);
    v->cw = _mm512_loadu_si512(s->cw);
    v->a0 = _mm512_loadu_si512(s->add[0]);
    v->a1 = _mm512_loadu_si512(s->add[1]);
    v->a2 = _mm512_loadu_si512(s->add[2]);
    v->steps = _mm512_loadu_si512(s->steps);
}

LANES_FN static inline void vec_store(const vec_t *const v, lanes_t *const s)
{
    _mm512_storeu_pd(s->t[0], v->t0);
    _mm512_storeu_pd(s->t[1], v->t1);
    _mm512_storeu_pd(s->t[2], v->t2);
    _mm512_storeu_pd(s->d[0], v->d0);
    _mm512_storeu_pd(s->d[1], v->d1);
    _mm512_storeu_pd(s->d[2], v->d2);
    _mm512_storeu_pd(s->len, v->len);
    _mm512_storeu_si512(s->c, v->c);
    _mm512_storeu_si512(s->ce, v->ce);
    _mm512_storeu_si512(s->cw, v->cw);
    _mm512_storeu_si512(s->add[0], v->a0);
    _mm512_storeu_si512(s->add[1], v->a1);
    _mm512_storeu_si512(s->add[2], v->a2);
    _mm512_storeu_si512(s->steps, v->steps);
}

/* The lanes of k take rays r[i ..] in lane order (expanding loads), their steps from 0. */
LANES_FN static inline void vec_take(vec_t *const v, const __mmask8 k, const rays_t *const r,
                                     const size_t i)
{
    v->t0 = _mm512_mask_expandloadu_pd(v->t0, k, &r->t[0][i]);
    v->t1 = _mm512_mask_expandloadu_pd(v->t1, k, &r->t[1][i]);
    v->t2 = _mm512_mask_expandloadu_pd(v->t2, k, &r->t[2][i]);
    v->d0 = _mm512_mask_expandloadu_pd(v->d0, k, &r->d[0][i]);
    v->d1 = _mm512_mask_expandloadu_pd(v->d1, k, &r->d[1][i]);
    v->d2 = _mm512_mask_expandloadu_pd(v->d2, k, &r->d[2][i]);
    v->len = _mm512_mask_expandloadu_pd(v->len, k, &r->len[i]);
    v->c = _mm512_mask_expandloadu_epi64(v->c, k, &r->c[i]);
    v->ce = _mm512_mask_expandloadu_epi64(v->ce, k, &r->ce[i]);
    v->cw = _mm512_mask_expandloadu_epi64(v->cw, k, &r->cw[i]);
    v->a0 = _mm512_mask_expandloadu_epi64(v->a0, k, &r->add[0][i]);
    v->a1 = _mm512_mask_expandloadu_epi64(v->a1, k, &r->add[1][i]);
    v->a2 = _mm512_mask_expandloadu_epi64(v->a2, k, &r->add[2][i]);
    v->steps = _mm512_maskz_mov_epi64((__mmask8)~k, v->steps);
}

/* One step of every live lane: OctoMap's axis (the smallest tMax, ties to the higher), its tMax
 * and the code's step on it (occ_code_step); returns the new codes (v->c keeps the old ones). */
LANES_FN static inline __m512i vec_step(vec_t *const v, const __mmask8 live)
{
    const __m512i m0x = _mm512_set1_epi64((long long)DILATED_X);
    const __m512i m1x = _mm512_slli_epi64(m0x, 1), m2x = _mm512_slli_epi64(m0x, 2);
    const __mmask8 lt12 = _mm512_cmp_pd_mask(v->t1, v->t2, _CMP_LT_OQ);
    const __mmask8 m0 = _mm512_cmp_pd_mask(v->t0, v->t1, _CMP_LT_OQ) &
                        _mm512_cmp_pd_mask(v->t0, v->t2, _CMP_LT_OQ);
    const __mmask8 m1 = (__mmask8)(~m0 & lt12), m2 = (__mmask8)(~m0 & ~lt12);
    v->t0 = _mm512_mask_add_pd(v->t0, m0, v->t0, v->d0);
    v->t1 = _mm512_mask_add_pd(v->t1, m1, v->t1, v->d1);
    v->t2 = _mm512_mask_add_pd(v->t2, m2, v->t2, v->d2);
    const __m512i m = _mm512_mask_blend_epi64(m2, _mm512_mask_blend_epi64(m1, m0x, m1x), m2x);
    const __m512i add =
        _mm512_mask_blend_epi64(m2, _mm512_mask_blend_epi64(m1, v->a0, v->a1), v->a2);
    const __m512i x = _mm512_and_si512(v->c, m);
    v->steps = _mm512_mask_add_epi64(v->steps, live, v->steps, _mm512_set1_epi64(1));
    return _mm512_add_epi64(v->c,
                            _mm512_sub_epi64(_mm512_and_si512(_mm512_add_epi64(x, add), m), x));
}

/* The lanes of `chunk` entered another chunk: their words from the cache (cache_slot's slots,
 * by gathers). Returns the lanes it cannot serve (a miss, or a code off the map: lane_enter). */
LANES_FN static inline unsigned vec_chunks(vec_t *const v, const unsigned chunk,
                                           const occi_mwalk_cache_t *const cache,
                                           const __m512i off)
{
    const __m512i key = _mm512_srli_epi64(v->c, 15);
    const __m512i fold = _mm512_xor_si512(key, _mm512_srli_epi64(key, 8));
    const __m512i slot = _mm512_and_si512(_mm512_xor_si512(fold, _mm512_srli_epi64(key, 16)),
                                          _mm512_set1_epi64((long long)(OCC_MARK_CACHE - 1u)));
    const __mmask8 on = (__mmask8)(chunk & ~(unsigned)_mm512_test_epi64_mask(v->c, off));
    const __m512i none = _mm512_setzero_si512();
    const __m512i got = _mm512_mask_i64gather_epi64(none, on, slot, cache->key, 8);
    const __mmask8 hit =
        _mm512_mask_cmpeq_epi64_mask(on, got, _mm512_add_epi64(key, _mm512_set1_epi64(1)));
    v->cw = _mm512_mask_i64gather_epi64(v->cw, hit, slot, cache->ptr, 8);
    return chunk & ~(unsigned)hit;
}

/* A step's marks, written one step later (read right after the vector stores, the words'
 * addresses waited on them): `pend` lanes of the step before, whose addresses and bits are in
 * the other half of the buffer. */
typedef struct {
    uint64_t adr[2][LANES], bit[2][LANES];
    unsigned pend, cur;
} marks_t;

LANES_FN static inline void marks_write(marks_t *const mk)
{
    const unsigned h = mk->cur ^ 1u;
    if (mk->pend == (1u << LANES) - 1u) { /* the common case, unrolled */
        for (unsigned l = 0; l < LANES; l++) {
            *(uint64_t *)(uintptr_t)mk->adr[h][l] |= mk->bit[h][l];
        }
        return;
    }
    for (unsigned p = mk->pend; p != 0u; p &= p - 1u) {
        const unsigned l = (unsigned)__builtin_ctz(p);
        *(uint64_t *)(uintptr_t)mk->adr[h][l] |= mk->bit[h][l];
    }
}

/* The voxels of codes c in words cw, for the `lanes`: stored now, written after the next step. */
LANES_FN static inline void marks_add(marks_t *const mk, const __m512i c, const __m512i cw,
                                      const unsigned lanes)
{
    const __m512i word = _mm512_and_si512(_mm512_srli_epi64(c, 6), _mm512_set1_epi64(511));
    _mm512_storeu_si512(mk->adr[mk->cur], _mm512_add_epi64(cw, _mm512_slli_epi64(word, 3)));
    const __m512i low = _mm512_and_si512(c, _mm512_set1_epi64(63));
    _mm512_storeu_si512(mk->bit[mk->cur], _mm512_sllv_epi64(_mm512_set1_epi64(1), low));
    marks_write(mk);
    mk->pend = lanes;
    mk->cur ^= 1u;
}

/* The lanes of `fin` ended: their visits into *acc, the next rays into them in order (the last
 * lanes go idle when too few are left). Returns the live lanes. */
LANES_FN static inline unsigned vec_finish(vec_t *const v, __m512i *const acc,
                                           const unsigned fin, unsigned live, rays_t *const r)
{
    *acc = _mm512_mask_add_epi64(*acc, (__mmask8)fin, *acc, v->steps);
    unsigned take = fin;
    const size_t left = r->n - r->next;
    while ((size_t)__builtin_popcount(take) > left) {
        take &= ~(1u << (31 - __builtin_clz(take)));
    }
    vec_take(v, (__mmask8)take, r, r->next);
    r->next += (size_t)__builtin_popcount(take);
    return live & ~(fin & ~take);
}

/* The vector loop. Returns when every lane is idle (0) or with the lanes that need lane_enter;
 * *end says which of them are at their end voxel. Adds the visits of the rays that ended to
 * *visits. */
__attribute__((target("avx512f"))) static unsigned
walk_lanes(lanes_t *const s, rays_t *const r, const occi_mwalk_cache_t *const cache,
           const uint64_t off_map, unsigned *const end_out, size_t *const visits)
{
    const __m512i off = _mm512_set1_epi64((long long)off_map);
    vec_t v;
    vec_load(&v, s);
    __m512i acc = _mm512_setzero_si512();
    unsigned live = s->live, slow = 0, end = 0;
    marks_t mk;
    mk.pend = 0u;
    mk.cur = 0u;
    while (live != 0u) {
        const __mmask8 lv = (__mmask8)live;
        const __m512i cn = vec_step(&v, lv);
        const unsigned past = (unsigned)(_mm512_mask_cmp_pd_mask(lv, v.t0, v.len, _CMP_GT_OQ) &
                                         _mm512_cmp_pd_mask(v.t1, v.len, _CMP_GT_OQ) &
                                         _mm512_cmp_pd_mask(v.t2, v.len, _CMP_GT_OQ));
        const __m512i moved = _mm512_srli_epi64(_mm512_xor_si512(cn, v.c), 15); /* chunk bits */
        const unsigned chunk = (unsigned)_mm512_mask_test_epi64_mask(lv, moved, moved) & ~past;
        v.c = cn;
        end = (unsigned)_mm512_mask_cmpeq_epi64_mask(lv, v.c, v.ce) & ~past;
        if (chunk != 0u) {
            slow = vec_chunks(&v, chunk, cache, off);
        }
        const unsigned fin = (past | end) & ~slow;
        marks_add(&mk, v.c, v.cw, live & ~fin & ~slow);
        if (fin != 0u) {
            live = vec_finish(&v, &acc, fin, live, r);
        }
        if (slow != 0u) {
            break;
        }
    }
    marks_write(&mk); /* the last step's */
    vec_store(&v, s);
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
