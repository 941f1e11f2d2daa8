/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_lookup_index.c - the lookup index (occ_query.h, src/query/lookup_index*.c, issue 22):
 *  - real maps (geb079.bt from Debian's liboctomap-dev, fr_079 from ../shared/data/maps; a
 *    missing file is skipped and counted): at every level from 0 to the root, every probe
 *    (random inside and around the map's box, on voxel borders and one float ulp either side,
 *    outside the box, off the map, NaN and Inf) answers exactly occ_map_state_at, one by one
 *    and in batches, and the batch equals the single lookups;
 *  - a map built by hand: table bytes per level worked out by hand, the answers of an occupied
 *    voxel, a free level-3 node and space outside the box;
 *  - fail closed: after a write, a clear or a re-init, every answer is UNKNOWN with
 *    OCC_ERR_STATE (a FREE voxel never reads FREE from a stale index);
 *  - memory: too small -> OCC_ERR_NOMEM with nothing written; the table ends within the bytes
 *    occ_lookup_index_need() gave (guard bytes after it untouched), unaligned memory works;
 *  - bad input: NULL, level > depth, NaN / Inf, off-map points, an unbuilt index, pick budgets;
 *  - level 0's bricks, every voxel against occ_map_state_at: bricks of one state (one node, or
 *    voxels of different log-odds) against mixed ones with their bytes by hand; bricks at the
 *    map's faces (keys 0 and 2^depth - 1, depths 1 to 16: a map smaller than a brick too) and
 *    a box not aligned to bricks (random, OCC_SEED); a map where every brick is mixed.
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

#include "occmap/occmap.h"
#include "support/lookup_probes.h"
#include "support/leak_check.h"
#include "support/test_rng.h"

/* Every probe through the index equals occ_map_state_at; the batch equals them too. */
static void check_probes(const occ_map_t *map, const occ_lookup_index_t *idx, const occ_vec3_t *pts,
                         size_t n, const char *what)
{
    occ_state_t *const out = malloc(n * sizeof *out);
    assert_non_null(out);
    assert_int_equal(occ_lookup_index_states(idx, pts, n, out), OCC_OK);
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_state_t want = occ_map_state_at(map, pts[i]);
        occ_state_t got = OCC_STATE_OCCUPIED;
        const occ_err_t e = occ_lookup_index_read(idx, pts[i], &got);
        occ_key_t k;
        const occ_err_t ke = occ_map_key(map, pts[i], &k);
        if (occ_lookup_index_state(idx, pts[i]) != want || got != want || out[i] != want ||
            e != ke) {
            if (bad++ < 5u) {
                printf("%s: point %zu (%.9g %.9g %.9g): want %d, state %d, read %d (%d), batch %d\n",
                       what, i, (double)pts[i].x, (double)pts[i].y, (double)pts[i].z, (int)want,
                       (int)occ_lookup_index_state(idx, pts[i]), (int)got, (int)e, (int)out[i]);
            }
        }
    }
    free(out);
    assert_int_equal(bad, 0u);
}

static void check_every_level(const occ_map_t *map, const char *name, size_t n_random)
{
    occ_map_stats_t st;
    occ_map_stats(map, &st);
    assert_true(st.has_known);
    const size_t cap = lp_probe_cap(n_random);
    occ_vec3_t *const pts = malloc(cap * sizeof *pts);
    assert_non_null(pts);
    const size_t n = lp_make_probes(map, st.bbox_min, st.bbox_max, pts, n_random);
    assert_true(n <= cap);
    for (unsigned level = 0; level <= map->cfg.depth_levels; level++) {
        size_t bytes = 0;
        assert_int_equal(occ_lookup_index_need(map, level, &bytes), OCC_OK);
        uint8_t *const mem = malloc(bytes + 3u + 1u);
        assert_non_null(mem);
        occ_lookup_index_t idx;
        /* Unaligned on odd levels: the table starts at the next 4-byte boundary. */
        uint8_t *const at = mem + (level % 2u);
        assert_int_equal(occ_lookup_index_build(&idx, map, level, at, bytes + 3u), OCC_OK);
        assert_int_equal(occ_lookup_index_status(&idx), OCC_OK);
        assert_int_equal(idx.level, level);
        assert_int_equal(idx.bytes, bytes);
        char what[64];
        snprintf(what, sizeof what, "%s level %u", name, level);
        check_probes(map, &idx, pts, n, what);
        free(mem);
    }
    printf("%s: %zu probes equal occ_map_state_at at every level 0..%u\n", name, n,
           (unsigned)map->cfg.depth_levels);
    free(pts);
}

static void real_map(const char *path, const char *name)
{
    occ_map_t map;
    void *const arena = lp_load_map(path, &map);
    if (arena == NULL) {
        skip();
    }
    check_every_level(&map, name, 20000u);
    free(arena);
}

static void test_geb079(void **state)
{
    (void)state;
    real_map(LP_GEB079, "geb079");
}

static void test_fr079(void **state)
{
    (void)state;
    real_map(LP_FR079, "fr_079");
}

/* The hand-made map of lookup_probes.h: its observed box is keys 32768..32783 per axis (16^3
 * voxels). */
static void test_hand_map(void **state)
{
    (void)state;
    static lp_small_t s;
    lp_small_init(&s);
    /* Bytes by hand: level 0: 2^3 bricks x 4 + 128 x (3 constant + 1 mixed: the occupied
     * voxel's; the free node is a whole brick) = 544; level 1: 8^3 x 4 = 2048; level 2: 4^3 x 4
     * = 256; level 3: 2^3 x 4 = 32; level 4 .. 16: one cell, 4 bytes. */
    const size_t want[6] = {544u, 2048u, 256u, 32u, 4u, 4u};
    for (unsigned l = 0; l < 6u; l++) {
        size_t b = 0;
        assert_int_equal(occ_lookup_index_need(&s.map, l, &b), OCC_OK);
        assert_int_equal(b, want[l]);
    }
    unsigned level = 99u;
    assert_int_equal(occ_lookup_index_pick(&s.map, 544u, &level), OCC_OK);
    assert_int_equal(level, 0u);
    assert_int_equal(occ_lookup_index_pick(&s.map, 543u, &level), OCC_OK);
    assert_int_equal(level, 2u);
    assert_int_equal(occ_lookup_index_pick(&s.map, 31u, &level), OCC_OK);
    assert_int_equal(level, 4u);
    level = 99u;
    assert_int_equal(occ_lookup_index_pick(&s.map, 3u, &level), OCC_ERR_NOMEM);
    assert_int_equal(level, 99u);
    static uint32_t mem[1024];
    for (unsigned l = 0; l <= 16u; l++) {
        occ_lookup_index_t idx;
        assert_int_equal(occ_lookup_index_build(&idx, &s.map, l, mem, sizeof mem), OCC_OK);
        assert_int_equal(idx.lo[0], l >= 16u ? 0u : (32768u >> l) << l);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.05f, 0.05f, 0.05f}),
                         OCC_STATE_OCCUPIED);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.15f, 0.05f, 0.05f}),
                         OCC_STATE_UNKNOWN);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){1.0f, 1.0f, 1.0f}), OCC_STATE_FREE);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.77f, 0.83f, 0.6f}),
                         OCC_STATE_UNKNOWN); /* x key 32775: just below the free node */
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.79f, 0.83f, 0.6f}),
                         occ_map_state_at(&s.map, (occ_vec3_t){0.79f, 0.83f, 0.6f}));
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){5.0f, 5.0f, 5.0f}),
                         OCC_STATE_UNKNOWN);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){-0.05f, 0.05f, 0.05f}),
                         OCC_STATE_UNKNOWN);
    }
    assert_int_equal(leak_check(&s.map), 0);
}

static void test_stale(void **state)
{
    (void)state;
    static lp_small_t s;
    lp_small_init(&s);
    static uint32_t mem[1024];
    occ_lookup_index_t idx;
    const occ_vec3_t freep = {1.0f, 1.0f, 1.0f};
    assert_int_equal(occ_lookup_index_build(&idx, &s.map, 0u, mem, sizeof mem), OCC_OK);
    assert_int_equal(occ_lookup_index_state(&idx, freep), OCC_STATE_FREE);
    /* A write elsewhere (the free node's answer did not change) still makes it stale. */
    assert_int_equal(occ_map_update(&s.map, (occ_vec3_t){0.35f, 0.05f, 0.05f}, -0.4f), OCC_OK);
    occ_state_t st = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_index_status(&idx), OCC_ERR_STATE);
    assert_int_equal(occ_lookup_index_state(&idx, freep), OCC_STATE_UNKNOWN);
    assert_int_equal(occ_lookup_index_read(&idx, freep, &st), OCC_ERR_STATE);
    assert_int_equal(st, OCC_STATE_UNKNOWN);
    occ_vec3_t pts[3] = {freep, freep, {0.05f, 0.05f, 0.05f}};
    occ_state_t out[3] = {OCC_STATE_FREE, OCC_STATE_FREE, OCC_STATE_FREE};
    assert_int_equal(occ_lookup_index_states(&idx, pts, 3u, out), OCC_ERR_STATE);
    for (unsigned i = 0; i < 3u; i++) {
        assert_int_equal(out[i], OCC_STATE_UNKNOWN);
    }
    /* Rebuilt: valid again, and the new voxel reads FREE. */
    for (unsigned l = 0; l <= 3u; l++) {
        assert_int_equal(occ_lookup_index_build(&idx, &s.map, l, mem, sizeof mem), OCC_OK);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.35f, 0.05f, 0.05f}),
                         OCC_STATE_FREE);
    }
    occ_map_clear(&s.map);
    assert_int_equal(occ_lookup_index_status(&idx), OCC_ERR_STATE);
    assert_int_equal(occ_lookup_index_state(&idx, freep), OCC_STATE_UNKNOWN);
    /* A re-init restarts write_gen: the root block (now none) tells it. */
    lp_small_init(&s);
    assert_int_equal(occ_lookup_index_build(&idx, &s.map, 2u, mem, sizeof mem), OCC_OK);
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(&s.map, &cfg, s.arena, sizeof s.arena), OCC_OK);
    assert_int_equal(occ_lookup_index_status(&idx), OCC_ERR_STATE);
    assert_int_equal(occ_lookup_index_state(&idx, freep), OCC_STATE_UNKNOWN);
}

static void test_memory(void **state)
{
    (void)state;
    static lp_small_t s;
    lp_small_init(&s);
    static uint32_t memw[(4096 + 16) / 4];
    uint8_t *const mem = (uint8_t *)memw;
    const size_t mem_size = sizeof memw;
    for (unsigned l = 0; l <= 4u; l++) {
        size_t need = 0;
        assert_int_equal(occ_lookup_index_need(&s.map, l, &need), OCC_OK);
        occ_lookup_index_t idx;
        memset(mem, 0xA5, mem_size);
        assert_int_equal(occ_lookup_index_build(&idx, &s.map, l, mem, need - 1u), OCC_ERR_NOMEM);
        for (size_t i = 0; i < mem_size; i++) {
            assert_int_equal(mem[i], 0xA5);
        }
        assert_int_equal(occ_lookup_index_status(&idx), OCC_ERR_STATE);
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.05f, 0.05f, 0.05f}),
                         OCC_STATE_UNKNOWN);
        /* Unaligned by one: needs 3 more bytes; with need + 2 it refuses. */
        assert_int_equal(occ_lookup_index_build(&idx, &s.map, l, mem + 1, need + 2u), OCC_ERR_NOMEM);
        assert_int_equal(occ_lookup_index_build(&idx, &s.map, l, mem + 1, need + 3u), OCC_OK);
        for (size_t i = 0; i < 4u; i++) {
            assert_int_equal(mem[i], 0xA5); /* the padding is not written */
        }
        for (size_t i = 4u + need; i < mem_size; i++) {
            assert_int_equal(mem[i], 0xA5); /* nothing past the table */
        }
        assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.05f, 0.05f, 0.05f}),
                         OCC_STATE_OCCUPIED);
    }
}

static void test_bad_input(void **state)
{
    (void)state;
    static lp_small_t s;
    lp_small_init(&s);
    static uint32_t mem[1024];
    occ_lookup_index_t idx;
    size_t b = 0;
    unsigned l = 0;
    assert_int_equal(occ_lookup_index_need(NULL, 0u, &b), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_need(&s.map, 0u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_need(&s.map, 17u, &b), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_pick(NULL, 100u, &l), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_pick(&s.map, 100u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_build(NULL, &s.map, 0u, mem, sizeof mem), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_build(&idx, NULL, 0u, mem, sizeof mem), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_build(&idx, &s.map, 17u, mem, sizeof mem), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_build(&idx, &s.map, 0u, NULL, sizeof mem), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_status(&idx), OCC_ERR_STATE);
    assert_int_equal(occ_lookup_index_status(NULL), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_state(NULL, (occ_vec3_t){0.05f, 0.05f, 0.05f}),
                     OCC_STATE_UNKNOWN);
    occ_state_t st = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_index_read(NULL, (occ_vec3_t){0, 0, 0}, &st), OCC_ERR_ARG);
    assert_int_equal(st, OCC_STATE_UNKNOWN);
    assert_int_equal(occ_lookup_index_states(NULL, NULL, 0u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_build(&idx, &s.map, 0u, mem, sizeof mem), OCC_OK);
    assert_int_equal(occ_lookup_index_states(&idx, NULL, 1u, &st), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_states(&idx, NULL, 0u, NULL), OCC_OK);
    st = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_index_read(&idx, (occ_vec3_t){NAN, 0, 0}, &st), OCC_ERR_ARG);
    assert_int_equal(st, OCC_STATE_UNKNOWN);
    assert_int_equal(occ_lookup_index_read(&idx, (occ_vec3_t){0, -INFINITY, 0}, &st), OCC_ERR_ARG);
    assert_int_equal(occ_lookup_index_read(&idx, (occ_vec3_t){0, 0, 1e5f}, &st), OCC_ERR_RANGE);
    assert_int_equal(occ_lookup_index_read(&idx, (occ_vec3_t){0.05f, 0.05f, 0.05f}, &st), OCC_OK);
    assert_int_equal(st, OCC_STATE_OCCUPIED);
    assert_int_equal(occ_lookup_index_read(&idx, (occ_vec3_t){0.05f, 0.05f, 0.05f}, NULL), OCC_OK);
    /* An empty map: no table, NULL memory is fine, everything UNKNOWN. */
    occ_map_clear(&s.map);
    assert_int_equal(occ_lookup_index_need(&s.map, 0u, &b), OCC_OK);
    assert_int_equal(b, 0u);
    assert_int_equal(occ_lookup_index_build(&idx, &s.map, 0u, NULL, 0u), OCC_OK);
    assert_int_equal(occ_lookup_index_state(&idx, (occ_vec3_t){0.05f, 0.05f, 0.05f}),
                     OCC_STATE_UNKNOWN);
    /* A uniform observed root: the box is the whole map, one cell at the root level. */
    assert_int_equal(occ_map_set_key(&s.map, (occ_key_t){{0u, 0u, 0u}}, 16u, -1.0f), OCC_OK);
    assert_int_equal(occ_lookup_index_need(&s.map, 16u, &b), OCC_OK);
    assert_int_equal(b, 4u);
    assert_int_equal(occ_lookup_index_need(&s.map, 0u, &b), OCC_OK);
#if SIZE_MAX > UINT32_MAX
    assert_true(b == ((size_t)1 << 41) + 384u); /* 2^39 bricks x 4 + the 3 constant bricks */
#else
    assert_true(b == SIZE_MAX); /* does not fit a 32-bit size_t */
#endif
    assert_int_equal(occ_lookup_index_pick(&s.map, 1024u, &l), OCC_OK);
    assert_int_equal(l, 14u); /* level 13: 8^3 cells x 4 = 2048 B, too big; 14: 4^3 x 4 = 256 */
}

/* Level 0 on `map`: every voxel key of xs x ys x zs (n keys per axis each) answers as
 * occ_map_state_at at its centre. Returns the table's bytes. */
static size_t check_voxels(const occ_map_t *map, const uint32_t *const keys, const size_t n)
{
    size_t bytes = 0;
    assert_int_equal(occ_lookup_index_need(map, 0u, &bytes), OCC_OK);
    void *const mem = malloc(bytes + 4u);
    assert_non_null(mem);
    occ_lookup_index_t idx;
    assert_int_equal(occ_lookup_index_build(&idx, map, 0u, mem, bytes + 4u), OCC_OK);
    assert_int_equal(idx.bytes, bytes);
    size_t bad = 0;
    for (size_t x = 0; x < n; x++) {
        for (size_t y = 0; y < n; y++) {
            for (size_t z = 0; z < n; z++) {
                const occ_key_t k = {{keys[x], keys[y], keys[z]}};
                const occ_vec3_t p = occ_map_key_center(map, k, 0u);
                const occ_state_t want = occ_map_state_at(map, p);
                const occ_state_t got = occ_lookup_index_state(&idx, p);
                if (got != want && bad++ < 5u) {
                    printf("key %u %u %u: want %d, index %d\n", (unsigned)k.k[0], (unsigned)k.k[1],
                           (unsigned)k.k[2], (int)want, (int)got);
                }
            }
        }
    }
    free(mem);
    assert_int_equal(bad, 0u);
    return bytes;
}

/* Keys lo .. lo + n - 1. */
static size_t key_run(uint32_t *const keys, const uint32_t lo, const size_t n)
{
    for (size_t i = 0; i < n; i++) {
        keys[i] = lo + (uint32_t)i;
    }
    return n;
}

static void set_voxel(occ_map_t *map, const uint32_t x, const uint32_t y, const uint32_t z,
                      const unsigned level, const float logodds)
{
    assert_int_equal(occ_map_set_key(map, (occ_key_t){{x, y, z}}, level, logodds), OCC_OK);
}

/* Bricks of keys 32768 + 8 i per axis: which are constant and which mixed, by hand. */
static void test_bricks_by_hand(void **state)
{
    (void)state;
    static occ_map_t map;
    static uint8_t arena[OCC_ARENA_BYTES(256, 512)];
    const occ_map_config_t cfg = occ_map_config_default();
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const uint32_t o = 32768u;
    set_voxel(&map, o, o, o, 3u, -1.0f); /* brick x 0: one free node: constant */
    for (uint32_t i = 0; i < 512u; i++) { /* x 1: 512 free voxels, all different: constant */
        set_voxel(&map, o + 8u + (i >> 6), o + ((i >> 3) & 7u), o + (i & 7u), 0u,
                  -0.1f - 0.003f * (float)i);
    }
    set_voxel(&map, o + 16u, o, o, 3u, -1.0f); /* x 2: free with one occupied voxel: mixed */
    set_voxel(&map, o + 21u, o + 2u, o + 7u, 0u, 2.0f);
    set_voxel(&map, o + 27u, o + 7u, o + 7u, 0u, 2.0f); /* x 3: one voxel, the rest unknown */
    set_voxel(&map, o + 32u, o, o, 4u, 3.0f); /* x 4, 5 (y, z 0, 1): one occupied node */
    for (uint32_t i = 0; i < 511u; i++) { /* x 0, y 1: 511 free voxels, one unknown: mixed */
        set_voxel(&map, o + (i >> 6), o + 8u + ((i >> 3) & 7u), o + (i & 7u), 0u, -1.0f);
    }
    uint32_t keys[64];
    const size_t n = key_run(keys, o - 8u, 64u);
    /* 6 x 2 x 2 bricks x 4 B + 128 B x (3 constant + 3 mixed). */
    assert_int_equal(check_voxels(&map, keys, n), 96u + 128u * 6u);
    assert_int_equal(leak_check(&map), 0);
}

/* Random voxels and small nodes of each state near both faces of the key space on every axis
 * (near one face from depth 10 on, where a box across the map would be large): bricks cut by the
 * map's faces (at depth < 3 the map is smaller than one brick) and a box that
 * does not start or end on a brick. */
static void test_bricks_at_faces(void **state)
{
    (void)state;
    const char *const env = getenv("OCC_SEED");
    const uint64_t seed = env != NULL ? strtoull(env, NULL, 0) : 22u;
    printf("seed %llu (OCC_SEED)\n", (unsigned long long)seed);
    static occ_map_t map;
    static uint8_t arena[OCC_ARENA_BYTES(4096, 8192)];
    for (unsigned depth = 1; depth <= 16u; depth++) {
        rng_state = seed * 977u + depth;
        occ_map_config_t cfg = occ_map_config_default();
        cfg.depth_levels = (uint8_t)depth;
        assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
        const uint32_t side = 1u << depth, near = side < 13u ? side : 13u;
        for (unsigned i = 0; i < 300u; i++) {
            uint32_t k[3];
            const unsigned level = rnd_below(4u) == 0u && depth > 1u ? rnd_below(2u) + 1u : 0u;
            for (unsigned a = 0; a < 3u; a++) {
                const uint32_t off = rnd_below(near);
                /* Both faces while the box's directory stays small, then one. */
                const bool low = depth <= 9u ? rnd_below(2u) == 0u : (depth & 1u) == 0u;
                k[a] = low ? off : side - 1u - off;
            }
            set_voxel(&map, k[0], k[1], k[2], level, rnd_below(2u) == 0u ? -1.0f : 2.0f);
        }
        /* Keys within 20 of each face; at depth <= 5 that is every key. */
        uint32_t keys[40];
        size_t n = key_run(keys, 0u, side < 20u ? side : 20u);
        if (side > 20u) {
            const uint32_t from = side >= 40u ? side - 20u : 20u;
            n += key_run(keys + n, from, side - from);
        }
        (void)check_voxels(&map, keys, n);
    }
}

/* Free and occupied alternate voxel by voxel: every brick is mixed, nothing prunes. */
static void test_every_brick_mixed(void **state)
{
    (void)state;
    static occ_map_t map;
    static uint8_t arena[OCC_ARENA_BYTES(1024, 4096)];
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 5u;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    for (uint32_t x = 0; x < 32u; x++) {
        for (uint32_t y = 0; y < 32u; y++) {
            for (uint32_t z = 0; z < 32u; z++) {
                set_voxel(&map, x, y, z, 0u, ((x + y + z) & 1u) != 0u ? 2.0f : -1.0f);
            }
        }
    }
    uint32_t keys[32];
    const size_t n = key_run(keys, 0u, 32u);
    /* 4^3 bricks x 4 B + 128 B x (3 + 64 mixed). */
    assert_int_equal(check_voxels(&map, keys, n), 256u + 128u * 67u);
    assert_int_equal(leak_check(&map), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_map),
        cmocka_unit_test(test_stale),
        cmocka_unit_test(test_memory),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_bricks_by_hand),
        cmocka_unit_test(test_bricks_at_faces),
        cmocka_unit_test(test_every_brick_mixed),
        cmocka_unit_test(test_geb079),
        cmocka_unit_test(test_fr079),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
