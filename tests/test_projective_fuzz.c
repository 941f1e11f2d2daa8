/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_projective_fuzz.c - OCC_INSERT_PROJECTIVE on random synthetic frames, voxel for voxel
 * against the brute-force oracle of the header's rule (tests/support/projective_ref.c). The
 * real TUM frames (test_projective.c) come from a level camera on a ground robot; a drone's
 * camera rolls, pitches and looks straight down. Here each case draws: any orientation (uniform
 * on SO(3), or an exact quarter-turn one: axis-aligned planes and corners), a position near
 * the map's centre (keys crossing 2^(D-1)) or on a voxel face, small images of odd shapes,
 * off-centre and out-of-image principal points, narrow to very wide fields of view, U16 or F32
 * depths (NaN, +-Inf, 0, -0, negative, absurdly far, beyond max range, inside min range),
 * every noise margin, maps of 16 or of 3 to 8 levels, and a misaligned scratch. Two or three
 * frames go into one map (the second onto the first's voxels); one map in three already holds
 * pruned blocks of either state and single voxels around the camera; one map in six has a
 * small pool, and a frame it cannot hold must leave it as it was (OCC_ERR_NOMEM). A refused call (scratch short)
 * must leave the map as it was. Random seed: printed, overridable with OCC_SEED. Also linked
 * against the release library (test_projective_fuzz_rel: the vectorised lanes and their AVX-512 or
 * AVX2 clones).
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
#include "support/depth_fixture.h"
#include "support/projective_ref.h"
#include "support/seeded_rng.h"

#define CASES 240u
#define SMALL_W 48u /* most cases: images up to 48 x 40 */
#define SMALL_H 40u
#define MAX_W 160u  /* one case in eight: up to 160 x 120 (the pyramid's windows, deeper walks) */
#define MAX_H 120u
/* The fixture's scratch holds any frame drawn here, plus 15 bytes of misalignment: a near ray
 * at every pixel (fx, fy below 32), each of at most sqrt(3) 32 + 4 voxels (max range is at
 * most 32 voxels), twice while sorted, and the walk's output. */
#define NEAR_SLOTS (2u * MAX_W * MAX_H * 60u)
typedef char fixture_scratch_holds_any_frame
    [OCC_PROJ_SCRATCH_BYTES(MAX_W, MAX_H, NEAR_SLOTS + 262144u) + 16u <= SCRATCH_BYTES ? 1 : -1];

static float pix_f32[MAX_H][MAX_W * 2u]; /* room for a pixel stride of 8 bytes */
static uint16_t pix_u16[MAX_H][MAX_W];

static int setup(void **state)
{
    (void)init_maps; /* the fixture's: the maps here have random shapes (random_map) */
    rng_seed("test_projective_fuzz");
    return depth_setup(state);
}

static float uniform(const float lo, const float hi)
{
    return lo + (hi - lo) * (float)(rng_next() >> 40) / (float)(1u << 24);
}

static uint32_t below(const uint32_t n)
{
    return (uint32_t)(rng_next() % n);
}

/* ---- the camera ---------------------------------------------------------------------------- */

/* A rotation: uniform on SO(3) (a point of the 4-ball, normalised to a unit quaternion by
 * occ_quat_normalize, its columns as occ_map_insert_depth builds them), or one of the 24 exact
 * quarter-turn rotations (signed permutations with determinant +1: exactly axis-aligned). */
static void random_rotation(float r[3][3])
{
    if (below(4u) == 0u) {
        static const unsigned perm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                            {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
        const unsigned p = below(6u);
        float s[3] = {below(2u) ? 1.0f : -1.0f, below(2u) ? 1.0f : -1.0f, 1.0f};
        s[2] = (p < 3u ? 1.0f : -1.0f) * s[0] * s[1]; /* odd permutations flip: det = +1 */
        memset(r, 0, 9u * sizeof(float));
        for (unsigned a = 0; a < 3u; a++) {
            r[perm[p][a]][a] = s[a];
        }
        return;
    }
    occ_quat_t q;
    float n2;
    do {
        q = (occ_quat_t){uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
        n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    } while (n2 > 1.0f || n2 < 1e-3f);
    occ_pose_t pose = occ_pose_identity();
    assert_int_equal(occ_quat_normalize(q, &pose.q), OCC_OK);
    projref_rotation_of(&pose, r);
}

/* A coordinate near the map's centre: random, or on a voxel face (a multiple of res). */
static float random_coord(const float res, const float span)
{
    const float c = uniform(-span, span);
    return below(3u) == 0u ? res * floorf(c / res) : c;
}

static occ_proj_camera_t random_camera(const uint32_t w, const uint32_t h, const float res,
                                       const float half_map)
{
    occ_proj_camera_t k;
    memset(&k, 0, sizeof k);
    /* fields of view from ~20 to ~150 degrees across the image */
    k.fx = (float)w * uniform(0.15f, 2.5f) + 0.5f;
    k.fy = below(2u) ? k.fx : (float)h * uniform(0.15f, 2.5f) + 0.5f;
    const float wf = (float)w, hf = (float)h;
    k.cx = below(5u) == 0u ? uniform(-0.5f * wf, 1.5f * wf) : 0.5f * (wf - 1.0f) + uniform(-2, 2);
    k.cy = below(5u) == 0u ? uniform(-0.5f * hf, 1.5f * hf) : 0.5f * (hf - 1.0f) + uniform(-2, 2);
    random_rotation(k.r);
    const float span = half_map < 1.0f ? 0.8f * half_map : 1.0f;
    k.t = (occ_vec3_t){random_coord(res, span), random_coord(res, span), random_coord(res, span)};
    /* The oracle visits the cube of half-edge max range: at most ~32 voxels each way. */
    k.max_range_m = res * uniform(4.0f, 32.0f);
    k.min_range_m = below(3u) == 0u ? 0.0f : uniform(0.0f, 0.3f * k.max_range_m);
    k.noise_rel = below(4u) == 0u ? 0.0f : (below(4u) == 0u ? 0.5f : uniform(0.0f, 0.5f));
    return k;
}

/* ---- the image ----------------------------------------------------------------------------- */

/* A depth: mostly a blocky surface (planes in pixel blocks) with noise, sometimes a special;
 * snapped to a multiple of `snap` when it is not 0 (voxel centres' depths for a camera on a
 * voxel face looking along an axis: ties of the free test q_2 < T(d)). */
static float random_depth(const occ_proj_camera_t *k, const uint32_t i, const uint32_t j,
                          const uint32_t bw, const uint32_t bh, const uint64_t scene,
                          const float snap)
{
    uint64_t z = scene ^ ((uint64_t)(i / bw) << 32) ^ (j / bh);
    z = (z ^ (z >> 29)) * 0xBF58476D1CE4E5B9ull;
    z ^= z >> 32;
    const float base = k->max_range_m * (0.1f + 1.2f * (float)(z % 1000u) / 1000.0f);
    float d = base * (1.0f + uniform(-0.02f, 0.02f)) + 0.01f * (float)(i % bw);
    if (snap > 0.0f) {
        d = snap * (floorf(d / snap) + 1.0f);
    }
    switch (below(40u)) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return 0.0f;
    case 4: return -0.0f;
    case 5: return -d;
    case 6: return 3000.0f * k->max_range_m; /* absurdly far: no return within range */
    case 7: return 0.5f * k->min_range_m;    /* blind zone */
    default: return (z >> 40) % 9u == 0u ? NAN : d; /* whole blocks without a reading */
    }
}

/* Fill the image (U16 or F32, pixel stride 4 or 8 for F32) and describe it. */
static occ_proj_image_t random_image(const occ_proj_camera_t *k, const uint32_t w,
                                     const uint32_t h, const float snap)
{
    const uint32_t bw = 1u + below(12u), bh = 1u + below(12u);
    const uint64_t scene = rng_next();
    const bool u16 = below(2u) == 0u;
    const float scale = below(2u) ? 1.0f / 5000.0f : 1.0f / 1000.0f;
    const size_t pstride = u16 ? 2u : (below(3u) == 0u ? 8u : 4u);
    for (uint32_t j = 0; j < h; j++) {
        for (uint32_t i = 0; i < w; i++) {
            const float d = random_depth(k, i, j, bw, bh, scene, snap);
            if (u16) {
                const float raw = d / scale;
                pix_u16[j][i] = raw > 0.0f && raw < 65535.0f ? (uint16_t)raw : 0u;
            } else {
                pix_f32[j][i * (pstride / 4u)] = d;
            }
        }
    }
    const occ_proj_image_t im = {u16 ? (const void *)pix_u16 : (const void *)pix_f32,
                                 u16 ? OCC_PROJ_U16 : OCC_PROJ_F32,
                                 w,
                                 h,
                                 u16 ? sizeof pix_u16[0] : sizeof pix_f32[0],
                                 pstride,
                                 scale};
    return im;
}

/* Key kt + off on one axis, clamped to [0, side - span] (span: the block's edge, 1 for a voxel). */
static uint32_t key_near(const uint32_t kt, const int64_t off, const uint32_t side,
                         const uint32_t span)
{
    const int64_t v = (int64_t)kt + off, hi = (int64_t)side - (int64_t)span;
    return (uint32_t)(v < 0 ? 0 : (v > hi ? hi : v));
}

/* ---- a map that is not empty ---------------------------------------------------------------- */

/* The same random content in both maps around the camera, before its frames: whole 8 x 8 x 8
 * blocks observed free or occupied 1 to 6 times (pruned nodes above the voxels, some at the
 * clamp) and single voxels, so that the walk's whole free nodes and bricks land on pruned
 * nodes of either state, on mixed ones and on voxels at the clamp. */
static void prepopulate(const occ_vec3_t t)
{
    occ_key_t kt;
    if (occ_map_key(&map_a, t, &kt) != OCC_OK) {
        return;
    }
    const uint32_t side = (uint32_t)1 << map_a.cfg.depth_levels;
    enum { MAX_CODES = 24u * 512u + 512u };
    occ_code_t *const c = malloc(MAX_CODES * sizeof *c);
    assert_non_null(c);
    for (unsigned pass = 0; pass < 1u + below(6u); pass++) {
        size_t n = 0;
        for (unsigned b = 0; b < 24u; b++) {
            const occ_code_t hit = below(3u) == 0u ? OCC_CODE_HIT_BIT : 0u;
            occ_key_t k0;
            for (unsigned a = 0; a < 3u; a++) { /* aligned to 8: maps have 3 levels or more */
                k0.k[a] = key_near(kt.k[a], (int64_t)below(49u) - 24, side, 8u) & ~7u;
            }
            for (uint32_t m = 0; m < 512u; m++) {
                const occ_key_t k = {{k0.k[0] + (m & 7u), k0.k[1] + ((m >> 3) & 7u),
                                      k0.k[2] + (m >> 6)}};
                c[n++] = occ_morton_encode(k) | hit;
            }
        }
        for (unsigned v = 0; v < 512u; v++) {
            occ_key_t k;
            for (unsigned a = 0; a < 3u; a++) {
                k.k[a] = key_near(kt.k[a], (int64_t)below(49u) - 24, side, 1u);
            }
            c[n++] = occ_morton_encode(k) | (below(2u) ? OCC_CODE_HIT_BIT : 0u);
        }
        const size_t u = projref_sort_unique(c, n);
        assert_int_equal(occ_map_observe_codes(&map_a, c, u, NULL), OCC_OK);
        assert_int_equal(occ_map_observe_codes(&map_b, c, u, NULL), OCC_OK);
    }
    free(c);
    assert_true(iotest_map_digest(&map_a) == iotest_map_digest(&map_b));
}

/* ---- one case ------------------------------------------------------------------------------ */

/* The map's shape: 16 levels at 0.05 to 0.25 m, or 3 to 8 levels spanning 4 m. */
static occ_map_config_t random_map(float *half_map)
{
    occ_map_config_t c = iotest_octomap_cfg();
    if (below(4u) == 0u) {
        c.depth_levels = (uint8_t)(3u + below(6u));
        c.resolution_m = 4.0f / (float)(1u << c.depth_levels);
    } else {
        static const float res[5] = {0.05f, 0.08f, 0.1f, 0.2f, 0.25f};
        c.resolution_m = res[below(5u)];
    }
    *half_map = 0.5f * c.resolution_m * (float)(1u << c.depth_levels);
    return c;
}

/* The insert (map_a's digest before it: `before`) through the header's default scratch, OCC_PROJ_SCRATCH_BYTES(w, h,
 * OCC_PROJ_OUT_DEFAULT(w, h)) at a random misalignment, and, when a frame needs more (a wide
 * field of view: a near ray at every pixel, each several voxels long), the refusal leaves the
 * map as it was and all of the test's scratch is enough. First, when drawn, a scratch short of
 * the fixed part: refused, map unchanged. */
static occ_err_t insert(const occ_proj_image_t *im, const occ_proj_camera_t *k,
                        const uint64_t before, occ_proj_result_t *r, size_t *retries)
{
    unsigned char *const s = scratch + below(16u);
    if (below(4u) == 0u) {
        assert_int_equal(occ_map_insert_projective(&map_a, im, k, s, below(4096u), r),
                         OCC_ERR_SCRATCH);
        assert_true(iotest_map_digest(&map_a) == before);
    }
    const size_t dflt = OCC_PROJ_SCRATCH_BYTES(im->width, im->height,
                                               OCC_PROJ_OUT_DEFAULT(im->width, im->height));
    const occ_err_t e = occ_map_insert_projective(&map_a, im, k, s, dflt, r);
    if (e != OCC_ERR_SCRATCH) {
        return e;
    }
    assert_true(iotest_map_digest(&map_a) == before);
    (*retries)++;
    return occ_map_insert_projective(&map_a, im, k, s, SCRATCH_BYTES - 16u, r);
}

static void print_case(const occ_proj_image_t *im, const occ_proj_camera_t *k)
{
    printf("case: %ux%u %s stride %zu, f %.4f %.4f c %.4f %.4f, t %.5f %.5f %.5f, "
           "range %.4f..%.4f, noise %.4f, res %.3f, depth %u\n",
           im->width, im->height, im->format == OCC_PROJ_U16 ? "u16" : "f32",
           im->pixel_stride_bytes, (double)k->fx, (double)k->fy, (double)k->cx, (double)k->cy,
           (double)k->t.x, (double)k->t.y, (double)k->t.z, (double)k->min_range_m,
           (double)k->max_range_m, (double)k->noise_rel, (double)map_a.cfg.resolution_m,
           (unsigned)map_a.cfg.depth_levels);
}

/* One frame into map_a by the walk and into map_b by the oracle: equal maps after it. */
static void frame_equals_oracle(const occ_proj_image_t *im, const occ_proj_camera_t *k,
                                size_t *updates, size_t *retries, size_t *refused)
{
    occ_proj_result_t r;
    const uint64_t before = iotest_map_digest(&map_a);
    const occ_err_t e = insert(im, k, before, &r, retries);
    if (e == OCC_ERR_RANGE || e == OCC_ERR_NOMEM) {
        /* the camera off a small map, or map_a's small pool full: map_a as it was, and the
         * oracle's map stays as it is too */
        assert_true(iotest_map_digest(&map_a) == before);
        *refused += e == OCC_ERR_NOMEM ? 1u : 0u;
        return;
    }
    if (e != OCC_OK) {
        print_case(im, k);
    }
    assert_int_equal(e, OCC_OK);
    occ_code_t *codes = NULL;
    size_t hits = 0;
    const size_t n = projref_codes(&map_b, im, k, &codes, &hits);
    size_t changed = 0;
    assert_int_equal(occ_map_observe_codes(&map_b, codes, n, &changed), OCC_OK);
    free(codes);
    assert_int_equal(r.insert.voxels_occupied, hits);
    assert_true(r.insert.voxels_updated <= n);
    if (iotest_map_digest(&map_a) != iotest_map_digest(&map_b)) {
        print_case(im, k);
        fail_msg("the walk's map differs from the oracle's");
    }
    assert_int_equal(occ_map_check(&map_a), OCC_OK);
    *updates += n;
}

static void test_random_frames_equal_oracle(void **state)
{
    (void)state;
    size_t updates = 0, frames = 0, retries = 0, refused = 0;
    for (unsigned c = 0; c < CASES; c++) {
        float half_map = 0.0f;
        const occ_map_config_t cfg = random_map(&half_map);
        /* One map in six gets a small pool: a frame it cannot hold is refused whole */
        const size_t bytes_a = below(6u) == 0u ? ((size_t)2 << 10) * (2u + below(24u))
                                               : ARENA_BYTES;
        assert_int_equal(occ_map_init(&map_a, &cfg, arena_a, bytes_a), OCC_OK);
        assert_int_equal(occ_map_init(&map_b, &cfg, arena_b, ARENA_BYTES), OCC_OK);
        const bool big = below(8u) == 0u;
        const uint32_t w = 1u + below(big ? MAX_W : SMALL_W);
        const uint32_t h = 1u + below(big ? MAX_H : SMALL_H);
        const unsigned n = 2u + below(2u);
        /* One case in four: depths on half-voxel steps (ties where the camera sits on a voxel
         * face and looks along an axis, which random_camera draws often). */
        const float snap = below(4u) == 0u ? 0.5f * cfg.resolution_m : 0.0f;
        occ_proj_camera_t k = random_camera(w, h, cfg.resolution_m, half_map);
        if (bytes_a == ARENA_BYTES && below(3u) == 0u) {
            prepopulate(k.t);
        }
        for (unsigned f = 0; f < n; f++) {
            if (f > 0u && below(2u) == 0u) {
                k = random_camera(w, h, cfg.resolution_m, half_map); /* else the same pose */
            }
            const occ_proj_image_t im = random_image(&k, w, h, snap);
            frame_equals_oracle(&im, &k, &updates, &retries, &refused);
            frames++;
        }
        assert_int_equal(leak_check(&map_a), 0);
        assert_int_equal(leak_check(&map_b), 0);
    }
    printf("%u cases, %zu frames (%zu needed more than the default scratch, %zu refused by a "
           "full pool), %zu oracle updates: equal\n", CASES, frames, retries, refused, updates);
    assert_true(updates > 0u && refused > 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_frames_equal_oracle),
    };
    return cmocka_run_group_tests(tests, setup, depth_teardown);
}
