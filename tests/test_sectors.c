/* SPDX-License-Identifier: BSD-3-Clause */
/* test_sectors.c - occ_sectors_compute() against the brute-force reference of
 * tests/support/sectors_ref.c on random maps and poses; plus hand-computed cases (behind = +-180
 * degrees, yaw wrap, the vehicle in unknown space, the edges of the map volume) and the NED map
 * as the mirrored ENU map. The floor, the band and the argument checks: test_sectors_floor.c. */
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

#define ARENA_BYTES (8u << 20)

static double urand(void)
{
    return (double)rand() / ((double)RAND_MAX + 1.0);
}

/* ---- random maps ------------------------------------------------------------------------------ */

/* A room-sized random map around the origin: mostly free, pruned blocks, holes of unknown,
 * occupied boxes and walls. */
static void random_map(void)
{
    occ_map_clear(&sref_map);
    occ_key_t k;
    for (double x = -3.2; x < 3.2; x += 0.8) {
        for (double y = -3.2; y < 3.2; y += 0.8) {
            for (double z = -0.8; z < 0.8; z += 0.8) {
                if (urand() < 0.85) {
                    sref_key_at(x + 0.05, y + 0.05, z + 0.05, &k);
                    assert_int_equal(occ_map_set_key(&sref_map, k, 3, -2.0f), OCC_OK);
                }
            }
        }
    }
    const int holes = 3 + rand() % 6;
    for (int i = 0; i < holes; i++) {
        sref_key_at(urand() * 6.0 - 3.0, urand() * 6.0 - 3.0, urand() * 1.2 - 0.6, &k);
        assert_int_equal(occ_map_forget_key(&sref_map, k, (unsigned)(rand() % 3)), OCC_OK);
    }
    const int boxes = 4 + rand() % 10;
    for (int i = 0; i < boxes; i++) {
        const double cx = urand() * 6.0 - 3.0, cy = urand() * 6.0 - 3.0, cz = urand() * 1.2 - 0.6;
        const int sx = 1 + rand() % 6, sy = 1 + rand() % 6, sz = 1 + rand() % 5;
        for (int a = 0; a < sx; a++) {
            for (int b = 0; b < sy; b++) {
                for (int c = 0; c < sz; c++) {
                    sref_key_at(cx + a * 0.1, cy + b * 0.1, cz + c * 0.1, &k);
                    assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
                }
            }
        }
    }
    /* A wall segment and a few isolated voxels. */
    const double wy = urand() * 4.0 - 2.0;
    for (double x = -2.5; x < 1.0; x += 0.1) {
        for (double z = -0.5; z < 0.5; z += 0.1) {
            sref_key_at(x, wy, z, &k);
            assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
        }
    }
    for (int i = 0; i < 40; i++) {
        sref_key_at(urand() * 6.0 - 3.0, urand() * 6.0 - 3.0, urand() * 1.2 - 0.6, &k);
        assert_int_equal(occ_map_update_key(&sref_map, k, urand() < 0.7 ? 1.0f : -1.0f), OCC_OK);
    }
    assert_int_equal(occ_map_check(&sref_map), OCC_OK);
}

static void random_config(occ_sectors_config_t *cfg)
{
    static const struct { uint8_t n; float inc; } shapes[] = {
        {72, 5.0f}, {36, 10.0f}, {8, 45.0f}, {16, 22.5f}, {12, 7.5f}, {4, 90.0f}};
    *cfg = occ_sectors_config_default();
    const unsigned i = (unsigned)rand() % (sizeof shapes / sizeof shapes[0]);
    cfg->n_sectors = shapes[i].n;
    cfg->increment_deg = shapes[i].inc;
    cfg->angle_offset_deg = (float)(urand() * 20.0 - 10.0);
    cfg->band_below_m = (float)(0.05 + urand() * 0.5);
    cfg->band_above_m = (float)(0.05 + urand() * 0.5);
    cfg->min_distance_cm = (uint16_t)(5 + rand() % 30);
    cfg->max_distance_cm = (uint16_t)(150 + rand() % 200);
    cfg->unknown_as_distance = (rand() & 1) != 0;
    cfg->ignore_ground = (rand() & 3) != 0;
    cfg->ground_clearance_m = (float)(urand() * 0.3);
}

static void test_random_maps(void **state)
{
    (void)state;
    unsigned bad = 0;
    for (int m = 0; m < 6; m++) {
        random_map();
        for (int i = 0; i < 8; i++) {
            occ_pose_t p = occ_pose_identity();
            p.p.x = (float)(urand() * 5.0 - 2.5);
            p.p.y = (float)(urand() * 5.0 - 2.5);
            p.p.z = (float)(urand() * 1.0 - 0.5);
            sref_set_yaw(&p, (float)(urand() * 4.0 * M_PI - 2.0 * M_PI));
            occ_sectors_config_t cfg;
            random_config(&cfg);
            bad += sref_compare(&p, &cfg, "random");
        }
    }
    assert_int_equal(bad, 0);
}

/* Yaw and yaw + 2 pi give the same sectors; so do +-pi. */
static void test_yaw_wrap(void **state)
{
    (void)state;
    random_map();
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300;
    static occ_sectors_t a;
    const float yaws[] = {(float)M_PI, (float)-M_PI, 0.0f, 3.0f, -3.1f, 6.2f};
    for (unsigned i = 0; i < sizeof yaws / sizeof yaws[0]; i++) {
        occ_pose_t p = sref_at_yaw(0.33f, -0.71f, 0.05f, yaws[i]);
        assert_int_equal(sref_compare(&p, &cfg, "yaw"), 0);
        memcpy(&a, &sref_sect, sizeof a);
        sref_set_yaw(&p, yaws[i] + 2.0f * (float)M_PI);
        assert_int_equal(sref_compare(&p, &cfg, "yaw+2pi"), 0);
        for (unsigned s = 0; s < cfg.n_sectors; s++) {
            assert_true(abs((int)a.distance_cm[s] - (int)sref_sect.distance_cm[s]) <= 1);
        }
    }
}

/* Hand-computed: free room, one wall behind the vehicle (body 180 deg = sector 36 of 72). */
static void test_behind_180(void **state)
{
    (void)state;
    occ_key_t k;
    /* Observe free space: the eight level-7 nodes (12.8 m cubes) around the origin. */
    for (int i = 0; i < 8; i++) {
        sref_key_at((i & 1) ? 0.05 : -0.05, (i & 2) ? 0.05 : -0.05, (i & 4) ? 0.05 : -0.05, &k);
        assert_int_equal(occ_map_set_key(&sref_map, k, 7, -2.0f), OCC_OK);
    }
    /* Wall x in [-1.0, -0.9), all y in [-3, 3), z in [-0.5, 0.5). */
    for (double y = -2.95; y < 3.0; y += 0.1) {
        for (double z = -0.45; z < 0.5; z += 0.1) {
            sref_key_at(-0.95, y, z, &k);
            assert_int_equal(occ_map_update_key(&sref_map, k, 2.0f), OCC_OK);
        }
    }
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 250;
    occ_pose_t p = sref_at_yaw(0.05f, 0.05f, 0.0f, 0.0f); /* facing east: wall behind */
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    /* Nearest wall point (-0.9, 0.05): 0.95 m. */
    assert_int_equal(sref_sect.distance_cm[36], 95);
    assert_int_equal(sref_sect.distance_cm[0], 251);   /* ahead: free up to 2.5 m: max + 1 */
    assert_int_equal(sref_sect.distance_cm[18], 251);  /* right (south) */
    assert_int_equal(sref_compare(&p, &cfg, "behind"), 0);
    /* Facing west (yaw pi): the wall is ahead, sector 0; yaw -pi the same. */
    sref_set_yaw(&p, (float)M_PI);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_int_equal(sref_sect.distance_cm[0], 95);
    assert_int_equal(sref_sect.distance_cm[36], 251);
    sref_set_yaw(&p, -(float)M_PI);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_int_equal(sref_sect.distance_cm[0], 95);
    /* Facing north (yaw pi/2): the wall is on the left, body 270 deg = sector 54. */
    sref_set_yaw(&p, (float)(M_PI / 2.0));
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_int_equal(sref_sect.distance_cm[54], 95);
    assert_int_equal(sref_compare(&p, &cfg, "left"), 0);
}

static void test_unknown_space(void **state)
{
    (void)state;
    occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = sref_at_yaw(1.0f, 2.0f, 0.3f, 0.4f);
    /* Empty map: the vehicle stands in unknown space. */
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    for (unsigned s = 0; s < 72; s++) {
        assert_int_equal(sref_sect.distance_cm[s], UINT16_MAX);
    }
    cfg.unknown_as_distance = true;
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    for (unsigned s = 0; s < 72; s++) {
        assert_int_equal(sref_sect.distance_cm[s], cfg.min_distance_cm);
    }
    /* A free bubble of 0.8 m around a voxel-aligned spot: unknown beyond it. */
    random_map();
    occ_key_t k;
    sref_key_at(0.05, 0.05, 0.05, &k);
    assert_int_equal(occ_map_forget_key(&sref_map, k, 4), OCC_OK);
    assert_int_equal(occ_map_set_key(&sref_map, k, 0, -1.0f), OCC_OK);
    occ_pose_t q = sref_at_yaw(0.05f, 0.05f, 0.05f, 1.0f);
    cfg.unknown_as_distance = false;
    assert_int_equal(sref_compare(&q, &cfg, "bubble"), 0);
    cfg.unknown_as_distance = true;
    cfg.max_distance_cm = 300;
    assert_int_equal(sref_compare(&q, &cfg, "bubble-dist"), 0);
    for (unsigned s = 0; s < 72; s++) {
        assert_int_equal(sref_sect.distance_cm[s], cfg.min_distance_cm); /* unknown above/below */
    }
}

/* The edges of the map volume: depth 5 at 0.1 m spans [-1.6, 1.6) per axis. */
static void test_map_edges(void **state)
{
    (void)state;
    sref_reinit(0.1f, 5);
    occ_key_t root = {{0, 0, 0}};
    assert_int_equal(occ_map_set_key(&sref_map, root, 5, -2.0f), OCC_OK);
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300;
    cfg.unknown_as_distance = true;
    cfg.band_below_m = cfg.band_above_m = 0.3f;
    occ_pose_t p = sref_at_yaw(1.0f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_compute(&sref_map, &p, &cfg, &sref_sect), OCC_OK);
    assert_int_equal(sref_sect.distance_cm[0], 60);   /* volume edge 0.6 m ahead */
    assert_int_equal(sref_sect.distance_cm[36], 260); /* 2.6 m behind */
    assert_int_equal(sref_compare(&p, &cfg, "edge"), 0);
    for (int i = 0; i < 20; i++) {
        occ_pose_t q = occ_pose_identity();
        q.p.x = (float)(urand() * 3.1 - 1.55);
        q.p.y = (float)(urand() * 3.1 - 1.55);
        q.p.z = (float)(urand() * 3.0 - 1.5);
        sref_set_yaw(&q, (float)(urand() * 7.0 - 3.5));
        occ_sectors_config_t c2;
        random_config(&c2);
        assert_int_equal(sref_compare(&q, &c2, "edges-random"), 0);
    }
    occ_pose_t out = sref_at_yaw(1.7f, 0.0f, 0.0f, 0.0f);
    assert_int_equal(occ_sectors_compute(&sref_map, &out, &cfg, &sref_sect), OCC_ERR_RANGE);
    assert_int_equal(sref_sect.n, 0);
    occ_map_clear(&sref_map);
    sref_setup(NULL);
}

/* A NED map is the ENU map mirrored (x <-> y, z -> -z): the same pose gives the same sectors. */
static uint8_t arena2[ARENA_BYTES];
static void test_ned_mirror(void **state)
{
    (void)state;
    static occ_map_t ned;
    static occ_sectors_t a;
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    for (int m = 0; m < 2; m++) {
        random_map();
        assert_int_equal(occ_map_init(&ned, &cfg, arena2, sizeof arena2), OCC_OK);
        const uint32_t top = (uint32_t)1 << sref_map.cfg.depth_levels;
        occ_walk_t w;
        occ_walk_node_t nd;
        occ_walk_begin(&w, &sref_map);
        while (occ_walk_next(&w, &nd)) {
            if (nd.has_children || !nd.observed) {
                continue;
            }
            const uint32_t size = (uint32_t)1 << nd.level;
            occ_key_t k = {{nd.key.k[1], nd.key.k[0], top - nd.key.k[2] - size}};
            assert_int_equal(occ_map_set_key(&ned, k, nd.level, occ_value_to_logodds(nd.value)),
                             OCC_OK);
        }
        for (int i = 0; i < 6; i++) {
            occ_pose_t p = occ_pose_identity();
            p.p.x = (float)(urand() * 5.0 - 2.5);
            p.p.y = (float)(urand() * 5.0 - 2.5);
            p.p.z = (float)(urand() * 1.0 - 0.5);
            const float yaw = (float)(urand() * 6.0 - 3.0);
            sref_set_yaw(&p, yaw);
            occ_sectors_config_t sc;
            random_config(&sc);
            assert_int_equal(occ_sectors_compute(&sref_map, &p, &sc, &a), OCC_OK);
            occ_pose_t q = p;
            q.p.x = p.p.y;
            q.p.y = p.p.x;
            q.p.z = -p.p.z;
            sref_set_yaw(&q, (float)(M_PI / 2.0) - yaw); /* NED <- FRD: heading from north */
            sc.map_ned = true;
            assert_int_equal(occ_sectors_compute(&ned, &q, &sc, &sref_sect), OCC_OK);
            for (unsigned s = 0; s < sc.n_sectors; s++) {
                const int da = a.distance_cm[s], db = sref_sect.distance_cm[s];
                if (abs(da - db) > 1) {
                    fprintf(stderr, "ned mirror sref_seed %u sector %u: enu %d ned %d\n", sref_seed, s, da, db);
                }
                assert_true(abs(da - db) <= 1);
            }
        }
        assert_int_equal(occ_map_check(&ned), OCC_OK);
    }
}

int main(void)
{
    const char *env = getenv("OCC_SEED");
    sref_seed = env != NULL ? (unsigned)strtoul(env, NULL, 0) : 12345u;
    printf("test_sectors: OCC_SEED=%u\n", sref_seed);
    srand(sref_seed);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_behind_180, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_unknown_space, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_yaw_wrap, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_map_edges, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_random_maps, sref_setup, sref_teardown),
        cmocka_unit_test_setup_teardown(test_ned_mirror, sref_setup, sref_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
