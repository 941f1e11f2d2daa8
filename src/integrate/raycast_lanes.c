/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * raycast_lanes.c - occi_dda_mark's walk over 8 rays at once, one per lane of AVX-512 vectors of
 * doubles (x86-64 GCC, where the CPU has it: OCC_MARK_LANES and occi_mwalk_lanes_ok). The
 * scalar walk's time is its axis branch, which the CPU mispredicts at random. Here every lane
 * picks its axis by three compares (OctoMap's rule: the smallest tMax, ties to the higher axis),
 * steps its tMax and its Morton code under that mask, and counts down to its next chunk. A lane
 * whose ray passes its length, reaches its end voxel or crosses into the next chunk leaves the
 * vector loop for a scalar step (the scalar walk's order: length, chunk, end); a lane whose ray
 * ended takes the batch's next ray. The voxels are marked from the lanes' codes one at a time:
 * two lanes may share a word. The same IEEE operations as the scalar walk in the same order, so
 * the same set, overflow and visits (test_integrate, the OctoMap comparisons, bench/ab_split's
 * digests).
 */
#include "integrate_internal.h"

#if OCC_MARK_LANES
#include <immintrin.h>
#include <string.h>

#define LANES 8u
#define DILATED_X 0x1249249249249249ull /* axis 0's bits of a code */

/* The lanes between vector loops: per lane its scalar walk (chunk coordinates, steps), and
 * what the vector loop steps, laid out for its loads. */
typedef struct {
    double t[3][LANES], d[3][LANES], len[LANES];
    uint64_t c[LANES], ce[LANES], add[3][LANES], n[3][LANES], cw[LANES];
    occi_mwalk_t w[LANES];
    unsigned live; /* lanes holding a ray */
} lanes_t;

/* The batch: the rays from o (key ko) to ends[0..n), the next to start, the set. */
typedef struct {
    const occ_raygeo_t *g;
    const float *o;
    const uint32_t *ko;
    const occi_ray_end_t *ends;
    size_t n, next;
    occ_vset_t *vs;
} batch_t;

/* Lane l takes walk w (its origin marked; cw its chunk's words). A code's step on axis a adds
 * -m (+1: x - m) or all ones (-1: x - 1) to the axis' bits x = c & m (occ_code_step). */
static void lane_load(lanes_t *const s, const unsigned l, const uint64_t *const cw)
{
    const occi_mwalk_t *const w = &s->w[l];
    for (unsigned a = 0; a < 3u; a++) {
        s->t[a][l] = w->dd.tmax[a];
        s->d[a][l] = w->dd.tdelta[a];
        s->n[a][l] = w->n[a];
        s->add[a][l] = w->dd.step[a] < 0 ? ~(uint64_t)0 : (uint64_t)0 - (DILATED_X << a);
    }
    s->len[l] = w->len;
    s->c[l] = w->c;
    s->ce[l] = w->ce;
    s->cw[l] = (uint64_t)(uintptr_t)cw;
}

/* Lane l takes the batch's next ray that has steps to walk; false when none is left. */
static bool lane_refill(lanes_t *const s, const unsigned l, batch_t *const b)
{
    while (b->next < b->n) {
        const occi_ray_end_t *const r = &b->ends[b->next++];
        uint64_t *cw = NULL;
        if (occi_mwalk_start(&s->w[l], &cw, b->g, b->o, r->e, b->ko, r->ke, b->vs)) {
            lane_load(s, l, cw);
            return true;
        }
    }
    return false;
}

/* Lane l's ray has ended: its visits, then the next ray (or the lane goes idle). */
static size_t lane_finish(lanes_t *const s, const unsigned l, batch_t *const b)
{
    occi_mwalk_t *const w = &s->w[l];
    for (unsigned a = 0; a < 3u; a++) {
        w->n[a] = (uint32_t)s->n[a][l];
    }
    const size_t visits = occi_mwalk_visits(w, b->ko);
    if (!lane_refill(s, l, b)) {
        s->live &= ~(1u << l);
    }
    return visits;
}

/* Lane l's step left the vector loop: past its length (the ray ends), into the next chunk on
 * the axis whose countdown is 0 (enter it, or the ray ends), at its end voxel (the ray ends),
 * else its voxel is marked. Returns the visits of a ray that ended. */
static size_t lane_event(lanes_t *const s, const unsigned l, const bool past, const bool end,
                         batch_t *const b)
{
    if (past) {
        return lane_finish(s, l, b);
    }
    occi_mwalk_t *const w = &s->w[l];
    for (unsigned a = 0; a < 3u; a++) {
        if (s->n[a][l] == 0u) {
            s->n[a][l] = 32u;
            w->cc[a] += (uint32_t)w->dd.step[a];
            uint64_t *const cw = occi_mwalk_enter(w, b->vs, s->c[l]);
            if (cw == NULL) {
                return lane_finish(s, l, b);
            }
            s->cw[l] = (uint64_t)(uintptr_t)cw;
        }
    }
    if (end) {
        return lane_finish(s, l, b);
    }
    const uint64_t c = s->c[l];
    ((uint64_t *)(uintptr_t)s->cw[l])[(c >> 6) & 511u] |= (uint64_t)1 << (c & 63u);
    return 0;
}

/* Steps every live lane until one of them has an event, marking the others' voxels on the way
 * (no call in the loop: every vector register would be saved around it). Returns the lanes with
 * an event; *past and *end say which passed the length or reached the end voxel. The lanes'
 * state goes back to s. */
__attribute__((target("avx512f"))) static unsigned walk_lanes(lanes_t *const s, unsigned *const past,
                                                              unsigned *const end)
{
    const __m512i one = _mm512_set1_epi64(1), zero = _mm512_setzero_si512();
    const __m512i m0x = _mm512_set1_epi64((long long)DILATED_X);
    const __m512i m1x = _mm512_slli_epi64(m0x, 1), m2x = _mm512_slli_epi64(m0x, 2);
    const __m512i words = _mm512_set1_epi64(511), bits = _mm512_set1_epi64(63);
    __m512d t0 = _mm512_loadu_pd(s->t[0]), t1 = _mm512_loadu_pd(s->t[1]);
    __m512d t2 = _mm512_loadu_pd(s->t[2]);
    const __m512d d0 = _mm512_loadu_pd(s->d[0]), d1 = _mm512_loadu_pd(s->d[1]);
    const __m512d d2 = _mm512_loadu_pd(s->d[2]), len = _mm512_loadu_pd(s->len);
    __m512i c = _mm512_loadu_si512(s->c);
    const __m512i ce = _mm512_loadu_si512(s->ce), cw = _mm512_loadu_si512(s->cw);
    const __m512i a0 = _mm512_loadu_si512(s->add[0]), a1 = _mm512_loadu_si512(s->add[1]);
    const __m512i a2 = _mm512_loadu_si512(s->add[2]);
    __m512i n0 = _mm512_loadu_si512(s->n[0]), n1 = _mm512_loadu_si512(s->n[1]);
    __m512i n2 = _mm512_loadu_si512(s->n[2]);
    const unsigned live = s->live;
    unsigned ev = 0, p = 0, e = 0;
    uint64_t adr[LANES], bit[LANES];
    while (ev == 0u) {
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
        c = _mm512_add_epi64(c, _mm512_sub_epi64(_mm512_and_si512(_mm512_add_epi64(x, add), m), x));
        n0 = _mm512_mask_sub_epi64(n0, m0, n0, one);
        n1 = _mm512_mask_sub_epi64(n1, m1, n1, one);
        n2 = _mm512_mask_sub_epi64(n2, m2, n2, one);
        const unsigned z = (unsigned)(_mm512_cmpeq_epi64_mask(n0, zero) |
                                      _mm512_cmpeq_epi64_mask(n1, zero) |
                                      _mm512_cmpeq_epi64_mask(n2, zero));
        p = (unsigned)(_mm512_cmp_pd_mask(t0, len, _CMP_GT_OQ) &
                       _mm512_cmp_pd_mask(t1, len, _CMP_GT_OQ) &
                       _mm512_cmp_pd_mask(t2, len, _CMP_GT_OQ));
        e = (unsigned)_mm512_cmpeq_epi64_mask(c, ce);
        ev = (z | p | e) & live;
        const __m512i word = _mm512_and_si512(_mm512_srli_epi64(c, 6), words);
        _mm512_storeu_si512(adr, _mm512_add_epi64(cw, _mm512_slli_epi64(word, 3)));
        _mm512_storeu_si512(bit, _mm512_sllv_epi64(one, _mm512_and_si512(c, bits)));
        for (unsigned mk = live & ~ev; mk != 0u; mk &= mk - 1u) {
            const unsigned l = (unsigned)__builtin_ctz(mk);
            *(uint64_t *)(uintptr_t)adr[l] |= bit[l];
        }
    }
    _mm512_storeu_pd(s->t[0], t0);
    _mm512_storeu_pd(s->t[1], t1);
    _mm512_storeu_pd(s->t[2], t2);
    _mm512_storeu_si512(s->c, c);
    _mm512_storeu_si512(s->n[0], n0);
    _mm512_storeu_si512(s->n[1], n1);
    _mm512_storeu_si512(s->n[2], n2);
    *past = p;
    *end = e;
    return ev;
}

bool occi_mwalk_lanes_ok(void)
{
    return __builtin_cpu_supports("avx512f");
}

size_t occi_mwalk_batch(const occ_raygeo_t *const g, const float o[3], const uint32_t ko[3],
                        const occi_ray_end_t *const ends, const size_t n, occ_vset_t *const vs)
{
    batch_t b = {g, o, ko, ends, n, 0u, vs};
    lanes_t s;
    memset(&s, 0, sizeof s); /* an idle lane's zeros: harmless in the vector loop, never used */
    for (unsigned l = 0; l < LANES; l++) {
        if (lane_refill(&s, l, &b)) {
            s.live |= 1u << l;
        }
    }
    size_t visits = 0;
    while (s.live != 0u) {
        unsigned past = 0, end = 0;
        for (unsigned ev = walk_lanes(&s, &past, &end); ev != 0u; ev &= ev - 1u) {
            const unsigned l = (unsigned)__builtin_ctz(ev);
            visits += lane_event(&s, l, ((past >> l) & 1u) != 0u, ((end >> l) & 1u) != 0u, &b);
        }
    }
    return visits;
}
#else
typedef int occi_raycast_lanes_unused; /* ISO C: no empty translation unit */
#endif
