/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_tree_shadow.c - the tree against a dense shadow grid (tests/support/shadow_grid.c).
 * Tens of thousands of random writes (observe hit/miss, update by arbitrary log-odds, set at
 * random levels, forget, batches of Morton codes, point updates) in a 32^3-voxel volume of maps
 * of depth_levels 5..16; hot regions are hammered until they saturate, so pruning and expansion
 * happen all the time. After each batch every voxel's value and state, every coarse node's max,
 * indicators and answering level (occ_map_read_key at every level), the pool use and the stats
 * equal the shadow's, and occ_map_check() holds. Also a config with an unknown band
 * (free_max < occupied_min) and the batch path against the per-voxel path.
 * Random seed: printed, overridable with OCC_SEED.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "occmap/occmap.h"
#include "core/tree_internal.h"
#include "support/shadow_grid.h"
#include "support/leak_check.h"

#define VOL_LOG2 5u
#define ARENA_SIZE OCC_ARENA_BYTES(60000, 40000)

static uint8_t arena[ARENA_SIZE];
static uint8_t arena2[ARENA_SIZE];
static occ_map_t map, map2;
static unsigned seed;

typedef struct {
    unsigned observe, update, set, forget, batch, batch_codes, point, rejected, checks;
} counts_t;
static counts_t total;

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
    printf("test_tree_shadow: seed %u (set OCC_SEED to repeat)\n", seed);
    srand(seed);
    return 0;
}

static int teardown_map(void **state)
{
    (void)state;
    return leak_check(&map);
}

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

static uint32_t urand(uint32_t n)
{
    return (uint32_t)(((uint32_t)rand() << 15) ^ (uint32_t)rand()) % n;
}

/* A hot region: a node of the volume hammered with mostly hits or mostly misses. */
typedef struct {
    occ_key_t first;
    unsigned level;
    bool hits;
} hot_t;

static void new_hot(const shadow_grid_t *s, hot_t *h)
{
    const unsigned top = s->vol_log2 < 3u ? s->vol_log2 : 3u;
    const uint32_t r = urand(20u);
    h->level = r < 10u ? 1u : (r < 17u ? 2u : 3u);
    h->level = h->level > top ? top : h->level;
    const occ_key_t k = mk(s->base[0] + urand(s->edge), s->base[1] + urand(s->edge),
                           s->base[2] + urand(s->edge));
    h->first = occ_key_at_level(k, h->level);
    h->hits = urand(2u) == 0u;
}

static occ_key_t pick_key(const shadow_grid_t *s, const hot_t *h)
{
    if (urand(10u) < 7u) {
        const uint32_t n = 1u << h->level;
        return mk(h->first.k[0] + urand(n), h->first.k[1] + urand(n), h->first.k[2] + urand(n));
    }
    return mk(s->base[0] + urand(s->edge), s->base[1] + urand(s->edge), s->base[2] + urand(s->edge));
}

static float rand_logodds(const shadow_grid_t *s)
{
    switch (urand(8u)) {
    case 0: return occ_value_to_logodds(s->q_cmax);
    case 1: return occ_value_to_logodds(s->q_cmin);
    case 2: return urand(2u) ? 31.5f : -31.5f;      /* near the fixed-point range */
    case 3: return urand(2u) ? 1000.0f : -1000.0f;  /* saturates to the range */
    case 4: return 0.0f;
    default: return (float)((int)urand(8001u) - 4000) / (float)OCC_FIXED_ONE;
    }
}

static int cmp_code(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a & ~OCC_CODE_HIT_BIT;
    const occ_code_t y = *(const occ_code_t *)b & ~OCC_CODE_HIT_BIT;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* One random write applied to the map and the shadow. */
static void random_op(occ_map_t *m, shadow_grid_t *s, hot_t *h, counts_t *c)
{
    if (urand(120u) == 0u) {
        new_hot(s, h);
    }
    const unsigned r = urand(100u);
    const occ_key_t k = pick_key(s, h);
    if (r < 40u) {
        const bool hit = urand(20u) < 19u ? h->hits : !h->hits;
        assert_int_equal(occ_map_observe_key(m, k, hit), OCC_OK);
        (void)shadow_update(s, k, hit ? s->q_hit : s->q_miss);
        c->observe++;
    } else if (r < 55u) {
        const float d = rand_logodds(s);
        assert_int_equal(occ_map_update_key(m, k, d), OCC_OK);
        (void)shadow_update(s, k, occi_delta_from_logodds(d));
        c->update++;
    } else if (r < 63u) {
        /* Through the point API: the voxel's centre maps back to the same key. */
        const occ_vec3_t p = occ_map_key_center(m, k, 0u);
        occ_key_t back;
        assert_int_equal(occ_map_key(m, p, &back), OCC_OK);
        assert_memory_equal(&back, &k, sizeof k);
        const float d = urand(2u) ? m->cfg.hit : m->cfg.miss;
        assert_int_equal(occ_map_update(m, p, d), OCC_OK);
        (void)shadow_update(s, k, occi_delta_from_logodds(d));
        c->point++;
    } else if (r < 73u) {
        unsigned level = urand(4u) == 0u ? urand(s->vol_log2 + 1u) : urand(3u);
        level = level > s->vol_log2 ? s->vol_log2 : level;
        float v = rand_logodds(s);
        if (level < s->vol_log2 && urand(3u) == 0u) { /* a neighbour's value: equal siblings */
            const occ_value_t nv = shadow_get(s, mk(k.k[0] ^ (1u << level), k.k[1], k.k[2]));
            if (occ_value_observed(nv)) {
                v = occ_value_to_logodds(nv);
            }
        }
        assert_int_equal(occ_map_set_key(m, k, level, v), OCC_OK);
        (void)shadow_set(s, k, level, occ_value_from_logodds(v));
        c->set++;
    } else if (r < 78u) {
        unsigned level = urand(4u) == 0u ? urand(s->vol_log2 + 1u) : urand(2u);
        level = level > s->vol_log2 ? s->vol_log2 : level;
        assert_int_equal(occ_map_forget_key(m, k, level), OCC_OK);
        (void)shadow_forget(s, k, level);
        c->forget++;
    } else if (r < 80u) {
        const float bad[] = {NAN, INFINITY, -INFINITY};
        assert_int_equal(occ_map_update_key(m, k, bad[urand(3u)]), OCC_ERR_ARG);
        assert_int_equal(occ_map_set_key(m, k, urand(3u), NAN), OCC_ERR_ARG);
        c->rejected++;
    } else {
        /* A batch of Morton codes: sorted, unique, bit 63 = hit. */
        occ_code_t codes[96];
        size_t n = 1u + urand(96u);
        for (size_t i = 0; i < n; i++) {
            const occ_key_t kk = pick_key(s, h);
            const bool hit = urand(10u) < 9u ? h->hits : !h->hits;
            codes[i] = occ_morton_encode(kk) | (hit ? OCC_CODE_HIT_BIT : 0u);
        }
        qsort(codes, n, sizeof codes[0], cmp_code);
        size_t u = 0;
        for (size_t i = 0; i < n; i++) {
            if (u == 0u || cmp_code(&codes[i], &codes[u - 1u]) != 0) {
                codes[u++] = codes[i];
            }
        }
        n = u;
        size_t changed = 999999u, want = 0;
        assert_int_equal(occ_map_observe_codes(m, codes, n, &changed), OCC_OK);
        for (size_t i = 0; i < n; i++) {
            const occ_key_t kk = occ_morton_decode(codes[i] & ~OCC_CODE_HIT_BIT);
            want += shadow_update(s, kk, (codes[i] & OCC_CODE_HIT_BIT) ? s->q_hit : s->q_miss);
        }
        assert_int_equal(changed, want);
        c->batch++;
        c->batch_codes += (unsigned)n;
    }
    /* Cheap per-op spot check of the touched voxel. */
    occ_node_info_t got;
    assert_int_equal(occ_map_read_key(m, k, 0u, &got), OCC_OK);
    const occ_value_t v = shadow_get(s, k);
    const float want = occ_value_to_logodds(v);
    assert_int_equal(got.observed, occ_value_observed(v));
    assert_int_equal(got.state, shadow_state(s, v));
    assert_true(!(got.logodds < want) && !(got.logodds > want));
}

static void full_compare(shadow_grid_t *s, const occ_map_t *m, const char *ctx)
{
    total.checks++;
    assert_int_equal(occ_map_check(m), OCC_OK);
    const unsigned bad = shadow_compare(s, m, 64u, ctx);
    if (bad != 0u) {
        fail_msg("%s: %u mismatches against the shadow (seed %u)", ctx, bad, seed);
    }
}

static void run_depth(const occ_map_config_t *cfg, const uint32_t base[3], unsigned vol_log2,
                      unsigned n_ops, unsigned batch)
{
    assert_int_equal(occ_map_init(&map, cfg, arena, sizeof arena), OCC_OK);
    shadow_grid_t s;
    assert_true(shadow_init(&s, &map, vol_log2, base));
    assert_memory_equal(&s.q_hit, &map.priv.q_hit, sizeof s.q_hit);
    assert_memory_equal(&s.q_miss, &map.priv.q_miss, sizeof s.q_miss);
    assert_memory_equal(&s.q_cmin, &map.priv.q_clamp_min, sizeof s.q_cmin);
    assert_memory_equal(&s.q_cmax, &map.priv.q_clamp_max, sizeof s.q_cmax);
    hot_t h;
    new_hot(&s, &h);
    char ctx[128];
    snprintf(ctx, sizeof ctx, "depth %u base (%u,%u,%u) band [%g,%g)", (unsigned)cfg->depth_levels,
             (unsigned)base[0], (unsigned)base[1], (unsigned)base[2], (double)cfg->free_max,
             (double)cfg->occupied_min);
    full_compare(&s, &map, ctx);
    for (unsigned i = 0; i < n_ops; i++) {
        random_op(&map, &s, &h, &total);
        if (i % batch == batch - 1u) {
            full_compare(&s, &map, ctx);
        }
    }
    full_compare(&s, &map, ctx);
    /* Forgetting the whole volume returns every block. */
    assert_int_equal(occ_map_forget_key(&map, mk(base[0], base[1], base[2]), vol_log2), OCC_OK);
    shadow_clear(&s);
    full_compare(&s, &map, ctx);
    assert_int_equal(map.inner.used, 0u);
    assert_int_equal(map.leaf.used, 0u);
    shadow_free(&s);
}

static void test_depths_5_to_16(void **state)
{
    (void)state;
    for (unsigned depth = 5; depth <= 16u; depth++) {
        occ_map_config_t cfg = occ_map_config_default();
        cfg.depth_levels = (uint8_t)depth;
        const uint32_t full = 1u << depth, half = full / 2u, e = 1u << VOL_LOG2;
        /* Corners, the centre (keys 2^(D-1)-1 | 2^(D-1) meet at x = 0) and the far edge. */
        const uint32_t choices[4] = {0u, full - e, half >= e ? half - e : 0u, half < full - e ? half : 0u};
        const uint32_t base[3] = {choices[depth % 4u], choices[(depth + 1u) % 4u],
                                  choices[(depth + 2u) % 4u]};
        run_depth(&cfg, base, VOL_LOG2, scaled(2000u), scaled(2000u) / 2u);
    }
    printf("shadow: %u observe, %u update, %u point, %u set, %u forget, %u batches (%u codes), "
           "%u rejected, %u full comparisons\n", total.observe, total.update, total.point,
           total.set, total.forget, total.batch, total.batch_codes, total.rejected, total.checks);
    assert_true(total.observe + total.update + total.point + total.set + total.forget +
                    total.batch_codes > scaled(20000u));
}

static void test_unknown_band(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 9u;
    cfg.free_max = -0.5f;
    cfg.occupied_min = 0.7f;
    const uint32_t base[3] = {256u, 224u, 0u};
    const unsigned before = total.observe;
    run_depth(&cfg, base, VOL_LOG2, scaled(4000u), scaled(4000u) / 2u);
    assert_true(total.observe > before);
    /* Hand-checked states: band values read UNKNOWN and set the unknown indicator. */
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const occ_key_t k = mk(3, 4, 5);
    assert_int_equal(occ_map_set_key(&map, k, 0u, 0.1f), OCC_OK);
    occ_node_info_t info;
    assert_int_equal(occ_map_read_key(&map, k, 0u, &info), OCC_OK);
    assert_true(info.observed);
    assert_int_equal(info.state, OCC_STATE_UNKNOWN);
    assert_true((info.flags & OCC_NODE_HAS_UNKNOWN) != 0u);
    assert_int_equal(occ_map_state_of(&map, -0.5f), OCC_STATE_UNKNOWN);
#if OCC_VALUE_BITS == 8
    /* One 1/36 step off the bands' edges (-0.51 rounds to -0.5 on the 8-bit grid). */
    assert_int_equal(occ_map_state_of(&map, -0.53f), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_of(&map, 0.67f), OCC_STATE_UNKNOWN);
#else
    assert_int_equal(occ_map_state_of(&map, -0.51f), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_of(&map, 0.69f), OCC_STATE_UNKNOWN);
#endif
    assert_int_equal(occ_map_state_of(&map, 0.7f), OCC_STATE_OCCUPIED);
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    assert_int_equal(st.unknown_band_leaves, 1u);
    assert_int_equal(st.occupied_leaves + st.free_leaves, 0u);
}

/* occ_map_observe_codes equals occ_map_observe_key per entry, in any order. */
static void test_batch_vs_per_voxel(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 12u;
    const uint32_t base[3] = {2048u - 32u, 2048u, 2048u - 32u};
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    assert_int_equal(occ_map_init(&map2, &cfg, arena2, sizeof arena2), OCC_OK);
    shadow_grid_t s;
    assert_true(shadow_init(&s, &map, VOL_LOG2, base));
    hot_t h;
    new_hot(&s, &h);
    static occ_code_t codes[4096];
    static occ_code_t order[4096];
    for (unsigned round = 0; round < scaled(12u); round++) {
        /* Clustered and scattered batches of up to 4096 codes. */
        size_t n = 1u + urand(4096u);
        for (size_t i = 0; i < n; i++) {
            const occ_key_t kk = round % 3u == 0u ? mk(base[0] + urand(32u), base[1] + urand(32u),
                                                        base[2] + urand(32u))
                                                 : pick_key(&s, &h);
            codes[i] = occ_morton_encode(kk) | (urand(3u) ? OCC_CODE_HIT_BIT : 0u);
        }
        qsort(codes, n, sizeof codes[0], cmp_code);
        size_t u = 0;
        for (size_t i = 0; i < n; i++) {
            if (u == 0u || cmp_code(&codes[i], &codes[u - 1u]) != 0) {
                codes[u++] = codes[i];
            }
        }
        n = u;
        size_t changed = 0, want = 0;
        assert_int_equal(occ_map_observe_codes(&map, codes, n, &changed), OCC_OK);
        /* The per-voxel path in a shuffled order. */
        memcpy(order, codes, n * sizeof codes[0]);
        for (size_t i = n; i > 1u; i--) {
            const size_t j = urand((uint32_t)i);
            const occ_code_t t = order[i - 1u];
            order[i - 1u] = order[j];
            order[j] = t;
        }
        for (size_t i = 0; i < n; i++) {
            const occ_key_t kk = occ_morton_decode(order[i] & ~OCC_CODE_HIT_BIT);
            assert_int_equal(occ_map_observe_key(&map2, kk, (order[i] & OCC_CODE_HIT_BIT) != 0u), OCC_OK);
            want += shadow_update(&s, kk, (order[i] & OCC_CODE_HIT_BIT) ? s.q_hit : s.q_miss);
        }
        assert_int_equal(changed, want);
        full_compare(&s, &map, "batch path");
        full_compare(&s, &map2, "per-voxel path");
        occ_map_stats_t a, b;
        occ_map_stats(&map, &a);
        occ_map_stats(&map2, &b);
        assert_int_equal(a.nodes, b.nodes);
        assert_int_equal(a.inner_used, b.inner_used);
        assert_int_equal(a.leaf_used, b.leaf_used);
        total.batch_codes += (unsigned)n;
        if (round % 4u == 3u) {
            new_hot(&s, &h);
        }
    }
    shadow_free(&s);
    occ_map_clear(&map2);
    assert_int_equal(map2.inner.used, 0u);
    assert_int_equal(map2.leaf.used, 0u);
}

/* A whole-map set at the root and voxels written next to the volume's outer corners. */
static void test_root_level_and_corners(void **state)
{
    (void)state;
    for (unsigned depth = 1; depth <= 21u; depth += 4u) {
        occ_map_config_t cfg = occ_map_config_default();
        cfg.depth_levels = (uint8_t)depth;
        assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
        const uint32_t top = (uint32_t)((1ull << depth) - 1u);
        const unsigned vl = depth < 3u ? depth : 3u;
        const uint32_t base[3] = {0u, top + 1u - (1u << vl), 0u};
        shadow_grid_t s;
        assert_true(shadow_init(&s, &map, vl, base));
        assert_int_equal(occ_map_set_key(&map, mk(0, 0, 0), depth, -1.5f), OCC_OK);
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&map, mk(top, top, top), 0u, &info), OCC_OK);
        assert_int_equal(info.level, depth);
        assert_int_equal(info.state, OCC_STATE_FREE);
        occ_map_stats_t st;
        occ_map_stats(&map, &st);
        assert_int_equal(st.nodes, 1u);
        assert_int_equal(st.free_leaves, 1u);
        assert_int_equal(st.free_voxels, (uint64_t)1 << (3u * depth));
        assert_int_equal(occ_map_forget_key(&map, mk(top, top, top), depth), OCC_OK);
        hot_t h;
        new_hot(&s, &h);
        for (unsigned i = 0; i < 400u; i++) {
            random_op(&map, &s, &h, &total);
        }
        full_compare(&s, &map, "corner volume");
        shadow_free(&s);
        occ_map_clear(&map);
    }
}

static bool inside_node(occ_key_t k, occ_key_t first, unsigned level)
{
    const occ_key_t a = occ_key_at_level(k, level);
    return memcmp(&a, &first, sizeof a) == 0;
}

/* The walk: Morton preorder, every observed node once, each agreeing with read_key, and
 * skip_children skips exactly the subtree. */
static void test_walk(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 8u;
    const uint32_t base[3] = {96u, 128u, 0u};
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    shadow_grid_t s;
    assert_true(shadow_init(&s, &map, VOL_LOG2, base));
    hot_t h;
    new_hot(&s, &h);
    for (unsigned i = 0; i < scaled(3000u); i++) {
        random_op(&map, &s, &h, &total);
    }
    full_compare(&s, &map, "walk fixture");
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    occ_walk_t w;
    occ_walk_node_t n, prev;
    uint64_t count = 0, leaves = 0, per_level[OCC_MAX_DEPTH + 1] = {0};
    occ_walk_begin(&w, &map);
    while (occ_walk_next(&w, &n)) {
        assert_true(n.observed);
        assert_true(n.level <= cfg.depth_levels);
        const occ_key_t first = occ_key_at_level(n.key, n.level);
        assert_memory_equal(&first, &n.key, sizeof first);
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&map, n.key, n.level, &info), OCC_OK);
        assert_int_equal(info.level, n.level);
        assert_int_equal(info.flags, n.flags);
        assert_int_equal((n.flags & OCC_NODE_UNIFORM) != 0u, !n.has_children);
        const float lv = occ_value_to_logodds(n.value);
        assert_true(!(lv < info.logodds) && !(lv > info.logodds));
        if (count > 0u) {
            const occ_code_t a = occ_morton_encode(prev.key), b = occ_morton_encode(n.key);
            if (prev.has_children) {
                assert_int_equal(n.level + 1u, prev.level); /* first observed child */
                assert_true(inside_node(n.key, prev.key, prev.level));
            } else {
                assert_true(b > a);
            }
        } else {
            assert_int_equal(n.level, cfg.depth_levels); /* the root first */
        }
        prev = n;
        count++;
        per_level[n.level]++;
        leaves += !n.has_children;
    }
    assert_int_equal(count, st.nodes);
    assert_int_equal(leaves, st.leaf_nodes);
    shadow_stats_t want;
    shadow_expect_stats(&s, &want);
    assert_int_equal(count, want.nodes);
    /* Skip random subtrees: nothing inside a skipped node comes back. */
    for (unsigned round = 0; round < 20u; round++) {
        occ_walk_begin(&w, &map);
        bool skipping = false;
        occ_walk_node_t skipped;
        uint64_t seen = 0;
        while (occ_walk_next(&w, &n)) {
            seen++;
            if (skipping) {
                assert_false(inside_node(n.key, skipped.key, skipped.level) && n.level < skipped.level);
            }
            if (n.has_children && urand(8u) == 0u) {
                occ_walk_skip_children(&w);
                skipped = n;
                skipping = true;
            }
        }
        assert_true(seen <= count);
    }
    /* Skipping the root ends the walk. */
    occ_walk_begin(&w, &map);
    assert_true(occ_walk_next(&w, &n));
    occ_walk_skip_children(&w);
    assert_false(occ_walk_next(&w, &n));
    shadow_free(&s);
    (void)per_level;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_depths_5_to_16, teardown_map),
        cmocka_unit_test_teardown(test_unknown_band, teardown_map),
        cmocka_unit_test_teardown(test_batch_vs_per_voxel, teardown_map),
        cmocka_unit_test_teardown(test_root_level_and_corners, teardown_map),
        cmocka_unit_test_teardown(test_walk, teardown_map),
    };
    return cmocka_run_group_tests_name("tree_shadow", tests, setup_seed, NULL);
}
