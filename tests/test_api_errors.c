/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_api_errors.c - caller mistakes: NaN/Inf/out-of-volume coordinates and keys, bad configs,
 * NULL pointers, malformed batches. Each must return its documented code and leave the map
 * byte-for-byte as it was (struct and arena). occ_err_str() for every code.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "occmap/occmap.h"
#include "support/leak_check.h"

#define ARENA_SIZE OCC_ARENA_BYTES(256, 256)
static uint8_t arena[ARENA_SIZE];
static uint8_t arena_copy[ARENA_SIZE];
static occ_map_t map;
static occ_map_t map_copy;

static void snapshot(void)
{
    memcpy(&map_copy, &map, sizeof map);
    memcpy(arena_copy, arena, sizeof arena);
}

static void assert_unchanged(const char *what)
{
    if (memcmp(&map_copy, &map, sizeof map) != 0) {
        fail_msg("%s: the map struct changed", what);
    }
    if (memcmp(arena_copy, arena, sizeof arena) != 0) {
        fail_msg("%s: the arena changed", what);
    }
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

static int setup_map(void **state)
{
    (void)state;
    memset(arena, 0x5A, sizeof arena);
    const occ_map_config_t cfg = occ_map_config_default();
    if (occ_map_init(&map, &cfg, arena, sizeof arena) != OCC_OK) {
        return -1;
    }
    /* Some content so "unchanged" means something. */
    for (uint32_t i = 0; i < 20u; i++) {
        if (occ_map_observe_key(&map, mk(32760u + i, 32768u, 32768u - i), (i % 3u) != 0u) != OCC_OK) {
            return -1;
        }
    }
    return 0;
}

static int teardown_map(void **state)
{
    (void)state;
    return leak_check(&map);
}

static void test_err_str(void **state)
{
    (void)state;
    const occ_err_t codes[] = {OCC_OK,         OCC_ERR_ARG,   OCC_ERR_RANGE,
                               OCC_ERR_NOMEM,  OCC_ERR_FORMAT, OCC_ERR_IO,
                               OCC_ERR_STATE,  OCC_ERR_UNSUPPORTED, OCC_ERR_CORRUPT,
                               OCC_ERR_SCRATCH, OCC_ERR_TIME};
    const size_t n = sizeof codes / sizeof codes[0];
    for (size_t i = 0; i < n; i++) {
        const char *const s = occ_err_str(codes[i]);
        assert_non_null(s);
        assert_true(strlen(s) > 0u);
        for (size_t j = 0; j < i; j++) {
            assert_string_not_equal(s, occ_err_str(codes[j]));
        }
    }
    assert_int_equal(OCC_OK, 0);
    for (size_t i = 1; i < n; i++) {
        assert_true((int)codes[i] < 0);
    }
    /* Codes outside the enum still give text. */
    const int odd[] = {1, -10, -100, 12345, INT32_MIN};
    for (size_t i = 0; i < sizeof odd / sizeof odd[0]; i++) {
        const char *const s = occ_err_str((occ_err_t)odd[i]);
        assert_non_null(s);
        assert_true(strlen(s) > 0u);
    }
}

typedef void (*cfg_mut_t)(occ_map_config_t *c);
#define MUT(name, body) static void name(occ_map_config_t *c) { body; }
MUT(m_res0, c->resolution_m = 0.0f)
MUT(m_resneg, c->resolution_m = -0.1f)
MUT(m_resnan, c->resolution_m = NAN)
MUT(m_resinf, c->resolution_m = INFINITY)
MUT(m_resninf, c->resolution_m = -INFINITY)
MUT(m_depth0, c->depth_levels = 0u)
MUT(m_depth22, c->depth_levels = 22u)
MUT(m_depth255, c->depth_levels = 255u)
MUT(m_hit0, c->hit = 0.0f)
MUT(m_hitneg, c->hit = -0.5f)
MUT(m_hitnan, c->hit = NAN)
MUT(m_hitinf, c->hit = INFINITY)
MUT(m_hitbig, c->hit = 40.0f)
MUT(m_miss0, c->miss = 0.0f)
MUT(m_misspos, c->miss = 0.4f)
MUT(m_missnan, c->miss = NAN)
MUT(m_missninf, c->miss = -INFINITY)
MUT(m_missbig, c->miss = -40.0f)
MUT(m_clampeq, c->clamp_min = c->clamp_max)
MUT(m_clamprev, { c->clamp_min = 3.0f; c->clamp_max = -2.0f; })
MUT(m_clampminnan, c->clamp_min = NAN)
MUT(m_clampmaxnan, c->clamp_max = NAN)
MUT(m_clampmaxbig, c->clamp_max = 40.0f)
MUT(m_clampminbig, c->clamp_min = -40.0f)
MUT(m_thr_rev, { c->free_max = 0.5f; c->occupied_min = -0.5f; })
MUT(m_freenan, c->free_max = NAN)
MUT(m_occinf, c->occupied_min = INFINITY)
MUT(m_occnan, c->occupied_min = NAN)

static void test_init_bad_config(void **state)
{
    (void)state;
    static uint8_t a2[OCC_ARENA_BYTES(4, 4)];
    const cfg_mut_t muts[] = {m_res0,      m_resneg,     m_resnan,     m_resinf,    m_resninf,
                              m_depth0,    m_depth22,    m_depth255,   m_hit0,      m_hitneg,
                              m_hitnan,    m_hitinf,     m_hitbig,     m_miss0,     m_misspos,
                              m_missnan,   m_missninf,   m_missbig,    m_clampeq,   m_clamprev,
                              m_clampminnan, m_clampmaxnan, m_clampmaxbig, m_clampminbig,
                              m_thr_rev,   m_freenan,    m_occinf,     m_occnan};
    for (size_t i = 0; i < sizeof muts / sizeof muts[0]; i++) {
        occ_map_config_t c = occ_map_config_default();
        muts[i](&c);
        occ_map_t m;
        const occ_err_t e = occ_map_init(&m, &c, a2, sizeof a2);
        if (e != OCC_ERR_ARG) {
            fail_msg("bad config #%u accepted: %d (%s)", (unsigned)i, (int)e, occ_err_str(e));
        }
    }
    /* Valid corners. */
    const uint8_t depths[] = {1u, 2u, 16u, 21u};
    for (size_t i = 0; i < sizeof depths; i++) {
        occ_map_config_t c = occ_map_config_default();
        c.depth_levels = depths[i];
        occ_map_t m;
        assert_int_equal(occ_map_init(&m, &c, a2, sizeof a2), OCC_OK);
        assert_int_equal(occ_map_check(&m), OCC_OK);
    }
    occ_map_config_t c = occ_map_config_default();
    c.free_max = -0.2f;
    c.occupied_min = 0.4f;
    occ_map_t m;
    assert_int_equal(occ_map_init(&m, &c, a2, sizeof a2), OCC_OK);
    c.free_max = c.occupied_min = 1.0f;
    assert_int_equal(occ_map_init(&m, &c, a2, sizeof a2), OCC_OK);
    /* NULLs. */
    c = occ_map_config_default();
    assert_int_equal(occ_map_init(NULL, &c, a2, sizeof a2), OCC_ERR_ARG);
    assert_int_equal(occ_map_init(&m, NULL, a2, sizeof a2), OCC_ERR_ARG);
    assert_int_equal(occ_map_init(&m, &c, NULL, sizeof a2), OCC_ERR_ARG);
}

/* The header: OCC_ERR_NOMEM if the arena cannot hold one inner and one leaf block. */
/* By design (occmap.h, occ_map_init): any arena size is accepted, even 0 bytes or NULL. Such a
 * map holds only a uniform root: reads answer UNKNOWN, every write that needs a block returns
 * OCC_ERR_NOMEM (counted), and the map stays consistent. */
static void test_init_small_arena(void **state)
{
    (void)state;
    static uint64_t a3[64];
    const occ_map_config_t c = occ_map_config_default();
    const size_t need = OCC_INNER_BLOCK_BYTES + OCC_LEAF_BLOCK_BYTES;
    const occ_key_t k = mk(5, 6, 7);
    for (size_t bytes = 0; bytes <= need + OCC_ARENA_ALIGN; bytes++) {
        for (unsigned misalign = 0; misalign < 2u; misalign++) {
            occ_map_t m;
            uint8_t *const base = (uint8_t *)a3 + misalign;
            assert_int_equal(occ_map_init(&m, &c, base, bytes), OCC_OK);
            assert_int_equal(occ_map_check(&m), OCC_OK);
            assert_true(m.arena_bytes <= bytes);
            const occ_err_t e = occ_map_observe_key(&m, k, true);
            /* depth 16 needs 15 inner blocks and 1 leaf block for a first voxel */
            const bool fits = m.arena_bytes >= 15u * OCC_INNER_BLOCK_BYTES + OCC_LEAF_BLOCK_BYTES;
            assert_int_equal(e, fits ? OCC_OK : OCC_ERR_NOMEM);
            assert_int_equal(m.oom_count, fits ? 0u : 1u);
            occ_node_info_t info;
            assert_int_equal(occ_map_read_key(&m, k, 0u, &info), OCC_OK);
            assert_int_equal(info.state, fits ? OCC_STATE_OCCUPIED : OCC_STATE_UNKNOWN);
            assert_int_equal(occ_map_check(&m), OCC_OK);
            /* A whole-map write needs no block at all and always succeeds. */
            assert_int_equal(occ_map_set_key(&m, k, c.depth_levels, -1.0f), OCC_OK);
            assert_int_equal(occ_map_state_at(&m, (occ_vec3_t){0.0f, 0.0f, 0.0f}), OCC_STATE_FREE);
            assert_int_equal(occ_map_check(&m), OCC_OK);
            occ_map_clear(&m);
            assert_int_equal(m.inner.used + m.leaf.used, 0u);
        }
    }
    occ_map_t m;
    assert_int_equal(occ_map_init(&m, &c, NULL, 0u), OCC_OK);
    assert_int_equal(occ_map_observe_key(&m, k, false), OCC_ERR_NOMEM);
    assert_int_equal(occ_map_check(&m), OCC_OK);
    assert_int_equal(occ_map_init(&m, &c, NULL, 8u), OCC_ERR_ARG);
}

static void test_coordinates(void **state)
{
    (void)state;
    const float bad[] = {NAN, INFINITY, -INFINITY};
    const float res = map.cfg.resolution_m;
    const float edge = res * 32768.0f;
    occ_key_t k = mk(1, 2, 3);
    for (unsigned axis = 0; axis < 3u; axis++) {
        for (size_t i = 0; i < 3u; i++) {
            float p3[3] = {1.0f, -2.0f, 0.5f};
            p3[axis] = bad[i];
            const occ_vec3_t p = {p3[0], p3[1], p3[2]};
            snapshot();
            assert_int_equal(occ_map_key(&map, p, &k), OCC_ERR_ARG);
            assert_int_equal(occ_map_update(&map, p, 0.85f), OCC_ERR_ARG);
            occ_node_info_t info;
            assert_int_equal(occ_map_read(&map, p, 0u, &info), OCC_ERR_ARG);
            assert_int_equal(occ_map_state_at(&map, p), OCC_STATE_UNKNOWN);
            assert_unchanged("NaN/Inf coordinate");
        }
        const float out[] = {edge, edge * 1.5f, -edge * 1.0001f, 1e30f, -1e30f, 3.0e9f};
        for (size_t i = 0; i < sizeof out / sizeof out[0]; i++) {
            float p3[3] = {1.0f, -2.0f, 0.5f};
            p3[axis] = out[i];
            const occ_vec3_t p = {p3[0], p3[1], p3[2]};
            snapshot();
            assert_int_equal(occ_map_key(&map, p, &k), OCC_ERR_RANGE);
            assert_int_equal(occ_map_update(&map, p, -0.4f), OCC_ERR_RANGE);
            occ_node_info_t info;
            assert_int_equal(occ_map_read(&map, p, 3u, &info), OCC_ERR_RANGE);
            assert_int_equal(occ_map_state_at(&map, p), OCC_STATE_UNKNOWN);
            assert_unchanged("out-of-volume coordinate");
        }
    }
    /* The volume is [-2^(D-1) res, 2^(D-1) res) with res the decimal 0.1: the low edge
     * -3276.8 is inside. The float -edge = -32768 * 0.1f = -3276.80005 lies below it (outside,
     * as in OcTree(0.1)); the next float up, -3276.79980, is inside, in voxel 0. */
    const occ_vec3_t below = {-edge, 0.0f, 0.0f};
    assert_int_equal(occ_map_key(&map, below, &k), OCC_ERR_RANGE);
    const float lo_in = nextafterf(-edge, 0.0f);
    const occ_vec3_t lo = {lo_in, lo_in, lo_in};
    assert_int_equal(occ_map_key(&map, lo, &k), OCC_OK);
    assert_int_equal(k.k[0], 0u);
    assert_int_equal(k.k[2], 0u);
    const occ_vec3_t zero = {0.0f, -0.0f, -1e-7f};
    assert_int_equal(occ_map_key(&map, zero, &k), OCC_OK);
    assert_int_equal(k.k[0], 32768u);
    assert_int_equal(k.k[1], 32768u);
    assert_int_equal(k.k[2], 32767u);
    /* Node sizes and centres (hand-computed at res 0.1, depth 16). */
    for (unsigned level = 0; level <= 16u; level++) {
        const float want = 0.1f * (float)(1u << level);
        assert_true(fabsf(occ_map_node_size(&map, level) - want) <= 1e-6f * want);
    }
    const occ_vec3_t c0 = occ_map_key_center(&map, mk(32768u, 32767u, 0u), 0u);
    assert_true(fabsf(c0.x - 0.05f) < 1e-6f && fabsf(c0.y + 0.05f) < 1e-6f &&
                fabsf(c0.z + 3276.75f) < 1e-3f);
    const occ_vec3_t c16 = occ_map_key_center(&map, mk(5u, 60000u, 32768u), 16u);
    assert_true(fabsf(c16.x) < 1e-6f && fabsf(c16.y) < 1e-6f && fabsf(c16.z) < 1e-6f);
    const occ_vec3_t c2 = occ_map_key_center(&map, mk(32775u, 32768u, 32768u), 2u);
    assert_true(fabsf(c2.x - 0.6f) < 1e-6f && fabsf(c2.y - 0.2f) < 1e-6f);
    /* NULL out-pointers and maps. */
    assert_int_equal(occ_map_key(&map, zero, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_key(NULL, zero, &k), OCC_ERR_ARG);
    assert_int_equal(occ_map_read(&map, zero, 0u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_update(NULL, zero, 1.0f), OCC_ERR_ARG);
    assert_int_equal(occ_map_state_at(NULL, zero), OCC_STATE_UNKNOWN);
}

static void test_keys_and_levels(void **state)
{
    (void)state;
    const uint32_t lim = 1u << map.cfg.depth_levels;
    const occ_key_t bad_keys[] = {mk(lim, 0, 0), mk(0, lim, 0), mk(0, 0, lim), mk(UINT32_MAX, 5, 5),
                                  mk(1u << 21, 1, 1)};
    for (size_t i = 0; i < sizeof bad_keys / sizeof bad_keys[0]; i++) {
        const occ_key_t k = bad_keys[i];
        occ_node_info_t info;
        snapshot();
        assert_int_equal(occ_map_update_key(&map, k, 0.5f), OCC_ERR_RANGE);
        assert_int_equal(occ_map_observe_key(&map, k, true), OCC_ERR_RANGE);
        assert_int_equal(occ_map_set_key(&map, k, 0u, 1.0f), OCC_ERR_RANGE);
        assert_int_equal(occ_map_set_key(&map, k, 4u, 1.0f), OCC_ERR_RANGE);
        assert_int_equal(occ_map_forget_key(&map, k, 0u), OCC_ERR_RANGE);
        assert_int_equal(occ_map_read_key(&map, k, 0u, &info), OCC_ERR_RANGE);
        assert_unchanged("key outside the map");
    }
    const occ_key_t k = mk(32760u, 32768u, 32768u);
    occ_node_info_t info;
    snapshot();
    assert_int_equal(occ_map_update_key(&map, k, NAN), OCC_ERR_ARG);
    assert_int_equal(occ_map_set_key(&map, k, 0u, NAN), OCC_ERR_ARG);
    assert_int_equal(occ_map_set_key(&map, k, 17u, 1.0f), OCC_ERR_ARG);
    assert_int_equal(occ_map_set_key(&map, k, 200u, 1.0f), OCC_ERR_ARG);
    assert_int_equal(occ_map_forget_key(&map, k, 17u), OCC_ERR_ARG);
    assert_int_equal(occ_map_read_key(&map, k, 17u, &info), OCC_ERR_ARG);
    assert_int_equal(occ_map_read_key(&map, k, 0u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_read_key(NULL, k, 0u, &info), OCC_ERR_ARG);
    assert_int_equal(occ_map_update_key(NULL, k, 1.0f), OCC_ERR_ARG);
    assert_int_equal(occ_map_observe_key(NULL, k, true), OCC_ERR_ARG);
    assert_int_equal(occ_map_set_key(NULL, k, 0u, 1.0f), OCC_ERR_ARG);
    assert_int_equal(occ_map_forget_key(NULL, k, 0u), OCC_ERR_ARG);
    assert_int_equal(occ_map_check(NULL), OCC_ERR_ARG);
    assert_unchanged("NaN value, level above the root, NULL");
    /* The root level itself is valid. */
    assert_int_equal(occ_map_read_key(&map, k, 16u, &info), OCC_OK);
    assert_int_equal(info.level, 16u);
    assert_true(info.observed);
}

static void test_batch_errors(void **state)
{
    (void)state;
    const occ_code_t a = occ_morton_encode(mk(100, 200, 300));
    const occ_code_t b = occ_morton_encode(mk(101, 200, 300));
    const occ_code_t too_big = (occ_code_t)1 << 48; /* key >= 2^16 on z */
    const occ_code_t unsorted[] = {b, a | OCC_CODE_HIT_BIT};
    const occ_code_t dup[] = {a, a | OCC_CODE_HIT_BIT};
    const occ_code_t big[] = {a, too_big};
    size_t changed = 77u;
    snapshot();
    assert_int_equal(occ_map_observe_codes(&map, unsorted, 2u, &changed), OCC_ERR_ARG);
    assert_int_equal(changed, 0u);
    assert_int_equal(occ_map_observe_codes(&map, dup, 2u, NULL), OCC_ERR_ARG);
    const occ_err_t e = occ_map_observe_codes(&map, big, 2u, NULL);
    assert_true(e == OCC_ERR_ARG || e == OCC_ERR_RANGE);
    assert_int_equal(occ_map_observe_codes(&map, NULL, 3u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_observe_codes(NULL, unsorted, 1u, NULL), OCC_ERR_ARG);
    assert_unchanged("malformed batch");
    changed = 5u;
    assert_int_equal(occ_map_observe_codes(&map, NULL, 0u, &changed), OCC_OK);
    assert_int_equal(changed, 0u);
    assert_unchanged("empty batch");
}

/* state_at never says FREE by error: a map that is FREE everywhere, asked about bad points. */
static void test_state_never_free_by_error(void **state)
{
    (void)state;
    const occ_key_t k = mk(0, 0, 0);
    assert_int_equal(occ_map_set_key(&map, k, map.cfg.depth_levels, -1.0f), OCC_OK);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    const occ_vec3_t good = {1.0f, 2.0f, 3.0f};
    assert_int_equal(occ_map_state_at(&map, good), OCC_STATE_FREE);
    const occ_vec3_t nan = {NAN, 2.0f, 3.0f}, far = {1.0f, 1e6f, 3.0f};
    assert_int_equal(occ_map_state_at(&map, nan), OCC_STATE_UNKNOWN);
    assert_int_equal(occ_map_state_at(&map, far), OCC_STATE_UNKNOWN);
    /* A NaN log-odds is no evidence of free space either. */
    assert_true(occ_map_state_of(&map, NAN) != OCC_STATE_FREE);
    assert_int_equal(occ_map_state_of(&map, -1.0f), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_of(&map, 0.0f), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_state_of(NULL, -1.0f), OCC_STATE_UNKNOWN);
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    assert_int_equal(st.nodes, 1u);
    assert_int_equal(st.free_leaves, 1u);
    assert_int_equal(st.inner_used, 0u);
    assert_int_equal(st.leaf_used, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_err_str),
        cmocka_unit_test(test_init_bad_config),
        cmocka_unit_test(test_init_small_arena),
        cmocka_unit_test_setup_teardown(test_coordinates, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_keys_and_levels, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_batch_errors, setup_map, teardown_map),
        cmocka_unit_test_setup_teardown(test_state_never_free_by_error, setup_map, teardown_map),
    };
    return cmocka_run_group_tests_name("api_errors", tests, NULL, NULL);
}
