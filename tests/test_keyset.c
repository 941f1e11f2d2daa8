/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_keyset.c - the integrators' radix sorts (src/integrate/keyset.c) against a brute-force
 * stable sort: occi_keyset_sort (codes, the hit flag carried along), occi_keyset_sort_records
 * (PROJECTIVE's end points: a key and a carried word per record) and occi_keyset_unique. The
 * codes are drawn so that the sorts' shortcuts are taken: digits equal in every code (a pass
 * skipped), live passes with gaps below the top one, all passes live, runs of equal keys
 * (stability), n = 0, 1, 2. Random seed: printed, overridable with OCC_SEED.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "integrate/integrate_internal.h"
#include "support/seeded_rng.h"

#define KEY_BITS 0x7FFFFFFFFFFFFFFFull
#define MAX_N 5000u

/* A key of one of the shapes the sorts special-case (bit 63 clear). */
static occ_code_t draw_key(const unsigned shape, const occ_code_t base)
{
    const uint64_t r = rng_next();
    switch (shape) {
    case 0: /* low 12 bits differ: passes above the second skipped */
        return base | (r & 0xFFFu);
    case 1: /* bits 0..7 and 40..47 differ: a gap of equal digits below the top live one */
        return (base & ~0xFF000000FFull) | (r & 0xFFu) | (((r >> 8) & 0xFFu) << 40);
    case 2: /* few distinct keys: long runs of equal keys (stability) */
        return base | (r % 5u);
    default: /* every bit may differ */
        return r & KEY_BITS;
    }
}

/* A record of the reference sort: the key's bits 0..62, then the input position (stable). */
typedef struct {
    occ_code_t word[2];
    size_t at;
} ref_rec_t;

static int ref_cmp(const void *pa, const void *pb)
{
    const ref_rec_t *const a = pa, *const b = pb;
    const occ_code_t ka = a->word[0] & KEY_BITS, kb = b->word[0] & KEY_BITS;
    if (ka != kb) {
        return ka < kb ? -1 : 1;
    }
    return a->at < b->at ? -1 : (a->at > b->at ? 1 : 0);
}

/* Stable sort (qsort with the input position as the tie-break) of n records of `width` words
 * by word 0's bits 0..62. */
static void ref_sort(occ_code_t *a, const size_t n, const size_t width)
{
    static ref_rec_t rec[MAX_N];
    for (size_t i = 0; i < n; i++) {
        memcpy(rec[i].word, &a[i * width], width * sizeof a[0]);
        rec[i].at = i;
    }
    qsort(rec, n, sizeof rec[0], ref_cmp);
    for (size_t i = 0; i < n; i++) {
        memcpy(&a[i * width], rec[i].word, width * sizeof a[0]);
    }
}

static size_t draw_n(const unsigned round)
{
    return round < 3u ? round : (size_t)(rng_next() % MAX_N);
}

/* 200 random arrays of n entries of `width` words sorted by the library and by ref_sort:
 * codes with the hit flag (width 1: occi_keyset_sort) or records whose second word is any
 * value (width 2: occi_keyset_sort_records); equal, entry for entry (stable). */
static void check_sorts(const size_t width)
{
    static occ_code_t a[4u * MAX_N], ref[2u * MAX_N];
    static uint32_t hist[OCC_KS_HIST_WORDS];
    for (unsigned round = 0; round < 200u; round++) {
        const size_t n = draw_n(round), words = width * n;
        const unsigned shape = round % 4u;
        const occ_code_t base = rng_next() & KEY_BITS;
        for (size_t i = 0; i < n; i++) {
            a[width * i] = draw_key(shape, base) | (width == 1u ? (rng_next() & 1u) << 63 : 0u);
            if (width == 2u) {
                a[2u * i + 1u] = rng_next();
            }
        }
        memcpy(ref, a, words * sizeof a[0]);
        ref_sort(ref, n, width);
        const occ_code_t *const got = width == 1u
                                          ? occi_keyset_sort(a, a + words, n, hist)
                                          : occi_keyset_sort_records(a, a + words, n, hist);
        assert_true(got == a || got == a + words);
        assert_memory_equal(got, ref, words * sizeof a[0]);
    }
}

static void test_sort_codes(void **state)
{
    (void)state;
    check_sorts(1u);
}

static void test_sort_records(void **state)
{
    (void)state;
    check_sorts(2u);
}

static void test_unique(void **state)
{
    (void)state;
    static occ_code_t a[MAX_N], ref[MAX_N];
    static uint32_t hist[OCC_KS_HIST_WORDS];
    static occ_code_t tmp[MAX_N];
    for (unsigned round = 0; round < 100u; round++) {
        const size_t n = draw_n(round);
        const occ_code_t base = rng_next() & KEY_BITS;
        for (size_t i = 0; i < n; i++) {
            a[i] = draw_key(2u, base) | ((rng_next() & 1u) << 63);
        }
        memcpy(ref, a, n * sizeof a[0]);
        ref_sort(ref, n, 1u);
        size_t m = 0; /* brute force: one entry per key, flag the OR of its run's */
        for (size_t i = 0; i < n; i++) {
            if (m > 0u && ((ref[m - 1u] ^ ref[i]) & KEY_BITS) == 0u) {
                ref[m - 1u] |= ref[i];
            } else {
                ref[m++] = ref[i];
            }
        }
        occ_code_t *const s = occi_keyset_sort(a, tmp, n, hist);
        assert_int_equal(occi_keyset_unique(s, n), m);
        assert_memory_equal(s, ref, m * sizeof a[0]);
    }
}

int main(void)
{
    rng_seed("test_keyset");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sort_codes),
        cmocka_unit_test(test_sort_records),
        cmocka_unit_test(test_unique),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
