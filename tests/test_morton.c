/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_morton.c - Morton codes against a brute-force bit-by-bit interleave: edge values, single
 * bits, random keys and codes, round trips, and the octree properties the tree relies on.
 * Built twice: the portable path (this binary) and, with -DTEST_MORTON_BMI2, a second binary
 * that also holds the BMI2 build of morton.c (symbols renamed bmi2_*) and compares both paths.
 * Random seed: printed, overridable with OCC_SEED.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "occmap/occmap.h"
#include "core/tree_internal.h"
#include "support/seeded_rng.h"

#ifdef TEST_MORTON_BMI2
occ_code_t bmi2_occ_morton_encode(occ_key_t key);
occ_key_t bmi2_occ_morton_decode(occ_code_t code);
#endif

#define KEY_MASK 0x1FFFFFu
#define N_RANDOM 200000u

static int setup_seed(void **state)
{
    (void)state;
    rng_seed("test_morton");
    return 0;
}

static occ_code_t brute_encode(const occ_key_t k)
{
    occ_code_t c = 0;
    for (unsigned i = 0; i < 21u; i++) {
        for (unsigned a = 0; a < 3u; a++) {
            if ((k.k[a] >> i) & 1u) {
                c |= (occ_code_t)1 << (3u * i + a);
            }
        }
    }
    return c;
}

static occ_key_t brute_decode(const occ_code_t c)
{
    occ_key_t k = {{0u, 0u, 0u}};
    for (unsigned i = 0; i < 21u; i++) {
        for (unsigned a = 0; a < 3u; a++) {
            if ((c >> (3u * i + a)) & 1u) {
                k.k[a] |= 1u << i;
            }
        }
    }
    return k;
}

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

/* One key through every path: portable (and BMI2) encode equal brute force, decode inverts. */
static void check_key(const occ_key_t k)
{
    const occ_code_t want = brute_encode(k);
    const occ_code_t got = occ_morton_encode(k);
    if (got != want) {
        fail_msg("encode(%u,%u,%u) = 0x%016llx, brute force 0x%016llx", (unsigned)k.k[0],
                 (unsigned)k.k[1], (unsigned)k.k[2], (unsigned long long)got,
                 (unsigned long long)want);
    }
    const occ_key_t back = occ_morton_decode(got);
    assert_int_equal(back.k[0], k.k[0]);
    assert_int_equal(back.k[1], k.k[1]);
    assert_int_equal(back.k[2], k.k[2]);
    assert_true((got >> 63) == 0u);
#ifdef TEST_MORTON_BMI2
    const occ_code_t g2 = bmi2_occ_morton_encode(k);
    if (g2 != want) {
        fail_msg("bmi2 encode(%u,%u,%u) = 0x%016llx, brute force 0x%016llx", (unsigned)k.k[0],
                 (unsigned)k.k[1], (unsigned)k.k[2], (unsigned long long)g2,
                 (unsigned long long)want);
    }
    const occ_key_t b2 = bmi2_occ_morton_decode(got);
    assert_int_equal(b2.k[0], k.k[0]);
    assert_int_equal(b2.k[1], k.k[1]);
    assert_int_equal(b2.k[2], k.k[2]);
#endif
}

static void check_code(const occ_code_t c)
{
    const occ_key_t want = brute_decode(c);
    const occ_key_t got = occ_morton_decode(c);
    assert_int_equal(got.k[0], want.k[0]);
    assert_int_equal(got.k[1], want.k[1]);
    assert_int_equal(got.k[2], want.k[2]);
    assert_true(occ_morton_encode(got) == c);
#ifdef TEST_MORTON_BMI2
    const occ_key_t g2 = bmi2_occ_morton_decode(c);
    assert_int_equal(g2.k[0], want.k[0]);
    assert_int_equal(g2.k[1], want.k[1]);
    assert_int_equal(g2.k[2], want.k[2]);
    assert_true(bmi2_occ_morton_encode(got) == c);
#endif
}

static void test_edge_values(void **state)
{
    (void)state;
    check_key(mk(0, 0, 0));
    check_key(mk(KEY_MASK, KEY_MASK, KEY_MASK));
    check_key(mk(KEY_MASK, 0, 0));
    check_key(mk(0, KEY_MASK, 0));
    check_key(mk(0, 0, KEY_MASK));
    check_key(mk(0x155555u, 0x0AAAAAu, 0x1FFFFEu));
    assert_true(occ_morton_encode(mk(KEY_MASK, KEY_MASK, KEY_MASK)) == (((occ_code_t)1 << 63) - 1u));
    assert_true(occ_morton_encode(mk(0, 0, 0)) == 0u);
    /* The OctoMap centre key at depth 16 and its neighbours. */
    check_key(mk(32768u, 32768u, 32768u));
    check_key(mk(32767u, 32767u, 32767u));
    check_key(mk(65535u, 0u, 32768u));
    check_code(0u);
    check_code(((occ_code_t)1 << 63) - 1u);
    check_code(0x1249249249249249ull);
    check_code(0x2492492492492492ull);
    check_code(0x4924924924924924ull & (((occ_code_t)1 << 63) - 1u));
}

static void test_single_bits(void **state)
{
    (void)state;
    for (unsigned i = 0; i < 21u; i++) {
        const uint32_t b = 1u << i;
        check_key(mk(b, 0, 0));
        check_key(mk(0, b, 0));
        check_key(mk(0, 0, b));
        check_key(mk(b, b, b));
        check_key(mk(KEY_MASK ^ b, KEY_MASK, KEY_MASK ^ b));
        assert_true(occ_morton_encode(mk(b, 0, 0)) == (occ_code_t)1 << (3u * i));
        assert_true(occ_morton_encode(mk(0, b, 0)) == (occ_code_t)1 << (3u * i + 1u));
        assert_true(occ_morton_encode(mk(0, 0, b)) == (occ_code_t)1 << (3u * i + 2u));
    }
    for (unsigned j = 0; j < 63u; j++) {
        check_code((occ_code_t)1 << j);
        check_code((((occ_code_t)1 << 63) - 1u) ^ ((occ_code_t)1 << j));
    }
}

static void test_random(void **state)
{
    (void)state;
    for (unsigned i = 0; i < N_RANDOM; i++) {
        const uint64_t r = rng_next();
        const occ_key_t k = mk((uint32_t)r & KEY_MASK, (uint32_t)(r >> 21) & KEY_MASK,
                               (uint32_t)(r >> 42) & KEY_MASK);
        check_key(k);
        check_code(rng_next() & (((occ_code_t)1 << 63) - 1u));
    }
}

/* The properties the tree uses: child slot bits, and a node's voxels form one code range. */
static void test_octree_properties(void **state)
{
    (void)state;
    for (unsigned i = 0; i < 20000u; i++) {
        const uint64_t r = rng_next();
        const occ_key_t k = mk((uint32_t)r & KEY_MASK, (uint32_t)(r >> 21) & KEY_MASK,
                               (uint32_t)(r >> 42) & KEY_MASK);
        const occ_code_t c = occ_morton_encode(k);
        for (unsigned level = 1; level <= 21u; level++) {
            const unsigned want = ((k.k[0] >> (level - 1u)) & 1u) |
                                  (((k.k[1] >> (level - 1u)) & 1u) << 1) |
                                  (((k.k[2] >> (level - 1u)) & 1u) << 2);
            assert_int_equal(occ_code_slot(c, level), want);
        }
        for (unsigned level = 0; level <= 21u; level++) {
            const occ_code_t lowmask = level == 21u ? (((occ_code_t)1 << 63) - 1u)
                                                    : (((occ_code_t)1 << (3u * level)) - 1u);
            const occ_key_t first = occ_key_at_level(k, level);
            assert_true(occ_morton_encode(first) == (c & ~lowmask));
        }
    }
    /* Order: increasing codes visit the 8 children of a node in OctoMap's child order. */
    for (unsigned slot = 0; slot < 8u; slot++) {
        const occ_key_t k = mk(slot & 1u, (slot >> 1) & 1u, (slot >> 2) & 1u);
        assert_true(occ_morton_encode(k) == slot);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edge_values),
        cmocka_unit_test(test_single_bits),
        cmocka_unit_test(test_random),
        cmocka_unit_test(test_octree_properties),
    };
#ifdef TEST_MORTON_BMI2
    const char *const name = "morton_bmi2";
#else
    const char *const name = "morton";
#endif
    return cmocka_run_group_tests_name(name, tests, setup_seed, NULL);
}
