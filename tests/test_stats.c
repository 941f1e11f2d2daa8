/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_stats.c - occ_map_stats() (src/core/stats.c) against OctoMap's own numbers and against
 * values worked out by hand:
 *  - OctoMap's example map geb079.bt (Debian liboctomap-dev) and fr_078_tidyup.bt
 *    (../shared/data/maps): node, leaf, occupied and free leaf counts equal octomap::OcTree's;
 *    occupied and free volumes equal the sums of OctoMap's leaf iterator (getSize()^3) to
 *    1e-9 relative; fr_078's free volume prints OctoMap's 326.251375 m3 (the float volume
 *    was 326.2514).
 *  - By hand: 2^30 free voxels at 0.1 m are 2^30 x 0.1^3 = 1073741.824 m3, in double (a float
 *    volume is 1073741.875, 5e-8 off; (double)0.1f cubed gives 1073741.968).
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
#include "occmap/occ_io.h"
#include "support/iotest.h"
#include "support/leak_check.h"
#include "support/oracle_stats.h"

#define GEB079 "/usr/share/doc/liboctomap-dev/examples/data/geb079.bt"
#define FR078 "../shared/data/maps/fr_078_tidyup.bt"

static bool rel_close(const double a, const double b, const double rel)
{
    return fabs(a - b) <= rel * fmax(fabs(a), fabs(b));
}

/* occ_map_stats() of the file read by occmap equals OctoMap's statistics of the same bytes.
 * `free_printed` (NULL: not checked): OctoMap's free volume as printed with 6 decimals. */
static void compare_file(const char *const path, const char *const free_printed)
{
    size_t len = 0;
    uint8_t *const file = iotest_read_file(path, &len);
    if (file == NULL) {
        printf("SKIP: %s absent\n", path);
        skip();
    }
    oracle_stats_t want;
    assert_true(oracle_stats_bt(file, len, &want));
    occ_map_t map;
    occ_err_t e = OCC_OK;
    void *const arena = iotest_load(&map, file, len, 0u, &e, NULL);
    assert_int_equal(e, OCC_OK);
    occ_map_stats_t got;
    occ_map_stats(&map, &got);
    printf("%s: occmap %.17g / %.17g m3 occupied / free, OctoMap %.17g / %.17g (res %g)\n", path,
           got.occupied_volume_m3, got.free_volume_m3, want.occupied_volume_m3,
           want.free_volume_m3, want.resolution_m);
    assert_int_equal(got.nodes, want.nodes);
    assert_int_equal(got.leaf_nodes, want.leaf_nodes);
    assert_int_equal(got.occupied_leaves, want.occupied_leaves);
    assert_int_equal(got.free_leaves, want.free_leaves);
    /* OctoMap's running sum over ~10^5 leaves drifts ~1e-11 relative (fr_078: 326.25137500149
     * against the exact 2610011 x 0.05^3 = 326.251375000000); a float volume, or one built on
     * (double)0.05f, is off by > 1e-7. */
    assert_true(rel_close(got.occupied_volume_m3, want.occupied_volume_m3, 1e-9));
    assert_true(rel_close(got.free_volume_m3, want.free_volume_m3, 1e-9));
    if (free_printed != NULL) {
        char ours[32], theirs[32];
        snprintf(ours, sizeof ours, "%.6f", got.free_volume_m3);
        snprintf(theirs, sizeof theirs, "%.6f", want.free_volume_m3);
        assert_string_equal(theirs, free_printed);
        assert_string_equal(ours, free_printed);
    }
    assert_int_equal(occ_map_check(&map), OCC_OK); /* (leak_check's block-by-block release is
                                                     * quadratic under OCC_POOL_PARANOID here) */
    free(arena);
    free(file);
}

static void test_geb079_vs_octomap(void **state)
{
    (void)state;
    compare_file(GEB079, NULL);
}

static void test_fr078_vs_octomap(void **state)
{
    (void)state;
    compare_file(FR078, "326.251375");
}

/* One free level-10 node at 0.1 m: 2^30 voxels, 2^30 x (0.1 x 0.1 x 0.1) m3 exactly as double
 * arithmetic gives it; the occupied voxel next to it adds 0.1^3. */
static void test_volume_by_hand(void **state)
{
    (void)state;
    static uint8_t arena[OCC_ARENA_BYTES(64, 64)];
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    occ_map_t map;
    assert_int_equal(occ_map_init(&map, &cfg, arena, sizeof arena), OCC_OK);
    const occ_key_t free_node = {{0u, 0u, 0u}};
    assert_int_equal(occ_map_set_key(&map, free_node, 10u, -1.0f), OCC_OK);
    const occ_key_t hit = {{40000u, 40000u, 40000u}};
    assert_int_equal(occ_map_update_key(&map, hit, 1.0f), OCC_OK);
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    assert_int_equal(st.free_voxels, (uint64_t)1 << 30);
    assert_int_equal(st.occupied_voxels, 1u);
    const double voxel_m3 = 0.1 * 0.1 * 0.1;
    const double want_free = 1073741824.0 * voxel_m3;
    printf("free %.17g m3 (want %.17g), occupied %.17g m3 (want %.17g)\n", st.free_volume_m3,
           want_free, st.occupied_volume_m3, voxel_m3);
    assert_memory_equal(&st.free_volume_m3, &want_free, sizeof want_free);
    assert_memory_equal(&st.occupied_volume_m3, &voxel_m3, sizeof voxel_m3);
    assert_true(rel_close(st.free_volume_m3, 1073741.824, 1e-15));
    assert_int_equal(leak_check(&map), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_volume_by_hand),
        cmocka_unit_test(test_geb079_vs_octomap),
        cmocka_unit_test(test_fr078_vs_octomap),
    };
    return cmocka_run_group_tests_name("stats", tests, NULL, NULL);
}
