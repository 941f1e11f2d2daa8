/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_query.c - the volume iterator, voxel counts, nearest-first search and information gain
 * against brute-force references (tests/support/oracle_query.cpp: Eigen geometry, every cell
 * enumerated) on random maps and random volumes: straddling node borders, outside the map,
 * covering the whole map. Random seed printed, OCC_SEED to repeat.
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
#include "support/oracle_query.h"
#include "support/query_shapes.h"

#define ARENA_BYTES (4u << 20)
#define MAX_CELLS 300000u

static uint8_t arena[ARENA_BYTES];
static occ_map_t map;
static uint64_t rng;
static uint64_t *ocodes, *qcodes;
static uint8_t *oamb;

static void make_map(float res, uint8_t depth, uint64_t seed, unsigned voxels)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = res;
    cfg.depth_levels = depth;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    assert_int_equal(oracle_q_random_map(&map, seed, voxels), OCC_OK);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static int setup(void **state)
{
    (void)state;
    ocodes = malloc(MAX_CELLS * sizeof *ocodes);
    qcodes = malloc(MAX_CELLS * sizeof *qcodes);
    oamb = malloc(MAX_CELLS);
    rng = qs_seed("test_query");
    return ocodes == NULL || qcodes == NULL || oamb == NULL;
}

static int teardown(void **state)
{
    (void)state;
    free(ocodes);
    free(qcodes);
    free(oamb);
    return 0;
}

static occ_code_t cell_code(occ_key_t k) { return occ_morton_encode(k); }

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* Compare sorted core cells with sorted oracle cells; ambiguous oracle cells may be missing,
 * core cells absent from the oracle list must be geometrically ambiguous. */
static void compare_sets(const qs_shape_t *s, size_t nq, size_t no, unsigned level,
                         const char *what)
{
    size_t i = 0, j = 0;
    while (i < nq || j < no) {
        if (j < no && (i == nq || ocodes[j] < qcodes[i])) {
            if (!oamb[j]) {
                occ_key_t k = occ_morton_decode(ocodes[j]);
                fail_msg("%s %s: oracle cell %u,%u,%u (level %u) not reported", what, s->desc,
                         k.k[0], k.k[1], k.k[2], level);
            }
            j++;
        } else if (i < nq && (j == no || qcodes[i] < ocodes[j])) {
            occ_key_t k = occ_morton_decode(qcodes[i]);
            const int g = oracle_q_cell(s->oracle, &map, k, level);
            if (g != -1) {
                fail_msg("%s %s: core reported cell %u,%u,%u (level %u), oracle says %d", what,
                         s->desc, k.k[0], k.k[1], k.k[2], level, g);
            }
            i++;
        } else {
            i++;
            j++;
        }
    }
}

/* Iterate with OCC_ITER_SPLIT at `level` and `states`: the cells must be the oracle's. */
static void check_split(const qs_shape_t *s, unsigned states, unsigned level)
{
    occ_pred_t pred = {(uint8_t)states, (uint8_t)level, (uint8_t)OCC_ITER_SPLIT};
    occ_query_iter_t it;
    assert_int_equal(occ_query_begin(&it, &map, &s->vol, pred), OCC_OK);
    occ_query_node_t n;
    size_t nq = 0;
    occ_code_t last = 0;
    bool first = true;
    while (occ_query_next(&it, &n)) {
        const occ_code_t code = occ_morton_encode(n.key);
        if (!first && code <= last) {
            fail_msg("%s: not in Morton order", s->desc);
        }
        first = false;
        last = code;
        assert_true(n.level >= level);
        if (n.level > level) {
            assert_true(n.uniform && n.inside);
        }
        /* The reported state must be wanted (uniform) or contained (mixed cells). */
        if (n.uniform) {
            const unsigned bit = n.state == OCC_STATE_OCCUPIED ? OCC_PRED_OCCUPIED
                                 : n.state == OCC_STATE_FREE   ? OCC_PRED_FREE
                                                               : OCC_PRED_UNKNOWN;
            assert_true((bit & states) != 0u);
        }
        const uint32_t span = 1u << (n.level - level);
        for (uint32_t d = 0; d < span * span * span; d++) {
            occ_key_t k = n.key;
            k.k[0] += (d % span) << level;
            k.k[1] += ((d / span) % span) << level;
            k.k[2] += (d / (span * span)) << level;
            assert_true(nq < MAX_CELLS);
            qcodes[nq++] = cell_code(k);
        }
    }
    qsort(qcodes, nq, sizeof *qcodes, cmp_u64);
    const size_t no = oracle_q_collect(&map, s->oracle, states, level, ocodes, oamb, MAX_CELLS);
    assert_true(no <= MAX_CELLS);
    char what[64];
    snprintf(what, sizeof what, "split states %u level %u", states, level);
    compare_sets(s, nq, no, level, what);
}

/* Without OCC_ITER_SPLIT at level 0: each uniform node reported once; the voxels of the reported
 * nodes that intersect the volume are exactly the oracle's. */
static void check_nosplit(const qs_shape_t *s, unsigned states)
{
    occ_pred_t pred = {(uint8_t)states, 0u, 0u};
    occ_query_iter_t it;
    assert_int_equal(occ_query_begin(&it, &map, &s->vol, pred), OCC_OK);
    occ_query_node_t n;
    size_t nq = 0;
    bool big = false;
    while (occ_query_next(&it, &n)) {
        assert_true(n.uniform);
        assert_int_not_equal(oracle_q_cell(s->oracle, &map, n.key, n.level), 0);
        occ_node_info_t info;
        assert_int_equal(occ_map_read_key(&map, n.key, n.level, &info), OCC_OK);
        assert_int_equal(info.state, n.state);
        if (n.level > 4u) {
            big = true;
            continue;
        }
        const uint32_t span = 1u << n.level;
        for (uint32_t d = 0; d < span * span * span; d++) {
            occ_key_t k = n.key;
            k.k[0] += d % span;
            k.k[1] += (d / span) % span;
            k.k[2] += d / (span * span);
            if (oracle_q_cell(s->oracle, &map, k, 0) == 1) {
                assert_true(nq < MAX_CELLS);
                qcodes[nq++] = cell_code(k);
            }
        }
    }
    if (big) {
        return;
    }
    qsort(qcodes, nq, sizeof *qcodes, cmp_u64);
    const size_t no = oracle_q_collect(&map, s->oracle, states, 0, ocodes, oamb, MAX_CELLS);
    /* Core list holds only definite voxels here: drop ambiguous oracle ones by marking. */
    compare_sets(s, nq, no, 0, "nosplit");
}

static void check_counts(const qs_shape_t *s)
{
    occ_query_counts_t c;
    assert_int_equal(occ_query_count(&map, &s->vol, &c), OCC_OK);
    uint64_t oc[3], amb;
    oracle_q_count(&map, s->oracle, oc, &amb);
    const uint64_t got[3] = {c.occupied, c.free, c.unknown};
    for (int i = 0; i < 3; i++) {
        if (got[i] < oc[i] || got[i] > oc[i] + amb) {
            fail_msg("count %s: state %d core %llu oracle %llu (+%llu ambiguous)", s->desc, i,
                     (unsigned long long)got[i], (unsigned long long)oc[i],
                     (unsigned long long)amb);
        }
    }
}

static void check_gain(const qs_shape_t *s, unsigned level)
{
    occ_info_gain_t g;
    assert_int_equal(occ_info_gain(&map, &s->vol, level, 0u, &g), OCC_OK);
    uint64_t def, amb;
    oracle_q_gain(&map, s->oracle, level, &def, &amb);
    if (g.unknown_cells < def || g.unknown_cells > def + amb) {
        fail_msg("gain %s level %u: core %llu oracle %llu (+%llu)", s->desc, level,
                 (unsigned long long)g.unknown_cells, (unsigned long long)def,
                 (unsigned long long)amb);
    }
    /* Unobserved cells carry one bit each. */
    assert_true(fabsf(g.entropy_bits - (float)g.unknown_cells) <= 1e-3f * (float)g.unknown_cells + 1e-3f);
}

static void random_volumes(float res, uint8_t depth, unsigned n_volumes)
{
    const uint64_t seed = qs_rand(&rng);
    make_map(res, depth, seed, 1500u);
    const double half = (double)res * (double)(1u << (depth - 1u));
    for (unsigned v = 0; v < n_volumes; v++) {
        qs_shape_t s;
        const int kind = (int)(v % 6u);
        const double reach = v % 10u == 9u ? 2.0 * half : half * 0.8;
        assert_true(qs_random_shape(&rng, &map, kind, reach, half * 0.6, &s));
        for (unsigned t = 0; t < 2u; t++) {
            const unsigned states = 1u + (unsigned)(qs_rand(&rng) % 7u);
            const unsigned level = (unsigned)(qs_rand(&rng) % (t == 0u ? 3u : 5u));
            check_split(&s, states, level);
        }
        check_nosplit(&s, 1u + (unsigned)(qs_rand(&rng) % 7u));
        check_counts(&s);
        check_gain(&s, (unsigned)(qs_rand(&rng) % 3u));
        qs_free(&s);
    }
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static void test_random_volumes_pow2(void **state)
{
    (void)state;
    random_volumes(0.25f, 6u, 60u);
}

static void test_random_volumes_res01(void **state)
{
    (void)state;
    random_volumes(0.1f, 6u, 36u);
}

/* Whole-map and off-map volumes. */
static void test_whole_and_outside(void **state)
{
    (void)state;
    make_map(0.25f, 5u, qs_rand(&rng), 800u);
    const double mn[3] = {-9, -9, -9}, mx[3] = {9, 9, 9};
    qs_shape_t s;
    s.oracle = oracle_q_aabb(mn, mx);
    snprintf(s.desc, sizeof s.desc, "whole-map aabb");
    const occ_vec3_t a = {-9.f, -9.f, -9.f}, b = {9.f, 9.f, 9.f};
    assert_int_equal(occ_volume_aabb(&s.vol, a, b), OCC_OK);
    for (unsigned st = 1; st < 8u; st++) {
        check_split(&s, st, 0);
        check_split(&s, st, 2);
    }
    occ_query_counts_t c;
    assert_int_equal(occ_query_count(&map, &s.vol, &c), OCC_OK);
    assert_true(c.outside);
    assert_true(c.occupied + c.free + c.unknown == (uint64_t)32 * 32 * 32);
    qs_free(&s);

    const double cc[3] = {0, 0, 0};
    s.oracle = oracle_q_sphere(cc, 30.0);
    const occ_vec3_t z = {0.f, 0.f, 0.f};
    assert_int_equal(occ_volume_sphere(&s.vol, z, 30.f), OCC_OK);
    check_split(&s, OCC_PRED_ANY, 0);
    check_nosplit(&s, OCC_PRED_FREE);
    qs_free(&s);

    const double far[3] = {50, 50, 50};
    s.oracle = oracle_q_sphere(far, 1.0);
    const occ_vec3_t f = {50.f, 50.f, 50.f};
    assert_int_equal(occ_volume_sphere(&s.vol, f, 1.f), OCC_OK);
    occ_query_iter_t it;
    occ_pred_t pred = {0u, 0u, 0u};
    assert_int_equal(occ_query_begin(&it, &map, &s.vol, pred), OCC_OK);
    occ_query_node_t n;
    assert_false(occ_query_next(&it, &n));
    qs_free(&s);
}

/* An empty map is one uniform unknown root; a uniform free map one free root. */
static void test_uniform_root(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 4;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    occ_volume_t v;
    const occ_vec3_t c = {0.05f, 0.05f, 0.05f};
    assert_int_equal(occ_volume_sphere(&v, c, 0.12f), OCC_OK);
    occ_query_iter_t it;
    occ_pred_t pred = {OCC_PRED_UNKNOWN, 0u, 0u};
    occ_query_node_t n;
    assert_int_equal(occ_query_begin(&it, &map, &v, pred), OCC_OK);
    assert_true(occ_query_next(&it, &n));
    assert_int_equal(n.level, 4);
    assert_false(n.observed);
    assert_false(occ_query_next(&it, &n));
    /* Split: the voxels within 0.12 m of (0.05,0.05,0.05): the 3x3x3 block around it minus the
     * 8 corners (corner distance 0.1*sqrt(3)=0.173 > 0.12, edge 0.141 > 0.12? -> no: face-edge
     * voxels at distance sqrt(0.05^2*... ) computed by hand: centre voxel 0, 6 face neighbours
     * at 0.0, 12 edge neighbours at sqrt(2)*0.05 = 0.0707, 8 corners at sqrt(3)*0.05 = 0.0866;
     * all 27 are within 0.12, next ring at >= 0.15. */
    pred.options = OCC_ITER_SPLIT;
    assert_int_equal(occ_query_begin(&it, &map, &v, pred), OCC_OK);
    unsigned cnt = 0;
    while (occ_query_next(&it, &n)) {
        cnt += n.inside ? (1u << (3u * n.level)) : 1u;
    }
    assert_int_equal(cnt, 27);
    occ_query_counts_t qc;
    assert_int_equal(occ_query_count(&map, &v, &qc), OCC_OK);
    assert_int_equal(qc.unknown, 27);
    assert_int_equal(qc.free + qc.occupied, 0);
    occ_info_gain_t g;
    assert_int_equal(occ_info_gain(&map, &v, 0, 0, &g), OCC_OK);
    assert_int_equal(g.unknown_cells, 27);
    assert_true(fabsf(g.entropy_bits - 27.0f) < 1e-4f);
    assert_int_equal(occ_info_gain(&map, &v, 1, 0, &g), OCC_OK);
    assert_int_equal(g.unknown_cells, 8); /* the 8 level-1 cells around the origin corner */
    /* Occlusion: nothing occupied yet, every cell is seen; then a wall of occupied voxels at
     * x = 0.1..0.2 hides the cells behind it from the sphere's centre. */
    assert_int_equal(occ_info_gain(&map, &v, 0, OCC_GAIN_OCCLUSION, &g), OCC_OK);
    assert_int_equal(g.unknown_cells, 27);
    for (uint32_t y = 0; y < 16u; y++) {
        for (uint32_t z = 0; z < 16u; z++) {
            const occ_key_t k = {{9u, y, z}};
            assert_int_equal(occ_map_set_key(&map, k, 0, 2.0f), OCC_OK);
        }
    }
    assert_int_equal(occ_info_gain(&map, &v, 0, 0, &g), OCC_OK);
    assert_int_equal(g.unknown_cells, 18); /* the 9 wall voxels are no longer unknown */
    assert_int_equal(occ_info_gain(&map, &v, 0, OCC_GAIN_OCCLUSION, &g), OCC_OK);
    assert_int_equal(g.unknown_cells, 18); /* the wall is the far layer: nothing behind it */
    v.u.sphere.r = 0.25f;
    v.bmin.x = v.bmin.y = v.bmin.z = 0.05f - 0.25f;
    v.bmax.x = v.bmax.y = v.bmax.z = 0.05f + 0.25f;
    occ_info_gain_t all;
    assert_int_equal(occ_info_gain(&map, &v, 0, 0, &all), OCC_OK);
    assert_int_equal(occ_info_gain(&map, &v, 0, OCC_GAIN_OCCLUSION, &g), OCC_OK);
    assert_true(g.unknown_cells < all.unknown_cells); /* cells at x >= 0.2 are behind the wall */
}

static void test_nearest(void **state)
{
    (void)state;
    make_map(0.25f, 5u, qs_rand(&rng), 600u);
    static occ_nearest_entry_t buf[4096];
    for (unsigned t = 0; t < 40u; t++) {
        const double p[3] = {qs_uniform(&rng, -5, 5), qs_uniform(&rng, -5, 5), qs_uniform(&rng, -5, 5)};
        const occ_vec3_t pf = {(float)p[0], (float)p[1], (float)p[2]};
        const unsigned states = t % 2u ? OCC_PRED_OCCUPIED : (OCC_PRED_OCCUPIED | OCC_PRED_UNKNOWN);
        const double od2 = oracle_q_nearest_d2(&map, p, states);
        occ_nearest_t it;
        occ_pred_t pred = {(uint8_t)states, 0u, 0u};
        assert_int_equal(occ_nearest_begin(&it, &map, pf, 100.f, pred, buf, 4096), OCC_OK);
        occ_query_node_t n;
        float d = 0, last = 0;
        bool found = false;
        unsigned k = 0;
        for (;;) {
            assert_int_equal(occ_nearest_next(&it, &n, &d, &found), OCC_OK);
            if (!found) break;
            if (k == 0u) {
                assert_true(od2 >= 0);
                if (fabs((double)d - sqrt(od2)) > 1e-4) {
                    fail_msg("nearest from %f,%f,%f: core %f oracle %f", p[0], p[1], p[2], (double)d, sqrt(od2));
                }
            }
            assert_true(d >= last - 1e-6f);
            last = d;
            if (++k > 50u) break;
        }
        if (k == 0u) {
            assert_true(od2 < 0);
        }
        /* Bounded: nothing beyond max distance. */
        occ_obstacle_t res = OCC_OBSTACLE_UNDECIDED;
        float dd = -1.f;
        assert_int_equal(occ_distance_to_obstacle(&map, pf, 0.3f,
                                                  t % 2u ? OCC_UNKNOWN_SAFE : OCC_UNKNOWN_UNSAFE,
                                                  buf, 4096, &dd, &res), OCC_OK);
        assert_true(res == OCC_OBSTACLE_FOUND || res == OCC_OBSTACLE_NONE);
        const bool f2 = res == OCC_OBSTACLE_FOUND;
        assert_true(f2 == (od2 >= 0 && sqrt(od2) <= 0.3 + 1e-5) || fabs(sqrt(od2) - 0.3) < 1e-4);
        if (f2) { /* the same distance as the nearest-first walk with the same predicate */
            assert_true(fabs((double)dd - sqrt(od2)) < 1e-4);
        } else {
            assert_true(!(dd < 0.3f) && !(dd > 0.3f)); /* max_dist: nothing nearer */
        }
    }
    /* A buffer of 1 overflows at the first expansion. */
    occ_nearest_t it;
    occ_pred_t pred = {OCC_PRED_OCCUPIED, 0u, 0u};
    const occ_vec3_t o = {0.f, 0.f, 0.f};
    assert_int_equal(occ_nearest_begin(&it, &map, o, 100.f, pred, buf, 1), OCC_OK);
    occ_query_node_t n;
    bool found;
    assert_int_equal(occ_nearest_next(&it, &n, NULL, &found), OCC_ERR_NOMEM);
}

/* The cached lookup answers exactly as occ_map_state_at, for jumps and for small steps; both
 * share their descent, so occ_map_state_at is held to occ_map_read (Morton codes, full entries). */
static void test_lookup_cursor(void **state)
{
    (void)state;
    make_map(0.1f, 7u, qs_rand(&rng), 3000u);
    occ_lookup_t lk;
    occ_lookup_init(&lk, &map);
    occ_vec3_t p = {0.f, 0.f, 0.f};
    unsigned n_occ = 0;
    for (unsigned i = 0; i < 200000u; i++) {
        if (i % 1000u == 0u) { /* jump, sometimes off the map */
            p.x = (float)qs_uniform(&rng, -7, 7);
            p.y = (float)qs_uniform(&rng, -7, 7);
            p.z = (float)qs_uniform(&rng, -7, 7);
        } else {
            p.x += (float)qs_uniform(&rng, -0.07, 0.07);
            p.y += (float)qs_uniform(&rng, -0.07, 0.07);
            p.z += (float)qs_uniform(&rng, -0.07, 0.07);
        }
        const occ_state_t want = occ_map_state_at(&map, p);
        occ_node_info_t info;
        const occ_state_t read = occ_map_read(&map, p, 0u, &info) == OCC_OK ? info.state
                                                                            : OCC_STATE_UNKNOWN;
        if (read != want) {
            fail_msg("lookup %u at %f,%f,%f: occ_map_read %d, occ_map_state_at %d", i,
                     (double)p.x, (double)p.y, (double)p.z, read, want);
        }
        const occ_state_t got = occ_lookup_state(&lk, p);
        if (got != want) {
            fail_msg("lookup %u at %f,%f,%f: cursor %d, occ_map_state_at %d", i, (double)p.x,
                     (double)p.y, (double)p.z, got, want);
        }
        n_occ += want == OCC_STATE_OCCUPIED;
    }
    const occ_vec3_t bad = {NAN, 0.f, 0.f};
    assert_int_equal(occ_lookup_state(&lk, bad), OCC_STATE_UNKNOWN);
    assert_true(n_occ > 0u);
}

static void test_bad_input(void **state)
{
    (void)state;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = 5;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    occ_volume_t v;
    const occ_vec3_t z = {0, 0, 0}, one = {1, 1, 1}, nan3 = {NAN, 0, 0}, inf3 = {0, INFINITY, 0};
    assert_int_equal(occ_volume_sphere(&v, z, -1.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_sphere(&v, nan3, 1.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_sphere(&v, z, NAN), OCC_ERR_ARG);
    assert_int_equal(occ_volume_sphere(NULL, z, 1.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_aabb(&v, one, z), OCC_ERR_ARG);
    assert_int_equal(occ_volume_aabb(&v, inf3, one), OCC_ERR_ARG);
    assert_int_equal(occ_volume_capsule(&v, z, one, -0.1f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_segment(&v, z, nan3), OCC_ERR_ARG);
    const float half[3] = {1, 1, 1}, neg[3] = {1, -1, 1};
    const occ_vec3_t good[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const occ_vec3_t skew[3] = {{1, 0, 0}, {0.7071f, 0.7071f, 0}, {0, 0, 1}};
    const occ_vec3_t zero[3] = {{1, 0, 0}, {0, 0, 0}, {0, 0, 1}};
    const occ_vec3_t longa[3] = {{2, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    assert_int_equal(occ_volume_obb(&v, z, half, good), OCC_OK);
    assert_int_equal(occ_volume_obb(&v, z, neg, good), OCC_ERR_ARG);
    assert_int_equal(occ_volume_obb(&v, z, half, skew), OCC_ERR_ARG);
    assert_int_equal(occ_volume_obb(&v, z, half, zero), OCC_ERR_ARG);
    assert_int_equal(occ_volume_obb(&v, z, half, longa), OCC_ERR_ARG);
    assert_int_equal(occ_volume_obb_yaw(&v, z, half, NAN), OCC_ERR_ARG);
    assert_int_equal(occ_volume_frustum(&v, z, good, 1.f, 1.f, 0.f, 5.f), OCC_OK);
    assert_int_equal(occ_volume_frustum(&v, z, good, 0.f, 1.f, 0.f, 5.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_frustum(&v, z, good, 1.f, 3.2f, 0.f, 5.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_frustum(&v, z, good, 1.f, 1.f, 5.f, 5.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_frustum(&v, z, good, 1.f, 1.f, -1.f, 5.f), OCC_ERR_ARG);
    assert_int_equal(occ_volume_frustum(&v, z, zero, 1.f, 1.f, 0.f, 5.f), OCC_ERR_ARG);
    occ_query_iter_t it;
    assert_int_equal(occ_volume_sphere(&v, z, 1.f), OCC_OK);
    occ_pred_t bad = {0x10u, 0u, 0u};
    assert_int_equal(occ_query_begin(&it, &map, &v, bad), OCC_ERR_ARG);
    occ_pred_t deep = {0u, 6u, 0u};
    assert_int_equal(occ_query_begin(&it, &map, &v, deep), OCC_ERR_ARG);
    assert_int_equal(occ_query_begin(&it, NULL, &v, deep), OCC_ERR_ARG);
    occ_info_gain_t g;
    assert_int_equal(occ_info_gain(&map, &v, 6u, 0u, &g), OCC_ERR_ARG);
    assert_int_equal(occ_info_gain(&map, &v, 0u, 0x8u, &g), OCC_ERR_ARG);
    occ_nearest_t nit;
    occ_nearest_entry_t buf[4];
    occ_pred_t p0 = {0u, 0u, 0u};
    assert_int_equal(occ_nearest_begin(&nit, &map, z, -1.f, p0, buf, 4), OCC_ERR_ARG);
    assert_int_equal(occ_nearest_begin(&nit, &map, nan3, 1.f, p0, buf, 4), OCC_ERR_ARG);
    assert_int_equal(occ_nearest_begin(&nit, &map, z, 1.f, p0, buf, 0), OCC_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_uniform_root),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_whole_and_outside),
        cmocka_unit_test(test_random_volumes_pow2),
        cmocka_unit_test(test_random_volumes_res01),
        cmocka_unit_test(test_nearest),
        cmocka_unit_test(test_lookup_cursor),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
