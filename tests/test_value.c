/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_value.c - the fixed-point value arithmetic of this build (issue 22), against values
 * computed by hand from OctoMap's float model: the quantized sensor model, hit/miss sequences,
 * clamps, the occupancy threshold, saturation at both ends of the value range, the reserved
 * unobserved value, the block sizes, .ot values rounded and saturated on load (a hand-built
 * one-node file), and that .occ snapshots of the other value family are refused. Built in the default 16-bit build and in the 8-bit variant (test-variant-v8);
 * the expectations follow OCC_VALUE_BITS. The float build has its own oracle tests.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "occmap/occmap.h"
#include "occmap/occ_io.h"
#include "core/tree_internal.h"

#if OCC_VALUE_FLOAT
#error "test_value tests the fixed-point builds"
#endif

/* Hand-computed: round(x * scale) of OctoMap's logit(0.7), logit(0.4), logit(0.1192), logit(0.971)
 * = 0.8472979, -0.4054651, -2.0000279, 3.5110307. */
#if OCC_VALUE_BITS == 8
#define SCALE 36
#define Q_HIT 31      /* 30.503 */
#define Q_MISS (-15)  /* -14.597 */
#define Q_CMIN (-72)  /* -72.001 */
#define Q_CMAX 126    /* 126.397 */
#define LEAF_B 8u
#define INNER_B 35u
#define STEP_ERR 0.0140f /* |31/36 - 0.8473| = 0.0138, |15/36 - 0.4055| = 0.0112 */
#else
#define SCALE 1024
#define Q_HIT 868     /* 867.633 */
#define Q_MISS (-415) /* -415.196 */
#define Q_CMIN (-2048) /* -2048.03 */
#define Q_CMAX 3595   /* 3595.295 */
#define LEAF_B 16u
#define INNER_B 56u
#define STEP_ERR 0.00049f
#endif

static uint8_t arena[OCC_ARENA_BYTES(64, 64)];

/* Exact float equality without -Wfloat-equal's ==. */
static bool feq(const float a, const float b)
{
    return !(a < b) && !(b < a);
}
static occ_map_t map;

static int setup(void **state)
{
    (void)state;
    const occ_map_config_t cfg = occ_map_config_default();
    return occ_map_init(&map, &cfg, arena, sizeof arena) == OCC_OK ? 0 : -1;
}

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

static float read_lo(occ_key_t k, bool *observed, occ_state_t *st)
{
    occ_node_info_t n;
    assert_int_equal(occ_map_read_key(&map, k, 0u, &n), OCC_OK);
    *observed = n.observed;
    *st = n.state;
    return n.logodds;
}

static void test_scale_and_sizes(void **state)
{
    (void)state;
    assert_int_equal(OCC_FIXED_ONE, SCALE);
    assert_int_equal(OCC_LEAF_BLOCK_BYTES, LEAF_B);
    assert_int_equal(OCC_INNER_BLOCK_BYTES, INNER_B);
    assert_int_equal(sizeof(occ_leaf_block_t), LEAF_B);
    assert_int_equal(sizeof(occ_inner_block_t), INNER_B);
    assert_int_equal(map.priv.q_hit, Q_HIT);
    assert_int_equal(map.priv.q_miss, Q_MISS);
    assert_int_equal(map.priv.q_clamp_min, Q_CMIN);
    assert_int_equal(map.priv.q_clamp_max, Q_CMAX);
    assert_int_equal(map.priv.q_free_max, 0);
    assert_int_equal(map.priv.q_occ_min, 0);
    /* Rounding error of the quantized sensor model against float, as the header states. */
    assert_true(fabsf(occ_value_to_logodds(map.priv.q_hit) - 0.8472979f) <= STEP_ERR);
    assert_true(fabsf(occ_value_to_logodds(map.priv.q_miss) + 0.4054651f) <= STEP_ERR);
#if OCC_VALUE_BITS == 8
    /* OctoMap's clamp bounds land on the grid: -2.0 exactly, 3.5 (3.511 - 0.011). */
    assert_true(feq(occ_value_to_logodds(map.priv.q_clamp_min), -2.0f));
    assert_true(feq(occ_value_to_logodds(map.priv.q_clamp_max), 3.5f));
#endif
}

static void test_conversion_saturates(void **state)
{
    (void)state;
    assert_int_equal(occ_value_from_logodds(0.0f), 0);
    assert_int_equal(occ_value_from_logodds(1.0e9f), OCC_VALUE_MAX);
    assert_int_equal(occ_value_from_logodds(-1.0e9f), OCC_VALUE_MIN);
    assert_int_equal(occ_value_from_logodds(NAN), OCC_VALUE_MIN);
    assert_int_equal(occ_value_from_logodds(INFINITY), OCC_VALUE_MAX);
    assert_int_equal(occ_value_from_logodds(-INFINITY), OCC_VALUE_MIN);
    /* Round to nearest, halves away from zero: 0.5 / SCALE -> 1. */
    assert_int_equal(occ_value_from_logodds(0.51f / (float)SCALE), 1);
    assert_int_equal(occ_value_from_logodds(-0.51f / (float)SCALE), -1);
    assert_int_equal(occ_value_from_logodds(0.49f / (float)SCALE), 0);
    /* Never the reserved unobserved value; it reads as 0 log-odds. */
    assert_true(OCC_VALUE_MIN > OCC_VALUE_UNOBSERVED);
    assert_false(occ_value_observed((occ_value_t)OCC_VALUE_UNOBSERVED));
    assert_true(occ_value_observed((occ_value_t)OCC_VALUE_MIN));
    assert_true(feq(occ_value_to_logodds((occ_value_t)OCC_VALUE_UNOBSERVED), 0.0f));
#if OCC_VALUE_BITS == 8
    assert_int_equal(OCC_VALUE_UNOBSERVED, -128);
    assert_int_equal(OCC_VALUE_MAX, 127);
#endif
}

/* n hits then m misses on a fresh voxel, against the hand model: raw sums clamped per step. */
static void hits_misses(const unsigned n_hit, const unsigned n_miss, const int want_raw,
                        const float want_float, const occ_state_t want_state)
{
    static uint32_t next = 0;
    const occ_key_t k = mk(next++, 5u, 7u);
    for (unsigned i = 0; i < n_hit; i++) {
        assert_int_equal(occ_map_observe_key(&map, k, true), OCC_OK);
    }
    for (unsigned i = 0; i < n_miss; i++) {
        assert_int_equal(occ_map_observe_key(&map, k, false), OCC_OK);
    }
    bool obs;
    occ_state_t st;
    const float lo = read_lo(k, &obs, &st);
    assert_true(obs);
    assert_true(feq(lo, (float)want_raw / (float)SCALE));
    assert_int_equal(st, want_state);
    /* The documented bound: k unclamped updates differ from float by <= k * STEP_ERR. */
    assert_true(fabsf(lo - want_float) <= (float)(n_hit + n_miss) * STEP_ERR + 0.012f);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

static void test_hit_miss_sequences(void **state)
{
    (void)state;
    /* float: 0.8473, occupied */
    hits_misses(1u, 0u, Q_HIT, 0.8472979f, OCC_STATE_OCCUPIED);
    /* float: -0.4055, free */
    hits_misses(0u, 1u, Q_MISS, -0.4054651f, OCC_STATE_FREE);
    /* float: 0.8473 - 0.4055 = 0.4418 */
    hits_misses(1u, 1u, Q_HIT + Q_MISS, 0.4418328f, OCC_STATE_OCCUPIED);
    /* float: 0.8473 - 0.8109 = 0.0364: still occupied in both */
    hits_misses(1u, 2u, Q_HIT + 2 * Q_MISS, 0.0363677f, OCC_STATE_OCCUPIED);
    /* float: 2 * 0.8473 - 4 * 0.4055 = 0.0727 */
    hits_misses(2u, 4u, 2 * Q_HIT + 4 * Q_MISS, 0.0727354f, OCC_STATE_OCCUPIED);
    /* float: 0.8473 - 3 * 0.4055 = -0.3691: free in both */
    hits_misses(1u, 3u, Q_HIT + 3 * Q_MISS, -0.3690974f, OCC_STATE_FREE);
}

static void test_clamps(void **state)
{
    (void)state;
    /* 5 hits: 4.236 in float, clamped to clamp_max (3.511; the grid's 3.5 in 8-bit). */
    const occ_key_t k = mk(100u, 1u, 1u);
    for (unsigned i = 0; i < 5u; i++) {
        assert_int_equal(occ_map_observe_key(&map, k, true), OCC_OK);
    }
    bool obs;
    occ_state_t st;
    assert_true(feq(read_lo(k, &obs, &st), (float)Q_CMAX / (float)SCALE));
    assert_true(fabsf(read_lo(k, &obs, &st) - 3.5110307f) <= 0.012f);
    /* At the bound: another hit keeps it; one miss takes it down by exactly one miss. */
    assert_int_equal(occ_map_observe_key(&map, k, true), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)Q_CMAX / (float)SCALE));
    assert_int_equal(occ_map_observe_key(&map, k, false), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)(Q_CMAX + Q_MISS) / (float)SCALE));
    /* 6 misses: -2.433 in float, clamped to clamp_min (-2.0 exactly in 8-bit). */
    const occ_key_t f = mk(101u, 1u, 1u);
    for (unsigned i = 0; i < 6u; i++) {
        assert_int_equal(occ_map_observe_key(&map, f, false), OCC_OK);
    }
    assert_true(feq(read_lo(f, &obs, &st), (float)Q_CMIN / (float)SCALE));
    assert_int_equal(st, OCC_STATE_FREE);
    assert_int_equal(occ_map_observe_key(&map, f, false), OCC_OK);
    assert_true(feq(read_lo(f, &obs, &st), (float)Q_CMIN / (float)SCALE));
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* Far deltas saturate at both ends and never wrap (the sum is taken in int32). */
static void test_saturation(void **state)
{
    (void)state;
    bool obs;
    occ_state_t st;
    const occ_key_t k = mk(200u, 2u, 2u);
    assert_int_equal(occ_map_update_key(&map, k, 1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)Q_CMAX / (float)SCALE));
    assert_int_equal(occ_map_update_key(&map, k, -1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)Q_CMIN / (float)SCALE));
    assert_int_equal(st, OCC_STATE_FREE);
    /* A node set (unclamped) to the top of the value range, then pushed further out: kept. The
     * largest delta (saturated to +-32767 delta steps) from one end of the value range: in
     * 8-bit mode it crosses the whole range and lands on the far clamp (as float would); in the
     * 16-bit mode the value range (+-32767) equals the delta range, so it lands on 0 (+-32
     * log-odds deltas are the 16-bit limit, documented there). */
#if OCC_VALUE_BITS == 8
#define FAR_LO Q_CMIN
#define FAR_HI Q_CMAX
#else
#define FAR_LO 0
#define FAR_HI 0
#endif
    assert_int_equal(occ_map_set_key(&map, k, 0u, 1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)OCC_VALUE_MAX / (float)SCALE));
    assert_int_equal(occ_map_update_key(&map, k, 1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)OCC_VALUE_MAX / (float)SCALE));
    assert_int_equal(occ_map_update_key(&map, k, -1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)FAR_LO / (float)SCALE));
    assert_int_equal(occ_map_set_key(&map, k, 0u, -1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)OCC_VALUE_MIN / (float)SCALE));
    assert_true(obs); /* the bottom of the range is observed, not the reserved value */
    assert_int_equal(occ_map_update_key(&map, k, 1.0e6f), OCC_OK);
    assert_true(feq(read_lo(k, &obs, &st), (float)FAR_HI / (float)SCALE));
    /* The internal rule directly, at the extremes of both operands (sums in int32: no wrap). */
    const occ_value_t vmax = (occ_value_t)OCC_VALUE_MAX, vmin = (occ_value_t)OCC_VALUE_MIN;
    const occ_delta_t dmax = (occ_delta_t)32767, dmin = (occ_delta_t)-32767;
    assert_int_equal(occ_value_apply_delta(&map, vmin, dmin), vmin); /* below clamp_min: kept */
    assert_int_equal(occ_value_apply_delta(&map, vmax, dmax), vmax); /* above clamp_max: kept */
    assert_int_equal(occ_value_apply_delta(&map, vmin, dmax), FAR_HI);
    assert_int_equal(occ_value_apply_delta(&map, vmax, dmin), FAR_LO);
    assert_int_equal(occ_value_apply_delta(&map, (occ_value_t)OCC_VALUE_UNOBSERVED, dmax), Q_CMAX);
    assert_int_equal(occ_value_apply_delta(&map, (occ_value_t)OCC_VALUE_UNOBSERVED, dmin), Q_CMIN);
    assert_int_equal(occi_delta_from_logodds(1.0e9f), 32767);
    assert_int_equal(occi_delta_from_logodds(-1.0e9f), -32767);
    assert_int_equal(occi_delta_from_logodds(-4.0f), OCC_VALUE_BITS == 8 ? -144 : -4096);
    assert_int_equal(occ_map_check(&map), OCC_OK);
}

/* The occupancy threshold 0 is exact: 0 is OCCUPIED, one step below is FREE. */
static void test_threshold(void **state)
{
    (void)state;
    const float step = 1.0f / (float)SCALE;
    assert_int_equal(occ_map_state_of(&map, 0.0f), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_state_of(&map, step), OCC_STATE_OCCUPIED);
    assert_int_equal(occ_map_state_of(&map, -step), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_of(&map, -2.0f), OCC_STATE_FREE);
    assert_int_equal(occ_map_state_of(&map, 3.5f), OCC_STATE_OCCUPIED);
    /* A value within half a step of 0 rounds to 0: the documented quantization. */
    assert_int_equal(occ_map_state_of(&map, -0.4f * step), OCC_STATE_OCCUPIED);
    /* Unobserved voxels are UNKNOWN. */
    bool obs;
    occ_state_t st;
    (void)read_lo(mk(300u, 3u, 3u), &obs, &st);
    assert_false(obs);
    assert_int_equal(st, OCC_STATE_UNKNOWN);
}

/* A snapshot round-trips bit-exactly in this build; its value kind byte is this build's; a
 * snapshot claiming the other fixed-point family is refused with OCC_ERR_UNSUPPORTED. */
static uint8_t file[4096];
static uint8_t arena2[OCC_ARENA_BYTES(64, 64)];

static void test_snapshot_kind(void **state)
{
    (void)state;
    for (uint32_t i = 0; i < 20u; i++) {
        assert_int_equal(occ_map_observe_key(&map, mk(i, i, 3u), (i % 3u) != 0u), OCC_OK);
    }
    occ_io_buf_t buf = {file, sizeof file, 0u};
    size_t n = 0;
    assert_int_equal(occ_io_write(&map, OCC_FORMAT_SNAPSHOT, occ_io_buf_write, &buf, &n), OCC_OK);
    assert_int_equal(file[12], OCC_VALUE_BITS == 8 ? 2 : 0);
    occ_map_t back;
    occ_io_info_t info;
    assert_int_equal(occ_io_load(&back, NULL, arena2, sizeof arena2, file, n, &info), OCC_OK);
    assert_int_equal(info.warnings & OCC_IO_WARN_QUANTIZED, 0);
    for (uint32_t i = 0; i < 20u; i++) {
        occ_node_info_t a, b;
        assert_int_equal(occ_map_read_key(&map, mk(i, i, 3u), 0u, &a), OCC_OK);
        assert_int_equal(occ_map_read_key(&back, mk(i, i, 3u), 0u, &b), OCC_OK);
        assert_true(feq(a.logodds, b.logodds) && a.state == b.state);
    }
    /* Relabel the kind (and fix the CRC so only the kind differs). */
    file[12] = OCC_VALUE_BITS == 8 ? 0u : 2u;
    const uint32_t crc = occ_crc32(0u, file, n - 4u);
    for (unsigned i = 0; i < 4u; i++) {
        file[n - 4u + i] = (uint8_t)(crc >> (8u * i));
    }
    assert_int_equal(occ_io_probe(file, n, NULL, &info), OCC_ERR_UNSUPPORTED);
    assert_int_equal(occ_io_load(&back, NULL, arena2, sizeof arena2, file, n, &info),
                     OCC_ERR_UNSUPPORTED);
    file[12] = 3u; /* no such kind */
    const uint32_t crc3 = occ_crc32(0u, file, n - 4u);
    for (unsigned i = 0; i < 4u; i++) {
        file[n - 4u + i] = (uint8_t)(crc3 >> (8u * i));
    }
    assert_int_equal(occ_io_probe(file, n, NULL, &info), OCC_ERR_FORMAT);
}

/* .ot load converts float log-odds with rounding and saturation: a one-node tree (the root, no
 * children) with value f, built by hand in OctoMap's .ot layout. */
static size_t ot_one_node(uint8_t *const out, const float f)
{
    static const char hdr[] = "# Octomap OcTree file\nid OcTree\nsize 1\nres 0.1\ndata\n";
    const size_t n = sizeof hdr - 1u;
    memcpy(out, hdr, n);
    memcpy(out + n, &f, 4u); /* little-endian hosts only, as the tests run */
    out[n + 4u] = 0u;        /* no children */
    return n + 5u;
}

static void ot_case(const float f, const int want_raw, const uint32_t want_warn)
{
    const size_t n = ot_one_node(file, f);
    occ_map_t m;
    occ_io_info_t info;
    assert_int_equal(occ_io_load(&m, NULL, arena2, sizeof arena2, file, n, &info), OCC_OK);
    occ_node_info_t ni;
    assert_int_equal(occ_map_read_key(&m, mk(32768u, 32768u, 32768u), 0u, &ni), OCC_OK);
    assert_true(ni.observed);
    assert_true(feq(ni.logodds, (float)want_raw / (float)SCALE));
    assert_int_equal(info.warnings & (OCC_IO_WARN_QUANTIZED | OCC_IO_WARN_CLAMPED), want_warn);
}

static void test_ot_conversion(void **state)
{
    (void)state;
    ot_case(0.0f, 0, 0u);
    ot_case(0.8472979f, Q_HIT, OCC_IO_WARN_QUANTIZED);
    ot_case(-2.0f, -2 * SCALE, 0u);
#if OCC_VALUE_BITS == 8
    ot_case(3.5f, 126, 0u);
    ot_case(10.0f, 127, OCC_IO_WARN_CLAMPED);  /* saturated to the 8-bit range */
    ot_case(-10.0f, -127, OCC_IO_WARN_CLAMPED);
    ot_case(-1.0e30f, -127, OCC_IO_WARN_CLAMPED);
#else
    ot_case(10.0f, 10 * SCALE, 0u);
    ot_case(40.0f, 32767, OCC_IO_WARN_CLAMPED);
    ot_case(-40.0f, -32767, OCC_IO_WARN_CLAMPED);
#endif
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_scale_and_sizes, setup),
        cmocka_unit_test_setup(test_conversion_saturates, setup),
        cmocka_unit_test_setup(test_hit_miss_sequences, setup),
        cmocka_unit_test_setup(test_clamps, setup),
        cmocka_unit_test_setup(test_saturation, setup),
        cmocka_unit_test_setup(test_threshold, setup),
        cmocka_unit_test_setup(test_snapshot_kind, setup),
        cmocka_unit_test_setup(test_ot_conversion, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
