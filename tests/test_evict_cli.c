/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_evict_cli.c - the `occmap build --arena-bytes/--evict/--keep-radius` helper
 * (tools/evict_cli.c, compiled in): flag parsing and errors, the JSON members, and inserting
 * OctoMap's real laser scan (build/data/scan.dat) into an arena half the map's size with
 * the automatic eviction: every insert succeeds, the arena is never exceeded, check() holds.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../tools/cli.c"
#include "../tools/evict_cli.c"
#include "occmap/host/occ_scan.h"

#define SCAN_DAT "build/data/scan.dat"
#ifndef ARENA_DIV
#define ARENA_DIV 2u
#endif

static int run_parse(evict_cli_t *c, int argc, char **argv)
{
    for (int i = 0; i < argc; i++) {
        const int r = evict_cli_parse(c, argc, argv, &i);
        if (r < 0) {
            return -1;
        }
    }
    return evict_cli_finish(c);
}

static void test_parse(void **state)
{
    (void)state;
    evict_cli_t c;
    evict_cli_init(&c);
    char *ok[] = {"--res", "0.1", "--arena-bytes", "2M", "--evict", "coarsen", "--keep-radius",
                  "4.5"};
    assert_int_equal(run_parse(&c, 8, ok), 0);
    assert_true(c.fixed_arena);
    assert_int_equal(c.arena_bytes, 2u << 20);
    assert_true(c.evict);
    assert_int_equal(c.policy.mode, OCC_EVICT_COARSEN);
    assert_true(c.policy.keep_radius_m > 4.49f && c.policy.keep_radius_m < 4.51f);
    int i = 0;
    char *other[] = {"--res", "0.1"};
    assert_int_equal(evict_cli_parse(&c, 2, other, &i), 0);
    assert_int_equal(i, 0);

    char *bad1[] = {"--arena-bytes", "-5"};
    char *bad2[] = {"--arena-bytes", "12Q"};
    char *bad3[] = {"--arena-bytes", "1M", "--evict", "sideways"};
    char *bad4[] = {"--arena-bytes", "1M", "--keep-radius", "nan"};
    char *bad5[] = {"--arena-bytes", "1M", "--keep-radius", "-1"};
    char *bad6[] = {"--evict", "robot"};
    char *bad7[] = {"--arena-bytes", "16"};
    char *bad8[] = {"--arena-bytes"};
    char **bads[] = {bad1, bad2, bad3, bad4, bad5, bad6, bad7, bad8};
    const int lens[] = {2, 2, 4, 4, 4, 2, 2, 1};
    for (size_t k = 0; k < sizeof lens / sizeof lens[0]; k++) {
        evict_cli_init(&c);
        assert_int_equal(run_parse(&c, lens[k], bads[k]), -1);
    }
    evict_cli_init(&c);
    char *robot[] = {"--arena-bytes", "1000000", "--evict", "robot"};
    assert_int_equal(run_parse(&c, 4, robot), 0);
    assert_int_equal(c.policy.mode, OCC_EVICT_ROBOT);
    assert_int_equal(c.arena_bytes, 1000000u);
}

static void test_json_and_insert(void **state)
{
    (void)state;
    if (access(SCAN_DAT, R_OK) != 0) {
        printf("SKIP test_json_and_insert: %s absent (make test builds it)\n", SCAN_DAT);
        skip();
    }
    occ_vec3_t *pts = NULL;
    size_t n = 0;
    char msg[128];
    assert_int_equal(occ_scan_read_xyz(SCAN_DAT, &pts, &n, msg, sizeof msg), OCC_OK);
    size_t kept = 0; /* every 16th point: enough rays, a small scratch */
    for (size_t j = 0; j < n; j += 16u) {
        pts[kept++] = pts[j];
    }
    n = kept;
    evict_cli_t c;
    evict_cli_init(&c);
    char json[512];
    FILE *f = fmemopen(json, sizeof json, "w");
    assert_non_null(f);
    evict_cli_print_json(f, &c);
    fclose(f);
    assert_string_equal(json, "\"arena_bytes\": null, \"evictions\": 0, \"blocks_evicted\": 0, "
                              "\"last_origin\": null");

    /* The scan as 8 sweeps from origins 20 m apart, at 0.1 m, max range 6 m. */
    occ_map_config_t cfg = occ_map_config_default();
    occ_insert_params_t ip = occ_insert_params_default();
    ip.max_range_m = 6.0f;
    static uint8_t big[16u << 20];
    occ_map_t ref;
    assert_int_equal(occ_map_init(&ref, &cfg, big, sizeof big), OCC_OK);
    const size_t sb = occ_insert_scratch_bytes(&ref, n, 6.0f, &ip);
    void *scratch = malloc(sb);
    occ_vec3_t *moved = malloc(n * sizeof *moved);
    assert_non_null(scratch);
    assert_non_null(moved);
    enum { SWEEPS = 8 };
    for (int s = 0; s < SWEEPS; s++) {
        const occ_vec3_t o = {20.0f * (float)s, 0.0f, 0.0f};
        for (size_t j = 0; j < n; j++) {
            moved[j] = pts[j];
            moved[j].x += o.x;
        }
        assert_int_equal(occ_map_insert_cloud(&ref, &o, moved, n, &ip, scratch, sb, NULL), OCC_OK);
    }
    occ_map_stats_t st;
    occ_map_pool_stats(&ref, &st);
    evict_cli_init(&c);
    char a[32];
    snprintf(a, sizeof a, "%zu", st.bytes_peak / ARENA_DIV);
    char *args[] = {"--arena-bytes", a, "--evict", "robot", "--keep-radius", "6"};
    assert_int_equal(run_parse(&c, 6, args), 0);
    uint8_t *arena = malloc(c.arena_bytes);
    assert_non_null(arena);
    occ_map_t m;
    assert_int_equal(occ_map_init(&m, &cfg, arena, c.arena_bytes), OCC_OK);
    for (int s = 0; s < SWEEPS; s++) {
        const occ_vec3_t o = {20.0f * (float)s, 0.0f, 0.0f};
        for (size_t j = 0; j < n; j++) {
            moved[j] = pts[j];
            moved[j].x += o.x;
        }
        const occ_err_t e = evict_cli_insert(&c, &m, &o, moved, n, &ip, scratch, sb, NULL);
        if (e != OCC_OK) {
            fail_msg("sweep %d: %s", s, occ_err_str(e));
        }
        assert_int_equal(occ_map_check(&m), OCC_OK);
        occ_map_pool_stats(&m, &st);
        assert_true(st.bytes_peak <= c.arena_bytes);
    }
    assert_true(c.out.evictions > 0u);
    assert_true(c.insert_retries > 0u);
    f = fmemopen(json, sizeof json, "w");
    evict_cli_print_json(f, &c);
    fclose(f);
    char want[512];
    snprintf(want, sizeof want,
             "\"arena_bytes\": %zu, \"evictions\": %llu, \"blocks_evicted\": %llu, "
             "\"last_origin\": [140, 0, 0]",
             c.arena_bytes, (unsigned long long)c.out.evictions,
             (unsigned long long)c.out.blocks_freed);
    assert_string_equal(json, want);
    printf("evict_cli: scan.dat x %d sweeps in an arena of %zu bytes (half the map): "
           "%u inserts needed eviction, %s\n", SWEEPS, c.arena_bytes, c.insert_retries, json);
    free(arena);
    occ_map_clear(&ref);
    free(moved);
    free(scratch);
    free(pts);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_json_and_insert),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
