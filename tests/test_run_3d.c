/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_run_3d.c - `occmap run --3d`'s search (tools/run_3d.c, compiled in) against brute force:
 * random occupied voxels (some in 2x2x2 blocks the map prunes into bigger nodes), random poses
 * (yaw, roll, pitch); above / below must equal the minimum over every inserted voxel of the
 * distance to its part above u0 + band_above / below u0 - band_below within R, and the FRD
 * vector must be the body's view of that point. Also: an empty side is not found, a NED map
 * flips the sides, and a full search buffer fails closed (both sides at min, straight up/down).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdlib.h>

#include "../tools/run_3d.c"

#define N_VOX 300
#define RES 0.1f

typedef struct {
    occ_vec3_t c; /* voxel centre */
} vox_t;

static uint32_t rng = 12345u;
static float frand(float lo, float hi)
{
    rng = rng * 1664525u + 1013904223u;
    return lo + (hi - lo) * (float)(rng >> 8) / 16777216.0f;
}

static void *arena;
static occ_map_t map;
static vox_t vox[N_VOX * 8];
static size_t n_vox;

static void add(occ_vec3_t p)
{
    occ_key_t k;
    assert_int_equal(occ_map_key(&map, p, &k), OCC_OK);
    const occ_vec3_t c = occ_map_key_center(&map, k, 0);
    for (size_t i = 0; i < n_vox; i++) {
        if (fabsf(vox[i].c.x - c.x) < 1e-4f && fabsf(vox[i].c.y - c.y) < 1e-4f &&
            fabsf(vox[i].c.z - c.z) < 1e-4f) {
            return;
        }
    }
    assert_int_equal(occ_map_update(&map, c, 3.0f), OCC_OK);
    assert_int_equal(occ_map_state_at(&map, c), OCC_STATE_OCCUPIED);
    vox[n_vox++].c = c;
}

static void build(void)
{
    const size_t bytes = (size_t)16 << 20;
    arena = malloc(bytes);
    occ_map_config_t cfg = occ_map_config_default();
    cfg.resolution_m = RES;
    assert_int_equal(occ_map_init(&map, &cfg, arena, bytes), OCC_OK);
    n_vox = 0;
    for (int i = 0; i < N_VOX; i++) {
        const occ_vec3_t p = {frand(-4, 4), frand(-4, 4), frand(-3, 3)};
        if (i % 10 == 0) { /* a 2x2x2 block: pruned into one level-1 node */
            const float b0 = 2.0f * RES * floorf(p.x / (2.0f * RES));
            const float b1 = 2.0f * RES * floorf(p.y / (2.0f * RES));
            const float b2 = 2.0f * RES * floorf(p.z / (2.0f * RES));
            for (int j = 0; j < 8; j++) {
                add((occ_vec3_t){b0 + RES * (0.5f + (float)(j & 1)),
                                 b1 + RES * (0.5f + (float)((j >> 1) & 1)),
                                 b2 + RES * (0.5f + (float)((j >> 2) & 1))});
            }
        } else {
            add(p);
        }
    }
}

static float clampd(float v, float lo, float hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* Brute force: nearest distance to the voxels' parts with s*z in [ulo, uhi]; -1 if none <= r. */
static float brute(occ_vec3_t p, float s, float ulo, float uhi, float r)
{
    float best = -1.0f;
    const float h = 0.5f * RES;
    for (size_t i = 0; i < n_vox; i++) {
        const occ_vec3_t c = vox[i].c;
        const float lo = fmaxf(s * c.z - h, ulo);
        const float hi = fminf(s * c.z + h, uhi);
        if (lo > hi) {
            continue;
        }
        const float dx = clampd(p.x, c.x - h, c.x + h) - p.x;
        const float dy = clampd(p.y, c.y - h, c.y + h) - p.y;
        const float dz = s * clampd(s * p.z, lo, hi) - p.z;
        const float d = sqrtf(dx * dx + dy * dy + dz * dz);
        if (d <= r && (best < 0.0f || d < best)) {
            best = d;
        }
    }
    return best;
}

static void check_side(const run_3d_side_t *side, float want, const occ_pose_t *pose, bool ned)
{
    if (want < 0.0f) {
        assert_false(side->found);
        return;
    }
    assert_true(side->found);
    assert_true(fabsf(side->dist_m - want) < 1e-4f);
    /* FRD: the body's view of the reported point */
    const occ_vec3_t d = {side->map_m.x - pose->p.x, side->map_m.y - pose->p.y,
                          side->map_m.z - pose->p.z};
    const occ_vec3_t back = occ_pose_rotate(pose, ned ? side->frd_m
                                                      : (occ_vec3_t){side->frd_m.x, -side->frd_m.y,
                                                                     -side->frd_m.z});
    assert_true(fabsf(back.x - d.x) < 1e-4f && fabsf(back.y - d.y) < 1e-4f &&
                fabsf(back.z - d.z) < 1e-4f);
    assert_true(fabsf(sqrtf(d.x * d.x + d.y * d.y + d.z * d.z) - want) < 1e-4f);
}

static void test_brute_force(void **state)
{
    (void)state;
    build();
    static occ_nearest_entry_t buf[16384];
    occ_sectors_config_t cfg = occ_sectors_config_default();
    cfg.max_distance_cm = 300; /* R = 3 m: some poses see nothing on a side */
    int found_sides = 0, empty_sides = 0;
    for (int t = 0; t < 200; t++) {
        cfg.map_ned = t % 4 == 3;
        const float s = cfg.map_ned ? -1.0f : 1.0f;
        occ_pose_t pose;
        pose.p = (occ_vec3_t){frand(-4, 4), frand(-4, 4), frand(-3, 3)};
        pose.q = occ_quat_from_euler(frand(-0.5f, 0.5f), frand(-0.5f, 0.5f), frand(-3.1f, 3.1f));
        cfg.band_below_m = frand(0.1f, 1.0f);
        cfg.band_above_m = frand(0.1f, 1.0f);
        run_3d_t out;
        run_3d_nearest(&map, &pose, &cfg, buf, sizeof buf / sizeof buf[0], &out);
        assert_int_equal(out.err, OCC_OK);
        const float u0 = s * pose.p.z;
        const float r = (float)cfg.max_distance_cm / 100.0f;
        const float wa = brute(pose.p, s, u0 + cfg.band_above_m, INFINITY, r);
        const float wb = brute(pose.p, s, -INFINITY, u0 - cfg.band_below_m, r);
        check_side(&out.above, wa, &pose, cfg.map_ned);
        check_side(&out.below, wb, &pose, cfg.map_ned);
        found_sides += (wa >= 0.0f) + (wb >= 0.0f);
        empty_sides += (wa < 0.0f) + (wb < 0.0f);
    }
    assert_true(found_sides > 100 && empty_sides > 10); /* both cases were exercised */
    free(arena);
}

static void test_fail_closed(void **state)
{
    (void)state;
    build();
    occ_nearest_entry_t buf[2];
    occ_sectors_config_t cfg = occ_sectors_config_default();
    const occ_pose_t pose = {{0.05f, 0.05f, 0.05f}, occ_quat_from_euler(0.2f, 0.1f, 1.0f)};
    run_3d_t out;
    run_3d_nearest(&map, &pose, &cfg, buf, 2, &out); /* the heap overflows at once */
    assert_int_equal(out.err, OCC_ERR_NOMEM);
    const float d = (float)cfg.min_distance_cm / 100.0f;
    assert_true(out.above.found && out.below.found);
    assert_true(fabsf(out.above.frd_m.z + d) < 1e-6f && fabsf(out.below.frd_m.z - d) < 1e-6f);
    assert_true(fabsf(out.above.frd_m.x) < 1e-6f && fabsf(out.below.frd_m.y) < 1e-6f);
    occ_pose_t bad = pose;
    bad.q.w = NAN;
    run_3d_nearest(&map, &bad, &cfg, buf, 2, &out);
    assert_int_equal(out.err, OCC_ERR_ARG);
    assert_true(out.above.found && out.below.found && fabsf(out.below.frd_m.z - d) < 1e-6f);
    free(arena);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_brute_force),
        cmocka_unit_test(test_fail_closed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
