/* SPDX-License-Identifier: BSD-3-Clause */
/* test_sectors_pose.c - the sectors take the library's one pose type (occ_pose_t):
 *  - a rolled and pitched vehicle gets exactly the sectors of the level vehicle with the same
 *    heading (the band is about the vehicle's z, the sectors are horizontal);
 *  - cfg.map_ned reads the pose as NED <- FRD: an autopilot pose (LOCAL_POSITION_NED, ATTITUDE)
 *    on a map built in NED gives the sectors of the same pose converted with occ_pose_from_ned()
 *    on the same room built in ENU;
 *  - a pose occ_pose_check() refuses (|q| off, NaN) is an error with the unsafe answer.
 * The room: 0.1 m voxels, observed free around the origin, walls on three sides at different
 * distances, a box on the floor, so every heading sees different sectors. */
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
#include "support/leak_check.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static uint8_t arena_enu[4u << 20], arena_ned[4u << 20];
static occ_map_t enu, ned;
static occ_sectors_t a, b; /* large: static */

/* A point of the room given in ENU, stored in `m` in its own frame (NED: x north = ENU y,
 * y east = ENU x, z down = -ENU z). */
static void update(occ_map_t *m, bool is_ned, double x, double y, double z, float logodds)
{
    const occ_vec3_t p = is_ned ? (occ_vec3_t){(float)y, (float)x, (float)-z}
                                : (occ_vec3_t){(float)x, (float)y, (float)z};
    assert_int_equal(occ_map_update(m, p, logodds), OCC_OK);
}

static void room(occ_map_t *m, bool is_ned)
{
    for (int ix = -40; ix < 40; ix++) {
        for (int iy = -40; iy < 40; iy++) {
            for (int iz = -5; iz < 20; iz++) { /* voxel [iz, iz + 1) * 0.1 m */
                const bool wall = ix >= 20 || iy >= 30 || ix < -15 || iz < -4 ||
                                  (ix >= 6 && ix < 10 && iy >= -12 && iy < -8 && iz < 2);
                update(m, is_ned, (ix + 0.5) * 0.1, (iy + 0.5) * 0.1, (iz + 0.5) * 0.1,
                       wall ? 2.0f : -2.0f);
            }
        }
    }
}

static void init_map(occ_map_t *m, uint8_t *arena, size_t bytes)
{
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = 0.1f;
    assert_int_equal(occ_map_init(m, &cfg, arena, bytes), OCC_OK);
}

static int setup(void **state)
{
    (void)state;
    init_map(&enu, arena_enu, sizeof arena_enu);
    init_map(&ned, arena_ned, sizeof arena_ned);
    room(&enu, false);
    room(&ned, true);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    return leak_check(&enu) | leak_check(&ned);
}

static occ_pose_t pose_at(float x, float y, float z, occ_quat_t q)
{
    occ_pose_t p;
    p.p.x = x;
    p.p.y = y;
    p.p.z = z;
    p.q = q;
    return p;
}

/* A level pose and a rolled / pitched one with the same position whose headings are equal bit
 * for bit, near heading yaw: from_euler and yaw round differently, so the yaws put in are nudged
 * by a few floats until the two come out the same. */
static void same_heading(float x, float y, float z, float yaw, float roll, float pitch,
                         occ_pose_t *level, occ_pose_t *tilted)
{
    float y_level = yaw;
    for (int i = 0; i < 32; i++, y_level = nextafterf(y_level, INFINITY)) {
        *level = pose_at(x, y, z, occ_quat_from_euler(0.0f, 0.0f, y_level));
        const float want = occ_pose_yaw(level);
        float y_tilted = want;
        for (int j = 0; j < 64; j++) {
            *tilted = pose_at(x, y, z, occ_quat_from_euler(roll, pitch, y_tilted));
            const float got = occ_pose_yaw(tilted);
            if (memcmp(&got, &want, sizeof got) == 0) {
                return;
            }
            y_tilted = nextafterf(y_tilted, got < want ? INFINITY : -INFINITY);
        }
    }
    fail_msg("no pair rolled %g pitched %g near yaw %.9g", (double)roll, (double)pitch,
             (double)yaw);
}

/* The sectors of the rolled / pitched vehicle are those of the level one with the same heading,
 * bit for bit (distances, metres, diagnostics). */
static void test_roll_pitch_ignored(void **state)
{
    (void)state;
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 500;
    const double rolls[5] = {0.0, 10.0, -35.0, 80.0, 175.0};
    const double pitches[5] = {0.0, 5.0, -40.0, 70.0, -85.0};
    unsigned differ_from_first = 0;
    uint16_t first[OCC_SECTORS_MAX];
    for (int h = 0; h < 8; h++) {
        const float yaw = (float)(-170.0 * DEG + h * 47.0 * DEG);
        const occ_pose_t level = pose_at(0.35f, -0.2f, 0.3f, occ_quat_from_euler(0, 0, yaw));
        assert_int_equal(occ_sectors_compute(&enu, &level, &cfg, &a), OCC_OK);
        if (h == 0) {
            memcpy(first, a.distance_cm, sizeof first);
        } else if (memcmp(first, a.distance_cm, sizeof first) != 0) {
            differ_from_first++;
        }
        for (int r = 0; r < 5; r++) {
            for (int p = 0; p < 5; p++) {
                occ_pose_t flat, tilted;
                same_heading(level.p.x, level.p.y, level.p.z, yaw, (float)(rolls[r] * DEG),
                             (float)(pitches[p] * DEG), &flat, &tilted);
                assert_true(fabs((double)occ_pose_yaw(&tilted) - (double)yaw) < 1e-5);
                assert_int_equal(occ_sectors_compute(&enu, &flat, &cfg, &a), OCC_OK);
                assert_int_equal(occ_sectors_compute(&enu, &tilted, &cfg, &b), OCC_OK);
                assert_int_equal(a.n, b.n);
                assert_memory_equal(a.distance_cm, b.distance_cm, sizeof a.distance_cm);
                assert_memory_equal(a.d_occ_m, b.d_occ_m, sizeof a.d_occ_m);
                assert_int_equal(a.nodes_read, b.nodes_read);
            }
        }
    }
    assert_int_equal(differ_from_first, 7); /* the headings do matter: the test can fail */
}

/* The MAVLink way in: LOCAL_POSITION_NED and ATTITUDE (roll, pitch, yaw from north). */
static void test_ned_map_reads_ned_frd(void **state)
{
    (void)state;
    const float north[3] = {-0.2f, 0.4f, 1.1f}, east[3] = {0.35f, -0.6f, 0.0f};
    const float down[3] = {-0.33f, -0.17f, -0.62f}; /* band edges off the voxel faces */
    const float att[4][3] = {{0, 0, 0}, {0.2f, -0.1f, 1.0f}, {-0.5f, 0.6f, -2.4f}, {0, 0.3f, 3.1f}};
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 4; k++) {
            const occ_vec3_t pos = {north[i], east[i], down[i]};
            const occ_quat_t q = occ_quat_from_euler(att[k][0], att[k][1], att[k][2]);
            occ_pose_t map_from_body;
            assert_int_equal(occ_pose_from_ned(pos, q, &map_from_body), OCC_OK);
            occ_sectors_config_t cfg = occ_sectors_config_default();
            cfg.max_distance_cm = 500;
            assert_int_equal(occ_sectors_compute(&enu, &map_from_body, &cfg, &a), OCC_OK);
            const occ_pose_t ned_from_frd = pose_at(pos.x, pos.y, pos.z, q);
            cfg.map_ned = true;
            assert_int_equal(occ_sectors_compute(&ned, &ned_from_frd, &cfg, &b), OCC_OK);
            unsigned obstacles = 0;
            for (unsigned s = 0; s < cfg.n_sectors; s++) {
                const int da = a.distance_cm[s], db = b.distance_cm[s];
                if (!(abs(da - db) <= 1)) {
                    fail_msg("pose %d att %d sector %u: ENU %d (%g %g), NED %d (%g %g)", i, k, s, da,
                             (double)a.d_occ_m[s], (double)a.d_unk_m[s], db, (double)b.d_occ_m[s],
                             (double)b.d_unk_m[s]);
                }
                obstacles += da <= (int)cfg.max_distance_cm ? 1u : 0u;
            }
            if (obstacles <= 10u) { /* walls in view: the comparison has teeth */
                fail_msg("pose %d att %d: %u obstacles", i, k, obstacles);
            }
            /* occ_pose_to_ned() of the ENU pose is the NED pose the sectors read. */
            occ_pose_t back;
            assert_int_equal(occ_pose_to_ned(&map_from_body, &back.p, &back.q), OCC_OK);
            assert_int_equal(occ_sectors_compute(&ned, &back, &cfg, &b), OCC_OK);
            for (unsigned s = 0; s < cfg.n_sectors; s++) {
                assert_true(abs((int)a.distance_cm[s] - (int)b.distance_cm[s]) <= 1);
            }
        }
    }
}

static void assert_unsafe(const occ_sectors_t *out, uint16_t min_cm)
{
    assert_int_equal(out->n, 0);
    for (unsigned s = 0; s < OCC_SECTORS_MAX; s++) {
        assert_int_equal(out->distance_cm[s], min_cm);
    }
}

static void test_bad_pose_refused(void **state)
{
    (void)state;
    const occ_sectors_config_t cfg = occ_sectors_config_default();
    occ_pose_t p = pose_at(0.35f, -0.2f, 0.3f, occ_quat_identity());
    assert_int_equal(occ_sectors_compute(&enu, &p, &cfg, &a), OCC_OK);
    p.q.w = 1.01f; /* |q| off by 1e-2 > OCC_POSE_QUAT_NORM_TOL */
    assert_int_equal(occ_sectors_compute(&enu, &p, &cfg, &a), OCC_ERR_ARG);
    assert_unsafe(&a, cfg.min_distance_cm);
    p.q.w = 1.0f + 0.5f * OCC_POSE_QUAT_NORM_TOL; /* within the tolerance: accepted */
    assert_int_equal(occ_sectors_compute(&enu, &p, &cfg, &a), OCC_OK);
    const occ_quat_t zero = {0, 0, 0, 0};
    p.q = zero;
    assert_int_equal(occ_sectors_compute(&enu, &p, &cfg, &a), OCC_ERR_ARG);
    assert_unsafe(&a, cfg.min_distance_cm);
    p.q = occ_quat_from_euler(NAN, 0, 0);
    assert_int_equal(occ_sectors_compute(&enu, &p, &cfg, &a), OCC_ERR_ARG);
    p = pose_at(0.35f, INFINITY, 0.3f, occ_quat_identity());
    assert_int_equal(occ_sectors_compute(&enu, &p, &cfg, &a), OCC_ERR_ARG);
    assert_unsafe(&a, cfg.min_distance_cm);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_roll_pitch_ignored, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ned_map_reads_ned_frd, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_pose_refused, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
