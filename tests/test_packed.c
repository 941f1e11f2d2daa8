/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_packed.c - block indices past 16 bits, and the 8-bit mode's packed inner block (24-bit
 * child indices, indicator bits one byte per flag; issue 22) with its pool cap of 2^24 - 1
 * blocks. Every build runs it (tests/foundation.mk adds the 8-bit one); the byte layout and the
 * cap's big arena are checked in the 8-bit mode only.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "core/tree_internal.h"

/* One voxel in each 4^3-voxel node of a 42^3 grid of them: 74088 leaf blocks and more inner
 * blocks (each level-2 node holds one voxel), so indices reach past 0xFFFF in both pools. */
#define GRID 42u
#define N_VOX (GRID * GRID * GRID)
#define BASE 32768u
static uint8_t arena[OCC_ARENA_BYTES(90000u, 76000u)];
static occ_map_t map;

static uint32_t hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7FEB352Du;
    x ^= x >> 15;
    x *= 0x846CA68Bu;
    return x ^ (x >> 16);
}

/* Voxel i: an offset inside its 4^3 node (so it sits in a different slot of its leaf block from
 * its neighbours) and a raw value in [-100, 100] (generation `gen` changes it). */
static occ_key_t vox_key(const uint32_t i)
{
    const uint32_t h = hash32(i);
    occ_key_t k;
    k.k[0] = BASE + 4u * (i % GRID) + (h & 3u);
    k.k[1] = BASE + 4u * (i / GRID % GRID) + ((h >> 2) & 3u);
    k.k[2] = BASE + 4u * (i / (GRID * GRID)) + ((h >> 4) & 3u);
    return k;
}

static float vox_logodds(const uint32_t i, const uint32_t gen)
{
    const int raw = (int)(hash32(i * 3u + gen) % 201u) - 100;
    return (float)raw / (float)OCC_FIXED_ONE;
}

static void set_range(const uint32_t from, const uint32_t to, const uint32_t gen)
{
    for (uint32_t i = from; i < to; i++) {
        assert_int_equal(occ_map_set_key(&map, vox_key(i), 0u, vox_logodds(i, gen)), OCC_OK);
    }
}

/* Every voxel reads its value, and its leaf-block neighbour (slot ^ 1) reads unobserved:
 * a child index with a byte dropped names another block, where neither holds. */
static void expect_voxels(const uint32_t n_live, const uint32_t gen_from, const uint32_t gen)
{
    for (uint32_t i = 0; i < N_VOX; i++) {
        occ_node_info_t info;
        const occ_key_t k = vox_key(i);
        assert_int_equal(occ_map_read_key(&map, k, 0u, &info), OCC_OK);
        if (i >= n_live) {
            assert_false(info.observed);
            continue;
        }
        const float want = vox_logodds(i, i >= gen_from ? gen : 0u);
        assert_true(info.observed);
        assert_int_equal(info.level, 0u);
        assert_int_equal(occ_value_from_logodds(info.logodds), occ_value_from_logodds(want));
        occ_key_t nb = k;
        nb.k[0] ^= 1u;
        assert_int_equal(occ_map_read_key(&map, nb, 0u, &info), OCC_OK);
        assert_false(info.observed);
    }
}

/* The level-1 node of voxel i: its child (a leaf block index) through the internal accessors. */
static uint32_t leaf_index_of(const uint32_t i)
{
    const occ_code_t code = occ_morton_encode(vox_key(i));
    occ_nodep_t n = occ_root(&map);
    for (unsigned l = map.cfg.depth_levels; l > 1u; l--) {
        assert_true(occ_node_child(n) != OCC_NONE);
        n = occ_inner_node(&map, occ_node_child(n), occ_code_slot(code, l));
    }
    return occ_node_child(n);
}

static int setup_map(void **state)
{
    (void)state;
    const occ_map_config_t cfg = occ_map_config_default();
    return occ_map_init(&map, &cfg, arena, sizeof arena) == OCC_OK ? 0 : -1;
}

/* (leak_check.h's release is quadratic in leaf blocks under OCC_POOL_PARANOID: too slow here.) */
static int teardown_map(void **state)
{
    (void)state;
    const int ok = occ_map_check(&map) == OCC_OK;
    occ_map_clear(&map);
    return ok && map.inner.used == 0u && map.leaf.used == 0u ? 0 : -1;
}

static void test_indices_past_16_bits(void **state)
{
    (void)state;
    set_range(0u, N_VOX, 0u);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    assert_true(map.leaf.hwm > 0x10000u && map.inner.hwm > 0x10000u);
    assert_true(leaf_index_of(N_VOX - 1u) > 0xFFFFu);
    expect_voxels(N_VOX, N_VOX, 0u);
}

/* The last voxels' blocks (the highest indices) go to the free lists and come back: the lists'
 * links past 16 bits, and no block handed out twice. */
static void test_free_lists_past_16_bits(void **state)
{
    (void)state;
    const uint32_t keep = N_VOX - 1500u;
    set_range(0u, N_VOX, 0u);
    const uint32_t inner_hwm = map.inner.hwm, leaf_hwm = map.leaf.hwm;
    for (uint32_t i = keep; i < N_VOX; i++) {
        assert_int_equal(occ_map_forget_key(&map, vox_key(i), 0u), OCC_OK);
    }
    assert_int_equal(occ_map_check(&map), OCC_OK);
    assert_true(map.leaf.free_count >= 1500u && map.inner.free_count >= 1500u);
    assert_true(map.leaf.priv.free_head > 0xFFFFu && map.inner.priv.free_head > 0xFFFFu);
    expect_voxels(keep, N_VOX, 0u);
    set_range(keep, N_VOX, 1u);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    assert_int_equal(map.inner.hwm, inner_hwm);
    assert_int_equal(map.leaf.hwm, leaf_hwm);
    expect_voxels(N_VOX, keep, 1u);
}

/* Each slot's child and flags read back what was stored, whatever the neighbours hold; in the
 * 8-bit mode at the bytes the layout says. */
static void test_block_accessors(void **state)
{
    (void)state;
    static const uint32_t kids[8] = {0u,        0xFFFFFEu, OCC_NONE, 0x123456u,
                                     0x00FF00u, 0xFF00FFu, 0x10000u, 0xFFFFu};
    occ_inner_block_t b;
    memset(&b, 0x5A, sizeof b);
    for (unsigned s = 0; s < 8u; s++) {
        occ_inner_set_child(&b, s, kids[s]);
        occ_inner_set_flags(&b, s, (uint8_t)(s % 7u + 1u));
    }
    for (unsigned s = 0; s < 8u; s++) {
        assert_int_equal(occ_inner_child(&b, s), kids[s]);
        assert_int_equal(occ_inner_flags(&b, s), s % 7u + 1u);
    }
    occ_inner_set_flags(&b, 4u, (uint8_t)OCC_NODE_HAS_FREE);
    assert_int_equal(occ_inner_flags(&b, 3u), 4u);
    assert_int_equal(occ_inner_flags(&b, 4u), OCC_NODE_HAS_FREE);
    assert_int_equal(occ_inner_flags(&b, 5u), 6u);
    assert_false(occ_inner_is_free(&b));
    occ_inner_mark_free(&b);
    assert_true(occ_inner_is_free(&b));
#if OCC_INNER_PACKED
    assert_int_equal(b.child[6], 0xFFu); /* OCC_NONE is stored as 0xFFFFFF */
    assert_int_equal(b.child[3u * 3u + 2u], 0x12u); /* little-endian, third byte last */
    assert_int_equal(b.flags[0], 0u); /* the free mark: no indicator bit at all */
    assert_int_equal(b.flags[1] | b.flags[2], 0u);
#endif
}

/* No pool is sized past OCC_POOL_MAX_BLOCKS. In the 8-bit mode an arena beyond 2^24 - 1 leaf
 * blocks is used up to that many (init only sizes it, so the memory stays untouched but for
 * the last block) and the last index handed out is 0xFFFFFE. */
static void test_pool_cap(void **state)
{
    (void)state;
    const size_t most = (SIZE_MAX - OCC_ARENA_ALIGN) / OCC_LEAF_BLOCK_BYTES;
    assert_int_equal(occ_arena_blocks_for_bytes(SIZE_MAX, 0u),
                     most < OCC_POOL_MAX_BLOCKS ? most : OCC_POOL_MAX_BLOCKS);
#if OCC_INNER_PACKED
    const size_t cap = (size_t)OCC_POOL_MAX_BLOCKS * OCC_LEAF_BLOCK_BYTES;
    assert_int_equal(occ_arena_blocks_for_bytes(cap + 4096u, 0u), OCC_POOL_MAX_BLOCKS);
    assert_int_equal(occ_arena_blocks_for_bytes(cap + 4096u, 1000u),
                     OCC_POOL_MAX_BLOCKS - (1000u * OCC_INNER_BLOCK_BYTES + 7u) / 8u);
    uint8_t *const big = malloc(cap + 4096u);
    assert_non_null(big);
    occ_map_t m;
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(&m, &cfg, big, cap + 4096u), OCC_OK);
    assert_int_equal(m.arena_bytes, cap);
    occ_map_stats_t st;
    occ_map_pool_stats(&m, &st);
    assert_int_equal(st.leaf_capacity, OCC_POOL_MAX_BLOCKS);
    assert_true(st.inner_capacity < OCC_POOL_MAX_BLOCKS);
    /* All but one leaf block carved (by hand: filling 2^24 blocks would take long). */
    m.leaf.hwm = OCC_POOL_MAX_BLOCKS - 1u;
    m.leaf.used = m.leaf.hwm;
    const uint32_t last = occi_pool_alloc_leaf(&m);
    assert_int_equal(last, 0xFFFFFEu);
    assert_int_equal(occi_pool_alloc_leaf(&m), OCC_NONE);
    assert_false(occi_pool_can_supply(&m, 0u, 1u));
    occ_nodep_t root = occ_root(&m);
    occ_node_set_child(root, last);
    assert_int_equal(occ_root_child(&m), 0xFFFFFEu);
    occ_node_set_child(root, OCC_NONE);
    assert_int_equal(occ_root_child(&m), OCC_NONE);
    free(big);
#endif
}

int main(void)
{
#define T(f) cmocka_unit_test_setup_teardown(f, setup_map, teardown_map)
    const struct CMUnitTest tests[] = {
        T(test_indices_past_16_bits),
        T(test_free_lists_past_16_bits),
        cmocka_unit_test(test_block_accessors),
        cmocka_unit_test(test_pool_cap),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
