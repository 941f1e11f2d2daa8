/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_asserts.c - OCC_ASSERT is live in the test build of the core (ASAN_CFLAGS maps it to
 * CMocka's mock_assert through tests/support/occ_test_config.h). Each test damages a small map
 * (through tree_internal.h) the way a core bug would, then proves that the path which trusts the
 * map stops at the broken invariant (expect_assert_failure) before it dereferences a block out of
 * the arena: read paths (state_at, read_key, the lookup cursor, castRay's cursor, the walk), a
 * write path, the pools' allocator, stack bounds (release, the file readers' tree builder),
 * level and slot ranges. The auditor, occ_map_check(), must instead report the same damage as
 * OCC_ERR_CORRUPT without asserting. That ordinary use fires no assert is the rest of the suite,
 * which runs on the same build.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "occmap/occmap.h"
#include "core/tree_internal.h"
#include "io/io_internal.h"

/* expect_assert_failure(call), and the assert that fired is the one named (its expression as
 * written in src/): another assert on the way would mean the path broke somewhere else first. */
#define expect_assert_on(call, expr)                                                               \
    do {                                                                                           \
        global_last_failed_assert = NULL;                                                          \
        expect_assert_failure(call);                                                               \
        assert_non_null(global_last_failed_assert);                                                \
        assert_string_equal(global_last_failed_assert, expr);                                      \
    } while (0)

#define DEPTH 4u
#define HALF 8 /* 2^(DEPTH-1): key of the voxel at x = 0 */
#define RES 0.1f

static uint8_t arena[OCC_ARENA_BYTES(64, 64)];
static occ_map_t map;

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

/* Centre (metres) of voxel key k: the point a read of that voxel uses. */
static occ_vec3_t centre(const occ_key_t k)
{
    occ_vec3_t p;
    p.x = ((float)((int)k.k[0] - HALF) + 0.5f) * RES;
    p.y = ((float)((int)k.k[1] - HALF) + 0.5f) * RES;
    p.z = ((float)((int)k.k[2] - HALF) + 0.5f) * RES;
    return p;
}

/* Depth 4: occupied voxels at (0,0,0) and (1,0,0) (a leaf block under a level-1 node), a free
 * voxel at (1,1,1), a far occupied voxel (15,15,15), and one freed leaf block and one freed inner
 * block on the free lists. */
static int setup_map(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = RES;
    cfg.depth_levels = (uint8_t)DEPTH;
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) {
        return -1;
    }
    const occ_key_t hits[] = {mk(0, 0, 0), mk(1, 0, 0), mk(15, 15, 15), mk(12, 0, 12)};
    for (size_t i = 0; i < sizeof hits / sizeof hits[0]; i++) {
        if (occ_map_observe_key(&map, hits[i], true) != OCC_OK) {
            return -1;
        }
    }
    if (occ_map_observe_key(&map, mk(1, 1, 1), false) != OCC_OK ||
        occ_map_forget_key(&map, mk(12, 0, 12), 0u) != OCC_OK) {
        return -1;
    }
    return map.inner.free_count >= 1u && map.leaf.free_count >= 1u &&
                   occ_map_check(&map) == OCC_OK
               ? 0
               : -1;
}

static int teardown_map(void **state)
{
    (void)state;
    occ_map_clear(&map); /* the damaged map is dropped whole */
    return 0;
}

/* The node at `level` >= 1 containing `key` (every ancestor has children in the fixture). */
static occ_nodep_t node_at(const occ_key_t key, const unsigned level)
{
    occ_nodep_t n = occ_root(&map);
    const occ_code_t code = occ_morton_encode(key);
    for (unsigned l = map.cfg.depth_levels; l > level; l--) {
        assert_true(*n.child != OCC_NONE);
        n = occ_inner_node(&map, *n.child, occ_code_slot(code, l));
    }
    return n;
}

/* Damage: the level-1 node above voxel (0,0,0) names a leaf block beyond the high-water mark
 * (a block that was never carved: the bytes there are the inner pool's or outside the arena). */
static void damage_leaf_child(void)
{
    const occ_nodep_t n = node_at(mk(0, 0, 0), 1u);
    assert_true(*n.child != OCC_NONE);
    *n.child = map.leaf.hwm + 3u;
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT); /* the auditor: an error, no assert */
}

/* Damage: the level-2 node above (0,0,0) names an inner block at the high-water mark. */
static void damage_inner_child(void)
{
    const occ_nodep_t n = node_at(mk(0, 0, 0), 2u);
    assert_true(*n.child != OCC_NONE);
    *n.child = map.inner.hwm;
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
}

static void walk_all(void)
{
    occ_walk_t w;
    occ_walk_node_t node;
    occ_walk_begin(&w, &map);
    while (occ_walk_next(&w, &node)) {
    }
}

static void test_undamaged_paths_fire_nothing(void **state)
{
    (void)state;
    /* The same calls as below on the intact map: they run to the end (an assert would fail). */
    assert_int_equal(occ_map_state_at(&map, centre(mk(0, 0, 0))), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_state_at(&map, centre(mk(1, 1, 1))), OCC_STATE_FREE);
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    assert_int_equal(occ_lookup_state(&lk, centre(mk(1, 1, 1))), OCC_STATE_FREE);
    assert_int_equal(occ_lookup_state(&lk, centre(mk(0, 0, 0))), OCC_STATE_OCCUPIED);
    occ_ray_result_t ray;
    const occ_vec3_t plus_x = {1.0f, 0.0f, 0.0f};
    assert_int_equal(occ_cast_ray(&map, centre(mk(0, 0, 0)), plus_x, true, 0.0f, &ray), OCC_OK);
    assert_true(ray.hit);
    walk_all();
    assert_int_equal(occ_map_update_key(&map, mk(0, 0, 0), -0.4f), OCC_OK);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static void test_read_state_at_leaf_beyond_hwm(void **state)
{
    (void)state;
    damage_leaf_child();
    expect_assert_on(occ_map_state_at(&map, centre(mk(0, 0, 0))), "idx < m->leaf.hwm");
}

static void test_read_key_inner_beyond_hwm(void **state)
{
    (void)state;
    damage_inner_child();
    occ_node_info_t info;
    expect_assert_on(occ_map_read_key(&map, mk(0, 0, 0), 0u, &info), "idx < m->inner.hwm");
}

static void test_lookup_cursor_leaf_beyond_hwm(void **state)
{
    (void)state;
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    /* A first lookup in the same level-1 node caches the path, then the damage, then a lookup
     * that re-descends from the cache (x bit 1 changes: from level 2 down). */
    assert_int_equal(occ_lookup_state(&lk, centre(mk(2, 0, 0))), OCC_STATE_UNKNOWN);
    damage_leaf_child();
    expect_assert_on(occ_lookup_state(&lk, centre(mk(0, 0, 0))), "idx < m->leaf.hwm");
}

static void test_castray_cursor_leaf_beyond_hwm(void **state)
{
    (void)state;
    damage_leaf_child();
    occ_ray_result_t ray;
    const occ_vec3_t plus_x = {1.0f, 0.0f, 0.0f};
    /* castRay indexes leaf blocks from a base pointer, not through occ_leaf_at: its own assert. */
    expect_assert_on(occ_cast_ray(&map, centre(mk(0, 0, 0)), plus_x, true, 0.0f, &ray),
                     "b < c->m->leaf.hwm");
}

static void test_castray_cursor_inner_beyond_hwm(void **state)
{
    (void)state;
    damage_inner_child();
    occ_ray_result_t ray;
    const occ_vec3_t plus_y = {0.0f, 1.0f, 0.0f};
    expect_assert_on(occ_cast_ray(&map, centre(mk(0, 0, 0)), plus_y, true, 0.0f, &ray),
                     "b < c->m->inner.hwm");
}

static void test_walk_inner_beyond_hwm(void **state)
{
    (void)state;
    damage_inner_child();
    expect_assert_on(walk_all(), "idx < m->inner.hwm");
}

static void test_write_update_leaf_beyond_hwm(void **state)
{
    (void)state;
    damage_leaf_child();
    expect_assert_on(occ_map_update_key(&map, mk(1, 0, 0), 0.5f), "idx < m->leaf.hwm");
}

static void test_pool_alloc_leaf_foreign_link(void **state)
{
    (void)state;
    /* The free list's head links to a block never carved: popping the head must not hand that
     * index on as the next block. */
    const uint32_t bad = map.leaf.hwm + 5u;
    memcpy(occ_leaf_at(&map, map.leaf.priv.free_head)->value, &bad, sizeof bad);
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
    expect_assert_on(occi_pool_alloc_leaf(&map),
                     "m->leaf.priv.free_head == OCC_NONE || m->leaf.priv.free_head < m->leaf.hwm");
}

static void test_pool_alloc_inner_without_free_mark(void **state)
{
    (void)state;
    /* The inner free list's head does not carry the free mark: a used block is on the list. */
    occ_inner_mark_used(occ_inner_at(&map, map.inner.priv.free_head));
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
    expect_assert_on(occi_pool_alloc_inner(&map),
                     "occ_inner_is_free(occ_inner_at(m, idx))");
}

static void test_pool_alloc_counters_broken(void **state)
{
    (void)state;
    /* The free list dropped: used + free_count no longer equals the blocks carved. */
    map.leaf.priv.free_head = OCC_NONE;
    map.leaf.free_count = 0u;
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
    expect_assert_on(occi_pool_alloc_leaf(&map), "p->used + p->free_count == p->hwm");
}

static void test_release_stack_bound(void **state)
{
    (void)state;
    /* A block that is its own child, on a map whose depth claims more levels than a walk stack
     * holds: releasing it would push frame after frame past OCC_MAX_DEPTH. */
    occ_inner_block_t *const root_block = occ_inner_at(&map, map.priv.root_child);
    root_block->child[0] = map.priv.root_child;
    map.cfg.depth_levels = 30u;
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
    expect_assert_on(occi_tree_release_children(&map, occ_root(&map), 30u),
                     "sp < OCC_MAX_DEPTH && lvl[sp] > 1u");
}

static void test_release_level_out_of_range(void **state)
{
    (void)state;
    /* A level above the root's is no node of this map. */
    expect_assert_on(occi_tree_release_children(&map, occ_root(&map), DEPTH + 1u),
                     "level >= 1u && level <= m->cfg.depth_levels");
}

static void test_builder_stack_bound(void **state)
{
    (void)state;
    /* The file readers drive the tree builder and guarantee it a depth <= 21; a builder told 30
     * levels (the dry run: no map, no block touched) stops at its frame stack's bound. */
    static occ_build_t b;
    occi_build_begin(&b, NULL, 30u);
    occi_build_open_root(&b);
    for (unsigned i = 0; i < OCC_MAX_DEPTH; i++) {
        occi_build_open(&b, 0u);
    }
    assert_int_equal(b.sp, OCC_MAX_DEPTH + 1u); /* every frame in use */
    expect_assert_on(occi_build_open(&b, 0u), "level >= 1u && b->sp <= OCC_MAX_DEPTH");
}

static void test_builder_slot_range(void **state)
{
    (void)state;
    static occ_build_t b;
    occi_build_begin(&b, NULL, DEPTH);
    occi_build_open_root(&b);
    expect_assert_on(occi_build_leaf(&b, 8u, 0), "b->sp >= 1u && slot < 8u");
    occi_build_leaf(&b, 7u, 0); /* slot 7 is the last one */
    assert_int_equal(b.st[0].set, 0x80u);
}

static void test_node_child_foreign_handle_is_an_error(void **state)
{
    (void)state;
    /* A caller's handle is not an internal invariant: range-checked, OCC_ERR_ARG, no assert. */
    occ_node_t root, bad, out;
    occ_map_node_root(&map, &root);
    assert_true(root.children != OCC_NONE);
    bad = root;
    bad.children = map.inner.hwm + 1u;
    assert_int_equal(occ_map_node_child(&map, &bad, 0u, &out), OCC_ERR_ARG);
    bad = root;
    bad.level = (uint8_t)(DEPTH + 1u);
    assert_int_equal(occ_map_node_child(&map, &bad, 0u, &out), OCC_ERR_ARG);
    assert_int_equal(occ_map_node_child(&map, &root, 0u, &out), OCC_OK);
    assert_int_equal(out.level, DEPTH - 1u);
}

int main(void)
{
#define T(f) cmocka_unit_test_setup_teardown(f, setup_map, teardown_map)
    const struct CMUnitTest tests[] = {
        T(test_undamaged_paths_fire_nothing),
        T(test_read_state_at_leaf_beyond_hwm),
        T(test_read_key_inner_beyond_hwm),
        T(test_lookup_cursor_leaf_beyond_hwm),
        T(test_castray_cursor_leaf_beyond_hwm),
        T(test_castray_cursor_inner_beyond_hwm),
        T(test_walk_inner_beyond_hwm),
        T(test_write_update_leaf_beyond_hwm),
        T(test_pool_alloc_leaf_foreign_link),
        T(test_pool_alloc_inner_without_free_mark),
        T(test_pool_alloc_counters_broken),
        T(test_release_stack_bound),
        T(test_release_level_out_of_range),
        T(test_builder_stack_bound),
        T(test_builder_slot_range),
        T(test_node_child_foreign_handle_is_an_error),
    };
#undef T
    return cmocka_run_group_tests_name("asserts", tests, NULL, NULL);
}
