/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * keyset.c - per-scan key sets as sorted Morton codes: LSD radix sort (digits that are equal in
 * every code are skipped) and run collapsing. Sorting is what makes the later tree update
 * touch memory in Morton order.
 */
#include <string.h>

#include "integrate_internal.h"

#define CODE_BITS ((occ_code_t)0x7FFFFFFFFFFFFFFFull)
#define DIGIT_MASK ((occ_code_t)(OCC_KS_RADIX - 1u))

/* The bits that differ between codes a[0], a[stride], ... (n of them; the hit flag aside). */
static OCC_ALWAYS_INLINE occ_code_t code_diff(const occ_code_t *const a, const size_t n,
                                              const size_t stride)
{
    const occ_code_t first = a[0] & CODE_BITS;
    occ_code_t diff = 0;
    for (size_t i = 0; i < n; i++) {
        diff |= (a[i * stride] & CODE_BITS) ^ first;
    }
    return diff;
}

/* The digit histograms of the passes that sort (a digit that differs somewhere), in one sweep;
 * returns the bits that differ between codes. A frame's or a scan's codes often differ in
 * their low bits only (not where the keys cross 2^(D-1) on an axis): counting every pass there
 * cost as much as the sort. */
static OCC_ALWAYS_INLINE occ_code_t histograms(const occ_code_t *const a, const size_t n,
                                               const size_t stride, uint32_t *const hist)
{
    const occ_code_t diff = code_diff(a, n, stride);
    unsigned live = 0, top = 0; /* bit p: pass p sorts; passes 0 .. top - 1 hold them all */
    for (unsigned p = 0; p < OCC_KS_PASSES; p++) {
        if (((diff >> (p * OCC_INSERT_RADIX_BITS)) & DIGIT_MASK) != 0u) {
            live |= 1u << p;
            top = p + 1u;
            memset(&hist[p * OCC_KS_RADIX], 0, OCC_KS_RADIX * sizeof hist[0]);
        }
    }
    /* Digits by shifts of a constant: a variable 64-bit shift is a library call on the M0+.
     * Two loops, as measured: counting the passes below top that do not sort too (the TUM
     * frames' end points cross 2^(D-1): 3.2 passes sort per frame, with gaps below the top
     * one) cost PROJECTIVE 1.03 to 1.05x; the test per pass in every case cost the M0+'s
     * 64-ray scan 2 %, where every pass below top sorts. */
    if (live + 1u == 1u << top) { /* passes 0 .. top - 1 all sort: no test per pass */
        for (size_t i = 0; i < n; i++) {
            occ_code_t v = a[i * stride] & CODE_BITS;
            for (unsigned p = 0; p < top; p++) {
                hist[p * OCC_KS_RADIX + (unsigned)(v & DIGIT_MASK)]++;
                v >>= OCC_INSERT_RADIX_BITS;
            }
        }
        return diff;
    }
    for (size_t i = 0; i < n; i++) {
        occ_code_t v = a[i * stride] & CODE_BITS;
        for (unsigned p = 0; p < top; p++) {
            if (((live >> p) & 1u) != 0u) {
                hist[p * OCC_KS_RADIX + (unsigned)(v & DIGIT_MASK)]++;
            }
            v >>= OCC_INSERT_RADIX_BITS;
        }
    }
    return diff;
}

/* Turn pass p's histogram into start offsets; NULL when every code has the same digit there
 * (the pass is skipped). */
static uint32_t *pass_offsets(uint32_t *const hist, const unsigned p, const occ_code_t diff)
{
    if (((diff >> (p * OCC_INSERT_RADIX_BITS)) & DIGIT_MASK) == 0u) {
        return NULL;
    }
    uint32_t *const h = &hist[p * OCC_KS_RADIX];
    uint32_t sum = 0;
    for (unsigned b = 0; b < OCC_KS_RADIX; b++) {
        const uint32_t c = h[b];
        h[b] = sum;
        sum += c;
    }
    return h;
}

/* The sort of n entries of `width` words (1: codes; 2: records, the second word carried),
 * keyed by the first word's bits 0..62; inlined into each caller with its width a constant. */
static OCC_ALWAYS_INLINE occ_code_t *sort_entries(occ_code_t *a, occ_code_t *tmp, const size_t n,
                                                  const size_t width, uint32_t *const hist)
{
    if (n < 2u) {
        return a;
    }
    const occ_code_t diff = histograms(a, n, width, hist);
    for (unsigned p = 0; p < OCC_KS_PASSES; p++) {
        uint32_t *const h = pass_offsets(hist, p, diff);
        if (h == NULL) {
            continue;
        }
        const unsigned shift = p * OCC_INSERT_RADIX_BITS;
        for (size_t i = 0; i < n; i++) {
            const occ_code_t c = a[width * i];
            const unsigned b = (unsigned)(((c & CODE_BITS) >> shift) & DIGIT_MASK);
            const size_t at = width * (size_t)h[b]++;
            tmp[at] = c;
            if (width == 2u) {
                tmp[at + 1u] = a[width * i + 1u];
            }
        }
        occ_code_t *const t = a;
        a = tmp;
        tmp = t;
    }
    return a;
}

occ_code_t *occi_keyset_sort(occ_code_t *a, occ_code_t *tmp, const size_t n, uint32_t *const hist)
{
    return sort_entries(a, tmp, n, 1u, hist);
}

occ_code_t *occi_keyset_sort_records(occ_code_t *r, occ_code_t *tmp, const size_t n,
                                     uint32_t *const hist)
{
    return sort_entries(r, tmp, n, 2u, hist);
}

size_t occi_keyset_unique(occ_code_t *const a, const size_t n)
{
    if (n == 0u) {
        return 0;
    }
    size_t w = 0;
    for (size_t i = 1; i < n; i++) {
        const occ_code_t c = a[i];
        if (((c ^ a[w]) & CODE_BITS) == 0u) {
            a[w] |= c; /* same voxel: the hit flag wins */
        } else {
            a[++w] = c;
        }
    }
    return w + 1u;
}

const uint16_t occi_spread5[32] = {
    0x0000, 0x0001, 0x0008, 0x0009, 0x0040, 0x0041, 0x0048, 0x0049, 0x0200, 0x0201, 0x0208,
    0x0209, 0x0240, 0x0241, 0x0248, 0x0249, 0x1000, 0x1001, 0x1008, 0x1009, 0x1040, 0x1041,
    0x1048, 0x1049, 0x1200, 0x1201, 0x1208, 0x1209, 0x1240, 0x1241, 0x1248, 0x1249};

static uint32_t compact3b(const uint32_t v)
{
    return (v & 1u) | ((v >> 2) & 2u) | ((v >> 4) & 4u);
}

size_t occi_bitset_extract(occ_bitset_t *const bs, const occ_code_t *const hits,
                           const size_t n_hits, occ_code_t *const out, const size_t cap,
                           occ_code_t *const tmp, uint32_t *const hist)
{
    /* Brick codes in place of the word indices, sorted. */
    uint64_t *const t = bs->touched;
    const size_t nt = bs->n_touched;
    const size_t ncx = bs->nb[0] >> 3, ncy = bs->nb[1] >> 3;
    for (size_t i = 0; i < nt; i++) {
        const size_t idx = (size_t)t[i];
        const size_t chunk = idx >> 9;
        const uint32_t in = (uint32_t)(idx & 511u);
        occ_key_t bk;
        bk.k[0] = bs->b0[0] + (uint32_t)(chunk % ncx) * 8u + compact3b(in);
        bk.k[1] = bs->b0[1] + (uint32_t)((chunk / ncx) % ncy) * 8u + compact3b(in >> 1);
        bk.k[2] = bs->b0[2] + (uint32_t)(chunk / (ncx * ncy)) * 8u + compact3b(in >> 2);
        t[i] = occ_morton_encode(bk);
    }
    occ_code_t *const s = occi_keyset_sort(t, tmp, nt, hist);
    if (s != t) {
        memcpy(t, s, nt * sizeof *t);
    }
    size_t n = 0, h = 0;
    for (size_t i = 0; i < nt; i++) {
        const occ_code_t base = t[i] << 6;
        const occ_key_t bk = occ_morton_decode(t[i]);
        const size_t idx = occ_bitset_index(bs, bk.k[0] - bs->b0[0], bk.k[1] - bs->b0[1],
                                            bk.k[2] - bs->b0[2]);
        uint64_t w = bs->words[idx];
        while (w != 0u) {
            const unsigned bit = (unsigned)__builtin_ctzll(w);
            w &= w - 1u;
            const occ_code_t c = base | bit;
            while (h < n_hits && (hits[h] & ~OCC_CODE_HIT_BIT) < c) {
                if (n == cap) {
                    return SIZE_MAX;
                }
                out[n++] = hits[h++];
            }
            if (n == cap) {
                return SIZE_MAX;
            }
            if (h < n_hits && (hits[h] & ~OCC_CODE_HIT_BIT) == c) {
                out[n++] = hits[h++];
            } else {
                out[n++] = c;
            }
        }
    }
    while (h < n_hits) {
        if (n == cap) {
            return SIZE_MAX;
        }
        out[n++] = hits[h++];
    }
    return n;
}

uint64_t *occi_keyset_sort_pairs(uint64_t *k, uint32_t *v, uint64_t *tk, uint32_t *tv,
                                 const size_t n, uint32_t *const hist)
{
    if (n < 2u) {
        return k;
    }
    const occ_code_t diff = histograms(k, n, 1u, hist);
    for (unsigned p = 0; p < OCC_KS_PASSES; p++) {
        uint32_t *const h = pass_offsets(hist, p, diff);
        if (h == NULL) {
            continue;
        }
        const unsigned shift = p * OCC_INSERT_RADIX_BITS;
        for (size_t i = 0; i < n; i++) {
            const unsigned b = (unsigned)(((k[i] & CODE_BITS) >> shift) & DIGIT_MASK);
            const uint32_t at = h[b]++;
            tk[at] = k[i];
            tv[at] = v[i];
        }
        uint64_t *const t1 = k;
        k = tk;
        tk = t1;
        uint32_t *const t2 = v;
        v = tv;
        tv = t2;
    }
    return k; /* the values are in the array paired with the returned keys */
}
