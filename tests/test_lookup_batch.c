/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_lookup_batch.c - occ_map_states_at (occ_query.h: many points in one call, through one
 * lookup cursor), against occ_map_state_at point by point:
 *  - real maps (geb079.bt from Debian's liboctomap-dev, fr_079 from ../shared/data/maps; a
 *    missing file is skipped and counted): random probes inside and around the map's box, far
 *    off the map, on voxel borders and one float ulp either side, NaN and Inf, in random order;
 *    then in the orders the cursor is built for: horizontal slices row by row (what the Python
 *    binding's plot_slice asks) and a trajectory of small steps. Every answer equals the single
 *    call's, exactly n bytes are written, and the batch cut into pieces answers the same;
 *  - a map built by hand: the states of an occupied voxel, a free level-3 node, unobserved space,
 *    off-map, NaN and Inf points; a write between two calls shows in the second (no cursor is
 *    kept between calls); an empty map and a uniform root;
 *  - bad input: NULL map, NULL points or output with n > 0 (OCC_ERR_ARG, every output UNKNOWN),
 *    n = 0.
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

#define GUARD 16u

/* occ_map_states_at over pts equals occ_map_state_at for each point, writes n bytes and no more,
 * and answers the same when the points come in pieces. Returns the count per state. */
static void check_batch(const occ_map_t *map, const occ_vec3_t *pts, size_t n, const char *what,
                        size_t count[3])
{
    uint8_t *const out = malloc(n + GUARD);
    uint8_t *const part = malloc(n + 1u);
    assert_non_null(out);
    assert_non_null(part);
    memset(out, 0xA5, n + GUARD);
    assert_int_equal(occ_map_states_at(map, pts, n, out), OCC_OK);
    for (size_t i = n; i < n + GUARD; i++) {
        assert_int_equal(out[i], 0xA5);
    }
    size_t bad = 0;
    count[0] = count[1] = count[2] = 0u;
    for (size_t i = 0; i < n; i++) {
        const occ_state_t want = occ_map_state_at(map, pts[i]);
        count[want]++;
        if (out[i] != (uint8_t)want && bad++ < 5u) {
            printf("%s: point %zu (%.9g %.9g %.9g): occ_map_state_at %d, batch %d\n", what, i,
                   (double)pts[i].x, (double)pts[i].y, (double)pts[i].z, (int)want, (int)out[i]);
        }
    }
    assert_int_equal(bad, 0u);
    /* Pieces of 1, 7 and 1000 points: each call starts its own cursor. */
    const size_t sizes[3] = {1u, 7u, 1000u};
    for (unsigned s = 0; s < 3u; s++) {
        memset(part, 0xA5, n + 1u);
        for (size_t i = 0; i < n; i += sizes[s]) {
            const size_t c = n - i < sizes[s] ? n - i : sizes[s];
            assert_int_equal(occ_map_states_at(map, pts + i, c, part + i), OCC_OK);
        }
        assert_memory_equal(part, out, n);
        assert_int_equal(part[n], 0xA5);
    }
    free(part);
    free(out);
}

/* Horizontal slices through the box [mn, mx] at voxel-centre spacing, row by row, at `nz`
 * heights; then a trajectory of small random steps from the box's centre (pts holds cap). */
static size_t coherent_points(const occ_map_t *map, occ_vec3_t mn, occ_vec3_t mx, occ_vec3_t *pts,
                              size_t cap)
{
    const float res = map->cfg.resolution_m;
    size_t n = 0;
    for (unsigned iz = 1; iz <= 3u; iz++) {
        const float z = mn.z + (mx.z - mn.z) * (float)iz / 4.0f;
        for (float y = mn.y - 4.0f * res; y < mx.y + 4.0f * res && n < cap / 2u; y += res) {
            for (float x = mn.x - 4.0f * res; x < mx.x + 4.0f * res && n < cap / 2u; x += res) {
                pts[n++] = (occ_vec3_t){x, y, z};
            }
        }
    }
    occ_vec3_t p = {(mn.x + mx.x) / 2.0f, (mn.y + mx.y) / 2.0f, (mn.z + mx.z) / 2.0f};
    uint32_t r = 12345u;
    while (n < cap) {
        r = r * 1664525u + 1013904223u;
        const float step = (float)((int)(r >> 24) - 128) / 128.0f * res;
        const unsigned axis = (r >> 8) % 3u;
        if (axis == 0u) p.x += step;
        if (axis == 1u) p.y += step;
        if (axis == 2u) p.z += step;
        pts[n++] = p;
    }
    return n;
}

static void real_map(const char *path, const char *name)
{
    occ_map_t map;
    void *const arena = lp_load_map(path, &map);
    if (arena == NULL) {
        skip();
    }
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    assert_true(st.has_known);
    const size_t n_random = 50000u;
    const size_t cap = lp_probe_cap(n_random) > 400000u ? lp_probe_cap(n_random) : 400000u;
    occ_vec3_t *const pts = malloc(cap * sizeof *pts);
    assert_non_null(pts);
    size_t count[3];
    const size_t n = lp_make_probes(&map, st.bbox_min, st.bbox_max, pts, n_random);
    check_batch(&map, pts, n, name, count);
    printf("%s: %zu probes (random, borders, off the map, NaN / Inf): %zu unknown, %zu free, "
           "%zu occupied, batch == single\n", name, n, count[0], count[1], count[2]);
    assert_true(count[0] > 100u && count[1] > 100u && count[2] > 100u); /* all three answers */
    /* The 12 NaN / Inf probes at the end answered UNKNOWN (check_batch held them to the single
     * call; this holds the single call to its contract). */
    for (size_t i = n - 12u; i < n; i++) {
        assert_int_equal(occ_map_state_at(&map, pts[i]), OCC_STATE_UNKNOWN);
    }
    const size_t m = coherent_points(&map, st.bbox_min, st.bbox_max, pts, 400000u);
    check_batch(&map, pts, m, name, count);
    printf("%s: %zu slice and trajectory points: %zu unknown, %zu free, %zu occupied, "
           "batch == single\n", name, m, count[0], count[1], count[2]);
    assert_true(count[1] > 100u && count[2] > 100u);
    free(pts);
    free(arena);
}

static const char *GEB079[2] = {LP_GEB079, "geb079"};
static const char *FR079[2] = {LP_FR079, "fr_079"};

static void test_real_map(void **state)
{
    const char *const *const map = *state; /* path, name */
    real_map(map[0], map[1]);
}

static void test_hand_map(void **state)
{
    (void)state;
    static lp_small_t s;
    lp_small_init(&s);
    const occ_vec3_t pts[] = {
        {0.05f, 0.05f, 0.05f}, /* occupied voxel */
        {1.0f, 1.0f, 1.0f},    /* free node */
        {0.85f, 1.55f, 0.95f}, /* same free node, another voxel */
        {0.79f, 1.0f, 1.0f},   /* just below the free node: unobserved */
        {0.15f, 0.05f, 0.05f}, /* next to the occupied voxel: unobserved */
        {0.05f, 0.05f, 0.05f}, /* back to the occupied voxel */
        {1e5f, 0.0f, 0.0f},    /* off the map (depth 16 at 0.1 m: +-3276.8 m) */
        {-3276.9f, 1.0f, 1.0f},
        {NAN, 1.0f, 1.0f},
        {1.0f, INFINITY, 1.0f},
        {1.0f, 1.0f, -INFINITY},
        {1.2f, 1.2f, 1.2f},    /* free again after the invalid points */
    };
    const uint8_t want[] = {2, 1, 1, 0, 0, 2, 0, 0, 0, 0, 0, 1};
    const size_t n = sizeof pts / sizeof pts[0];
    uint8_t out[sizeof want];
    memset(out, 0xA5, sizeof out);
    assert_int_equal(occ_map_states_at(&s.map, pts, n, out), OCC_OK);
    assert_memory_equal(out, want, n);
    /* A write between two calls shows in the second: the free node's voxel becomes occupied. */
    assert_int_equal(occ_map_update(&s.map, (occ_vec3_t){1.0f, 1.0f, 1.0f}, 5.0f), OCC_OK);
    assert_int_equal(occ_map_states_at(&s.map, pts, n, out), OCC_OK);
    assert_int_equal(out[1], OCC_STATE_OCCUPIED);
    assert_int_equal(out[2], OCC_STATE_FREE);
    /* Cleared: all unknown (the root has no children). */
    occ_map_clear(&s.map);
    memset(out, 0xA5, sizeof out);
    assert_int_equal(occ_map_states_at(&s.map, pts, n, out), OCC_OK);
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(out[i], OCC_STATE_UNKNOWN);
    }
    /* A uniform free root: every point on the map is FREE, off-map and NaN / Inf stay UNKNOWN. */
    assert_int_equal(occ_map_set_key(&s.map, (occ_key_t){{0u, 0u, 0u}}, 16u, -1.0f), OCC_OK);
    assert_int_equal(occ_map_states_at(&s.map, pts, n, out), OCC_OK);
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(out[i], i >= 6u && i <= 10u ? OCC_STATE_UNKNOWN : OCC_STATE_FREE);
    }
    assert_int_equal(leak_check(&s.map), 0);
}

static void test_bad_input(void **state)
{
    (void)state;
    static lp_small_t s;
    lp_small_init(&s);
    const occ_vec3_t p[2] = {{0.05f, 0.05f, 0.05f}, {1.0f, 1.0f, 1.0f}};
    uint8_t out[2] = {0xA5, 0xA5};
    assert_int_equal(occ_map_states_at(NULL, p, 2u, out), OCC_ERR_ARG);
    assert_int_equal(out[0], OCC_STATE_UNKNOWN); /* fail closed */
    assert_int_equal(out[1], OCC_STATE_UNKNOWN);
    out[0] = out[1] = 0xA5;
    assert_int_equal(occ_map_states_at(&s.map, NULL, 2u, out), OCC_ERR_ARG);
    assert_int_equal(out[0], OCC_STATE_UNKNOWN);
    assert_int_equal(out[1], OCC_STATE_UNKNOWN);
    assert_int_equal(occ_map_states_at(&s.map, p, 2u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_states_at(NULL, NULL, 0u, NULL), OCC_ERR_ARG);
    assert_int_equal(occ_map_states_at(&s.map, NULL, 0u, NULL), OCC_OK);
    out[0] = out[1] = 0xA5;
    assert_int_equal(occ_map_states_at(&s.map, p, 0u, out), OCC_OK);
    assert_int_equal(out[0], 0xA5); /* n = 0 writes nothing */
    assert_int_equal(occ_map_states_at(&s.map, p, 2u, out), OCC_OK);
    assert_int_equal(out[0], OCC_STATE_OCCUPIED);
    assert_int_equal(out[1], OCC_STATE_FREE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_map),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test_prestate(test_real_map, (void *)GEB079),
        cmocka_unit_test_prestate(test_real_map, (void *)FR079),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
