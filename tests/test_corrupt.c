/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_corrupt.c - damage the pools and the tree on purpose (through tree_internal.h) and prove
 * occ_map_check() returns OCC_ERR_CORRUPT for each kind of damage, OCC_OK on the undamaged map,
 * and OCC_OK again once the damage is undone.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "occmap/occmap.h"
#include "core/tree_internal.h"
#include "support/leak_check.h"

#define ARENA_SIZE OCC_ARENA_BYTES(64, 64)
/* Indices past every pool that a child field can still hold (24 bits in the 8-bit mode). */
#if OCC_INNER_PACKED
#define BAD_LINK 0x7FFFFFu
#define BAD_INDEX 0xFFFFFEu
#else
#define BAD_LINK 0x7FFFFFFFu
#define BAD_INDEX (OCC_NONE - 1u)
#endif
static uint8_t arena[ARENA_SIZE];
static uint8_t arena_copy[ARENA_SIZE];
static occ_map_t map;
static occ_map_t map_copy;

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

/* Depth 4 (16^3 voxels): voxels in a leaf block, a pruned level-2 FREE node, a pruned level-1
 * OCCUPIED node, and at least two free blocks on each free list. */
static int setup_map(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 4u;
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) {
        return -1;
    }
    const occ_key_t hits[] = {mk(0, 0, 0), mk(1, 0, 0), mk(0, 1, 0), mk(15, 15, 15), mk(12, 0, 12),
                              mk(4, 12, 0)};
    for (size_t i = 0; i < sizeof hits / sizeof hits[0]; i++) {
        if (occ_map_observe_key(&map, hits[i], true) != OCC_OK) {
            return -1;
        }
    }
    if (occ_map_observe_key(&map, mk(1, 1, 1), false) != OCC_OK ||
        occ_map_set_key(&map, mk(8, 8, 8), 2u, -1.0f) != OCC_OK ||
        occ_map_set_key(&map, mk(0, 8, 0), 1u, 2.0f) != OCC_OK ||
        occ_map_forget_key(&map, mk(15, 15, 15), 0u) != OCC_OK ||
        occ_map_forget_key(&map, mk(12, 0, 12), 0u) != OCC_OK ||
        occ_map_forget_key(&map, mk(4, 12, 0), 1u) != OCC_OK) {
        return -1;
    }
    if (map.inner.free_count < 2u || map.leaf.free_count < 2u || occ_map_check(&map) != OCC_OK) {
        fprintf(stderr, "setup: free lists %u/%u, check %d\n", (unsigned)map.inner.free_count,
                (unsigned)map.leaf.free_count, (int)occ_map_check(&map));
        return -1;
    }
    memcpy(&map_copy, &map, sizeof map);
    memcpy(arena_copy, arena, sizeof arena);
    return 0;
}

static int teardown_map(void **state)
{
    (void)state;
    return leak_check(&map);
}

static void restore(void)
{
    memcpy(&map, &map_copy, sizeof map);
    memcpy(arena, arena_copy, sizeof arena);
}

/* The check says CORRUPT now, and OK once the damage is undone. */
static void expect_corrupt(const char *what)
{
    const occ_err_t e = occ_map_check(&map);
    if (e != OCC_ERR_CORRUPT) {
        fail_msg("damage not detected: %s (check returned %d)", what, (int)e);
    }
    restore();
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* The node at `level` >= 1 containing `key` (must exist: every ancestor has children). */
static occ_nodep_t node_at(const occ_key_t key, const unsigned level)
{
    occ_nodep_t n = occ_root(&map);
    const occ_code_t code = occ_morton_encode(key);
    for (unsigned l = map.cfg.depth_levels; l > level; l--) {
        assert_true(occ_node_child(n) != OCC_NONE);
        n = occ_inner_node(&map, occ_node_child(n), occ_code_slot(code, l));
    }
    return n;
}

static uint32_t leaf_next(uint32_t idx)
{
    uint32_t next;
    memcpy(&next, occ_leaf_at(&map, idx)->value, sizeof next);
    return next;
}

static void test_undamaged(void **state)
{
    (void)state;
    assert_int_equal(occ_map_check(&map), OCC_OK);
    /* The fixture has what the damage cases need. */
    assert_true(occ_node_child(node_at(mk(0, 0, 0), 1u)) != OCC_NONE);
    assert_true(occ_node_child(node_at(mk(8, 8, 8), 2u)) == OCC_NONE);
    assert_true(occ_node_child(node_at(mk(0, 8, 0), 1u)) == OCC_NONE);
    occ_node_info_t info;
    assert_int_equal(occ_map_read_key(&map, mk(9, 9, 9), 0u, &info), OCC_OK);
    assert_int_equal(info.state, OCC_STATE_FREE);
    assert_int_equal(info.level, 2u);
}

static void test_free_list_cycles(void **state)
{
    (void)state;
    /* Inner: the last free block points back to the head. */
    uint32_t i = map.inner.priv.free_head, last = i;
    while (i != OCC_NONE) {
        last = i;
        i = occ_inner_child(occ_inner_at(&map, i), 0);
    }
    occ_inner_set_child(occ_inner_at(&map, last), 0, map.inner.priv.free_head);
    expect_corrupt("inner free-list cycle (tail -> head)");
    occ_inner_set_child(occ_inner_at(&map, map.inner.priv.free_head), 0, map.inner.priv.free_head);
    expect_corrupt("inner free-list self loop");
    /* Leaf: the same. */
    i = map.leaf.priv.free_head;
    last = i;
    while (i != OCC_NONE) {
        last = i;
        i = leaf_next(i);
    }
    memcpy(occ_leaf_at(&map, last)->value, &map.leaf.priv.free_head, sizeof(uint32_t));
    expect_corrupt("leaf free-list cycle (tail -> head)");
    const uint32_t h = map.leaf.priv.free_head;
    memcpy(occ_leaf_at(&map, h)->value, &h, sizeof h);
    expect_corrupt("leaf free-list self loop");
}

static void test_free_list_foreign(void **state)
{
    (void)state;
    map.inner.priv.free_head = map.inner.hwm + 3u;
    expect_corrupt("inner free head beyond the high-water mark");
    map.leaf.priv.free_head = map.leaf.hwm;
    expect_corrupt("leaf free head at the high-water mark");
    occ_inner_set_child(occ_inner_at(&map, map.inner.priv.free_head), 0, BAD_LINK);
    expect_corrupt("inner free-list link to a foreign index");
    const uint32_t bad = map.leaf.hwm + 1u;
    memcpy(occ_leaf_at(&map, map.leaf.priv.free_head)->value, &bad, sizeof bad);
    expect_corrupt("leaf free-list link to a foreign index");
    /* The inner free mark cleared on a free block (looks used). */
    occ_inner_mark_used(occ_inner_at(&map, map.inner.priv.free_head));
    expect_corrupt("inner free block without its free mark");
}

static void test_counters(void **state)
{
    (void)state;
    map.inner.used++;
    expect_corrupt("inner used + 1");
    map.leaf.used--;
    expect_corrupt("leaf used - 1");
    map.inner.free_count--;
    expect_corrupt("inner free_count - 1");
    map.leaf.free_count++;
    expect_corrupt("leaf free_count + 1");
    map.inner.hwm++;
    expect_corrupt("inner hwm + 1");
    map.leaf.hwm--;
    expect_corrupt("leaf hwm - 1");
    map.leaf.peak = map.leaf.used - 1u;
    expect_corrupt("leaf peak below used");
    map.inner.hwm = (uint32_t)(map.arena_bytes / OCC_INNER_BLOCK_BYTES) + 1u;
    map.inner.used = map.inner.hwm - map.inner.free_count;
    map.inner.peak = map.inner.used;
    expect_corrupt("pools larger than the arena");
    /* used and free_count moved together (sum still equals hwm). */
    map.leaf.used++;
    map.leaf.free_count--;
    expect_corrupt("leaf used/free_count shifted together");
}

/* The auditor must survive any bytes (OCC_ASSERT is live in this build: an index or depth it
 * followed unchecked would fail the test instead of returning CORRUPT). */
static void test_depth_out_of_range(void **state)
{
    (void)state;
    static const uint8_t bad[] = {0u, OCC_MAX_DEPTH + 1u, 0xFFu};
    for (size_t i = 0; i < sizeof bad; i++) {
        map.cfg.depth_levels = bad[i];
        expect_corrupt("depth_levels outside 1..21");
    }
    map.cfg.depth_levels = 3u; /* valid, but one less than the tree's: levels run out */
    expect_corrupt("depth_levels one below the tree's");
    map.cfg.depth_levels = 5u;
    expect_corrupt("depth_levels one above the tree's");
}

static void test_leaked_block(void **state)
{
    (void)state;
    /* Taken from the pool, never linked. */
    (void)occi_pool_alloc_leaf(&map);
    expect_corrupt("leaked leaf block (from the free list)");
    (void)occi_pool_alloc_inner(&map);
    expect_corrupt("leaked inner block (from the free list)");
    map.leaf.priv.free_head = OCC_NONE;
    map.leaf.free_count = 0u;
    map.leaf.hwm++; /* one more block carved (by hand: the allocator asserts on these counters) */
    map.leaf.used = map.leaf.hwm - 0u; /* consistent counters, unreachable blocks */
    map.leaf.peak = map.leaf.used;
    expect_corrupt("free list dropped: blocks neither used nor free");
    /* A subtree unlinked: the node claims no children but the block is still counted used. */
    const occ_nodep_t n = node_at(mk(0, 0, 0), 1u);
    occ_node_set_child(n, OCC_NONE);
    expect_corrupt("child link cut, block leaked");
}

static void test_wrong_values(void **state)
{
    (void)state;
    occ_nodep_t n = node_at(mk(0, 0, 0), 1u);
    (*n.value)++;
    expect_corrupt("inner max one step too high");
    n = node_at(mk(0, 0, 0), 2u);
    (*n.value)--;
    expect_corrupt("level-2 max one step too low");
    map.priv.root_value = (occ_value_t)(map.priv.root_value - 100);
    expect_corrupt("root max wrong");
    /* A voxel raised above its parent's max. */
    n = node_at(mk(0, 0, 0), 1u);
    occ_leaf_at(&map, occ_node_child(n))->value[1] = (occ_value_t)(*n.value + 1);
    expect_corrupt("voxel above its parent's max");
    /* A pruned node's value changed: its parent's max or flags no longer agree. */
    n = node_at(mk(0, 8, 0), 1u);
    *n.value = (occ_value_t)(*n.value + 50);
    expect_corrupt("pruned node value above the parent's max");
}

static void test_wrong_indicators(void **state)
{
    (void)state;
    static const uint8_t bits[] = {OCC_NODE_HAS_FREE, OCC_NODE_HAS_UNKNOWN, OCC_NODE_HAS_OCCUPIED};
    for (size_t b = 0; b < sizeof bits; b++) {
        occ_nodep_t n = node_at(mk(0, 0, 0), 1u);
        occ_node_set_flags(n, (uint8_t)(occ_node_flags(n) ^ bits[b]));
        expect_corrupt("level-1 indicator flipped");
        n = node_at(mk(8, 8, 8), 3u);
        occ_node_set_flags(n, (uint8_t)(occ_node_flags(n) ^ bits[b]));
        expect_corrupt("level-3 indicator flipped");
        n = node_at(mk(8, 8, 8), 2u); /* pruned: flags follow from the value */
        occ_node_set_flags(n, (uint8_t)(occ_node_flags(n) ^ bits[b]));
        expect_corrupt("pruned node indicator flipped");
        occ_root_set_flags(&map, (uint8_t)(occ_root_flags(&map) ^ bits[b]));
        expect_corrupt("root indicator flipped");
    }
}

static void test_unpruned_equal_block(void **state)
{
    (void)state;
    /* Expand a uniform node without refreshing: 8 equal children that should have been pruned. */
    occ_nodep_t n = node_at(mk(8, 8, 8), 2u);
    assert_true(occi_pool_can_supply(&map, 1u, 0u));
    occi_tree_expand(&map, n, 2u);
    expect_corrupt("level-2 node expanded into 8 equal uniform children");
    n = node_at(mk(0, 8, 0), 1u);
    occi_tree_expand(&map, n, 1u);
    expect_corrupt("level-1 node expanded into a leaf block of 8 equal voxels");
    /* Make a real leaf block all equal by hand. */
    n = node_at(mk(0, 0, 0), 1u);
    occ_leaf_block_t *const b = occ_leaf_at(&map, occ_node_child(n));
    for (unsigned i = 0; i < 8u; i++) {
        b->value[i] = b->value[0];
    }
    *n.value = b->value[0];
    occ_node_set_flags(n, occ_value_flags(&map, b->value[0]));
    expect_corrupt("leaf block of 8 equal voxels left unpruned");
}

static void test_child_index_out_of_range(void **state)
{
    (void)state;
    occ_nodep_t n = node_at(mk(0, 0, 0), 1u);
    occ_node_set_child(n, map.leaf.hwm);
    expect_corrupt("leaf child index == leaf hwm");
    n = node_at(mk(0, 0, 0), 1u);
    occ_node_set_child(n, BAD_INDEX);
    expect_corrupt("leaf child index just below OCC_NONE");
    n = node_at(mk(0, 0, 0), 2u);
    occ_node_set_child(n, map.inner.hwm + 5u);
    expect_corrupt("inner child index beyond inner hwm");
    occ_root_set_child(&map, map.inner.hwm);
    expect_corrupt("root child index == inner hwm");
    /* A child index that names a block on the free list. */
    n = node_at(mk(0, 0, 0), 2u);
    occ_node_set_child(n, map.inner.priv.free_head);
    expect_corrupt("child index of a free inner block");
}

static void test_shared_and_freed_blocks(void **state)
{
    (void)state;
    /* Two nodes own the same leaf block (the other's block leaks). */
    const occ_nodep_t a = node_at(mk(0, 0, 0), 1u);
    const occ_nodep_t p = node_at(mk(0, 0, 0), 2u);
    (void)p;
    const occ_nodep_t b = node_at(mk(0, 8, 0), 1u); /* pruned: no block of its own */
    occ_node_set_child(b, occ_node_child(a));
    *b.value = *a.value;
    occ_node_set_flags(b, occ_node_flags(a));
    expect_corrupt("leaf block owned by two nodes");
    /* A block in the tree and on the free list (freed while still linked). */
    assert_true(occi_pool_free_leaf(&map, occ_node_child(node_at(mk(0, 0, 0), 1u))));
    expect_corrupt("linked leaf block on the free list");
    assert_true(occi_pool_free_inner(&map, occ_node_child(node_at(mk(0, 0, 0), 2u))));
    expect_corrupt("linked inner block on the free list");
}

int main(void)
{
#define T(f) cmocka_unit_test_setup_teardown(f, setup_map, teardown_map)
    const struct CMUnitTest tests[] = {
        T(test_undamaged),          T(test_free_list_cycles),        T(test_free_list_foreign),
        T(test_counters),           T(test_depth_out_of_range),      T(test_leaked_block),            T(test_wrong_values),
        T(test_wrong_indicators),   T(test_unpruned_equal_block),    T(test_child_index_out_of_range),
        T(test_shared_and_freed_blocks),
    };
#undef T
    return cmocka_run_group_tests_name("corrupt", tests, NULL, NULL);
}
