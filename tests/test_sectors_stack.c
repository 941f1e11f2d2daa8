/* SPDX-License-Identifier: BSD-3-Clause */
/* test_sectors_stack.c - the sector walk's full-stack path. This binary compiles sectors.c with
 * a walk limit of 9 entries (instead of OCC_SECTORS_STACK, which the depth bound makes
 * unreachable), so a map with detail near the vehicle overflows it: the call must return
 * OCC_ERR_NOMEM with every value at the unsafe answer, never a partial "clear" result. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#define OCC_SECTORS_WALK_LIMIT 9u
#include "sectors/sectors.c" /* this binary's occ_sectors_compute; libocc's copy is not linked */

static uint8_t arena[1u << 20];
static occ_map_t map;
static occ_sectors_t sect;

static void test_stack_full(void **state)
{
    (void)state;
    occ_map_config_t mc = occ_map_config_default();
    mc.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(&map, &mc, arena, sizeof arena), OCC_OK);
    occ_sectors_config_t cfg = occ_sectors_config_default();
    const occ_pose_t p = {{0.05f, 0.05f, 0.05f}, {1.0f, 0.0f, 0.0f, 0.0f}}; /* facing east */
    /* One uniform free root: one node read, the limit is never reached. */
    const occ_key_t root = {{0, 0, 0}};
    assert_int_equal(occ_map_set_key(&map, root, mc.depth_levels, -2.0f), OCC_OK);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_OK);
    assert_int_equal(sect.n, 72);
    for (unsigned s = 0; s < 72u; s++) {
        assert_int_equal(sect.distance_cm[s], cfg.max_distance_cm + 1u);
    }
    /* A voxel 1 m ahead: the walk descends 16 levels and needs more than 9 entries. */
    const occ_vec3_t v = {1.05f, 0.05f, 0.05f};
    assert_int_equal(occ_map_update(&map, v, 2.0f), OCC_OK);
    assert_int_equal(occ_sectors_compute(&map, &p, &cfg, &sect), OCC_ERR_NOMEM);
    assert_int_equal(sect.n, 0);
    for (unsigned s = 0; s < OCC_SECTORS_MAX; s++) {
        assert_int_equal(sect.distance_cm[s], cfg.min_distance_cm);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stack_full),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
