/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_tree_dense.c - occi_tree_apply_dense (src/core/tree_dense.c, the integrator's update by
 * 4x4x4 bricks) against occ_map_observe_codes on the same set's codes: the same tree node for
 * node (a walk digest of keys, levels, values and indicators), the same pool use, counts and
 * changed voxels. The maps start from random content (whole nodes set at levels 0..6, values
 * from clamp to clamp, observed voxels) and take random sets round after round until values
 * saturate: whole bricks, whole bytes (level-1 nodes), sparse voxels, hits inside and outside the
 * listed chunks. Also: pools too small for the bound give OCC_ERR_NOMEM with the map unchanged.
 * Random seed: printed, overridable with OCC_SEED.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "occmap/occmap.h"
#include "core/tree_internal.h"
#include "support/integrate_fixture.h"
#include "support/test_rng.h"

#define ARENA_BYTES OCC_ARENA_BYTES(200000, 200000)
#define CHUNKS 6u
#define HITS 300u

static uint8_t arena_a[ARENA_BYTES], arena_b[ARENA_BYTES];
static uint64_t words[CHUNKS * 512u];
static uint64_t chunk_codes[CHUNKS], slots[CHUNKS];
static occ_code_t hits[HITS], codes[CHUNKS * 512u * 64u + HITS];

/* A chunk code near the map's centre (keys 32768 +- a few chunks). */
static uint64_t near_chunk(void)
{
    const occ_key_t k = {{1024u + (uint32_t)(rnd() % 4u), 1024u + (uint32_t)(rnd() % 4u),
                          1023u + (uint32_t)(rnd() % 3u)}};
    return occ_morton_encode(k);
}

/* One brick's mask: empty, whole, whole bytes, or sparse. */
static uint64_t brick_mask(void)
{
    switch (rnd() % 6u) {
    case 0:
    case 1:
        return 0u;
    case 2:
        return ~(uint64_t)0;
    case 3: {
        uint64_t m = 0;
        for (unsigned j = 0; j < 8u; j++) {
            m |= rnd() % 2u ? (uint64_t)0xFF << (8u * j) : 0u;
        }
        return m;
    }
    default:
        return rnd() & rnd() & rnd();
    }
}

static int cmp_code(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a & ~OCC_CODE_HIT_BIT;
    const occ_code_t y = *(const occ_code_t *)b & ~OCC_CODE_HIT_BIT;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* A random set: distinct sorted chunks with shuffled slots, and sorted unique hits. */
static void random_set(occi_dense_t *const d)
{
    size_t n = 0;
    const size_t want_chunks = 1u + rnd_below(CHUNKS);
    for (unsigned i = 0; i < CHUNKS && n < want_chunks; i++) {
        const uint64_t c = near_chunk();
        bool dup = false;
        for (size_t j = 0; j < n; j++) {
            dup = dup || chunk_codes[j] == c;
        }
        if (!dup) {
            chunk_codes[n++] = c;
        }
    }
    qsort(chunk_codes, n, sizeof chunk_codes[0], cmp_code);
    for (size_t i = 0; i < n; i++) {
        slots[i] = (n - 1u - i + 2u) % n; /* any permutation */
    }
    const bool sparse = rnd() % 3u == 0u;
    for (size_t i = 0; i < n * 512u; i++) {
        words[i] = sparse && rnd() % 8u != 0u ? 0u : brick_mask();
    }
    size_t nh = 0;
    const size_t want = rnd_below(HITS);
    for (size_t i = 0; i < want; i++) {
        const uint64_t c = rnd() % 4u == 0u ? near_chunk() : chunk_codes[rnd_below((unsigned)n)];
        hits[nh++] = ((c << 15) | (rnd() & 0x7FFFu)) | OCC_CODE_HIT_BIT;
    }
    qsort(hits, nh, sizeof hits[0], cmp_code);
    size_t u = 0;
    for (size_t i = 0; i < nh; i++) {
        if (u == 0u || ((hits[i] ^ hits[u - 1u]) & ~OCC_CODE_HIT_BIT) != 0u) {
            hits[u++] = hits[i];
        }
    }
    d->words = words;
    d->chunks = chunk_codes;
    d->slots = slots;
    d->n_chunks = n;
    d->hits = hits;
    d->n_hits = u;
}

/* The same random content in both maps: whole nodes at levels 0..6 and single voxels. */
static void random_content(occ_map_t *const a, occ_map_t *const b)
{
    const unsigned nodes = (unsigned)(rnd() % 40u);
    for (unsigned i = 0; i < nodes; i++) {
        const unsigned level = (unsigned)(rnd() % 7u);
        const occ_key_t k = {{32768u + (uint32_t)(rnd() % 128u), 32768u + (uint32_t)(rnd() % 128u),
                              32736u + (uint32_t)(rnd() % 96u)}};
        const float lo = (float)((int)(rnd() % 13u) - 4) * 0.5f; /* -2 .. 4, past both clamps */
        assert_int_equal(occ_map_set_key(a, k, level, lo), OCC_OK);
        assert_int_equal(occ_map_set_key(b, k, level, lo), OCC_OK);
    }
}

static void one_round(occ_map_t *const a, occ_map_t *const b)
{
    occi_dense_t d;
    random_set(&d);
    occi_dense_out_t o;
    assert_int_equal(occi_tree_apply_dense(a, &d, &o), OCC_OK);
    occi_dense_cursor_t cur = {0u, 0u, 0u};
    const size_t cap = sizeof codes / sizeof codes[0];
    const size_t n = occi_dense_read(&d, &cur, codes, cap);
    assert_true(n + 64u <= cap); /* all of the set in one piece, room to spare */
    assert_int_equal(occi_dense_read(&d, &cur, codes + n, cap - n), 0);
    size_t changed = 0;
    assert_int_equal(occ_map_observe_codes(b, codes, n, &changed), OCC_OK);
    assert_int_equal(o.voxels, n);
    assert_int_equal(o.changed, changed);
    size_t na, nb;
    assert_true(it_map_digest(a, &na) == it_map_digest(b, &nb));
    assert_int_equal(na, nb);
    assert_int_equal(a->inner.used, b->inner.used);
    assert_int_equal(a->leaf.used, b->leaf.used);
    assert_int_equal(occ_map_check(a), OCC_OK);
}

static void test_against_codes(void **state)
{
    (void)state;
    occ_map_t a, b;
    size_t rounds = 0;
    for (unsigned map_i = 0; map_i < 30u; map_i++) {
        const float res = map_i % 2u ? 0.1f : 0.05f;
        it_init_map(&a, arena_a, sizeof arena_a, res);
        it_init_map(&b, arena_b, sizeof arena_b, res);
        random_content(&a, &b);
        for (unsigned r = 0; r < 12u; r++, rounds++) {
            one_round(&a, &b);
        }
    }
    printf("  %zu rounds on 30 maps: equal trees\n", rounds);
}

/* Pools below the bound: OCC_ERR_NOMEM, nothing written, oom_count unchanged. */
static void test_nomem_unchanged(void **state)
{
    (void)state;
    static uint8_t small[OCC_ARENA_BYTES(40, 40)];
    occ_map_t m;
    it_init_map(&m, small, sizeof small, 0.1f);
    occi_dense_t d;
    random_set(&d);
    for (size_t i = 0; i < 512u; i++) {
        words[i] = ~(uint64_t)0 >> (i % 64u); /* many level-1 nodes */
    }
    size_t n0, n1;
    const uint64_t d0 = it_map_digest(&m, &n0);
    const uint64_t gen = m.write_gen;
    occi_dense_out_t o;
    assert_int_equal(occi_tree_apply_dense(&m, &d, &o), OCC_ERR_NOMEM);
    assert_true(it_map_digest(&m, &n1) == d0);
    assert_int_equal(n0, n1);
    assert_int_equal(m.oom_count, 0);
    assert_true(m.write_gen == gen);
}

static int setup_seed(void **state)
{
    (void)state;
    const char *const env = getenv("OCC_SEED");
    rng_state = env != NULL ? strtoull(env, NULL, 0) : (uint64_t)time(NULL);
    printf("test_tree_dense: seed %llu (set OCC_SEED to repeat)\n", (unsigned long long)rng_state);
    rng_state = rng_state * 2654435761u + 1u;
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_against_codes, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_nomem_unchanged, it_timer_setup, it_timer_teardown),
    };
    return cmocka_run_group_tests(tests, setup_seed, NULL);
}
