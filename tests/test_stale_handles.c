/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_stale_handles.c - issue 16, "fail closed", stale handles: handles that keep block indices
 * between calls (lookup cursor, volume iterator, nearest iterator, walk, node handle) answer
 * OCC_ERR_STATE after each kind of write instead of following stale indices (ASan watches the
 * reads); reads and refused writes keep them valid. The map: tests/support/failclosed_map.h.
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
#include "occmap/host/occ_collide_ccd.h"
#include "occmap/occ_evict.h"
#include "support/query_shapes.h"
#include "support/failclosed_map.h"

#define ARENA_BYTES OCC_ARENA_BYTES(4096, 4096)
static uint8_t arena[ARENA_BYTES];
static uint8_t scratch[1u << 20];
static uint8_t filebuf[1u << 16];
static occ_map_t map;

static void make_map(void)
{
    fc_make_map(&map, arena, sizeof arena);
}

static occ_key_t key_of(occ_vec3_t p)
{
    return fc_key_of(&map, p);
}

static int teardown(void **state)
{
    (void)state;
    return fc_forget_all(&map);
}

/* ---- stale handles --------------------------------------------------------------------------- */

typedef void (*write_fn)(void);

static void w_update(void)
{
    assert_int_equal(occ_map_update(&map, v3(-2.05f, 0.05f, 0.05f), 3.f), OCC_OK);
}

static void w_observe_key(void)
{
    assert_int_equal(occ_map_observe_key(&map, key_of(v3(0.05f, 2.05f, 0.05f)), false), OCC_OK);
}

static void w_observe_codes(void)
{
    const occ_code_t c = occ_morton_encode(key_of(v3(0.05f, 0.05f, -2.05f))) | OCC_CODE_HIT_BIT;
    assert_int_equal(occ_map_observe_codes(&map, &c, 1u, NULL), OCC_OK);
}

static void w_set(void) /* the level-3 node (0.8 m) holding P_OCC becomes free */
{
    assert_int_equal(occ_map_set_key(&map, key_of(P_OCC), 3u, -2.f), OCC_OK);
}

static void w_forget(void)
{
    assert_int_equal(occ_map_forget_key(&map, key_of(P_OCC), 0u), OCC_OK);
}

static void w_insert(void)
{
    occ_insert_params_t ip = occ_insert_params_default();
    const occ_vec3_t pts[2] = {{0.05f, 0.05f, 1.05f}, {0.55f, -0.35f, 0.85f}};
    occ_insert_result_t res;
    assert_int_equal(occ_map_insert_cloud(&map, &P_FREE, pts, 2u, &ip, scratch, sizeof scratch,
                                          &res), OCC_OK);
    assert_true(res.voxels_changed > 0u);
}

/* FAST_DISCRETE with n = 0 and a ray clipped at max range: only its coarse pass writes (the
 * level-1 nodes along the ray are cleared, no voxel batch follows). */
static void w_insert_fast(void)
{
    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_FAST_DISCRETE;
    ip.fast_d = 1u;
    ip.fast_n = 0u;
    ip.max_range_m = 0.5f;
    const occ_vec3_t far = {0.05f, 0.05f, 3.05f};
    occ_insert_result_t res;
    assert_int_equal(occ_map_insert_cloud(&map, &P_FREE, &far, 1u, &ip, scratch, sizeof scratch,
                                          &res), OCC_OK);
    assert_true(res.coarse_updated > 0u);
    assert_int_equal(res.voxels_updated, 0u);
}

static void w_evict(void) /* forget everything more than 0.5 m from (-3, -3, 0) */
{
    occ_evict_policy_t pol = occ_evict_policy_default();
    pol.keep_radius_m = 0.5f;
    occ_evict_out_t out;
    occ_evict_out_init(&out);
    const occ_vec3_t c = v3(-3.f, -3.f, 0.f);
    assert_int_equal(occ_map_evict(&map, &c, &pol, UINT32_MAX, &out), OCC_OK);
    assert_true(out.last_evictions > 0u);
}

static void w_clear(void)
{
    occ_map_clear(&map);
}

static void w_io_read(void) /* the same content, read back from a snapshot: new blocks */
{
    occ_io_buf_t b = {filebuf, sizeof filebuf, 0u};
    assert_int_equal(occ_io_write(&map, OCC_FORMAT_SNAPSHOT, occ_io_buf_write, &b, NULL), OCC_OK);
    assert_int_equal(occ_io_read(&map, filebuf, b.len, NULL), OCC_OK);
    assert_int_equal(occ_map_state_at(&map, P_OCC), OCC_STATE_OCCUPIED);
}

static void stale_lookup(write_fn write)
{
    make_map();
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    assert_int_equal(occ_lookup_state(&lk, P_OCC), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_lookup_status(&lk), OCC_OK);
    write();
    assert_int_equal(occ_lookup_status(&lk), OCC_ERR_STATE);
    /* The same voxel (the cached node) and another one (a descent from cached blocks). */
    assert_int_equal(occ_lookup_state(&lk, P_OCC), OCC_STATE_UNKNOWN);
    occ_state_t s = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_read(&lk, P_FREE, &s), OCC_ERR_STATE);
    assert_int_equal(s, OCC_STATE_UNKNOWN);
    /* A fresh cursor reads the new map. */
    occ_lookup_init(&lk, &map);
    assert_int_equal(occ_lookup_read(&lk, P_OCC, &s), OCC_OK);
    assert_int_equal(s, occ_map_state_at(&map, P_OCC));
}

static void stale_query(write_fn write)
{
    make_map();
    occ_volume_t v;
    assert_int_equal(occ_volume_sphere(&v, P_FREE, 1.5f), OCC_OK);
    const occ_pred_t pred = {(uint8_t)OCC_PRED_ANY, 0u, 0u};
    occ_query_iter_t it;
    occ_query_node_t n;
    assert_int_equal(occ_query_begin(&it, &map, &v, pred), OCC_OK);
    assert_true(occ_query_next(&it, &n));
    assert_int_equal(occ_query_status(&it), OCC_OK);
    write();
    assert_int_equal(occ_query_status(&it), OCC_ERR_STATE);
    assert_false(occ_query_next(&it, &n));
    assert_int_equal(occ_query_begin(&it, &map, &v, pred), OCC_OK);
    assert_true(occ_query_next(&it, &n)); /* the sphere meets some node of any map */
    assert_int_equal(occ_query_status(&it), OCC_OK);
}

static void stale_nearest(write_fn write)
{
    make_map();
    static occ_nearest_entry_t buf[512];
    const occ_pred_t pred = {(uint8_t)(OCC_PRED_OCCUPIED | OCC_PRED_UNKNOWN), 0u, 0u};
    occ_nearest_t it;
    occ_query_node_t n;
    bool found = false;
    assert_int_equal(occ_nearest_begin(&it, &map, P_FREE, 3.f, pred, buf, 512), OCC_OK);
    assert_int_equal(occ_nearest_next(&it, &n, NULL, &found), OCC_OK);
    assert_true(found);
    write();
    found = true;
    assert_int_equal(occ_nearest_next(&it, &n, NULL, &found), OCC_ERR_STATE);
    assert_false(found);
    assert_int_equal(occ_nearest_begin(&it, &map, P_FREE, 3.f, pred, buf, 512), OCC_OK);
    assert_int_equal(occ_nearest_next(&it, &n, NULL, &found), OCC_OK);
    assert_true(found); /* unknown space within 3 m on any of these maps */
}

static void stale_walk(write_fn write)
{
    make_map();
    occ_walk_t w;
    occ_walk_node_t n;
    occ_walk_begin(&w, &map);
    assert_true(occ_walk_next(&w, &n));
    assert_true(occ_walk_next(&w, &n));
    assert_int_equal(occ_walk_status(&w), OCC_OK);
    write();
    assert_int_equal(occ_walk_status(&w), OCC_ERR_STATE);
    assert_false(occ_walk_next(&w, &n));
    occ_walk_begin(&w, &map);
    while (occ_walk_next(&w, &n)) {
    }
    assert_int_equal(occ_walk_status(&w), OCC_OK);
}

static unsigned slot_of(occ_key_t k, unsigned level) /* child slot at `level` - 1 */
{
    return ((k.k[0] >> (level - 1u)) & 1u) | (((k.k[1] >> (level - 1u)) & 1u) << 1) |
           (((k.k[2] >> (level - 1u)) & 1u) << 2);
}

static void stale_node(write_fn write)
{
    make_map();
    const occ_key_t k = key_of(P_OCC);
    occ_node_t root, child, grandchild;
    occ_map_node_root(&map, &root);
    assert_int_equal(occ_map_node_child(&map, &root, slot_of(k, 16u), &child), OCC_OK);
    assert_true(child.children != OCC_NONE);
    write();
    memset(&grandchild, 0x5A, sizeof grandchild);
    assert_int_equal(occ_map_node_child(&map, &child, slot_of(k, 15u), &grandchild),
                     OCC_ERR_STATE);
    fc_assert_unknown_node(&grandchild);
    /* The unknown answer is itself stale: nothing below it is followed either. */
    assert_int_equal(occ_map_node_child(&map, &grandchild, 0u, &grandchild), OCC_ERR_STATE);
    fc_assert_unknown_node(&grandchild);
    assert_int_equal(occ_map_node_child(&map, &root, 0u, &root), OCC_ERR_STATE); /* aliased */
    fc_assert_unknown_node(&root);
    occ_map_node_root(&map, &root);
    assert_int_equal(occ_map_node_child(&map, &root, slot_of(k, 16u), &child), OCC_OK);
}

static void stale_all(write_fn write)
{
    stale_lookup(write);
    stale_query(write);
    stale_nearest(write);
    stale_walk(write);
    stale_node(write);
}

#define STALE_TEST(name, fn)                  \
    static void name(void **state)            \
    {                                         \
        (void)state;                          \
        stale_all(fn);                        \
    }
STALE_TEST(test_stale_after_update, w_update)
STALE_TEST(test_stale_after_observe_key, w_observe_key)
STALE_TEST(test_stale_after_observe_codes, w_observe_codes)
STALE_TEST(test_stale_after_set, w_set)
STALE_TEST(test_stale_after_forget, w_forget)
STALE_TEST(test_stale_after_insert, w_insert)
STALE_TEST(test_stale_after_insert_fast_discrete, w_insert_fast)
STALE_TEST(test_stale_after_evict, w_evict)
STALE_TEST(test_stale_after_clear, w_clear)
STALE_TEST(test_stale_after_io_read, w_io_read)

/* Reads, and writes refused before they touch the tree, leave every handle valid. */
static void test_reads_and_refused_writes_keep_handles(void **state)
{
    (void)state;
    make_map();
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    assert_int_equal(occ_lookup_state(&lk, P_OCC), OCC_STATE_OCCUPIED);
    occ_walk_t w;
    occ_walk_node_t wn;
    occ_walk_begin(&w, &map);
    assert_true(occ_walk_next(&w, &wn));
    const uint32_t gen = map.write_gen;

    occ_collision_t col;
    occ_map_stats_t st;
    occ_nearest_entry_t buf[64];
    float d;
    occ_obstacle_t r;
    occ_io_buf_t b = {filebuf, sizeof filebuf, 0u};
    assert_int_equal(occ_collide_sphere(&map, P_OCC, 0.5f, OCC_UNKNOWN_SAFE, &col), OCC_OK);
    assert_int_equal(occ_distance_to_obstacle(&map, P_FREE, 2.f, OCC_UNKNOWN_SAFE, buf, 64, &d, &r),
                     OCC_OK);
    occ_map_stats(&map, &st);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    assert_int_equal(occ_io_write(&map, OCC_FORMAT_SNAPSHOT, occ_io_buf_write, &b, NULL), OCC_OK);

    occ_key_t far = key_of(P_OCC);
    far.k[0] = 1u << 16;
    const occ_code_t c_occ = occ_morton_encode(key_of(P_OCC));
    const occ_code_t c_free = occ_morton_encode(key_of(P_FREE));
    const occ_code_t descending[2] = {c_occ > c_free ? c_occ : c_free,
                                      c_occ > c_free ? c_free : c_occ};
    assert_int_equal(occ_map_update(&map, P_OCC, NAN), OCC_ERR_ARG);
    assert_int_equal(occ_map_update(&map, v3(1e9f, 0.f, 0.f), 1.f), OCC_ERR_RANGE);
    assert_int_equal(occ_map_observe_key(&map, far, true), OCC_ERR_RANGE);
    assert_int_equal(occ_map_observe_codes(&map, descending, 2u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_set_key(&map, key_of(P_OCC), 17u, 1.f), OCC_ERR_ARG);
    assert_int_equal(occ_map_forget_key(&map, far, 0u), OCC_ERR_RANGE);
    assert_int_equal(occ_io_read(&map, filebuf, 10u, NULL), OCC_ERR_FORMAT);
    occ_evict_policy_t pol = occ_evict_policy_default();
    pol.keep_radius_m = 100.f; /* everything protected: nothing to evict */
    occ_evict_out_t eo;
    occ_evict_out_init(&eo);
    assert_int_equal(occ_map_evict(&map, &P_FREE, &pol, 4000u, &eo), OCC_OK);
    assert_int_equal(eo.last_evictions, 0u);

    assert_int_equal(map.write_gen, gen);
    assert_int_equal(occ_lookup_status(&lk), OCC_OK);
    assert_int_equal(occ_lookup_state(&lk, P_OCC), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_walk_status(&w), OCC_OK);
    assert_true(occ_walk_next(&w, &wn));
}

/* occ_lookup_read names the error occ_lookup_state hides, with UNKNOWN; NULL handles are ARG. */
static void test_lookup_read_errors(void **state)
{
    (void)state;
    make_map();
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    occ_state_t s = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_read(&lk, v3(NAN, 0.f, 0.f), &s), OCC_ERR_ARG);
    assert_int_equal(s, OCC_STATE_UNKNOWN);
    s = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_read(&lk, v3(0.f, 0.f, INFINITY), &s), OCC_ERR_ARG);
    assert_int_equal(s, OCC_STATE_UNKNOWN);
    s = OCC_STATE_FREE;
    assert_int_equal(occ_lookup_read(&lk, v3(0.f, 3276.8f, 0.f), &s), OCC_ERR_RANGE); /* edge */
    assert_int_equal(s, OCC_STATE_UNKNOWN);
    assert_int_equal(occ_lookup_read(&lk, P_FREE, &s), OCC_OK);
    assert_int_equal(s, OCC_STATE_FREE);
    assert_int_equal(occ_lookup_read(&lk, P_OCC, NULL), OCC_OK);
    assert_int_equal(occ_lookup_read(NULL, P_OCC, &s), OCC_ERR_ARG);
    assert_int_equal(s, OCC_STATE_UNKNOWN);
    assert_int_equal(occ_lookup_state(NULL, P_OCC), OCC_STATE_UNKNOWN);
    assert_int_equal(occ_lookup_status(NULL), OCC_ERR_ARG);
    assert_int_equal(occ_query_status(NULL), OCC_ERR_ARG);
    assert_int_equal(occ_walk_status(NULL), OCC_ERR_ARG);
    occ_query_node_t n;
    bool found = true;
    assert_int_equal(occ_nearest_next(NULL, &n, NULL, &found), OCC_ERR_ARG);
    assert_false(found);
}

/* An iterator whose begin was refused (the error ignored) reports nothing and reads nothing,
 * whatever the caller's memory held before. */
static void test_refused_iterators_report_nothing(void **state)
{
    (void)state;
    make_map();
    occ_volume_t v;
    assert_int_equal(occ_volume_sphere(&v, P_FREE, 1.f), OCC_OK);
    occ_query_iter_t it;
    memset(&it, 0x5A, sizeof it);
    const occ_pred_t bad = {0x10u, 0u, 0u};
    assert_int_equal(occ_query_begin(&it, &map, &v, bad), OCC_ERR_ARG);
    occ_query_node_t n;
    assert_false(occ_query_next(&it, &n));
    assert_int_equal(occ_query_status(&it), OCC_ERR_ARG);
    occ_nearest_t nit;
    memset(&nit, 0x5A, sizeof nit);
    occ_nearest_entry_t buf[8];
    const occ_pred_t any = {0u, 0u, 0u};
    assert_int_equal(occ_nearest_begin(&nit, &map, P_FREE, -1.f, any, buf, 8), OCC_ERR_ARG);
    bool found = true;
    assert_int_equal(occ_nearest_next(&nit, &n, NULL, &found), OCC_ERR_ARG);
    assert_false(found);
}

/* The bug the generation guards against: a cursor kept over occ_map_clear() and a refill of the
 * arena with other content. Random refills; ASan would see a read outside the arena if a stale
 * index were followed, and the answers must be UNKNOWN / done. Seed printed, OCC_SEED repeats. */
static void test_stale_over_refill(void **state)
{
    (void)state;
    uint64_t rng = qs_seed("test_failclosed refill");
    static occ_nearest_entry_t buf[4096];
    for (unsigned round = 0; round < 20u; round++) {
        make_map();
        for (unsigned i = 0; i < 200u; i++) { /* deep, scattered content */
            const occ_vec3_t p = v3((float)qs_uniform(&rng, -50, 50), (float)qs_uniform(&rng, -50, 50),
                                    (float)qs_uniform(&rng, -5, 5));
            assert_int_equal(occ_map_update(&map, p, (i % 2u) != 0u ? 2.f : -1.f), OCC_OK);
        }
        occ_lookup_t lk;
        occ_lookup_init(&lk, &map);
        (void)occ_lookup_state(&lk, P_OCC);
        occ_walk_t w;
        occ_walk_node_t wn;
        occ_walk_begin(&w, &map);
        for (unsigned i = 0; i < 40u && occ_walk_next(&w, &wn); i++) {
        }
        occ_nearest_t nit;
        occ_query_node_t qn;
        bool found;
        const occ_pred_t pred = {(uint8_t)OCC_PRED_OCCUPIED, 0u, 0u};
        assert_int_equal(occ_nearest_begin(&nit, &map, P_FREE, 100.f, pred, buf, 4096), OCC_OK);
        assert_int_equal(occ_nearest_next(&nit, &qn, NULL, &found), OCC_OK);
        occ_map_clear(&map);
        for (unsigned i = 0; i < 200u; i++) { /* the same blocks, other meaning */
            const occ_vec3_t p = v3((float)qs_uniform(&rng, -3, 3), (float)qs_uniform(&rng, -3, 3),
                                    (float)qs_uniform(&rng, -3, 3));
            assert_int_equal(occ_map_update(&map, p, 2.f), OCC_OK);
        }
        for (unsigned i = 0; i < 100u; i++) {
            const occ_vec3_t p = v3((float)qs_uniform(&rng, -50, 50), (float)qs_uniform(&rng, -50, 50),
                                    (float)qs_uniform(&rng, -5, 5));
            assert_int_equal(occ_lookup_state(&lk, p), OCC_STATE_UNKNOWN);
        }
        unsigned steps = 0;
        while (occ_walk_next(&w, &wn)) {
            steps++;
        }
        assert_int_equal(steps, 0u);
        assert_int_equal(occ_walk_status(&w), OCC_ERR_STATE);
        assert_int_equal(occ_nearest_next(&nit, &qn, NULL, &found), OCC_ERR_STATE);
        assert_false(found);
        assert_int_equal(occ_map_check(&map), OCC_OK);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_stale_after_update, teardown),
        cmocka_unit_test_teardown(test_stale_after_observe_key, teardown),
        cmocka_unit_test_teardown(test_stale_after_observe_codes, teardown),
        cmocka_unit_test_teardown(test_stale_after_set, teardown),
        cmocka_unit_test_teardown(test_stale_after_forget, teardown),
        cmocka_unit_test_teardown(test_stale_after_insert, teardown),
        cmocka_unit_test_teardown(test_stale_after_insert_fast_discrete, teardown),
        cmocka_unit_test_teardown(test_stale_after_evict, teardown),
        cmocka_unit_test_teardown(test_stale_after_clear, teardown),
        cmocka_unit_test_teardown(test_stale_after_io_read, teardown),
        cmocka_unit_test_teardown(test_reads_and_refused_writes_keep_handles, teardown),
        cmocka_unit_test_teardown(test_lookup_read_errors, teardown),
        cmocka_unit_test_teardown(test_refused_iterators_report_nothing, teardown),
        cmocka_unit_test_teardown(test_stale_over_refill, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
