/* SPDX-License-Identifier: BSD-3-Clause */
/* test_sectors_floor.c - occ_sectors_compute() on a room with a floor (the ground rule, the band
 * below and above) against the reference of tests/support/sectors_ref.c and hand-computed
 * values; every error fails closed; the argument checks of occ_sectors_config_check(). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "occmap/occ_sectors.h"
#include "support/sectors_ref.h"

/* A room on a floor: observed free space z in [0, 1.6) over [-3.2, 3.2)^2, the floor voxels
 * z in [-0.1, 0) occupied (unknown below), a wall x in [2.0, 2.1) up to 1.6 m. */
static void floor_room(void)
{
    occ_key_t k;
    for (double x = -3.2; x < 3.2; x += 1.6) {
        for (double y = -3.2; y < 3.2; y += 1.6) {
            sref_key_at(x + 0.05, y + 0.05, 0.05, &k);
            assert_int_equal(occ_map_set_key(&sref_map, k, 4, -2.0f), OCC_OK);
        }
    }
    for (double x = -2.95; x < 3.0; x += 0.1) {
        for (double y = -2.95; y < 3.0; y += 0.1) {
            sref_key_at(x, y, -0.05, &k);
            assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
        }
    }
    for (double y = -2.95; y < 3.0; y += 0.1) {
        for (double z = -0.05; z < 1.6; z += 0.1) {
            sref_key_at(2.05, y, z, &k);
            assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
        }
    }
}

static unsigned sectors_below(unsigned cm)
{
    unsigned n = 0;
    for (unsigned s = 0; s < sref_sect.n; s++) {
        n += sref_sect.distance_cm[s] < cm ? 1u : 0u;
    }
    return n;
}

/* The vehicle standing on the floor can arm (ArduPilot wants > 0.6 m in every face): the ground
 * rule keeps the floor out of the band, the wall stays in; without it the floor is everywhere. */
static void test_floor_standing(void **state)
{
    (void)state;
    floor_room();
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300; /* the free room reaches 3.15 m */
    occ_pose_t p = sref_at_yaw(0.05f, 0.05f, 0.05f, 0.0f); /* 5 cm above the floor, facing east */
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_int_equal(sectors_below(61), 0);
    assert_int_equal(sref_sect.distance_cm[0], 195);   /* the wall ahead */
    assert_int_equal(sref_sect.distance_cm[36], 301);  /* behind: free (floor ignored) */
    assert_int_equal(sref_compare(&p, &cfg, "floor-standing"), 0);
    /* Flying over it at 0.3 m and at 1.2 m: the same. */
    p.p.z = 0.3f;
    assert_int_equal(sref_compare(&p, &cfg, "floor-0.3"), 0);
    assert_int_equal(sectors_below(61), 0);
    p.p.z = 1.2f;
    assert_int_equal(sref_compare(&p, &cfg, "floor-1.2"), 0);
    assert_int_equal(sectors_below(61), 0);
    /* The old band: the floor is an obstacle at 0 m in every sector (min_distance). */
    cfg.ignore_ground = false;
    p.p.z = 0.05f;
    assert_int_equal(sref_compare(&p, &cfg, "floor-kept"), 0);
    assert_int_equal(sectors_below(21), 72);
    /* A box on the floor (z 0..0.3) taller than the clearance is an obstacle (west, 1.05 m). */
    occ_key_t k;
    for (double z = 0.05; z < 0.3; z += 0.1) {
        sref_key_at(-1.05, 0.05, z, &k);
        assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
    }
    cfg.ignore_ground = true;
    assert_int_equal(sref_compare(&p, &cfg, "floor-box"), 0);
    assert_true(sref_sect.distance_cm[36] >= 104 && sref_sect.distance_cm[36] <= 105);
    /* With a clearance above its top it is not. */
    cfg.ground_clearance_m = 0.35f;
    assert_int_equal(sref_compare(&p, &cfg, "floor-box-low"), 0);
    assert_int_equal(sref_sect.distance_cm[36], 301);
}

/* Separate settings below and above: a shelf at 0.8..0.9 m north, a low box south. */
static void test_band_below_above(void **state)
{
    (void)state;
    floor_room();
    occ_key_t k;
    for (double x = -0.45; x < 0.5; x += 0.1) {
        sref_key_at(x, 1.05, 0.85, &k); /* shelf: 1.0 m north, z 0.8..0.9 */
        assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
        sref_key_at(x, -1.55, 0.25, &k); /* box top: 1.5 m south, z 0.2..0.3 */
        assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
    }
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300; /* the free room reaches 3.15 m */
    occ_pose_t p = sref_at_yaw(0.05f, 0.05f, 0.6f, (float)(M_PI / 2.0)); /* facing north */
    cfg.band_below_m = 0.2f;
    cfg.band_above_m = 0.1f; /* [0.4, 0.7): neither */
    assert_int_equal(sref_compare(&p, &cfg, "band-none"), 0);
    assert_int_equal(sref_sect.distance_cm[0], 301);
    assert_int_equal(sref_sect.distance_cm[36], 301);
    cfg.band_above_m = 0.3f; /* [0.4, 0.9): the shelf ahead */
    assert_int_equal(sref_compare(&p, &cfg, "band-above"), 0);
    assert_int_equal(sref_sect.distance_cm[0], 95);
    assert_int_equal(sref_sect.distance_cm[36], 301);
    cfg.band_above_m = 0.1f;
    cfg.band_below_m = 0.35f; /* [0.25, 0.7): the box behind */
    assert_int_equal(sref_compare(&p, &cfg, "band-below"), 0);
    assert_int_equal(sref_sect.distance_cm[0], 301);
    assert_int_equal(sref_sect.distance_cm[36], 155);
}

static void assert_unsafe(uint16_t want)
{
    assert_int_equal(sref_sect.n, 0);
    for (unsigned s = 0; s < OCC_SECTORS_MAX; s++) {
        assert_int_equal(sref_sect.distance_cm[s], want);
        assert_true(fabsf(sref_sect.d_occ_m[s]) + fabsf(sref_sect.d_unk_m[s]) < 1e-30f);
    }
}

/* Every error leaves the unsafe answer (an obstacle at min_distance) in all 72 values, also
 * over the values of an earlier good call. */
static void test_fail_closed(void **state)
{
    (void)state;
    floor_room();
    occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = sref_at_yaw(0.05f, 0.05f, 0.05f, 0.0f);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_true(sref_sect.distance_cm[36] > cfg.min_distance_cm);
    assert_int_equal(occ_sectors_compute(NULL, &p, &cfg, &sref_sect), OCC_ERR_ARG);
    assert_unsafe(cfg.min_distance_cm);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_int_equal(occ_sectors_compute(&sref_map, NULL, &cfg, &sref_sect), OCC_ERR_ARG);
    assert_unsafe(cfg.min_distance_cm);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, NULL, &sref_sect), OCC_ERR_ARG);
    assert_unsafe(1);
    occ_sectors_config_t bad = cfg;
    bad.n_sectors = 0;
    bad.min_distance_cm = 35;
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &bad, &sref_sect), OCC_ERR_ARG);
    assert_unsafe(35);
    sref_set_yaw(&p, NAN);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_ERR_ARG);
    assert_unsafe(cfg.min_distance_cm);
    sref_set_yaw(&p, 0.0f);
    p.p.x = 1e7f;
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_ERR_RANGE);
    assert_unsafe(cfg.min_distance_cm);
    bad = cfg;
    bad.ground_clearance_m = -0.1f;
    p.p.x = 0.05f;
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &bad, &sref_sect), OCC_ERR_ARG);
    bad.ground_clearance_m = NAN;
    assert_int_equal(occ_sectors_config_check(&bad), OCC_ERR_ARG);
    bad = cfg;
    bad.max_distance_cm = OCC_SECTORS_MAX_DISTANCE_CM + 1u; /* max + 1 would read "unknown" */
    assert_int_equal(occ_sectors_config_check(&bad), OCC_ERR_ARG);
    bad.max_distance_cm = OCC_SECTORS_MAX_DISTANCE_CM;
    assert_int_equal(occ_sectors_config_check(&bad), OCC_OK);
}

static void test_args(void **state)
{
    (void)state;
    occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = sref_at_yaw(0.0f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_config_check(&cfg), OCC_OK);
    assert_int_equal(occ_sectors_compute(NULL, &p, &cfg, &sref_sect), OCC_ERR_ARG);
    assert_int_equal(occ_sectors_compute(&sref_map, NULL, &cfg, &sref_sect), OCC_ERR_ARG);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, NULL, &sref_sect), OCC_ERR_ARG);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, NULL), OCC_ERR_ARG);
    occ_sectors_config_t c = cfg;
    c.n_sectors = 0;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.n_sectors = 73;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.increment_deg = 6.0f; /* 72 x 6 > 360 */
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.n_sectors = 2;
    c.increment_deg = 120.0f;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.min_distance_cm = 0;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.min_distance_cm = c.max_distance_cm;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.max_distance_cm = 65535;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.band_below_m = c.band_above_m = 0.0f;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    c = cfg;
    c.angle_offset_deg = NAN;
    assert_int_equal(occ_sectors_config_check(&c), OCC_ERR_ARG);
    sref_set_yaw(&p, NAN);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_ERR_ARG);
    sref_set_yaw(&p, 0.0f);
    p.p.x = INFINITY;
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_ERR_ARG);
    p.p.x = 1e7f;
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_ERR_RANGE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_args, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_floor_standing, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_band_below_above, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_fail_closed, sref_setup, sref_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
