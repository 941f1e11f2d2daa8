/* SPDX-License-Identifier: BSD-3-Clause */
/* test_io_header.c - the OctoMap text header as AbstractOcTree::readHeader reads it, entry by
 * entry, through occ_io_probe on a real tree's data behind hand-written headers: numbers the way
 * istream >> double reads them (signs, exponents either way, more digits than a float holds),
 * comments, unknown keywords (skipped, warned), the legacy id, keywords in any order, and
 * headers that must be refused. The writer and real files: test_io_octomap.c. */
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

static uint8_t arena[1u << 20];
static uint8_t *tree;    /* a small map's .bt data (after "data\n") */
static size_t tree_len;
static unsigned long long tree_size; /* its node count, the header's "size" */

static int setup(void **state)
{
    (void)state;
    occ_map_config_t cfg = iotest_octomap_cfg();
    cfg.resolution_m = 0.1f;
    occ_map_t m;
    assert_int_equal(occ_map_init(&m, &cfg, arena, sizeof arena), OCC_OK);
    for (uint32_t i = 0; i < 20u; i++) {
        const occ_key_t key = {{32768u + i, 32768u - i % 3u, 32770u + i % 4u}};
        assert_int_equal(occ_map_update_key(&m, key, (i % 2u) ? 0.85f : -0.4f), OCC_OK);
    }
    size_t len = 0;
    uint8_t *bt = iotest_write(&m, OCC_FORMAT_BT, &len);
    assert_non_null(bt);
    occ_io_info_t info;
    assert_int_equal(occ_io_probe(bt, len, NULL, &info), OCC_OK);
    tree_len = len - info.data_offset;
    tree_size = (unsigned long long)info.header_nodes;
    tree = (uint8_t *)malloc(tree_len);
    assert_non_null(tree);
    memcpy(tree, bt + info.data_offset, tree_len);
    free(bt);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    free(tree);
    return 0;
}

/* Bit for bit (-Wfloat-equal). */
static bool same_float(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* "# Octomap OcTree binary file\n" + body (its "%llu", if any, is the tree's node count) + the
 * tree's data (unless !with_tree), probed. */
static occ_err_t probe_bytes(const char *body, bool with_tree, occ_io_info_t *info)
{
    char head[256];
    const int h = snprintf(head, sizeof head, "# Octomap OcTree binary file\n");
    const int b = snprintf(head + h, sizeof head - (size_t)h, body, tree_size);
    assert_true(h > 0 && b >= 0 && (size_t)(h + b) < sizeof head);
    const size_t n = (size_t)(h + b) + (with_tree ? tree_len : 0u);
    uint8_t *buf = (uint8_t *)malloc(n);
    assert_non_null(buf);
    memcpy(buf, head, (size_t)(h + b));
    if (with_tree) {
        memcpy(buf + h + b, tree, tree_len);
    }
    memset(info, 0, sizeof *info);
    const occ_err_t e = occ_io_probe(buf, n, NULL, info);
    free(buf);
    return e;
}

static occ_err_t probe(const char *body, occ_io_info_t *info)
{
    return probe_bytes(body, true, info);
}

/* Each res text reads as OctoMap reads it: a double (strtod here), then float. */
static void test_res_numbers(void **state)
{
    (void)state;
    const char *const texts[] = {"0.1",   "1e-1",  "5E-2",    "+0.25", "2.5e+0", "100e-3",
                                 ".5",    "7.",    "0.0625",  "1e-5",  "12345.5", "3e2",
                                 "0.000001", "999999"};
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        char body[96];
        snprintf(body, sizeof body, "id OcTree\nsize %%llu\nres %s\ndata\n", texts[i]);
        occ_io_info_t info;
        const occ_err_t e = probe(body, &info);
        const float want = (float)strtod(texts[i], NULL);
        if (e != OCC_OK || !same_float(info.resolution_m, want) || info.warnings != 0u) {
            printf("res %s: %s, read %.9g, want %.9g, warnings 0x%x\n", texts[i], occ_err_str(e),
                   (double)info.resolution_m, (double)want, (unsigned)info.warnings);
            fail();
        }
    }
}

/* More significant digits than 19: the rest only scale (within a float's rounding). */
static void test_res_long(void **state)
{
    (void)state;
    occ_io_info_t info;
    assert_int_equal(probe("id OcTree\nsize %llu\nres 0.1000000000000000000000000001\ndata\n", &info),
                     OCC_OK);
    assert_true(info.resolution_m > 0.0999999f && info.resolution_m < 0.1000001f);
    assert_int_equal(probe("id OcTree\nsize %llu\nres 00000000000000000000000000.5\ndata\n", &info),
                     OCC_OK);
    assert_true(same_float(info.resolution_m, 0.5f));
    assert_int_equal(probe("id OcTree\nsize %llu\nres 1234567890123456789012345678e-27\ndata\n",
                           &info),
                     OCC_OK);
    assert_true(info.resolution_m > 1.2345677f && info.resolution_m < 1.2345681f);
}

/* Entries in any order, comments and unknown keywords between them (skipped to the end of their
 * line, as OctoMap does; unknown ones are warned about), the legacy id. */
static void test_entries(void **state)
{
    (void)state;
    occ_io_info_t info;
    assert_int_equal(probe("res 0.1\nsize %llu\nid OcTree\ndata\n", &info), OCC_OK);
    assert_true(same_float(info.resolution_m, 0.1f) && info.header_nodes == tree_size);
    assert_string_equal(info.tree_id, "OcTree");
    assert_int_equal(info.warnings, 0u);
    assert_int_equal(probe("# a comment, id 7 res 9\nid OcTree\n#x\nsize %llu\nres 0.1\ndata\n", &info),
                     OCC_OK);
    assert_true(same_float(info.resolution_m, 0.1f));
    assert_int_equal(info.warnings, 0u);
    assert_int_equal(probe("id OcTree\nstamp 17 res 9\nsize %llu\nres 0.1\ndata\n", &info), OCC_OK);
    assert_true(same_float(info.resolution_m, 0.1f));
    assert_int_equal(info.warnings, OCC_IO_WARN_UNKNOWN_KEY);
    assert_int_equal(probe("id 1\nsize %llu\nres 0.1\ndata\n", &info), OCC_OK);
    assert_string_equal(info.tree_id, "OcTree");
    assert_int_equal(info.warnings, OCC_IO_WARN_LEGACY_ID);
    /* Whitespace of any kind between tokens; the last res wins. */
    assert_int_equal(probe("  id\tOcTree size\n%llu res 0.3 res 0.1\r\ndata\n", &info), OCC_OK);
    assert_true(same_float(info.resolution_m, 0.1f));
}

/* With a valid tree behind it (with_tree), only the header can be what is refused. */
static void expect_refused(const char *body, bool with_tree)
{
    occ_io_info_t info;
    const occ_err_t e = probe_bytes(body, with_tree, &info);
    if (e != OCC_ERR_FORMAT || info.error == NULL || info.error[0] == '\0') {
        printf("header \"%s\": %s, want OCC_ERR_FORMAT with a reason\n", body, occ_err_str(e));
        fail();
    }
}

/* Headers OctoMap cannot read, or that name no usable tree: refused with a reason. */
static void test_refused(void **state)
{
    (void)state;
    const char *const bodies[] = {
        "size %llu\nres 0.1\ndata\n",                    /* no id */
        "id OcTree\nsize %llu\ndata\n",                  /* no res */
        "id OcTree\nsize %llu\nres x\ndata\n",           /* malformed res */
        "id OcTree\nsize %llu\nres -.\ndata\n",          /* no digit */
        "id OcTree\nsize %llu\nres 1e-7\ndata\n",        /* below 1e-6 */
        "id OcTree\nsize %llu\nres 1e6\ndata\n",         /* 1e6 and above */
        "id OcTree\nsize %llu\nres 1e99999999\ndata\n",  /* saturates */
        "id OcTree\nsize -3\nres 0.1\ndata\n",         /* OctoMap reads an unsigned */
        "id OcTree\nsize 4294967296\nres 0.1\ndata\n", /* more than an unsigned */
        "id OcTreeWithAnIdLongerThanThirtyOneBytes\nsize %llu\nres 0.1\ndata\n",
    };
    for (size_t i = 0; i < sizeof bodies / sizeof bodies[0]; i++) {
        expect_refused(bodies[i], true);
    }
    /* Cut short: a line that never ends, no data line. */
    expect_refused("id OcTree\nsize %llu\nres 0.1\nunknown", false);
    expect_refused("id OcTree\nsize %llu\nres 0.1\n# comment", false);
    expect_refused("id OcTree\nsize %llu\nres 0.1\n", false);
    expect_refused("id OcTree\nsize %llu\nres 0.1\ndata", false);
    expect_refused("id OcTree\nsize %llu\nres", false);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_res_numbers),
        cmocka_unit_test(test_res_long),
        cmocka_unit_test(test_entries),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
