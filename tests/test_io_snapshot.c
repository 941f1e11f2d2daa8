/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_io_snapshot.c - the native snapshot (.occ): exact round trips (every node, every pool
 * counter), CRC-32 against zlib's check value, every kind of corruption refused with the map
 * unchanged, exhaustion at every small arena size, and the POSIX atomic save / load helpers.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_file.h"
#include "support/iotest.h"

#define GEB079 "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"

static uint32_t rng_state;
static uint32_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static uint8_t arena_a[8u << 20];
static uint8_t arena_b[8u << 20];

static void build_random(occ_map_t *m, unsigned n, uint8_t depth)
{
    const char *const s = getenv("OCC_SEED");
    rng_state = s != NULL ? (uint32_t)strtoul(s, NULL, 0) : 77u;
    if (rng_state == 0u) {
        rng_state = 1u;
    }
    printf("seed %u (set OCC_SEED to repeat)\n", (unsigned)rng_state);
    occ_map_config_t cfg = occ_map_config_default();
    cfg.depth_levels = depth;
    cfg.free_max = -0.2f;   /* a non-empty unknown band, to cover the flags */
    cfg.occupied_min = 0.3f;
    assert_int_equal(occ_map_init(m, &cfg, arena_a, sizeof arena_a), OCC_OK);
    const uint32_t half = 1u << (depth - 1u);
    for (unsigned i = 0; i < n; i++) {
        occ_key_t k = {{half - 30u + rng() % 60u, half - 30u + rng() % 60u, half - 8u + rng() % 16u}};
        assert_int_equal(occ_map_observe_key(m, k, rng() % 3u == 0u), OCC_OK);
    }
    /* Some coarse uniform regions too. */
    occ_key_t k = {{half + half / 2u, half, half}};
    assert_int_equal(occ_map_set_key(m, k, 5u, 1.25f), OCC_OK);
}

static uint8_t *snap(const occ_map_t *m, size_t *len)
{
    uint8_t *b = iotest_write(m, OCC_FORMAT_SNAPSHOT, len);
    assert_non_null(b);
    return b;
}

static void test_crc32(void **state)
{
    (void)state;
    assert_int_equal(occ_crc32(0u, "123456789", 9u), 0xCBF43926u);
    assert_int_equal(occ_crc32(occ_crc32(0u, "1234", 4u), "56789", 5u), 0xCBF43926u);
    assert_int_equal(occ_crc32(0u, "", 0u), 0u);
}

static void roundtrip(uint8_t depth)
{
    occ_map_t a, b;
    build_random(&a, 3000u, depth);
    assert_int_equal(occ_map_check(&a), OCC_OK);
    size_t n = 0;
    uint8_t *s1 = snap(&a, &n);
    occ_io_info_t info;
    assert_int_equal(occ_io_load(&b, NULL, arena_b, sizeof arena_b, s1, n, &info), OCC_OK);
    assert_int_equal(info.format, OCC_FORMAT_SNAPSHOT);
    assert_int_equal(occ_map_check(&b), OCC_OK);
    /* Same nodes, values, flags, pool counts and config. */
    assert_int_equal(iotest_map_digest(&a), iotest_map_digest(&b));
    assert_true(a.cfg.depth_levels == b.cfg.depth_levels);
    occ_map_stats_t sa, sb;
    occ_map_stats(&a, &sa);
    occ_map_stats(&b, &sb);
    assert_int_equal(sa.nodes, sb.nodes);
    assert_int_equal(sa.occupied_voxels, sb.occupied_voxels);
    size_t n2 = 0;
    uint8_t *s2 = snap(&b, &n2);
    assert_int_equal(n, n2);
    assert_memory_equal(s1, s2, n);
    printf("depth %u: %llu nodes, %zu bytes (%.2f bytes/node)\n", (unsigned)depth,
           (unsigned long long)sb.nodes, n, (double)n / (double)sb.nodes);
    free(s1);
    free(s2);
}

static void test_roundtrip(void **state)
{
    (void)state;
    roundtrip(16u);
    roundtrip(21u);
    roundtrip(8u);
}

static void test_geb079(void **state)
{
    (void)state;
    size_t len = 0;
    uint8_t *file = iotest_read_file(GEB079, &len);
    assert_non_null(file);
    occ_map_t a, b;
    occ_err_t e;
    void *ar = iotest_load(&a, file, len, 0u, &e, NULL);
    assert_non_null(ar);
    size_t n = 0;
    uint8_t *s = snap(&a, &n);
    occ_io_info_t info;
    assert_int_equal(occ_io_probe(s, n, NULL, &info), OCC_OK);
    void *br = malloc(info.arena_bytes_needed);
    assert_int_equal(occ_io_load(&b, NULL, br, info.arena_bytes_needed, s, n, &info), OCC_OK);
    assert_int_equal(iotest_map_digest(&a), iotest_map_digest(&b));
    printf("geb079: .bt %zu bytes, snapshot %zu bytes, arena %zu bytes\n", len, n,
           info.arena_bytes_needed);
    free(br);
    free(s);
    free(ar);
    free(file);
}

/* Recompute the CRC so a structural corruption gets past the checksum. */
static void fix_crc(uint8_t *b, size_t n)
{
    const uint32_t c = occ_crc32(0u, b, n - 4u);
    b[n - 4u] = (uint8_t)c;
    b[n - 3u] = (uint8_t)(c >> 8);
    b[n - 2u] = (uint8_t)(c >> 16);
    b[n - 1u] = (uint8_t)(c >> 24);
}

static void expect_refused(occ_map_t *victim, const uint8_t *b, size_t n, occ_err_t want,
                           const char *what)
{
    const uint64_t d = iotest_map_digest(victim);
    const occ_map_t before = *victim;
    occ_io_info_t info;
    const occ_err_t e1 = occ_io_read(victim, b, n, &info);
    const occ_err_t e2 = occ_io_load(victim, NULL, arena_a, sizeof arena_a, b, n, NULL);
    if (e1 != want || e2 != want) {
        printf("%s: got %s / %s (%s at %zu), want %s\n", what, occ_err_str(e1), occ_err_str(e2),
               info.error, info.error_offset, occ_err_str(want));
        fail();
    }
    assert_memory_equal(&before, victim, sizeof before);
    assert_int_equal(iotest_map_digest(victim), d);
    assert_int_equal(occ_map_check(victim), OCC_OK);
}

static void test_corrupt(void **state)
{
    (void)state;
    occ_map_t m;
    build_random(&m, 150u, 16u);
    size_t n = 0;
    uint8_t *s = snap(&m, &n);
    uint8_t *b = (uint8_t *)malloc(n);
    /* Every truncation. */
    for (size_t cut = 0; cut < n; cut++) {
        expect_refused(&m, s, cut, OCC_ERR_FORMAT, "truncated");
    }
    /* Every single-bit flip: the CRC (or the magic/length checks) catch it. */
    for (size_t i = 0; i < n; i++) {
        memcpy(b, s, n);
        b[i] ^= (uint8_t)(1u << (i % 8u));
        const occ_err_t want = (i == 8u || i == 9u) ? OCC_ERR_UNSUPPORTED : OCC_ERR_FORMAT;
        expect_refused(&m, b, n, want, "bit flip");
    }
    /* Structural damage behind a valid CRC. */
    struct {
        size_t at;
        uint8_t val;
        occ_err_t want;
        const char *what;
    } cases[] = {
        {13u, 22u, OCC_ERR_FORMAT, "depth 22"},
        {13u, 0u, OCC_ERR_FORMAT, "depth 0"},
        {12u, 7u, OCC_ERR_FORMAT, "value kind"},
        {8u, 2u, OCC_ERR_UNSUPPORTED, "version 2"},
        {19u, 0xFFu, OCC_ERR_FORMAT, "resolution NaN"},
        {64u, 9u, OCC_ERR_FORMAT, "root tag"},
        {65u, 0u, OCC_ERR_FORMAT, "empty observed mask"},
        {44u, 0x7Fu, OCC_ERR_FORMAT, "block count"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        memcpy(b, s, n);
        b[cases[i].at] = cases[i].val;
        fix_crc(b, n);
        expect_refused(&m, b, n, cases[i].want, cases[i].what);
    }
    /* has-children mask not a subset of the observed mask. */
    memcpy(b, s, n);
    b[66] = (uint8_t)(b[66] | (uint8_t)~b[65]);
    if (b[65] != 0xFFu) {
        fix_crc(b, n);
        expect_refused(&m, b, n, OCC_ERR_FORMAT, "child mask outside observed mask");
    }
    free(b);
    free(s);
}

/* Exhaustion: refused at every arena size below the probe's figure, accepted at it. */
static void test_every_small_arena(void **state)
{
    (void)state;
    occ_map_t m, v;
    build_random(&m, 60u, 16u);
    size_t n = 0;
    uint8_t *s = snap(&m, &n);
    occ_io_info_t info;
    assert_int_equal(occ_io_probe(s, n, NULL, &info), OCC_OK);
    const size_t exact = (size_t)info.peak_inner_blocks * OCC_INNER_BLOCK_BYTES +
                         (size_t)info.peak_leaf_blocks * OCC_LEAF_BLOCK_BYTES;
    occ_map_config_t cfg = occ_map_config_default();
    static uint8_t small[4096] __attribute__((aligned(8)));
    assert_int_equal(occ_map_init(&v, &cfg, small, sizeof small), OCC_OK);
    const uint64_t d = iotest_map_digest(&v);
    for (size_t bytes = 0; bytes < exact; bytes += 8u) {
        const occ_err_t e = occ_io_load(&v, NULL, arena_b, bytes, s, n, NULL);
        assert_int_equal(e, OCC_ERR_NOMEM);
        assert_int_equal(iotest_map_digest(&v), d);
    }
    assert_int_equal(occ_io_load(&v, NULL, arena_b, exact, s, n, NULL), OCC_OK);
    assert_int_equal(iotest_map_digest(&v), iotest_map_digest(&m));
    free(s);
}

/* POSIX helpers: atomic save in each format, load back, failure leaves the old file. */
static void test_files(void **state)
{
    (void)state;
    occ_map_t m;
    build_random(&m, 800u, 16u);
    char dir[] = "/tmp/occ_io_test_XXXXXX";
    assert_non_null(mkdtemp(dir));
    const char *const ext[3] = {"bt", "ot", "occ"};
    char msg[256];
    for (unsigned i = 0; i < 3u; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/map.%s", dir, ext[i]);
        assert_int_equal(occ_file_save(path, &m, msg, sizeof msg), OCC_OK);
        occ_map_t back;
        void *arena = NULL;
        occ_io_info_t info;
        occ_map_config_t cfg = m.cfg;
        assert_int_equal(occ_file_load_alloc(path, &cfg, &back, 0u, &arena, &info, msg, sizeof msg),
                         OCC_OK);
        if (i == 2u) {
            assert_int_equal(iotest_map_digest(&back), iotest_map_digest(&m));
        } else {
            /* .bt keeps the maximum-likelihood state, .ot every value (to the step). */
            occ_map_stats_t a, b;
            occ_map_stats(&m, &a);
            occ_map_stats(&back, &b);
            assert_int_equal(a.occupied_voxels, b.occupied_voxels);
            if (i == 1u) {
                assert_int_equal(a.free_voxels, b.free_voxels);
                assert_int_equal(iotest_map_digest(&back) != 0u, 1);
            }
        }
        free(arena);
        /* No temporary file left behind. */
        char tmp[600];
        snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
        assert_int_not_equal(access(tmp, F_OK), 0);
    }
    /* A failing save (unknown extension, unwritable directory) leaves the old file intact. */
    char path[512];
    snprintf(path, sizeof path, "%s/map.occ", dir);
    size_t before_len = 0;
    uint8_t *before = iotest_read_file(path, &before_len);
    assert_int_equal(occ_file_save("/tmp/x.unknown", &m, msg, sizeof msg), OCC_ERR_ARG);
    assert_int_equal(occ_file_save("/nonexistent_dir/map.occ", &m, msg, sizeof msg), OCC_ERR_IO);
    size_t after_len = 0;
    uint8_t *after = iotest_read_file(path, &after_len);
    assert_int_equal(before_len, after_len);
    assert_memory_equal(before, after, before_len);
    /* Loading garbage: a clear message with the byte offset; the map stays as it was. */
    char bad[512];
    snprintf(bad, sizeof bad, "%s/bad.bt", dir);
    FILE *f = fopen(bad, "wb");
    fputs("# Octomap OcTree binary file\nid OcTree\nsize 5\nres 0.1\ndata\n\x03", f);
    fclose(f);
    const uint64_t d = iotest_map_digest(&m);
    assert_int_equal(occ_file_load(bad, NULL, &m, arena_a, sizeof arena_a, msg, sizeof msg),
                     OCC_ERR_FORMAT);
    printf("message: %s\n", msg);
    assert_non_null(strstr(msg, "at byte"));
    assert_int_equal(iotest_map_digest(&m), d);
    free(before);
    free(after);
    for (unsigned i = 0; i < 3u; i++) {
        snprintf(path, sizeof path, "%s/map.%s", dir, ext[i]);
        unlink(path);
    }
    unlink(bad);
    rmdir(dir);
}

/* Fuzz corpus and crash regressions (tests/fuzz/regress/): every file is either refused with a
 * reason and the map untouched, or loads into a map that passes the self-check. */
#include <dirent.h>
static void test_fuzz_regressions(void **state)
{
    (void)state;
    DIR *d = opendir("tests/fuzz/regress");
    if (d == NULL) {
        printf("SKIP: tests/fuzz/regress absent (run from the repository root)\n");
        skip();
        return;
    }
    occ_map_t m;
    build_random(&m, 100u, 16u);
    unsigned n = 0, ok = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        if (de->d_name[0] == '.') {
            continue;
        }
        char path[512];
        snprintf(path, sizeof path, "tests/fuzz/regress/%s", de->d_name);
        size_t len = 0;
        uint8_t *b = iotest_read_file(path, &len);
        assert_non_null(b);
        const uint64_t dg = iotest_map_digest(&m);
        occ_io_info_t info;
        occ_map_t v;
        const occ_err_t e = occ_io_load(&v, NULL, arena_b, sizeof arena_b, b, len, &info);
        if (e == OCC_OK) {
            assert_int_equal(occ_map_check(&v), OCC_OK);
            ok++;
        } else {
            assert_true(info.error[0] != '\0');
        }
        assert_int_equal(occ_io_read(&m, b, len, &info) == OCC_OK || iotest_map_digest(&m) == dg, 1);
        build_random(&m, 100u, 16u);
        free(b);
        n++;
    }
    closedir(d);
    printf("%u regression inputs, %u load\n", n, ok);
    assert_true(n > 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc32),
        cmocka_unit_test(test_roundtrip),
        cmocka_unit_test(test_geb079),
        cmocka_unit_test(test_corrupt),
        cmocka_unit_test(test_every_small_arena),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_fuzz_regressions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
