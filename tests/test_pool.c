/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_pool.c - the block pools: alloc/free/stats through the internal pool calls and the map
 * API, double free and foreign indices rejected, arena sizing helpers, and exhaustion at every
 * arena size from 0 to 64 leaf-block units: every write either succeeds exactly when the blocks
 * it needs fit (a byte model of the two-ended arena, independent of the core) or returns
 * OCC_ERR_NOMEM with the map struct (except oom_count) and the arena byte-for-byte unchanged;
 * occ_map_check() holds after every call and the content equals a dense shadow model.
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
#include "support/shadow_grid.h"
#include "support/leak_check.h"

#define MAX_UNITS 64u
#define BIG_BYTES OCC_ARENA_BYTES(64, 128)

static uint8_t arena[BIG_BYTES + 16u];
static uint8_t arena_copy[sizeof arena];
static occ_map_t map;
static unsigned seed;

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

/* OCC_TEST_QUICK=1 (the compile-time variant builds in tests/foundation.mk): a quarter of the work. */
static unsigned scaled(unsigned n)
{
    const char *const q = getenv("OCC_TEST_QUICK");
    return q != NULL && q[0] == '1' ? (n + 3u) / 4u : n;
}

static int setup_seed(void **state)
{
    (void)state;
    const char *const env = getenv("OCC_SEED");
    seed = env != NULL ? (unsigned)strtoul(env, NULL, 0) : (unsigned)time(NULL);
    printf("test_pool: seed %u (set OCC_SEED to repeat)\n", seed);
    srand(seed);
    return 0;
}

static int setup_map(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 16u;
    return occ_map_init(&map, &cfg, arena, BIG_BYTES) == OCC_OK ? 0 : -1;
}

/* Every fixture ends with the leak check (it clears the map) and every pool back to used == 0. */
static int teardown_map(void **state)
{
    (void)state;
    if (leak_check(&map) != 0) {
        return -1;
    }
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    if (st.inner_used != 0u || st.leaf_used != 0u || map.inner.used != 0u ||
        map.leaf.used != 0u || st.oom_count != 0u || st.nodes != 0u ||
        occ_map_check(&map) != OCC_OK) {
        fprintf(stderr, "teardown: pools not empty after clear\n");
        return -1;
    }
    return 0;
}

static void assert_pool(const occ_pool_t *p, uint32_t used, uint32_t hwm, uint32_t free_count)
{
    assert_int_equal(p->used, used);
    assert_int_equal(p->hwm, hwm);
    assert_int_equal(p->free_count, free_count);
    assert_true(p->peak >= p->used);
}

static void test_alloc_free_inner(void **state)
{
    (void)state;
    uint32_t idx[6];
    for (unsigned i = 0; i < 6u; i++) {
        idx[i] = occi_pool_alloc_inner(&map);
        assert_int_equal(idx[i], i);
    }
    assert_pool(&map.inner, 6, 6, 0);
    assert_int_equal(map.inner.peak, 6u);
    /* Blocks sit at the top of the arena, inside it, without overlap. */
    for (unsigned i = 0; i < 6u; i++) {
        const uint8_t *const b = (const uint8_t *)occ_inner_at(&map, idx[i]);
        assert_true(b >= map.priv.arena && b + sizeof(occ_inner_block_t) <= map.priv.arena + map.arena_bytes);
#if !OCC_INNER_PACKED
        assert_true(((uintptr_t)b % 4u) == 0u); /* packed blocks are bytes only */
#endif
    }
    assert_true(occi_pool_free_inner(&map, idx[2]));
    assert_true(occi_pool_free_inner(&map, idx[4]));
    assert_pool(&map.inner, 4, 6, 2);
    /* Double free (head of the list and deeper) and foreign indices: rejected, nothing changes. */
    const occ_pool_t before = map.inner;
    assert_false(occi_pool_free_inner(&map, idx[4]));
    assert_false(occi_pool_free_inner(&map, idx[2]));
    assert_false(occi_pool_free_inner(&map, 6u));
    assert_false(occi_pool_free_inner(&map, 1000u));
    assert_false(occi_pool_free_inner(&map, OCC_NONE));
    assert_memory_equal(&before, &map.inner, sizeof before);
    /* Free blocks are reused before the arena is carved further. */
    const uint32_t r1 = occi_pool_alloc_inner(&map), r2 = occi_pool_alloc_inner(&map);
    assert_true((r1 == 2u && r2 == 4u) || (r1 == 4u && r2 == 2u));
    assert_pool(&map.inner, 6, 6, 0);
    assert_int_equal(occi_pool_alloc_inner(&map), 6u);
    for (unsigned i = 0; i <= 6u; i++) {
        assert_true(occi_pool_free_inner(&map, i));
    }
    assert_pool(&map.inner, 0, 7, 7);
    assert_false(occi_pool_free_inner(&map, 3u));
    assert_int_equal(map.inner.peak, 7u);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static void test_alloc_free_leaf(void **state)
{
    (void)state;
    for (unsigned i = 0; i < 5u; i++) {
        assert_int_equal(occi_pool_alloc_leaf(&map), i);
    }
    for (unsigned i = 0; i < 5u; i++) {
        const uint8_t *const b = (const uint8_t *)occ_leaf_at(&map, i);
        assert_true(b >= map.priv.arena && b + sizeof(occ_leaf_block_t) <= map.priv.arena + map.arena_bytes);
    }
    assert_true(occi_pool_free_leaf(&map, 1u));
    assert_true(occi_pool_free_leaf(&map, 3u));
    assert_true(occi_pool_free_leaf(&map, 0u));
    assert_pool(&map.leaf, 2, 5, 3);
    const occ_pool_t before = map.leaf;
    assert_false(occi_pool_free_leaf(&map, 0u)); /* head of the free list */
    assert_false(occi_pool_free_leaf(&map, 1u)); /* tail */
    assert_false(occi_pool_free_leaf(&map, 3u)); /* middle */
    assert_false(occi_pool_free_leaf(&map, 5u));
    assert_false(occi_pool_free_leaf(&map, OCC_NONE));
    assert_memory_equal(&before, &map.leaf, sizeof before);
    assert_true(occi_pool_free_leaf(&map, 2u));
    assert_true(occi_pool_free_leaf(&map, 4u));
    assert_pool(&map.leaf, 0, 5, 5);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    /* Exhaust the leaf pool: exactly as many blocks as the byte model says. */
    const uint32_t expect = (uint32_t)((map.arena_bytes - (size_t)map.inner.hwm * OCC_INNER_BLOCK_BYTES) /
                                       OCC_LEAF_BLOCK_BYTES);
    uint32_t n = 0;
    while (occi_pool_alloc_leaf(&map) != OCC_NONE) {
        n++;
        assert_true(n <= expect);
    }
    assert_int_equal(n, expect);
    assert_false(occi_pool_can_supply(&map, 0u, 1u));
    assert_int_equal(occi_pool_alloc_inner(&map), OCC_NONE);
    for (uint32_t i = 0; i < n; i++) {
        assert_true(occi_pool_free_leaf(&map, i));
    }
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* A block taken from the pool and not in the tree is a leak; check() says so until it is freed. */
static void test_leak_seen_by_check(void **state)
{
    (void)state;
    assert_int_equal(occ_map_observe_key(&map, mk(5, 6, 7), true), OCC_OK);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    const uint32_t l = occi_pool_alloc_leaf(&map);
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
    assert_true(occi_pool_free_leaf(&map, l));
    assert_int_equal(occ_map_check(&map), OCC_OK);
    const uint32_t i = occi_pool_alloc_inner(&map);
    assert_int_equal(occ_map_check(&map), OCC_ERR_CORRUPT);
    assert_true(occi_pool_free_inner(&map, i));
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* The teardowns' leak check can fail: a block taken from a pool and never linked is reported,
 * and once it is returned the check passes (and leaves the map cleared). */
static void test_leak_check_fails_on_leak(void **state)
{
    (void)state;
    assert_int_equal(occ_map_observe_key(&map, mk(5, 6, 7), true), OCC_OK);
    const uint32_t l = occi_pool_alloc_leaf(&map);
    assert_true(l != OCC_NONE);
    assert_int_equal(leak_check(&map), -1);
    assert_true(occi_pool_free_leaf(&map, l));
    const uint32_t i = occi_pool_alloc_inner(&map);
    assert_true(i != OCC_NONE);
    assert_int_equal(leak_check(&map), -1);
    assert_true(occi_pool_free_inner(&map, i));
    assert_int_equal(leak_check(&map), 0);
    assert_int_equal(map.inner.used + map.leaf.used, 0u);
}

static void test_stats_through_api(void **state)
{
    (void)state;
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    assert_int_equal(st.arena_bytes, map.arena_bytes);
    assert_int_equal(st.inner_capacity, map.arena_bytes / OCC_INNER_BLOCK_BYTES);
    assert_int_equal(st.leaf_capacity, map.arena_bytes / OCC_LEAF_BLOCK_BYTES);
    assert_int_equal(st.bytes_used, 0u);
    assert_int_equal(st.nodes, 0u);
    assert_false(st.has_known);
    const occ_key_t k = mk(32768u, 32768u, 32768u);
    assert_int_equal(occ_map_observe_key(&map, k, true), OCC_OK);
    occ_map_stats(&map, &st);
    assert_int_equal(st.inner_used, 15u);
    assert_int_equal(st.leaf_used, 1u);
    assert_int_equal(st.bytes_used, 15u * OCC_INNER_BLOCK_BYTES + OCC_LEAF_BLOCK_BYTES);
    assert_int_equal(st.bytes_peak, st.bytes_used);
    assert_int_equal(st.nodes, 17u);
    assert_int_equal(st.inner_nodes, 16u);
    assert_int_equal(st.leaf_nodes, 1u);
    assert_int_equal(st.occupied_leaves, 1u);
    assert_int_equal(st.free_leaves, 0u);
    assert_int_equal(st.inner_capacity,
                     (map.arena_bytes - OCC_LEAF_BLOCK_BYTES) / OCC_INNER_BLOCK_BYTES);
    assert_int_equal(st.leaf_capacity,
                     (map.arena_bytes - 15u * OCC_INNER_BLOCK_BYTES) / OCC_LEAF_BLOCK_BYTES);
    /* A second voxel in the same leaf block costs nothing; a far one a new path. */
    assert_int_equal(occ_map_observe_key(&map, mk(32769u, 32768u, 32768u), false), OCC_OK);
    occ_map_pool_stats(&map, &st);
    assert_int_equal(st.inner_used, 15u);
    assert_int_equal(st.leaf_used, 1u);
    assert_int_equal(occ_map_observe_key(&map, mk(0u, 0u, 0u), false), OCC_OK);
    occ_map_pool_stats(&map, &st);
    assert_int_equal(st.inner_used, 15u + 14u);
    assert_int_equal(st.leaf_used, 2u);
    /* Forgetting releases blocks; peaks stay; clear resets them. */
    assert_int_equal(occ_map_forget_key(&map, k, 16u), OCC_OK);
    occ_map_stats(&map, &st);
    assert_int_equal(st.inner_used, 0u);
    assert_int_equal(st.leaf_used, 0u);
    assert_int_equal(st.inner_peak, 29u);
    assert_int_equal(st.leaf_peak, 2u);
    assert_int_equal(st.bytes_peak, 29u * OCC_INNER_BLOCK_BYTES + 2u * OCC_LEAF_BLOCK_BYTES);
    assert_int_equal(st.nodes, 0u);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* OCC_ARENA_BYTES(i, j) holds i inner and j leaf blocks at any alignment, and
 * occ_arena_blocks_for_bytes() never promises more than fits. */
static void test_arena_sizing(void **state)
{
    (void)state;
    const occ_map_config_t cfg = occ_map_config_default();
    /* The public size macros are the internal block sizes. */
    assert_int_equal(OCC_INNER_BLOCK_BYTES, sizeof(occ_inner_block_t));
    assert_int_equal(OCC_LEAF_BLOCK_BYTES, sizeof(occ_leaf_block_t));
#if OCC_INNER_PACKED
    /* 35-byte inner blocks are bytes only: aligned at any address the arena's end gives them. */
    struct byte_then_block {
        char c;
        occ_inner_block_t b;
    };
    assert_int_equal(offsetof(struct byte_then_block, b), 1u);
#else
    assert_int_equal(OCC_INNER_BLOCK_BYTES % OCC_ARENA_ALIGN, 0u);
#endif
    assert_int_equal(OCC_LEAF_BLOCK_BYTES % OCC_ARENA_ALIGN, 0u);
    for (uint32_t i = 0; i <= 6u; i++) {
        for (uint32_t j = 0; j <= MAX_UNITS; j++) {
            const size_t bytes = OCC_ARENA_BYTES(i, j);
            assert_true(occ_arena_blocks_for_bytes(bytes, i) >= j);
            for (unsigned mis = 0; mis < 8u; mis++) {
                occ_map_t m;
                const occ_err_t e = occ_map_init(&m, &cfg, arena + mis, bytes);
                if (i == 0u || j == 0u) {
                    continue; /* may or may not hold one block of each (see B1) */
                }
                assert_int_equal(e, OCC_OK);
                assert_true(m.priv.arena >= arena + mis && m.priv.arena + m.arena_bytes <= arena + mis + bytes);
                assert_true(((uintptr_t)m.priv.arena % OCC_ARENA_ALIGN) == 0u);
                assert_true(occi_pool_can_supply(&m, i, j));
                for (uint32_t a = 0; a < i; a++) {
                    assert_int_equal(occi_pool_alloc_inner(&m), a);
                }
                for (uint32_t a = 0; a < j; a++) {
                    assert_int_equal(occi_pool_alloc_leaf(&m), a);
                }
                for (uint32_t a = 0; a < i; a++) {
                    assert_true(occi_pool_free_inner(&m, a));
                }
                for (uint32_t a = 0; a < j; a++) {
                    assert_true(occi_pool_free_leaf(&m, a));
                }
                assert_int_equal(occ_map_check(&m), OCC_OK);
            }
        }
    }
    /* Every byte size: the helper's count always fits next to n_inner blocks. */
    for (size_t bytes = 0; bytes <= OCC_ARENA_BYTES(6, MAX_UNITS); bytes++) {
        for (uint32_t i = 1; i <= 6u; i++) {
            const uint32_t r = occ_arena_blocks_for_bytes(bytes, i);
            if (r == 0u) {
                continue;
            }
            for (unsigned mis = 0; mis < 8u; mis += 3u) {
                occ_map_t m;
                assert_int_equal(occ_map_init(&m, &cfg, arena + mis, bytes), OCC_OK);
                assert_true(m.arena_bytes >= (size_t)i * OCC_INNER_BLOCK_BYTES +
                                                 (size_t)r * OCC_LEAF_BLOCK_BYTES);
            }
        }
    }
}

/* ---- exhaustion ------------------------------------------------------------------------------- */

typedef struct {
    unsigned calls, ok, nomem, mismatches;
} tally_t;

static occ_key_t rand_key(const shadow_grid_t *s)
{
    return mk(s->base[0] + (uint32_t)rand() % s->edge, s->base[1] + (uint32_t)rand() % s->edge,
              s->base[2] + (uint32_t)rand() % s->edge);
}

/* One random write with its expected outcome; returns false on a contract violation. */
static bool one_op(occ_map_t *m, shadow_grid_t *s, uint8_t *ar, size_t ar_len, tally_t *t,
                   const char *ctx)
{
    const occ_key_t k = rand_key(s);
    const int kind = rand() % 10;
    uint32_t ni = 0, nl = 0;
    unsigned level = 0;
    occ_value_t qv = 0;
    float lv = 0.0f;
    bool hit = false;
    if (kind < 5) { /* observe */
        hit = rand() % 3 != 0;
        qv = hit ? s->q_hit : s->q_miss;
        shadow_need_update(s, k, qv, &ni, &nl);
    } else if (kind < 6) { /* arbitrary delta */
        qv = occ_value_from_logodds((float)(rand() % 4001 - 2000) / (float)OCC_FIXED_ONE);
        lv = occ_value_to_logodds(qv);
        shadow_need_update(s, k, qv, &ni, &nl);
    } else if (kind < 8) { /* set */
        level = (unsigned)rand() % (s->vol_log2 + 1u);
        qv = rand() % 6 == 0 ? s->q_cmax
                             : occ_value_from_logodds((float)(rand() % 4001 - 2000) / (float)OCC_FIXED_ONE);
        lv = occ_value_to_logodds(qv);
        shadow_need_set(s, k, level, qv, &ni, &nl);
    } else { /* forget */
        level = (unsigned)rand() % (s->vol_log2 + 1u);
        shadow_need_set(s, k, level, OCC_VALUE_UNOBSERVED, &ni, &nl);
    }
    const bool fits = shadow_pool_fits(m, ni, nl);
    occ_map_t before;
    memcpy(&before, m, sizeof before);
    memcpy(arena_copy, ar, ar_len);
    occ_err_t e;
    if (kind < 5) {
        e = occ_map_observe_key(m, k, hit);
    } else if (kind < 6) {
        e = occ_map_update_key(m, k, lv);
    } else if (kind < 8) {
        e = occ_map_set_key(m, k, level, lv);
    } else {
        e = occ_map_forget_key(m, k, level);
    }
    t->calls++;
    if (occ_map_check(m) != OCC_OK) {
        fprintf(stderr, "%s: occ_map_check fails after op kind %d (err %d)\n", ctx, kind, (int)e);
        return false;
    }
    if (e == OCC_ERR_NOMEM) {
        t->nomem++;
        before.oom_count++;
        if (memcmp(&before, m, sizeof before) != 0 || memcmp(arena_copy, ar, ar_len) != 0) {
            fprintf(stderr, "%s: map changed after OCC_ERR_NOMEM (op kind %d)\n", ctx, kind);
            return false;
        }
        if (fits) {
            fprintf(stderr, "%s: OCC_ERR_NOMEM although %u inner + %u leaf blocks fit (op %d, "
                    "inner hwm %u free %u, leaf hwm %u free %u, arena %u)\n", ctx, (unsigned)ni,
                    (unsigned)nl, kind, (unsigned)m->inner.hwm, (unsigned)m->inner.free_count,
                    (unsigned)m->leaf.hwm, (unsigned)m->leaf.free_count, (unsigned)m->arena_bytes);
            return false;
        }
        return true;
    }
    if (e != OCC_OK) {
        fprintf(stderr, "%s: op kind %d returned %d\n", ctx, kind, (int)e);
        return false;
    }
    t->ok++;
    if (!fits) {
        fprintf(stderr, "%s: op kind %d succeeded although %u inner + %u leaf blocks do not fit\n",
                ctx, kind, (unsigned)ni, (unsigned)nl);
        return false;
    }
    if (kind < 6) {
        (void)shadow_update(s, k, qv);
    } else if (kind < 8) {
        (void)shadow_set(s, k, level, qv);
    } else {
        (void)shadow_forget(s, k, level);
    }
    return true;
}

static void run_exhaustion(unsigned depth, unsigned vol_log2, uint32_t base_key, unsigned mis,
                           tally_t *t)
{
    const occ_map_config_t c0 = occ_map_config_default();
    occ_map_config_t cfg = c0;
    cfg.depth_levels = (uint8_t)depth;
    for (uint32_t units = 0; units <= MAX_UNITS; units++) {
        const size_t bytes = OCC_ARENA_BYTES(0, units);
        uint8_t *const ar = arena + mis;
        memset(arena, 0xEE, sizeof arena);
        const occ_err_t ie = occ_map_init(&map, &cfg, ar, bytes);
        if (ie != OCC_OK) {
            assert_int_equal(ie, OCC_ERR_NOMEM);
            assert_true(bytes < OCC_INNER_BLOCK_BYTES + OCC_LEAF_BLOCK_BYTES + OCC_ARENA_ALIGN);
            continue;
        }
        assert_int_equal(occ_map_check(&map), OCC_OK);
        shadow_grid_t s;
        const uint32_t base[3] = {base_key, base_key, base_key};
        assert_true(shadow_init(&s, &map, vol_log2, base));
        char ctx[96];
        snprintf(ctx, sizeof ctx, "depth %u, %u units (%u bytes), misalign %u, seed %u", depth,
                 (unsigned)units, (unsigned)bytes, mis, seed);
        for (unsigned i = 0; i < scaled(200u); i++) {
            if (!one_op(&map, &s, ar, bytes, t, ctx)) {
                t->mismatches++;
                shadow_free(&s);
                fail_msg("%s: op %u", ctx, i);
            }
            if (i % 25u == 24u) {
                const unsigned bad = shadow_compare(&s, &map, 4u, ctx);
                if (bad != 0u) {
                    shadow_free(&s);
                    fail_msg("%s: %u mismatches against the shadow after op %u", ctx, bad, i);
                }
            }
        }
        occ_map_stats_t st;
        occ_map_stats(&map, &st);
        assert_true(st.inner_peak * OCC_INNER_BLOCK_BYTES + st.leaf_peak * OCC_LEAF_BLOCK_BYTES <=
                    2u * map.arena_bytes); /* peaks of two pools sharing one arena */
        assert_true(st.bytes_peak <= map.arena_bytes);
        assert_true(st.oom_count == map.oom_count);
        occ_map_clear(&map);
        occ_map_pool_stats(&map, &st);
        assert_int_equal(st.inner_used, 0u);
        assert_int_equal(st.leaf_used, 0u);
        assert_int_equal(st.oom_count, 0u);
        assert_int_equal(occ_map_check(&map), OCC_OK);
        shadow_free(&s);
    }
}

static void test_exhaustion_every_size(void **state)
{
    (void)state;
    tally_t t = {0, 0, 0, 0};
    run_exhaustion(1u, 1u, 0u, 0u, &t);
    run_exhaustion(2u, 2u, 0u, 0u, &t);
    run_exhaustion(3u, 3u, 0u, 5u, &t);
    run_exhaustion(5u, 3u, 8u, 0u, &t);
    run_exhaustion(8u, 2u, 124u, 3u, &t);
    run_exhaustion(16u, 2u, 32764u, 0u, &t);
    run_exhaustion(21u, 1u, (1u << 20) - 2u, 7u, &t);
    printf("exhaustion: %u writes, %u ok, %u OCC_ERR_NOMEM, check() after each\n", t.calls, t.ok,
           t.nomem);
    assert_true(t.nomem > scaled(1000u));
    assert_true(t.ok > scaled(1000u));
}

/* A batch that does not fit is refused whole; one that fits applies whole. */
static void test_batch_all_or_nothing(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 4u;
    unsigned refused = 0, applied = 0, result_fits = 0;
    for (uint32_t units = 4; units <= MAX_UNITS; units++) {
        const size_t bytes = OCC_ARENA_BYTES(0, units);
        assert_int_equal(occ_map_init(&map, &cfg, arena, bytes), OCC_OK);
        shadow_grid_t s;
        const uint32_t base[3] = {0u, 0u, 0u};
        assert_true(shadow_init(&s, &map, 4u, base));
        for (unsigned round = 0; round < scaled(20u); round++) {
            occ_code_t codes[64];
            size_t n = 0;
            occ_code_t c = (occ_code_t)(rand() % 64);
            while (n < 1u + (size_t)(rand() % 40) && c < ((occ_code_t)1 << 12)) {
                codes[n++] = c | (rand() % 2 ? OCC_CODE_HIT_BIT : 0u);
                c += 1u + (occ_code_t)(rand() % (rand() % 2 ? 3 : 300));
            }
            memcpy(arena_copy, arena, bytes);
            occ_map_t before;
            memcpy(&before, &map, sizeof before);
            size_t changed = 0;
            const occ_err_t e = occ_map_observe_codes(&map, codes, n, &changed);
            assert_int_equal(occ_map_check(&map), OCC_OK);
            if (e == OCC_ERR_NOMEM) {
                before.oom_count++;
                assert_memory_equal(&before, &map, sizeof before);
                assert_memory_equal(arena_copy, arena, bytes);
                refused++;
                /* Would the result have fitted? (the core reserves for no frees: an upper bound) */
                shadow_grid_t t2;
                assert_true(shadow_init(&t2, &map, 4u, base));
                shadow_copy(&t2, &s);
                for (size_t i = 0; i < n; i++) {
                    (void)shadow_update(&t2, occ_morton_decode(codes[i] & ~OCC_CODE_HIT_BIT),
                                        (codes[i] & OCC_CODE_HIT_BIT) ? s.q_hit : s.q_miss);
                }
                shadow_stats_t fin;
                shadow_expect_stats(&t2, &fin);
                const uint32_t ni = fin.inner_used > map.inner.used ? fin.inner_used - map.inner.used : 0u;
                const uint32_t nl = fin.leaf_used > map.leaf.used ? fin.leaf_used - map.leaf.used : 0u;
                if (shadow_pool_fits(&map, ni, nl)) {
                    result_fits++;
                }
                shadow_free(&t2);
                continue;
            }
            assert_int_equal(e, OCC_OK);
            size_t want_changed = 0;
            for (size_t i = 0; i < n; i++) {
                const occ_key_t k = occ_morton_decode(codes[i] & ~OCC_CODE_HIT_BIT);
                want_changed += shadow_update(&s, k, (codes[i] & OCC_CODE_HIT_BIT) ? s.q_hit : s.q_miss);
            }
            assert_int_equal(changed, want_changed);
            applied++;
            assert_int_equal(shadow_compare(&s, &map, 0u, "batch"), 0u);
        }
        shadow_free(&s);
        occ_map_clear(&map);
        assert_int_equal(map.inner.used, 0u);
        assert_int_equal(map.leaf.used, 0u);
    }
    printf("batches: %u applied, %u refused whole (%u of them would have fitted after pruning)\n",
           applied, refused, result_fits);
    assert_true(applied > scaled(50u) && refused > scaled(50u));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_alloc_free_inner, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_alloc_free_leaf, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_leak_seen_by_check, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_leak_check_fails_on_leak, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_stats_through_api, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_arena_sizing, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_exhaustion_every_size, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_batch_all_or_nothing, setup_map, teardown_map),
    };
    return cmocka_run_group_tests_name("pool", tests, setup_seed, NULL);
}
