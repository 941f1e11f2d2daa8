/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_io_corrupt.c - .bt / .ot input occmap must refuse: every kind of corrupt input (truncated,
 * wrong magic or id, bad header fields, impossible trees, NaN values, byte flips) and a map that
 * does not fit the arena leave the destination map unchanged. Round trips against OctoMap:
 * test_io_octomap.c.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "support/iotest.h"

#define GEB079 "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"

static uint8_t big_arena[64u << 20];

/* ---- corrupt input ------------------------------------------------------------------------ */

static occ_map_t victim;
static uint64_t victim_digest;

/* A small non-empty map the corrupt reads must leave alone. */
static void make_victim(void)
{
    occ_map_config_t cfg = iotest_octomap_cfg();
    cfg.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(&victim, &cfg, big_arena, 1u << 20), OCC_OK);
    for (uint32_t i = 0; i < 50u; i++) {
        occ_key_t key = {{32768u + i, 32760u + i % 7u, 32768u - i % 5u}};
        assert_int_equal(occ_map_update_key(&victim, key, (i % 3u) ? 0.85f : -0.4f), OCC_OK);
    }
    victim_digest = iotest_map_digest(&victim);
}

/* The bytes must be refused with `want` by both read and load, and the victim unchanged. */
static void expect_refused(const uint8_t *buf, size_t len, occ_err_t want, const char *what)
{
    occ_io_info_t info;
    const occ_err_t e1 = occ_io_read(&victim, buf, len, &info);
    const occ_map_t before = victim;
    const occ_err_t e2 = occ_io_load(&victim, NULL, big_arena, 1u << 20, buf, len, NULL);
    if (e1 != want || e2 != want) {
        printf("%s: got %s / %s (%s at %zu), want %s\n", what, occ_err_str(e1), occ_err_str(e2),
               info.error, info.error_offset, occ_err_str(want));
        fail();
    }
    assert_memory_equal(&before, &victim, sizeof victim);
    assert_int_equal(iotest_map_digest(&victim), victim_digest);
    assert_int_equal(occ_map_check(&victim), OCC_OK);
    assert_true(info.error != NULL && info.error[0] != '\0');
}

static uint8_t *with_header(const char *hdr, const uint8_t *data, size_t n, size_t *len)
{
    const size_t h = strlen(hdr);
    uint8_t *b = (uint8_t *)malloc(h + n + 1u);
    memcpy(b, hdr, h);
    if (n > 0u) {
        memcpy(b + h, data, n);
    }
    *len = h + n;
    return b;
}

#define BT_HDR(size) "# Octomap OcTree binary file\nid OcTree\nsize " size "\nres 0.1\ndata\n"

static void test_corrupt_bt(void **state)
{
    (void)state;
    make_victim();
    size_t len = 0;
    uint8_t *file = iotest_read_file(GEB079, &len);
    assert_non_null(file);
    /* Truncations: every length of a small .bt, and geb079 inside the header, at the data
     * and across the data. */
    size_t ns = 0;
    uint8_t *small_bt = iotest_write(&victim, OCC_FORMAT_BT, &ns);
    for (size_t cut = 0; cut < ns; cut++) {
        expect_refused(small_bt, cut, OCC_ERR_FORMAT, "small .bt truncated");
    }
    free(small_bt);
    for (size_t cut = 0; cut < len; cut += (cut < 200u ? 7u : 20011u)) {
        char what[64];
        snprintf(what, sizeof what, "geb079 truncated to %zu", cut);
        expect_refused(file, cut, OCC_ERR_FORMAT, what);
    }
    /* Wrong magic. */
    uint8_t *b = (uint8_t *)malloc(len);
    memcpy(b, file, len);
    b[2] = 'o';
    expect_refused(b, len, OCC_ERR_FORMAT, "wrong magic");
    free(b);
    size_t n = 0;
    /* Unknown tree id. */
    static const uint8_t one_leaf[2] = {0x02u, 0x00u};  /* child 0 occupied */
    b = with_header("# Octomap OcTree binary file\nid CountingOcTree\nsize 2\nres 0.1\ndata\n",
                    one_leaf, 2u, &n);
    expect_refused(b, n, OCC_ERR_UNSUPPORTED, "unknown id");
    free(b);
    /* Sizes: absurd, mismatched, negative, missing id/res, bad res. */
    const char *const bad_headers[] = {
        BT_HDR("99999999999"), BT_HDR("3"), BT_HDR("1"), BT_HDR("-2"), BT_HDR("x"),
        "# Octomap OcTree binary file\nsize 2\nres 0.1\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres 0\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres -0.1\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres nan\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres 1e30\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres 1e-30\ndata\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres 0.1\n",
        "# Octomap OcTree binary file\nid OcTree\nsize 2\nres 0.1\ndata",
        "# Octomap OcTree binary file\nid OcTreeOcTreeOcTreeOcTreeOcTreeOcTree\nsize 2\n",
    };
    for (size_t i = 0; i < sizeof bad_headers / sizeof bad_headers[0]; i++) {
        b = with_header(bad_headers[i], one_leaf, 2u, &n);
        expect_refused(b, n, OCC_ERR_FORMAT, bad_headers[i]);
        free(b);
    }
    /* The good one is accepted (control). */
    b = with_header(BT_HDR("2"), one_leaf, 2u, &n);
    occ_io_info_t info;
    assert_int_equal(occ_io_probe(b, n, NULL, &info), OCC_OK);
    assert_int_equal(info.nodes, 2);
    free(b);
    /* Impossible trees: a root without children; an inner child without children; a chain of
     * inner nodes below the voxels. */
    static const uint8_t root0[2] = {0u, 0u};
    b = with_header(BT_HDR("1"), root0, 2u, &n);
    expect_refused(b, n, OCC_ERR_FORMAT, "root without children");
    free(b);
    static const uint8_t empty_inner[4] = {0x03u, 0u, 0u, 0u};
    b = with_header(BT_HDR("2"), empty_inner, 4u, &n);
    expect_refused(b, n, OCC_ERR_FORMAT, "inner node without children");
    free(b);
    uint8_t chain[2 * 18];
    for (unsigned i = 0; i < 17u; i++) {
        chain[2u * i] = 0x03u;  /* child 0 has children */
        chain[2u * i + 1u] = 0u;
    }
    chain[34] = 0x02u;
    chain[35] = 0u;
    b = with_header(BT_HDR("19"), chain, sizeof chain, &n);
    expect_refused(b, n, OCC_ERR_FORMAT, "voxel with children");
    free(b);
    /* Every single-byte flip in the data: refused or read into a valid map. */
    const size_t data_at = (size_t)((uint8_t *)strstr((char *)file, "data\n") - file) + 5u;
    b = (uint8_t *)malloc(len);
    unsigned refused = 0, accepted = 0;
    for (size_t i = data_at; i < len; i += 4999u) {
        memcpy(b, file, len);
        b[i] ^= 0x5Au;
        occ_io_info_t inf;
        const occ_err_t e = occ_io_probe(b, len, NULL, &inf);
        if (e == OCC_OK) {
            accepted++;
        } else {
            assert_int_equal(e, OCC_ERR_FORMAT);
            refused++;
        }
    }
    printf("byte flips: %u refused, %u still well-formed\n", refused, accepted);
    free(b);
    free(file);
}

static void test_corrupt_ot(void **state)
{
    (void)state;
    make_victim();
    size_t n1 = 0;
    uint8_t *w = iotest_write(&victim, OCC_FORMAT_OT, &n1);
    const size_t data_at = (size_t)((uint8_t *)strstr((char *)w, "data\n") - w) + 5u;
    for (size_t cut = 0; cut < n1; cut++) {
        expect_refused(w, cut, OCC_ERR_FORMAT, ".ot truncated");
    }
    uint8_t *b = (uint8_t *)malloc(n1);
    memcpy(b, w, n1);
    const uint32_t nan_bits = 0x7FC00000u;
    memcpy(b + data_at, &nan_bits, 4u);
    expect_refused(b, n1, OCC_ERR_FORMAT, "NaN log-odds");
    /* A voxel with children: the last record is a voxel; give it a child mask. */
    memcpy(b, w, n1);
    b[n1 - 1u] = 0x01u;
    expect_refused(b, n1, OCC_ERR_FORMAT, "voxel with children / size");
    /* Unknown type and a type whose extra payload is not there. */
    size_t n = 0;
    uint8_t *c = with_header("# Octomap OcTree file\nid MapNode\nsize 1\nres 0.1\ndata\n",
                             b + data_at, 5u, &n);
    expect_refused(c, n, OCC_ERR_UNSUPPORTED, "unknown .ot id");
    free(c);
    char hdr[128];
    snprintf(hdr, sizeof hdr, "# Octomap OcTree file\nid ColorOcTree\nsize %llu\nres 0.1\ndata\n",
             (unsigned long long)occ_io_octomap_nodes(&victim, OCC_FORMAT_OT));
    c = with_header(hdr, w + data_at, n1 - data_at, &n);
    expect_refused(c, n, OCC_ERR_FORMAT, "ColorOcTree without colour bytes");
    free(c);
    free(b);
    free(w);
}

/* A map that does not fit the arena is refused whole; read at exactly the needed size works. */
static void test_nomem(void **state)
{
    (void)state;
    make_victim();
    size_t len = 0;
    uint8_t *file = iotest_read_file(GEB079, &len);
    occ_io_info_t info;
    assert_int_equal(occ_io_probe(file, len, NULL, &info), OCC_OK);
    const size_t exact = (size_t)info.peak_inner_blocks * OCC_INNER_BLOCK_BYTES +
                         (size_t)info.peak_leaf_blocks * OCC_LEAF_BLOCK_BYTES;
    printf("geb079: %u inner + %u leaf blocks (peak %u + %u), %zu arena bytes\n",
           (unsigned)info.inner_blocks, (unsigned)info.leaf_blocks,
           (unsigned)info.peak_inner_blocks, (unsigned)info.peak_leaf_blocks, exact);
    /* big_arena is 8-aligned: `exact` bytes must do, 8 fewer must not. */
    const occ_map_t before = victim;
    assert_int_equal(occ_io_load(&victim, NULL, big_arena, exact - 8u, file, len, &info),
                     OCC_ERR_NOMEM);
    assert_memory_equal(&before, &victim, sizeof victim);
    assert_int_equal(iotest_map_digest(&victim), victim_digest);
    occ_map_t m;
    assert_int_equal(occ_io_load(&m, NULL, big_arena, exact, file, len, &info), OCC_OK);
    assert_int_equal(occ_map_check(&m), OCC_OK);
    /* Into an existing small map: refused, unchanged. */
    occ_map_config_t cfg = iotest_octomap_cfg();
    cfg.resolution_m = info.resolution_m;
    static uint8_t small[1u << 16];
    occ_map_t sm;
    assert_int_equal(occ_map_init(&sm, &cfg, small, sizeof small), OCC_OK);
    occ_key_t key = {{1000u, 1000u, 1000u}};
    assert_int_equal(occ_map_update_key(&sm, key, 1.0f), OCC_OK);
    const uint64_t d = iotest_map_digest(&sm);
    assert_int_equal(occ_io_read(&sm, file, len, &info), OCC_ERR_NOMEM);
    assert_int_equal(iotest_map_digest(&sm), d);
    /* Depth/resolution mismatch for occ_io_read; depth != 16 cannot write OctoMap files. */
    cfg.resolution_m = 0.123f;
    assert_int_equal(occ_map_init(&sm, &cfg, small, sizeof small), OCC_OK);
    assert_int_equal(occ_io_read(&sm, file, len, &info), OCC_ERR_ARG);
    cfg.depth_levels = 12u;
    assert_int_equal(occ_map_init(&sm, &cfg, small, sizeof small), OCC_OK);
    assert_int_equal(occ_io_write(&sm, OCC_FORMAT_BT, NULL, NULL, NULL), OCC_ERR_UNSUPPORTED);
    free(file);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_corrupt_bt),
        cmocka_unit_test(test_corrupt_ot),
        cmocka_unit_test(test_nomem),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
