/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_io_octomap.c - .bt / .ot against OctoMap 1.9.7 as the oracle: OctoMap writes, occmap
 * reads and writes again, bytes identical (or, where OctoMap's file is not canonical, the trees
 * equal leaf for leaf within the fixed-point step); OctoMap reads what occmap writes; other
 * tree types; the header text. Corrupt input and a too small arena: test_io_corrupt.c.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "support/iotest.h"
#include "support/oracle_io.h"

#define GEB079 "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"
#define GRAPH "/usr/share/doc/liboctomap-dev/examples/data/spherical_scan.graph"
#define SHARED_MAPS "../shared/data/maps"
#if OCC_VALUE_FLOAT
#define TOL 0.0f  /* the float build stores OctoMap's values bit for bit */
#else
/* Fixed point: values round to 1/1024, so a float log-odds moves by at most half a step. */
#define TOL (0.5f / (float)OCC_FIXED_ONE + 1e-6f)
#endif

static uint32_t rng_state;
static uint32_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}
static void seed_rng(void)
{
    const char *const s = getenv("OCC_SEED");
    rng_state = s != NULL ? (uint32_t)strtoul(s, NULL, 0) : 20261125u;
    if (rng_state == 0u) {
        rng_state = 1u;
    }
    printf("seed %u (set OCC_SEED to repeat)\n", (unsigned)rng_state);
}

static bool same_bytes(const uint8_t *a, size_t na, const uint8_t *b, size_t nb, const char *what)
{
    if (na != nb || memcmp(a, b, na) != 0) {
        size_t i = 0;
        while (i < na && i < nb && a[i] == b[i]) {
            i++;
        }
        printf("%s: %zu vs %zu bytes, first difference at %zu\n", what, na, nb, i);
        return false;
    }
    return true;
}

/* OctoMap writes .bt; occmap reads it and writes it again: identical bytes. Returns the
 * loaded map's arena (caller frees) with the map in *map. */
static void *bt_roundtrip(const uint8_t *file, size_t len, occ_map_t *map, const char *name)
{
    oracle_io_t *o = oracle_io_read_bt(file, len);
    assert_non_null(o);
    size_t n_ref = 0;
    uint8_t *ref = oracle_io_write_bt(o, &n_ref);
    occ_err_t e;
    occ_io_info_t info;
    void *arena = iotest_load(map, file, len, 0u, &e, &info);
    if (arena == NULL) {
        printf("%s: load failed: %s (%s at %zu)\n", name, occ_err_str(e), info.error,
               info.error_offset);
    }
    assert_non_null(arena);
    assert_int_equal(occ_map_check(map), OCC_OK);
    size_t n_out = 0;
    uint8_t *out = iotest_write(map, OCC_FORMAT_BT, &n_out);
    assert_non_null(out);
    const bool same_as_file = n_out == len && memcmp(out, file, len) == 0;
    printf("%s: %llu nodes, %zu bytes; occmap rewrite %s OctoMap's writeBinary; %s the file\n",
           name, (unsigned long long)info.nodes, n_out,
           (n_out == n_ref && memcmp(out, ref, n_ref) == 0) ? "==" : "!=",
           same_as_file ? "==" : "!=");
    assert_true(same_bytes(out, n_out, ref, n_ref, name));
    char why[256];
    if (!iotest_equivalent(map, o, TOL, why, sizeof why)) {
        printf("%s: %s\n", name, why);
        fail();
    }
    free(out);
    free(ref);
    oracle_io_free(o);
    return arena;
}

static void test_geb079_bt(void **state)
{
    (void)state;
    size_t len = 0;
    uint8_t *file = iotest_read_file(GEB079, &len);
    assert_non_null(file);
    occ_map_t map;
    void *arena = bt_roundtrip(file, len, &map, "geb079.bt");
    free(arena);
    free(file);
}

/* .ot: occmap's tree equals OctoMap's leaf for leaf (within the step); OctoMap reads occmap's
 * .ot back to an equivalent tree and rewrites it byte for byte; occmap's rewrite is stable. */
static void ot_roundtrip(const uint8_t *file, size_t len, const char *name)
{
    oracle_io_t *o = oracle_io_read_ot(file, len);
    assert_non_null(o);
    occ_map_t map;
    occ_err_t e;
    occ_io_info_t info;
    void *arena = iotest_load(&map, file, len, 0u, &e, &info);
    assert_non_null(arena);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    char why[256];
    if (!iotest_equivalent(&map, o, TOL, why, sizeof why)) {
        printf("%s: %s\n", name, why);
        fail();
    }
    size_t n1 = 0, n2 = 0, n3 = 0;
    uint8_t *w1 = iotest_write(&map, OCC_FORMAT_OT, &n1);
    assert_non_null(w1);
    oracle_io_t *o2 = oracle_io_read_ot(w1, n1);
    assert_non_null(o2);
    assert_int_equal(oracle_io_size(o2), occ_io_octomap_nodes(&map, OCC_FORMAT_OT));
    if (!oracle_io_equivalent(o, o2, TOL, why, sizeof why)) {
        printf("%s: OctoMap re-read: %s\n", name, why);
        fail();
    }
    uint8_t *w2 = oracle_io_write_ot(o2, &n2);
    assert_true(same_bytes(w1, n1, w2, n2, "OctoMap rewrite of occmap's .ot"));
    occ_map_t map2;
    void *arena2 = iotest_load(&map2, w1, n1, 0u, &e, NULL);
    assert_non_null(arena2);
    uint8_t *w3 = iotest_write(&map2, OCC_FORMAT_OT, &n3);
    assert_true(same_bytes(w1, n1, w3, n3, "occmap rewrite of its own .ot"));
#if OCC_VALUE_FLOAT
    /* Float build: a canonical OctoMap .ot (pruned, inner = max of children) comes back byte
     * for byte; a non-canonical one (unpruned) describes the same voxels, values bit-exact. */
    if (occ_io_octomap_nodes(&map, OCC_FORMAT_OT) == info.nodes &&
        (info.warnings & OCC_IO_WARN_INNER_VALUE) == 0u) {
        assert_true(same_bytes(w1, n1, file, len, "float build: .ot rewrite vs OctoMap's file"));
    }
    assert_int_equal(info.warnings & (OCC_IO_WARN_QUANTIZED | OCC_IO_WARN_CLAMPED), 0u);
#endif
    printf("%s: %llu nodes in the file, %llu after occmap (pruned/quantized), warnings 0x%x, "
           "%s OctoMap's bytes\n",
           name, (unsigned long long)info.nodes,
           (unsigned long long)occ_io_octomap_nodes(&map, OCC_FORMAT_OT),
           (unsigned)info.warnings, (n1 == len && memcmp(w1, file, len) == 0) ? "==" : "!=");
    /* The same map as .bt: OctoMap's writeBinary of its own tree and occmap's describe the same
     * voxels (OctoMap prunes with an early exit, so bytes may differ). */
    size_t nb1 = 0, nb2 = 0;
    uint8_t *b1 = iotest_write(&map, OCC_FORMAT_BT, &nb1);
    uint8_t *b2 = oracle_io_write_bt(o, &nb2);
    oracle_io_t *ob1 = oracle_io_read_bt(b1, nb1);
    oracle_io_t *ob2 = oracle_io_read_bt(b2, nb2);
    assert_non_null(ob1);
    assert_non_null(ob2);
    if (!oracle_io_equivalent(ob1, ob2, 1e-6f, why, sizeof why)) {
        printf("%s as .bt: %s\n", name, why);
        fail();
    }
    printf("%s as .bt: %zu bytes, %s OctoMap's writeBinary\n", name, nb1,
           (nb1 == nb2 && memcmp(b1, b2, nb1) == 0) ? "==" : "!=");
    oracle_io_free(ob1);
    oracle_io_free(ob2);
    free(b1);
    free(b2);
    free(w1);
    free(w2);
    free(w3);
    free(arena);
    free(arena2);
    oracle_io_free(o2);
    oracle_io_free(o);
}

static void test_shared_maps(void **state)
{
    (void)state;
    DIR *d = opendir(SHARED_MAPS);
    if (d == NULL) {
        printf("SKIP: %s absent (no ../shared checkout)\n", SHARED_MAPS);
        skip();
        return;
    }
    unsigned n = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        const char *const dot = strrchr(de->d_name, '.');
        if (dot == NULL || (strcmp(dot, ".bt") != 0 && strcmp(dot, ".ot") != 0)) {
            continue;
        }
        /* OCC_IO_ONLY_OT=1: the float build's step checks the float log-odds maps only. */
        const char *const only_ot = getenv("OCC_IO_ONLY_OT");
        if (only_ot != NULL && strcmp(only_ot, "1") == 0 && strcmp(dot, ".ot") != 0) {
            n++;
            continue;
        }
        char path[512];
        snprintf(path, sizeof path, "%s/%s", SHARED_MAPS, de->d_name);
        size_t len = 0;
        uint8_t *file = iotest_read_file(path, &len);
        assert_non_null(file);
        if (strcmp(dot, ".bt") == 0) {
            occ_map_t map;
            free(bt_roundtrip(file, len, &map, de->d_name));
        } else {
            ot_roundtrip(file, len, de->d_name);
        }
        free(file);
        n++;
    }
    closedir(d);
    assert_true(n >= 3u);
}

/* Random updates with clustered keys, applied to OctoMap and to occmap. */
static void random_updates(oracle_io_t *o, occ_map_t *m, unsigned n, bool representable)
{
    const uint32_t base = 32768u - 40u;
    for (unsigned i = 0; i < n; i++) {
        const uint32_t k[3] = {base + rng() % 80u, base + rng() % 80u, base + rng() % 24u};
        /* Multiples of 1/1024 stay exact in float: both sides then hold the same values. */
#if OCC_VALUE_BITS == 8
        /* The 8-bit grid's hit / miss (k / 36: float keeps their sums within 1e-6). */
        const float d = representable ? ((rng() % 3u) ? -15.0f : 31.0f) / 36.0f
                                      : ((rng() % 3u) ? -0.405465f : 0.847298f);
#else
        const float d = representable ? ((rng() % 3u) ? -415.0f : 868.0f) / 1024.0f
                                      : ((rng() % 3u) ? -0.405465f : 0.847298f);
#endif
        if (o != NULL) {
            oracle_io_update(o, k[0], k[1], k[2], d);
        }
        if (m != NULL) {
            occ_key_t key = {{k[0], k[1], k[2]}};
            assert_int_equal(occ_map_update_key(m, key, d), OCC_OK);
        }
    }
}

static uint8_t big_arena[64u << 20];

static void test_updates(void **state)
{
    (void)state;
    seed_rng();
    /* OctoMap-built tree with real float log-odds. */
    oracle_io_t *o = oracle_io_new(ORACLE_OCTREE, 0.1);
    random_updates(o, NULL, 20000u, false);
    size_t nb = 0, no = 0;
    uint8_t *ot = oracle_io_write_ot(o, &no);
    ot_roundtrip(ot, no, "updates.ot");
    uint8_t *bt = oracle_io_write_bt(o, &nb);
    occ_map_t map;
    free(bt_roundtrip(bt, nb, &map, "updates.bt"));
    free(bt);
    free(ot);
    oracle_io_free(o);

    /* occmap-built map: OctoMap reads its .ot / .bt and writes the same bytes back. */
    occ_map_config_t cfg = iotest_octomap_cfg();
    assert_int_equal(occ_map_init(&map, &cfg, big_arena, sizeof big_arena), OCC_OK);
    random_updates(NULL, &map, 20000u, false);
    const occ_format_t fmts[2] = {OCC_FORMAT_OT, OCC_FORMAT_BT};
    for (unsigned f = 0; f < 2u; f++) {
        size_t n1 = 0, n2 = 0;
        uint8_t *w1 = iotest_write(&map, fmts[f], &n1);
        oracle_io_t *r = fmts[f] == OCC_FORMAT_OT ? oracle_io_read_ot(w1, n1)
                                                   : oracle_io_read_bt(w1, n1);
        assert_non_null(r);
        if (fmts[f] == OCC_FORMAT_OT) {
            char why[256];
            if (!iotest_equivalent(&map, r, 1e-6f, why, sizeof why)) {
                printf("occmap .ot read by OctoMap: %s\n", why);
                fail();
            }
        }
        uint8_t *w2 = fmts[f] == OCC_FORMAT_OT ? oracle_io_write_ot(r, &n2)
                                                : oracle_io_write_bt(r, &n2);
        assert_true(same_bytes(w1, n1, w2, n2, "OctoMap rewrite of occmap output"));
        printf("occmap-built map as %s: %zu bytes, OctoMap rewrites them identically\n",
               fmts[f] == OCC_FORMAT_OT ? ".ot" : ".bt", n1);
        free(w1);
        free(w2);
        oracle_io_free(r);
    }

    /* Same updates with representable deltas on both sides: the .ot bytes are identical. */
    o = oracle_io_new(ORACLE_OCTREE, 0.1);
    assert_int_equal(occ_map_init(&map, &cfg, big_arena, sizeof big_arena), OCC_OK);
    const uint32_t saved = rng_state;
    random_updates(o, NULL, 5000u, true);
    rng_state = saved;
    random_updates(NULL, &map, 5000u, true);
    size_t n1 = 0, n2 = 0;
    uint8_t *w1 = oracle_io_write_ot(o, &n1);
    uint8_t *w2 = iotest_write(&map, OCC_FORMAT_OT, &n2);
    /* OctoMap's clamp bounds are not multiples of 1/1024: compare leaf for leaf there. */
    char why[256];
    if (!iotest_equivalent(&map, o, TOL, why, sizeof why)) {
        printf("representable updates: %s\n", why);
        fail();
    }
    printf("representable updates: OctoMap .ot %zu bytes, occmap .ot %zu bytes (%s)\n", n1, n2,
           (n1 == n2 && memcmp(w1, w2, n1) == 0) ? "identical" : "clamped values differ");
    free(w1);
    free(w2);
    oracle_io_free(o);
}

/* Real scans: OctoMap's spherical_scan.graph inserted by OctoMap, then the round trips. */
static void test_real_scans(void **state)
{
    (void)state;
    oracle_io_t *o = oracle_io_new(ORACLE_OCTREE, 0.2);
    if (!oracle_io_insert_graph(o, GRAPH, 3u, 10.0)) {
        printf("SKIP: %s unreadable\n", GRAPH);
        oracle_io_free(o);
        skip();
        return;
    }
    size_t nb = 0, no = 0;
    uint8_t *ot = oracle_io_write_ot(o, &no);
    ot_roundtrip(ot, no, "spherical_scan.ot");
    uint8_t *bt = oracle_io_write_bt(o, &nb);
    occ_map_t map;
    free(bt_roundtrip(bt, nb, &map, "spherical_scan.bt"));
    free(bt);
    free(ot);
    oracle_io_free(o);
}

/* ColorOcTree / OcTreeStamped: .bt read as OcTree with a warning; .ot extra bytes skipped. */
static void test_other_tree_types(void **state)
{
    (void)state;
    const oracle_io_kind_t kinds[2] = {ORACLE_COLOR, ORACLE_STAMPED};
    for (unsigned k = 0; k < 2u; k++) {
        seed_rng();
        oracle_io_t *plain = oracle_io_new(ORACLE_OCTREE, 0.05);
        oracle_io_t *typed = oracle_io_new(kinds[k], 0.05);
        const uint32_t saved = rng_state;
        random_updates(plain, NULL, 3000u, false);
        rng_state = saved;
        random_updates(typed, NULL, 3000u, false);
        size_t no = 0, nb = 0;
        uint8_t *ot = oracle_io_write_ot(typed, &no);
        occ_map_t map;
        occ_err_t e;
        occ_io_info_t info;
        void *arena = iotest_load(&map, ot, no, 0u, &e, &info);
        assert_non_null(arena);
        assert_true((info.warnings & OCC_IO_WARN_TREE_TYPE) != 0u);
        /* OctoMap 1.9.7 writes colours into a ColorOcTree .ot, no time stamps for Stamped. */
        assert_int_equal((info.warnings & OCC_IO_WARN_EXTRA_SKIPPED) != 0u, kinds[k] == ORACLE_COLOR);
        printf("%s .ot: %llu nodes, warnings 0x%x\n", info.tree_id,
               (unsigned long long)info.nodes, (unsigned)info.warnings);
        char why[256];
        if (!iotest_equivalent(&map, plain, TOL, why, sizeof why)) {
            printf("%s .ot: %s\n", info.tree_id, why);
            fail();
        }
        free(arena);
        uint8_t *bt = oracle_io_write_bt(typed, &nb);
        arena = iotest_load(&map, bt, nb, 0u, &e, &info);
        if (arena == NULL) {
            printf("%s .bt: %s (%s at %zu)\n", info.tree_id, occ_err_str(e), info.error,
                   info.error_offset);
        }
        assert_non_null(arena);
        assert_true((info.warnings & OCC_IO_WARN_TREE_TYPE) != 0u);
        oracle_io_t *ref = oracle_io_read_bt(bt, nb);  /* OctoMap reads it as an OcTree too */
        assert_non_null(ref);
        if (!iotest_equivalent(&map, ref, TOL, why, sizeof why)) {
            printf("%s .bt: %s\n", info.tree_id, why);
            fail();
        }
        oracle_io_free(ref);
        free(arena);
        free(bt);
        free(ot);
        oracle_io_free(plain);
        oracle_io_free(typed);
    }
}

/* The header: resolution printed exactly as OctoMap's iostream does. */
static void test_header_text(void **state)
{
    (void)state;
    const float res[] = {0.05f, 0.1f, 0.2f, 0.08f, 1.0f, 0.025f, 0.3333333f, 12.5f, 0.0001f,
                         0.00001f, 2.0e-6f, 123456.7f, 0.15f, 0.01f, 0.004f};
    for (size_t i = 0; i < sizeof res / sizeof res[0]; i++) {
        occ_map_config_t cfg = iotest_octomap_cfg();
        cfg.resolution_m = res[i];
        occ_map_t map;
        assert_int_equal(occ_map_init(&map, &cfg, big_arena, 1u << 16), OCC_OK);
        occ_key_t key = {{32768u, 32768u, 32768u}};
        assert_int_equal(occ_map_update_key(&map, key, 0.85f), OCC_OK);
        oracle_io_t *o = oracle_io_new(ORACLE_OCTREE, (double)res[i]);
        oracle_io_update(o, 32768u, 32768u, 32768u, 0.85f);
        for (unsigned f = 0; f < 2u; f++) {
            size_t n1 = 0, n2 = 0;
            uint8_t *w1 = iotest_write(&map, f ? OCC_FORMAT_BT : OCC_FORMAT_OT, &n1);
            uint8_t *w2 = f ? oracle_io_write_bt(o, &n2) : oracle_io_write_ot(o, &n2);
            const size_t hdr = (size_t)((uint8_t *)strstr((char *)w2, "data\n") - w2);
            if (memcmp(w1, w2, hdr) != 0) {
                printf("res %g: occmap header\n%.*s\nOctoMap header\n%.*s\n", (double)res[i],
                       (int)hdr, (char *)w1, (int)hdr, (char *)w2);
                fail();
            }
            /* And the empty map: "size 0", no data. */
            free(w1);
            free(w2);
        }
        oracle_io_free(o);
    }
    occ_map_config_t cfg = iotest_octomap_cfg();
    occ_map_t map;
    assert_int_equal(occ_map_init(&map, &cfg, big_arena, 1u << 16), OCC_OK);
    oracle_io_t *o = oracle_io_new(ORACLE_OCTREE, 0.1);
    size_t n1 = 0, n2 = 0;
    uint8_t *w1 = iotest_write(&map, OCC_FORMAT_BT, &n1);
    uint8_t *w2 = oracle_io_write_bt(o, &n2);
    assert_true(same_bytes(w1, n1, w2, n2, "empty .bt"));
    occ_io_info_t info;
    assert_int_equal(occ_io_read(&map, w2, n2, &info), OCC_OK);
    assert_int_equal(info.nodes, 0);
    free(w1);
    free(w2);
    oracle_io_free(o);
}

#include <time.h>
static struct timespec t_start;
static int t_setup(void **state)
{
    (void)state;
    clock_gettime(CLOCK_MONOTONIC, &t_start);
    return 0;
}
static int t_teardown(void **state)
{
    (void)state;
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    fprintf(stderr, "(%.2f s)\n", (double)(t.tv_sec - t_start.tv_sec) + 1e-9 * (double)(t.tv_nsec - t_start.tv_nsec));
    return 0;
}
#define IO_TEST(f) cmocka_unit_test_setup_teardown(f, t_setup, t_teardown)

int main(void)
{
    const struct CMUnitTest tests[] = {
        IO_TEST(test_geb079_bt),
        IO_TEST(test_shared_maps),
        IO_TEST(test_updates),
        IO_TEST(test_real_scans),
        IO_TEST(test_other_tree_types),
        IO_TEST(test_header_text),
    };
    /* The shared maps hold 4.6 M nodes: under ASan that takes minutes, so `make test` runs
     * test_shared_maps in the optimized build of this file (step io-octomap-full,
     * OCC_IO_FULL=1); elsewhere it is left out (not a skip: a skip is counted, and fails CI). */
    const char *const full = getenv("OCC_IO_FULL");
    if (full == NULL || strcmp(full, "1") != 0) {
        cmocka_set_skip_filter("test_shared_maps");
    }
    return cmocka_run_group_tests(tests, NULL, NULL);
}
