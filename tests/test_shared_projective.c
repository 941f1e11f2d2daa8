/* SPDX-License-Identifier: BSD-3-Clause */
/* test_shared_projective.c - a depth frame by projection on a shared map is ONE version: a view
 * opened before the frame sees none of it, a view opened after sees all of it (the writes of the
 * projective integrator, coarse nodes then voxels, are one write section). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_depth.h"

/* An 8x8 time-of-flight array 2 m from a wall, camera looking along map +x. */
static float tof[8][8];
static const occ_depth_params_t tof_dp = {{9.656854f, 9.656854f, 3.5f, 3.5f}, 0.05f, 3.0f, 1u};
static const occ_pose_t tof_pose = {{0.31f, 0.12f, 1.03f}, {0.5f, -0.5f, 0.5f, -0.5f}};

static void test_frame_is_one_version(void **state)
{
    (void)state;
    for (unsigned v = 0; v < 8u; v++) {
        for (unsigned u = 0; u < 8u; u++) {
            tof[v][u] = 2.0f;
        }
    }
    const size_t arena_bytes = (size_t)4 << 20;
    uint8_t *arena = malloc(arena_bytes);
    assert_non_null(arena);
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.05f;
    occ_map_t map;
    assert_int_equal(occ_map_init(&map, &cfg, arena, arena_bytes), OCC_OK);
    const size_t shared_bytes = occ_shared_bytes(&map, 2u);
    uint8_t *mem = malloc(shared_bytes);
    assert_non_null(mem);
    assert_int_equal(occ_map_share(&map, mem, shared_bytes, 2u), OCC_OK);

    occ_view_t before;
    assert_int_equal(occ_read_begin(&map, 0u, &before), OCC_OK);
    const uint32_t v0 = occ_map_version(&map);

    occ_insert_params_t ip = occ_insert_params_default();
    ip.method = OCC_INSERT_PROJECTIVE;
    const size_t scratch_bytes = occ_depth_scratch_bytes(&map, 8u, 8u, 1u, tof_dp.max_range_m, &ip);
    assert_true(scratch_bytes > 0u);
    void *scratch = malloc(scratch_bytes);
    assert_non_null(scratch);
    const occ_depth_image_t im = {tof, OCC_DEPTH_F32, 8u, 8u, sizeof tof[0], 1.0f};
    occ_depth_result_t r;
    assert_int_equal(occ_map_insert_depth(&map, &im, &tof_dp, &tof_pose, &ip, scratch,
                                          scratch_bytes, &r),
                     OCC_OK);
    /* Coarse free nodes and voxel updates: one version, not two or three. */
    assert_int_equal(occ_map_version(&map), v0 + 1u);

    const occ_vec3_t ahead = {tof_pose.p.x + 1.0f, tof_pose.p.y, tof_pose.p.z};
    const float off = 0.5f * 2.0f / 9.656854f;
    const occ_vec3_t wall = {tof_pose.p.x + 2.0f, tof_pose.p.y + off, tof_pose.p.z + off};
    assert_int_equal(occ_map_state_at(&map, ahead), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_at(&map, wall), OCC_STATE_OCCUPIED);
    /* The old view: nothing of the frame. */
    assert_int_equal(occ_map_state_at(occ_view_map(&before), ahead), OCC_STATE_UNKNOWN);
    assert_int_equal(occ_map_state_at(occ_view_map(&before), wall), OCC_STATE_UNKNOWN);
    /* A new view: all of it. */
    occ_view_t after;
    assert_int_equal(occ_read_begin(&map, 1u, &after), OCC_OK);
    assert_int_equal(after.version, v0 + 1u);
    assert_int_equal(occ_map_state_at(occ_view_map(&after), ahead), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_at(occ_view_map(&after), wall), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_check(occ_view_map(&after)), OCC_OK);
    occ_read_end(&map, &after);
    occ_read_end(&map, &before);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    free(scratch);
    free(mem);
    free(arena);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frame_is_one_version),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
