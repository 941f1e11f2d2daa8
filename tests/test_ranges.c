/* SPDX-License-Identifier: BSD-3-Clause */
/* test_ranges.c - occ_map_insert_ranges() (range beams) and occ_map_insert_rays() (per-point hit
 * flags): hand-computed voxels, insert_cloud where the two coincide, brute force over the exact
 * ray keys for mixed scans and every method, OctoMap's insertRay(), cones, the scratch formula
 * and bounded work, and every bad input (an error, the map unchanged). */
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
#include "occmap/occ_ranges.h"
#include "support/leak_check.h"
#include "support/oracle_rays.h"
#include "support/oracle_ranges.h"

#define ARENA_BYTES ((size_t)16 << 20)
#define SCRATCH_BYTES ((size_t)16 << 20)
#define RES 0.1f
#define MAX_KEYS 200000u

static uint8_t *arena, *arena2, *scratch;
static occ_map_t map, map2;
static uint64_t rng_state;

static float frand(float lo, float hi)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return lo + (hi - lo) * (float)(rng_state >> 40) / (float)(1u << 24);
}

static occ_map_config_t octo_cfg(void)
{
    occ_map_config_t c = occ_map_config_default();
    c.resolution_m = RES;
    c.hit = logf(0.7f / 0.3f);
    c.miss = logf(0.4f / 0.6f);
    c.clamp_min = logf(0.1192f / 0.8808f);
    c.clamp_max = logf(0.971f / 0.029f);
    return c;
}

static int setup(void **state)
{
    (void)state;
    const occ_map_config_t c = octo_cfg();
    assert_int_equal(occ_map_init(&map, &c, arena, ARENA_BYTES), OCC_OK);
    assert_int_equal(occ_map_init(&map2, &c, arena2, ARENA_BYTES), OCC_OK);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    return leak_check(&map) != 0 || leak_check(&map2) != 0 ? -1 : 0;
}

static occ_range_beam_t beam(float dx, float dy, float dz, float d, float min_m, float max_m)
{
    const occ_range_beam_t b = {{dx, dy, dz}, d, min_m, max_m, 0.0f, true};
    return b;
}

static occ_pose_t pose_at(float x, float y, float z)
{
    const occ_pose_t p = {{x, y, z}, {1.0f, 0.0f, 0.0f, 0.0f}};
    return p;
}

static occ_pose_t random_pose(void)
{
    occ_quat_t q;
    const occ_vec3_t axis = {frand(-1, 1), frand(-1, 1), frand(-1, 1)};
    assert_int_equal(occ_quat_from_axis_angle(axis, frand(-3.1f, 3.1f), &q), OCC_OK);
    occ_pose_t p = pose_at(frand(-1, 1), frand(-1, 1), frand(-1, 1));
    p.q = q;
    return p;
}

static occ_err_t ranges(occ_map_t *m, const occ_pose_t *pose, const occ_range_beam_t *b, size_t n,
                        occ_insert_method_t method, occ_ranges_result_t *out)
{
    occ_insert_params_t p = occ_insert_params_default();
    p.method = method;
    return occ_map_insert_ranges(m, pose, b, n, &p, scratch, SCRATCH_BYTES, out);
}

/* The key of voxel offset (i, j, k) from the voxel holding point o. */
static occ_key_t key_off(const occ_map_t *m, occ_vec3_t o, int i, int j, int k)
{
    occ_key_t key;
    assert_int_equal(occ_map_key(m, o, &key), OCC_OK);
    key.k[0] = (uint32_t)((int32_t)key.k[0] + i);
    key.k[1] = (uint32_t)((int32_t)key.k[1] + j);
    key.k[2] = (uint32_t)((int32_t)key.k[2] + k);
    return key;
}

static occ_state_t voxel_state(const occ_map_t *m, occ_key_t k)
{
    occ_node_info_t info;
    assert_int_equal(occ_map_read_key(m, k, 0, &info), OCC_OK);
    return info.observed ? info.state : OCC_STATE_UNKNOWN;
}

/* Observed voxels of the map (a leaf at level L counts 8^L), and of them occupied. */
static void volume(const occ_map_t *m, size_t *voxels, size_t *occupied)
{
    occ_walk_t w;
    occ_walk_node_t nd;
    *voxels = 0;
    *occupied = 0;
    occ_walk_begin(&w, m);
    while (occ_walk_next(&w, &nd)) {
        if (!nd.has_children && nd.observed) {
            const size_t n = (size_t)1 << (3u * nd.level);
            *voxels += n;
            *occupied += occ_map_state_of(m, occ_value_to_logodds(nd.value)) == OCC_STATE_OCCUPIED
                             ? n
                             : 0u;
        }
    }
}

/* Every node of a walk (key, level, raw value, flags) folded into a checksum. */
static uint64_t fingerprint(const occ_map_t *m)
{
    uint64_t h = 14695981039346656037ull;
    occ_walk_t w;
    occ_walk_node_t nd;
    occ_walk_begin(&w, m);
    while (occ_walk_next(&w, &nd)) {
        const uint64_t word = ((uint64_t)nd.key.k[0] << 42) ^ ((uint64_t)nd.key.k[1] << 21) ^
                              nd.key.k[2] ^ ((uint64_t)nd.level << 58) ^
                              ((uint64_t)(uint16_t)nd.value << 24) ^ nd.flags;
        h = (h ^ word) * 1099511628211ull;
    }
    return h;
}

/* ---- hand-computed voxels ------------------------------------------------------------------- */
static void test_hit_hand(void **state)
{
    (void)state;
    /* Origin at the centre of a voxel, beam +x 1.0 m: voxels 0..9 free, voxel 10 (x = 1.05)
     * hit, nothing else. */
    const occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    const occ_range_beam_t b = beam(2.0f, 0.0f, 0.0f, 1.0f, 0.2f, 5.0f); /* dir normalised */
    occ_ranges_result_t r;
    assert_int_equal(ranges(&map, &pose, &b, 1, OCC_INSERT_SIMPLE, &r), OCC_OK);
    assert_int_equal(r.beams_hit, 1);
    assert_int_equal(r.rays, 1);
    assert_int_equal(r.insert.voxels_updated, 11);
    for (int i = 0; i <= 9; i++) {
        assert_int_equal(voxel_state(&map, key_off(&map, pose.p, i, 0, 0)), OCC_STATE_FREE);
    }
    assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 10, 0, 0)), OCC_STATE_OCCUPIED);
    assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 11, 0, 0)), OCC_STATE_UNKNOWN);
    size_t v, o;
    volume(&map, &v, &o);
    assert_int_equal(v, 11);
    assert_int_equal(o, 1);
}

static void test_no_return_hand(void **state)
{
    (void)state;
    /* Rotated sensor: its x axis is the map's +y (yaw 90 deg). d = 7 >= max 2: voxels 0..19
     * along +y free, voxel 20 (y = 2.05, the max) not marked. d == max is no return too. */
    occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    pose.q = occ_quat_from_euler(0.0f, 0.0f, 1.5707963f);
    const occ_range_beam_t b[2] = {beam(1, 0, 0, 7.0f, 0.2f, 2.0f), beam(1, 0, 0, 2.0f, 0.2f, 2.0f)};
    for (size_t n = 1; n <= 2; n++) {
        occ_ranges_result_t r;
        assert_int_equal(ranges(&map, &pose, &b[n - 1], 1, OCC_INSERT_SIMPLE, &r), OCC_OK);
        assert_int_equal(r.beams_no_return, 1);
        assert_int_equal(r.beams_hit, 0);
        assert_int_equal(r.insert.voxels_occupied, 0);
        assert_int_equal(r.insert.rays_no_hit, 1);
        for (int i = 0; i <= 19; i++) {
            assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 0, i, 0)), OCC_STATE_FREE);
        }
        assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 0, 20, 0)), OCC_STATE_UNKNOWN);
        size_t v, o;
        volume(&map, &v, &o);
        assert_int_equal(v, 20);
        assert_int_equal(o, 0);
    }
}

static void test_skipped_counted(void **state)
{
    (void)state;
    const occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    occ_range_beam_t b[6] = {beam(1, 0, 0, 0.1f, 0.2f, 5.0f),      beam(1, 0, 0, NAN, 0.2f, 5.0f),
                             beam(1, 0, 0, INFINITY, 0.2f, 5.0f), beam(1, 0, 0, -INFINITY, 0.2f, 5.0f),
                             beam(1, 0, 0, 1.0f, 0.2f, 5.0f),      beam(0, 1, 0, 0.2f, 0.2f, 5.0f)};
    b[4].valid = false;
    b[4].dir.x = NAN; /* an invalid beam is skipped unread: its bad dir is no error */
    occ_ranges_result_t r;
    assert_int_equal(ranges(&map, &pose, b, 6, OCC_INSERT_SIMPLE, &r), OCC_OK);
    assert_int_equal(r.beams_too_close, 1); /* 0.1 < min */
    assert_int_equal(r.beams_bad, 3);       /* NaN, +Inf and -Inf: never "no return" */
    assert_int_equal(r.beams_invalid, 1);
    assert_int_equal(r.beams_hit, 1); /* d == min is a return */
    assert_int_equal(r.rays, 1);
    assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 0, 2, 0)), OCC_STATE_OCCUPIED);
    size_t v, o;
    volume(&map, &v, &o);
    assert_int_equal(v, 3);
}

/* ---- insert_cloud where the semantics coincide ---------------------------------------------- */
/* The end point insert_ranges computes for a thin beam: map_from_sensor(normalised dir * len). */
static occ_vec3_t beam_end(const occ_pose_t *pose, const occ_range_beam_t *b, float len)
{
    const float n = sqrtf(b->dir.x * b->dir.x + b->dir.y * b->dir.y + b->dir.z * b->dir.z);
    const float s = 1.0f / n;
    const occ_vec3_t u = {b->dir.x * s, b->dir.y * s, b->dir.z * s};
    const occ_vec3_t v = {u.x * len, u.y * len, u.z * len};
    return occ_pose_apply(pose, v);
}

#define N_RANDOM 300u

static void test_hits_equal_insert_cloud(void **state)
{
    (void)state;
    static occ_range_beam_t b[N_RANDOM];
    static occ_vec3_t ends[N_RANDOM];
    static const occ_insert_method_t methods[] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                                  OCC_INSERT_SUPER_RAYS, OCC_INSERT_FAST_DISCRETE};
    for (unsigned mi = 0; mi < 4u; mi++) {
        const occ_pose_t pose = random_pose();
        for (size_t i = 0; i < N_RANDOM; i++) {
            b[i] = beam(frand(-1, 1), frand(-1, 1), frand(-1, 1), frand(0.3f, 3.9f), 0.3f, 4.0f);
            ends[i] = beam_end(&pose, &b[i], b[i].distance_m);
        }
        occ_insert_params_t p = occ_insert_params_default();
        p.method = methods[mi];
        occ_ranges_result_t r;
        assert_int_equal(occ_map_insert_ranges(&map, &pose, b, N_RANDOM, &p, scratch,
                                               SCRATCH_BYTES, &r),
                         OCC_OK);
        assert_int_equal(r.beams_hit, N_RANDOM);
        assert_int_equal(occ_map_insert_cloud(&map2, &pose.p, ends, N_RANDOM, &p, scratch,
                                              SCRATCH_BYTES, NULL),
                         OCC_OK);
        assert_true(fingerprint(&map) == fingerprint(&map2));
        assert_true(r.insert.voxels_occupied > N_RANDOM / 2u);
    }
}

static void test_no_return_equals_insert_cloud_max_range(void **state)
{
    (void)state;
    static occ_range_beam_t b[N_RANDOM];
    static occ_vec3_t far[N_RANDOM];
    const occ_pose_t pose = random_pose();
    for (size_t i = 0; i < N_RANDOM; i++) {
        b[i] = beam(frand(-1, 1), frand(-1, 1), frand(-1, 1), frand(3.0f, 9.0f), 0.3f, 3.0f);
        far[i] = beam_end(&pose, &b[i], 9.5f);
    }
    occ_ranges_result_t r;
    assert_int_equal(ranges(&map, &pose, b, N_RANDOM, OCC_INSERT_SIMPLE, &r), OCC_OK);
    assert_int_equal(r.beams_no_return, N_RANDOM);
    occ_insert_params_t p = occ_insert_params_default();
    p.max_range_m = 3.0f;
    occ_insert_result_t c;
    assert_int_equal(occ_map_insert_cloud(&map2, &pose.p, far, N_RANDOM, &p, scratch,
                                          SCRATCH_BYTES, &c),
                     OCC_OK);
    assert_int_equal(c.rays_clipped, N_RANDOM);
    assert_int_equal(r.insert.voxels_occupied, 0);
    assert_true(fingerprint(&map) == fingerprint(&map2));
}

/* ---- mixed scans against brute force over occ_ray_keys() ------------------------------------ */
typedef struct {
    uint32_t k[3];
    int hit;
} vox_t;

static int vox_cmp(const void *a, const void *b)
{
    return memcmp(((const vox_t *)a)->k, ((const vox_t *)b)->k, sizeof(uint32_t[3]));
}

static size_t add_ray(const occ_map_t *m, occ_vec3_t o, occ_vec3_t e, int hit, vox_t *v, size_t n)
{
    static occ_key_t keys[4096];
    size_t nk = 0;
    assert_int_equal(occ_ray_keys(m, o, e, keys, 4096, &nk), OCC_OK);
    for (size_t i = 0; i < nk; i++) {
        memcpy(v[n].k, keys[i].k, sizeof v[n].k);
        v[n++].hit = 0;
    }
    if (hit) {
        occ_key_t ke;
        assert_int_equal(occ_map_key(m, e, &ke), OCC_OK);
        memcpy(v[n].k, ke.k, sizeof v[n].k);
        v[n++].hit = 1;
    }
    return n;
}

/* The map after one scan from empty must hold exactly the voxels v[0..n) (a hit wins). */
static void assert_map_is(const occ_map_t *m, vox_t *v, size_t n)
{
    qsort(v, n, sizeof *v, vox_cmp);
    size_t u = 0, hits = 0;
    for (size_t i = 0; i < n; i++) {
        if (u > 0u && vox_cmp(&v[u - 1u], &v[i]) == 0) {
            v[u - 1u].hit |= v[i].hit;
        } else {
            v[u++] = v[i];
        }
    }
    for (size_t i = 0; i < u; i++) {
        const occ_key_t k = {{v[i].k[0], v[i].k[1], v[i].k[2]}};
        assert_int_equal(voxel_state(m, k), v[i].hit ? OCC_STATE_OCCUPIED : OCC_STATE_FREE);
        hits += (size_t)v[i].hit;
    }
    size_t vol, occ;
    volume(m, &vol, &occ);
    assert_int_equal(vol, u);
    assert_int_equal(occ, hits);
}

static void test_mixed_brute_force(void **state)
{
    (void)state;
    static occ_range_beam_t b[N_RANDOM];
    static vox_t vox[MAX_KEYS];
    static const occ_insert_method_t methods[] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                                  OCC_INSERT_SUPER_RAYS};
    for (unsigned mi = 0; mi < 3u; mi++) {
        assert_int_equal(leak_check(&map), 0);
        const occ_pose_t pose = random_pose();
        size_t n = 0, hits = 0, none = 0;
        for (size_t i = 0; i < N_RANDOM; i++) {
            const float max_m = frand(0.8f, 4.0f);
            b[i] = beam(frand(-1, 1), frand(-1, 1), frand(-1, 1), frand(0.0f, 5.0f), 0.3f, max_m);
            if (b[i].distance_m < b[i].min_m) {
                continue;
            }
            const bool hit = b[i].distance_m < max_m;
            occ_vec3_t e = beam_end(&pose, &b[i], hit ? b[i].distance_m : max_m);
            if (hit && methods[mi] == OCC_INSERT_DISCRETE) { /* a ray to the end voxel's centre */
                occ_key_t ke;
                assert_int_equal(occ_map_key(&map, e, &ke), OCC_OK);
                e = occ_map_key_center(&map, ke, 0);
            }
            n = add_ray(&map, pose.p, e, hit, vox, n);
            hits += hit ? 1u : 0u;
            none += hit ? 0u : 1u;
        }
        occ_ranges_result_t r;
        assert_int_equal(ranges(&map, &pose, b, N_RANDOM, methods[mi], &r), OCC_OK);
        assert_int_equal(r.beams_hit, hits);
        assert_int_equal(r.beams_no_return, none);
        assert_true(hits > 50u && none > 50u);
        assert_map_is(&map, vox, n);
    }
}

/* ---- OctoMap insertRay() ------------------------------------------------------------------- */
static void test_octomap_insert_ray(void **state)
{
    (void)state;
    /* Beam after beam, one call each: OctoMap's insertRay(origin, end, max) per beam gives the
     * same map (hits: end = the return; no return: a far end cut at max by OctoMap). */
    void *t = oracle_ins_new((double)RES);
    const occ_pose_t pose = random_pose();
    const float o[3] = {pose.p.x, pose.p.y, pose.p.z};
    size_t none = 0;
    for (unsigned i = 0; i < 200u; i++) {
        const occ_range_beam_t b = beam(frand(-1, 1), frand(-1, 1), frand(-1, 1), frand(0.3f, 5.0f),
                                        0.3f, 3.0f);
        occ_ranges_result_t r;
        assert_int_equal(ranges(&map, &pose, &b, 1, OCC_INSERT_SIMPLE, &r), OCC_OK);
        const bool hit = b.distance_m < b.max_m;
        const occ_vec3_t e = beam_end(&pose, &b, hit ? b.distance_m : 2.0f * b.max_m);
        const float ef[3] = {e.x, e.y, e.z};
        oracle_ins_ray(t, o, ef, hit ? -1.0 : (double)b.max_m);
        none += hit ? 0u : 1u;
    }
    size_t v, occ, tv, tocc;
    volume(&map, &v, &occ);
    oracle_ins_volume(t, &tv, &tocc);
    printf("  200 beams (%zu no return): %zu voxels, %zu occupied; OctoMap %zu, %zu\n", none, v,
           occ, tv, tocc);
    assert_true(none > 50u);
    assert_int_equal(v, tv);
    assert_int_equal(occ, tocc);
    /* every voxel of ours has OctoMap's log-odds */
    occ_walk_t w;
    occ_walk_node_t nd;
    occ_walk_begin(&w, &map);
    while (occ_walk_next(&w, &nd)) {
        if (nd.has_children || !nd.observed) {
            continue;
        }
        float ref;
        unsigned level;
        const uint32_t k[3] = {nd.key.k[0], nd.key.k[1], nd.key.k[2]};
        assert_true(oracle_ins_search(t, k, &ref, &level));
        assert_true(fabsf(occ_value_to_logodds(nd.value) - ref) < 0.002f);
    }
    oracle_ins_delete(t);
}

/* ---- cones ---------------------------------------------------------------------------------- */
static void test_cone_rays(void **state)
{
    (void)state;
    /* Axis +x, half-angle 0.3, d = 2: the axis end and a ring of 8 at (cos h, -sin h sin phi,
     * sin h cos phi) * 2 (u = +z, v = -y), phi = j * 45 deg - every one occupied. */
    const occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    occ_range_beam_t b = beam(1, 0, 0, 2.0f, 0.2f, 5.0f);
    b.cone_half_rad = 0.3f;
    occ_ranges_result_t r;
    assert_int_equal(ranges(&map, &pose, &b, 1, OCC_INSERT_SIMPLE, &r), OCC_OK);
    assert_int_equal(r.rays, OCC_RANGES_CONE_RAYS);
    assert_int_equal(r.insert.voxels_occupied, 9);
    /* 2 cos 0.3 = 1.9107, 2 sin 0.3 = 0.5910, times 0.7071 = 0.4179; offsets from the origin's
     * voxel: floor((0.05 + c) / 0.1), e.g. 0.05 - 0.4179 -> -4, 0.05 - 0.5910 -> -6 */
    static const int hand[9][3] = {{20, 0, 0},   {19, 0, 6},  {19, -4, 4}, {19, -6, 0}, {19, -4, -4},
                                   {19, 0, -6}, {19, 4, -4}, {19, 6, 0},  {19, 4, 4}};
    for (unsigned i = 0; i < 9u; i++) {
        assert_int_equal(voxel_state(&map, key_off(&map, pose.p, hand[i][0], hand[i][1], hand[i][2])),
                         OCC_STATE_OCCUPIED);
    }
    /* between the axis and the ring: not sampled, unknown */
    assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 19, 2, 2)), OCC_STATE_UNKNOWN);
    /* a no-return cone clears the same rays to max and marks nothing */
    b.distance_m = 9.0f;
    assert_int_equal(ranges(&map2, &pose, &b, 1, OCC_INSERT_SIMPLE, &r), OCC_OK);
    assert_int_equal(r.rays, OCC_RANGES_CONE_RAYS);
    assert_int_equal(r.insert.voxels_occupied, 0);
    assert_int_equal(r.insert.rays_no_hit, 9);
    assert_int_equal(voxel_state(&map2, key_off(&map2, pose.p, 19, 0, 6)), OCC_STATE_FREE);
}

/* ---- scratch formula and bounded work ------------------------------------------------------- */
#define FW_BEAMS 16u
#define FW_MAX_M 3.0f
static uint8_t fw_scratch[OCC_RANGES_SCRATCH_BYTES(FW_BEAMS, OCC_RANGES_CONE_RAYS, 32)];

static void test_scratch_formula_and_work(void **state)
{
    (void)state;
    /* 16 wide cones out to max 3 m (ceil(3 / 0.1) + 2 = 32 voxels) along the diagonals (the
     * most voxels per metre), half of them without a return: the static buffer the macro sized is enough for every method
     * it covers; the visits stay within rays x (3 (max / res + 2) + 2); half the bytes are
     * refused with OCC_ERR_SCRATCH and the map unchanged. */
    occ_range_beam_t b[FW_BEAMS];
    for (unsigned i = 0; i < FW_BEAMS; i++) {
        b[i] = beam((i & 1u) ? 1.0f : -1.0f, (i & 2u) ? 1.0f : -1.0f, (i & 4u) ? 1.0f : -1.0f,
                    (i & 8u) ? 2.9f : 10.0f, 0.1f, FW_MAX_M);
        b[i].cone_half_rad = 0.4f;
    }
    const occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    occ_insert_params_t p = occ_insert_params_default();
    assert_true(occ_ranges_scratch_bytes(&map, b, FW_BEAMS, &p) <= sizeof fw_scratch);
    static const occ_insert_method_t methods[] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                                  OCC_INSERT_SUPER_RAYS, OCC_INSERT_FAST_DISCRETE};
    for (unsigned mi = 0; mi < 4u; mi++) {
        p.method = methods[mi];
        p.fast_d = 0;
        assert_int_equal(leak_check(&map), 0);
        occ_ranges_result_t r;
        assert_int_equal(occ_map_insert_ranges(&map, &pose, b, FW_BEAMS, &p, fw_scratch,
                                               sizeof fw_scratch, &r),
                         OCC_OK);
        assert_int_equal(r.rays, FW_BEAMS * OCC_RANGES_CONE_RAYS);
        const size_t per_ray = 3u * (size_t)(FW_MAX_M / RES + 2.0f) + 2u;
        assert_true(r.insert.voxel_visits <= r.rays * per_ray);
        const uint64_t before = fingerprint(&map);
        assert_int_equal(occ_map_insert_ranges(&map, &pose, b, FW_BEAMS, &p, fw_scratch,
                                               sizeof fw_scratch / 2u, &r),
                         OCC_ERR_SCRATCH);
        assert_true(fingerprint(&map) == before);
    }
}

/* ---- bad input: an error and the map unchanged ---------------------------------------------- */
static void expect_refused(const occ_pose_t *pose, const occ_range_beam_t *b, size_t n,
                           const occ_insert_params_t *p, occ_err_t want)
{
    const uint64_t before = fingerprint(&map);
    const uint32_t inner = map.inner.used, leaf = map.leaf.used;
    assert_int_equal(occ_map_insert_ranges(&map, pose, b, n, p, scratch, SCRATCH_BYTES, NULL),
                     want);
    assert_true(fingerprint(&map) == before);
    assert_int_equal(map.inner.used, inner);
    assert_int_equal(map.leaf.used, leaf);
}

static void test_bad_input(void **state)
{
    (void)state;
    const occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    const occ_range_beam_t good = beam(1, 0, 0, 1.0f, 0.2f, 5.0f);
    const occ_insert_params_t p = occ_insert_params_default();
    assert_int_equal(occ_map_insert_ranges(&map, &pose, &good, 1, &p, scratch, SCRATCH_BYTES, NULL),
                     OCC_OK); /* something to keep */
    assert_int_equal(occ_map_insert_ranges(NULL, &pose, &good, 1, &p, scratch, SCRATCH_BYTES, NULL),
                     OCC_ERR_ARG);
    expect_refused(NULL, &good, 1, &p, OCC_ERR_ARG);
    expect_refused(&pose, NULL, 1, &p, OCC_ERR_ARG);
    expect_refused(&pose, &good, 1, NULL, OCC_ERR_ARG);
    occ_pose_t bad_pose = pose;
    bad_pose.p.y = NAN;
    expect_refused(&bad_pose, &good, 1, &p, OCC_ERR_ARG);
    bad_pose = pose;
    bad_pose.q.w = 0.5f; /* not unit */
    expect_refused(&bad_pose, &good, 1, &p, OCC_ERR_ARG);
    const occ_pose_t outside = pose_at(1e6f, 0.0f, 0.0f);
    expect_refused(&outside, &good, 1, &p, OCC_ERR_RANGE);
    occ_insert_params_t bad_p = p;
    bad_p.method = (occ_insert_method_t)9;
    expect_refused(&pose, &good, 1, &bad_p, OCC_ERR_ARG);
    /* a bad configuration of any one valid beam refuses the whole call */
    occ_range_beam_t two[2] = {good, good};
    for (unsigned c = 0; c < 10u; c++) {
        occ_range_beam_t *const x = &two[1];
        *x = good;
        switch (c) {
        case 0: x->dir.x = 0.0f; break;
        case 1: x->dir.y = NAN; break;
        case 2: x->min_m = -0.1f; break;
        case 3: x->max_m = 0.2f; break; /* == min */
        case 4: x->max_m = INFINITY; break;
        case 5: x->min_m = NAN; break;
        case 6: x->cone_half_rad = -0.1f; break;
        case 7: x->cone_half_rad = OCC_RANGES_CONE_MAX_RAD * 1.01f; break;
        case 8: x->cone_half_rad = NAN; break;
        default: x->dir.z = INFINITY; break;
        }
        expect_refused(&pose, two, 2, &p, OCC_ERR_ARG);
        assert_int_equal(occ_ranges_scratch_bytes(&map, two, 2, &p), 0);
    }
    /* scratch: NULL, or too small for the ends, or for the integrator */
    assert_int_equal(occ_map_insert_ranges(&map, &pose, &good, 1, &p, NULL, 0, NULL),
                     OCC_ERR_SCRATCH);
    assert_int_equal(occ_map_insert_ranges(&map, &pose, &good, 1, &p, NULL, 8, NULL), OCC_ERR_ARG);
    for (size_t bytes = 0; bytes < 40u; bytes += 3u) {
        assert_int_equal(occ_map_insert_ranges(&map, &pose, &good, 1, &p, scratch + 1, bytes, NULL),
                         OCC_ERR_SCRATCH);
    }
}

static void test_params_max_range_clips(void **state)
{
    (void)state;
    /* params->max_range_m clips a beam further, as insert_cloud's: d = 3 < max 5 but beyond the
     * call's 2 m: free to 2, no hit. */
    const occ_pose_t pose = pose_at(0.05f, 0.05f, 0.05f);
    const occ_range_beam_t b = beam(0, 0, 1, 3.0f, 0.2f, 5.0f);
    occ_insert_params_t p = occ_insert_params_default();
    p.max_range_m = 2.0f;
    occ_ranges_result_t r;
    assert_int_equal(occ_map_insert_ranges(&map, &pose, &b, 1, &p, scratch, SCRATCH_BYTES, &r),
                     OCC_OK);
    assert_int_equal(r.beams_hit, 1);
    assert_int_equal(r.insert.rays_clipped, 1);
    assert_int_equal(r.insert.voxels_occupied, 0);
    assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 0, 0, 19)), OCC_STATE_FREE);
    assert_int_equal(voxel_state(&map, key_off(&map, pose.p, 0, 0, 20)), OCC_STATE_UNKNOWN);
}

int main(void)
{
    const char *s = getenv("OCC_SEED");
    rng_state = s != NULL ? strtoull(s, NULL, 0) : 0x5EEDull;
    rng_state = rng_state != 0u ? rng_state : 1u;
    printf("test_ranges seed %llu (set OCC_SEED to repeat)\n", (unsigned long long)rng_state);
    arena = malloc(ARENA_BYTES);
    arena2 = malloc(ARENA_BYTES);
    scratch = malloc(SCRATCH_BYTES);
#define T(f) cmocka_unit_test_setup_teardown(f, setup, teardown)
    const struct CMUnitTest tests[] = {
        T(test_hit_hand),         T(test_no_return_hand),         T(test_skipped_counted),
        T(test_hits_equal_insert_cloud),  T(test_no_return_equals_insert_cloud_max_range),
        T(test_mixed_brute_force),        T(test_octomap_insert_ray),     T(test_cone_rays),
        T(test_scratch_formula_and_work), T(test_bad_input),     T(test_params_max_range_clips),
    };
    const int rc = cmocka_run_group_tests(tests, NULL, NULL);
    free(arena);
    free(arena2);
    free(scratch);
    return rc;
}
