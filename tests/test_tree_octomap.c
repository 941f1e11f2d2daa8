/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_tree_octomap.c - occmap against OctoMap itself (Debian's liboctomap through
 * tests/support/oracle_tree.cpp): the same voxel updates (OcTree::updateNode(key, occupied),
 * OctoMap's sensor model, resolution (double)cfg.resolution_m) go into an octomap::OcTree and
 * into occmap; then every leaf (level, state, log-odds within the fixed-point bound), the node
 * count after pruning (OcTree::size() vs stats.nodes) and the leaf iterator's occupied/free
 * counts must agree, in both directions. Inputs: random sequences and the endpoints of OctoMap's
 * real scan.dat. Also coordinate -> key against coordToKeyChecked.
 *
 * Tolerance: occmap stores round(x * 1024) and adds quantized hit/miss, so after k updates a
 * voxel differs from OctoMap's float by at most k * 0.5/1024 plus 0.5/1024 for the clamp bound
 * (value.c, occmap.h). With OCC_VALUE_FLOAT=1 the values must be bit-exact (tolerance 0). States may only differ where OctoMap's value is within that bound of the
 * threshold; the test counts such cases and requires them to be 0 on these inputs.
 * Random seed: printed, overridable with OCC_SEED.
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
#include <time.h>
#include <sys/stat.h>

#include "occmap/occmap.h"
#include "occmap/host/occ_scan.h"
#include "support/oracle_tree.h"
#include "support/leak_check.h"

#define STEP_ERR (0.5f / (float)OCC_FIXED_ONE)
#define SCAN_BZ2 "/usr/share/doc/liboctomap-dev/examples/data/scan.dat.bz2"

static unsigned seed;
static uint8_t *arena;
static size_t arena_bytes;
static occ_map_t map;
static oracle_tree_t *oracle;

/* OCC_TEST_QUICK=1 (the compile-time variant builds in tests/foundation.mk): less work. */
static bool quick(void)
{
    const char *const q = getenv("OCC_TEST_QUICK");
    return q != NULL && q[0] == '1';
}

static int setup_all(void **state)
{
    (void)state;
    const char *const env = getenv("OCC_SEED");
    seed = env != NULL ? (unsigned)strtoul(env, NULL, 0) : (unsigned)time(NULL);
    printf("test_tree_octomap: seed %u (set OCC_SEED to repeat)\n", seed);
    srand(seed);
    arena_bytes = (size_t)64 << 20;
    arena = malloc(arena_bytes);
    return arena != NULL ? 0 : -1;
}

static int teardown_all(void **state)
{
    (void)state;
    free(arena);
    return 0;
}

static int teardown_maps(void **state)
{
    (void)state;
    oracle_tree_free(oracle);
    oracle = NULL;
    return leak_check(&map);
}

static uint32_t urand(uint32_t n)
{
    return (uint32_t)(((uint32_t)rand() << 15) ^ (uint32_t)rand()) % n;
}

static occ_key_t mk(uint32_t x, uint32_t y, uint32_t z)
{
    occ_key_t k;
    k.k[0] = x;
    k.k[1] = y;
    k.k[2] = z;
    return k;
}

/* occmap configured with the oracle's exact sensor model (depth 16 = OctoMap's). */
static void init_pair(float res)
{
    oracle = oracle_tree_new((double)res);
    assert_non_null(oracle);
    occ_map_config_t cfg = occ_map_config_default();
    float thr;
    oracle_tree_params(oracle, &cfg.hit, &cfg.miss, &cfg.clamp_min, &cfg.clamp_max, &thr);
    cfg.free_max = thr;
    cfg.occupied_min = thr;
    cfg.resolution_m = res;
    cfg.depth_levels = 16u;
    assert_int_equal(occ_map_init(&map, &cfg, arena, arena_bytes), OCC_OK);
}

/* ---- comparison -------------------------------------------------------------------------------- */

typedef struct {
    float tol;
    uint64_t leaves, level_mismatch, value_mismatch, state_mismatch, state_near_threshold;
    float max_err;
    float thr;
    bool counts; /* structure must match (complete patterns) */
} cmp_t;

static void on_oracle_leaf(void *ctx, const uint32_t key[3], unsigned level, float logodds,
                           bool occupied)
{
    cmp_t *const c = ctx;
    c->leaves++;
    occ_node_info_t info;
    if (occ_map_read_key(&map, mk(key[0], key[1], key[2]), level, &info) != OCC_OK || !info.observed) {
        if (c->level_mismatch++ < 5u) {
            fprintf(stderr, "oracle leaf (%u,%u,%u) level %u: occmap has nothing observed\n",
                    (unsigned)key[0], (unsigned)key[1], (unsigned)key[2], level);
        }
        return;
    }
    if (info.level != level || (info.flags & OCC_NODE_UNIFORM) == 0u) {
        if (c->level_mismatch++ < 5u && c->counts) {
            fprintf(stderr, "oracle leaf (%u,%u,%u) level %u: occmap answers at level %u flags 0x%x\n",
                    (unsigned)key[0], (unsigned)key[1], (unsigned)key[2], level,
                    (unsigned)info.level, (unsigned)info.flags);
        }
    }
    const float err = fabsf(info.logodds - logodds);
    c->max_err = err > c->max_err ? err : c->max_err;
    if (err > c->tol) {
        if (c->value_mismatch++ < 5u) {
            fprintf(stderr, "leaf (%u,%u,%u) level %u: occmap %.6f OctoMap %.6f (tol %.6f)\n",
                    (unsigned)key[0], (unsigned)key[1], (unsigned)key[2], level,
                    (double)info.logodds, (double)logodds, (double)c->tol);
        }
    }
    const bool occ = info.state == OCC_STATE_OCCUPIED;
    if (occ != occupied || info.state == OCC_STATE_UNKNOWN) {
        if (fabsf(logodds - c->thr) <= c->tol) {
            c->state_near_threshold++;
        } else if (c->state_mismatch++ < 5u) {
            fprintf(stderr, "leaf (%u,%u,%u): occmap state %d, OctoMap occupied %d (%.6f)\n",
                    (unsigned)key[0], (unsigned)key[1], (unsigned)key[2], (int)info.state,
                    (int)occupied, (double)logodds);
        }
    }
}

/* Every leaf both ways, node and leaf counts. `tol` bounds the log-odds difference. */
static void compare_trees(float tol, bool counts, const char *what)
{
    cmp_t c;
    memset(&c, 0, sizeof c);
#if OCC_VALUE_FLOAT
    tol = 0.0f;    /* float values do OctoMap's arithmetic: bit-exact ... */
    counts = true; /* ... so the trees are the same at every moment */
#endif
    c.tol = tol;
    c.counts = counts;
    float h, m, lo, hi;
    oracle_tree_params(oracle, &h, &m, &lo, &hi, &c.thr);
    const size_t n = oracle_tree_for_each_leaf(oracle, on_oracle_leaf, &c);
    /* occmap's leaves must be OctoMap's leaves. */
    occ_walk_t w;
    occ_walk_node_t node;
    uint64_t occ_leaves = 0, missing = 0;
    occ_walk_begin(&w, &map);
    while (occ_walk_next(&w, &node)) {
        if (node.has_children) {
            continue;
        }
        occ_leaves++;
        unsigned found;
        float lv;
        bool kids;
        if (!oracle_tree_search(oracle, node.key.k, node.level, &found, &lv, &kids) ||
            found != node.level || kids) {
            if (missing++ < 5u && counts) {
                fprintf(stderr, "occmap leaf (%u,%u,%u) level %u is not an OctoMap leaf\n",
                        (unsigned)node.key.k[0], (unsigned)node.key.k[1], (unsigned)node.key.k[2],
                        (unsigned)node.level);
            }
        }
    }
    occ_map_stats_t st;
    occ_map_stats(&map, &st);
    uint64_t o_occ, o_free;
    oracle_tree_leaf_counts(oracle, &o_occ, &o_free);
    printf("%s: %zu OctoMap leaves, %llu occmap leaves; nodes %zu / %llu; occupied %llu / %llu, "
           "free %llu / %llu; max |dlogodds| %.6f (tol %.6f), %llu states at the threshold\n", what,
           n, (unsigned long long)occ_leaves, oracle_tree_size(oracle),
           (unsigned long long)st.nodes, (unsigned long long)o_occ,
           (unsigned long long)st.occupied_leaves, (unsigned long long)o_free,
           (unsigned long long)st.free_leaves, (double)c.max_err, (double)tol,
           (unsigned long long)c.state_near_threshold);
    assert_int_equal(c.value_mismatch, 0u);
    assert_int_equal(c.state_mismatch, 0u);
    /* A state may differ only for a voxel whose OctoMap value lies within the documented
     * fixed-point bound (tol) of the threshold: e.g. a voxel at clamp_min (-2.0000279 in float,
     * -2048/1024 in fixed point) plus a delta of exactly +2.0 reads 0.0 (occupied) here and
     * -0.0000279 (free) in OctoMap. The float build has tol 0 and must agree exactly. */
    assert_true(c.state_near_threshold == 0u || c.tol > 0.0f);
    assert_int_equal(occ_map_check(&map), OCC_OK);
    if (!counts) {
        return;
    }
    assert_int_equal(c.level_mismatch, 0u);
    assert_int_equal(missing, 0u);
    assert_int_equal(occ_leaves, n);
    assert_int_equal(oracle_tree_num_leaf_nodes(oracle), n);
    assert_int_equal(st.nodes, oracle_tree_size(oracle));
    assert_int_equal(st.leaf_nodes, n);
    const long long slack = (long long)c.state_near_threshold;
    assert_true(llabs((long long)st.occupied_leaves - (long long)o_occ) <= slack);
    assert_true(llabs((long long)st.free_leaves - (long long)o_free) <= slack);
    assert_int_equal(st.unknown_band_leaves, 0u);
}

/* ---- tests ---------------------------------------------------------------------------------- */

/* occ_map_config_default() is OctoMap's sensor model, to the fixed-point step. */
static void test_default_config_is_octomaps(void **state)
{
    (void)state;
    oracle = oracle_tree_new(0.1);
    assert_non_null(oracle);
    float h, m, lo, hi, thr;
    oracle_tree_params(oracle, &h, &m, &lo, &hi, &thr);
    const occ_map_config_t c = occ_map_config_default();
    printf("default hit %.6f miss %.6f clamp [%.6f, %.6f]; OctoMap hit %.6f miss %.6f clamp "
           "[%.6f, %.6f]\n", (double)c.hit, (double)c.miss, (double)c.clamp_min,
           (double)c.clamp_max, (double)h, (double)m, (double)lo, (double)hi);
    assert_true(fabsf(c.resolution_m - 0.1f) < 1e-9f);
    assert_int_equal(c.depth_levels, 16u);
    assert_true(fabsf(c.free_max - thr) <= STEP_ERR && fabsf(c.occupied_min - thr) <= STEP_ERR);
    /* Within half a fixed-point step of OctoMap's float numbers. */
    assert_true(fabsf(c.hit - h) <= STEP_ERR);
    assert_true(fabsf(c.miss - m) <= STEP_ERR);
    assert_true(fabsf(c.clamp_min - lo) <= STEP_ERR);
    assert_true(fabsf(c.clamp_max - hi) <= STEP_ERR);
}

/* With OCC_RAY_DOUBLE 0 (float key arithmetic, the firmware default) the header allows a key to
 * differ from OctoMap's only for points within ~1e-7 relative of a voxel border (or the volume's
 * edge). Returns true when p/res is that close to an integer. */
#if !OCC_RAY_DOUBLE
static bool near_border(float p, float res)
{
    const double q = (double)p / (double)res;
    const double d = fabs(q - floor(q + 0.5));
    return d <= 4e-7 * (fabs(q) > 1.0 ? fabs(q) : 1.0);
}
#endif

/* Keys: occ_map_key() equals coordToKeyChecked() for random, border and out-of-range points. */
static void test_keys_vs_octomap(void **state)
{
    (void)state;
    const float resolutions[] = {0.1f, 0.05f, 0.2f, 0.37f, 1.0f, 0.01f};
    uint64_t compared = 0, border_diffs = 0;
    for (size_t r = 0; r < sizeof resolutions / sizeof resolutions[0]; r++) {
        init_pair(resolutions[r]);
        const float res = resolutions[r];
        const float edge = res * 32768.0f;
        for (unsigned i = 0; i < (quick() ? 15000u : 60000u); i++) {
            float p[3];
            for (unsigned a = 0; a < 3u; a++) {
                switch (urand(6u)) {
                case 0: /* on a voxel border, maybe nudged by one ulp */
                    p[a] = (float)((int)urand(2000u) - 1000) * res;
                    if (urand(2u)) {
                        p[a] = nextafterf(p[a], urand(2u) ? INFINITY : -INFINITY);
                    }
                    break;
                case 1: /* near the volume's edges */
                    p[a] = (urand(2u) ? edge : -edge) + ((float)urand(2001u) - 1000.0f) * res * 0.01f;
                    break;
                case 2:
                    p[a] = urand(2u) ? nextafterf(edge, 0.0f) : -edge;
                    break;
                default:
                    p[a] = ((float)urand(2000001u) - 1000000.0f) * 1e-6f * edge * 1.1f;
                    break;
                }
            }
            const occ_vec3_t v = {p[0], p[1], p[2]};
            occ_key_t k;
            uint32_t ok[3];
            const occ_err_t e = occ_map_key(&map, v, &k);
            const bool inside = oracle_tree_coord_to_key(oracle, (double)p[0], (double)p[1],
                                                         (double)p[2], ok);
            if (inside != (e == OCC_OK) || (inside && memcmp(ok, k.k, sizeof ok) != 0)) {
#if !OCC_RAY_DOUBLE
                if (near_border(p[0], res) || near_border(p[1], res) || near_border(p[2], res)) {
                    border_diffs++;
                    continue;
                }
#endif
                fail_msg("res %g point (%.9g, %.9g, %.9g): occmap %d key (%u,%u,%u), OctoMap %d "
                         "key (%u,%u,%u)", (double)res, (double)p[0], (double)p[1], (double)p[2],
                         (int)e, (unsigned)k.k[0], (unsigned)k.k[1], (unsigned)k.k[2], (int)inside,
                         (unsigned)ok[0], (unsigned)ok[1], (unsigned)ok[2]);
            }
            if (e != OCC_OK) {
                assert_int_equal(e, OCC_ERR_RANGE);
            }
            compared++;
        }
        oracle_tree_free(oracle);
        oracle = NULL;
    }
    init_pair(0.1f);
    printf("keys (OCC_RAY_DOUBLE %d): %llu points agree with coordToKeyChecked, %llu differ "
           "within 4e-7 relative of a voxel border\n", (int)OCC_RAY_DOUBLE,
           (unsigned long long)compared, (unsigned long long)border_diffs);
#if OCC_RAY_DOUBLE
    assert_int_equal(border_diffs, 0u);
#endif
}

/* ---- random sequences ----------------------------------------------------------------------------- */

#define MAX_PAT 48u
#define MAX_LEN 14u
typedef struct {
    uint8_t len;
    bool hit[MAX_LEN];
    float f;          /* OctoMap's float result */
    occ_value_t q;    /* occmap's result */
} pattern_t;

/* OctoMap's update rule in float, and occmap's on quantized values. */
static float octo_step(float v, bool observed, float d, float lo, float hi)
{
    if (observed && ((d >= 0.0f && v >= hi) || (d <= 0.0f && v <= lo))) {
        return v;
    }
    v = (observed ? v : 0.0f) + d;
    return v < lo ? lo : (v > hi ? hi : v);
}

#if OCC_VALUE_FLOAT
typedef float acc_t;
#else
typedef int32_t acc_t;
#endif

static bool veq(occ_value_t a, occ_value_t b)
{
    return !(a < b) && !(b < a);
}

/* occmap's rule on raw values (int32 sum then clamp = saturating int16 within the clamps). */
static acc_t occ_step(acc_t v, bool observed, acc_t d, acc_t lo, acc_t hi)
{
    if (observed && ((d >= 0 && v >= hi) || (d <= 0 && v <= lo))) {
        return v;
    }
    v = (observed ? v : 0) + d;
    return v < lo ? lo : (v > hi ? hi : v);
}

/* Patterns whose results are equal in float exactly when they are equal in fixed point, so
 * OctoMap and occmap must prune the same sibling sets. */
static unsigned make_patterns(pattern_t *p, unsigned want)
{
    float h, m, lo, hi, thr;
    oracle_tree_params(oracle, &h, &m, &lo, &hi, &thr);
    unsigned n = 0, tries = 0;
    while (n < want && tries++ < 100000u) {
        pattern_t c;
        c.len = (uint8_t)(1u + urand(MAX_LEN));
        const unsigned bias = urand(5u);
        float f = 0.0f;
        acc_t q = 0;
        for (unsigned i = 0; i < c.len; i++) {
            c.hit[i] = urand(4u) < (bias < 2u ? 3u : (bias < 4u ? 1u : 2u));
            f = octo_step(f, i > 0u, c.hit[i] ? h : m, lo, hi);
            q = occ_step(q, i > 0u, c.hit[i] ? map.priv.q_hit : map.priv.q_miss, map.priv.q_clamp_min,
                         map.priv.q_clamp_max);
        }
        c.f = f;
        c.q = (occ_value_t)q;
        if (fabsf(f - thr) < 0.01f) {
            continue; /* keep states unambiguous */
        }
        bool consistent = true;
        for (unsigned j = 0; j < n && consistent; j++) {
            const bool feq = !(p[j].f < f) && !(p[j].f > f);
            consistent = feq == veq(p[j].q, c.q);
        }
        if (consistent) {
            p[n++] = c;
        }
    }
    return n;
}

static void run_random_sequence(unsigned edge_log2, uint32_t base, unsigned n_pat_want)
{
    static pattern_t pat[MAX_PAT];
    const unsigned n_pat = make_patterns(pat, n_pat_want);
    assert_true(n_pat >= 4u);
    const uint32_t edge = 1u << edge_log2;
    const uint32_t nvox = edge * edge * edge;
    int16_t *const which = malloc(nvox * sizeof *which); /* pattern per voxel, -1 = never */
    uint8_t *const step = calloc(nvox, 1u);
    uint32_t *const todo = malloc(nvox * sizeof *todo);
    assert_non_null(which);
    assert_non_null(step);
    assert_non_null(todo);
    for (uint32_t i = 0; i < nvox; i++) {
        which[i] = -1;
    }
    /* Regions of 1, 8, 64 or 512 voxels share a pattern, so siblings end equal and prune. */
    for (unsigned r = 0; r < nvox / 6u; r++) {
        const unsigned lv = urand(10u) < 5u ? 0u : (urand(3u) == 0u ? 2u : 1u);
        const uint32_t n = 1u << lv;
        const uint32_t x0 = urand(edge) & ~(n - 1u), y0 = urand(edge) & ~(n - 1u),
                       z0 = urand(edge) & ~(n - 1u);
        const int16_t pidx = urand(8u) == 0u ? (int16_t)-1 : (int16_t)urand(n_pat);
        for (uint32_t z = 0; z < n; z++) {
            for (uint32_t y = 0; y < n; y++) {
                for (uint32_t x = 0; x < n; x++) {
                    which[((z0 + z) * edge + y0 + y) * edge + x0 + x] = pidx;
                }
            }
        }
    }
    uint32_t n_todo = 0;
    uint64_t n_updates = 0;
    for (uint32_t i = 0; i < nvox; i++) {
        if (which[i] >= 0) {
            todo[n_todo++] = i;
        }
    }
    unsigned checkpoints = 0;
    while (n_todo > 0u) {
        /* A random voxel with steps left takes its next step (per-voxel order kept). */
        const uint32_t t = urand(n_todo);
        const uint32_t i = todo[t];
        const pattern_t *const p = &pat[which[i]];
        const bool hit = p->hit[step[i]];
        const uint32_t kx = base + i % edge, ky = base + (i / edge) % edge, kz = base + i / (edge * edge);
        oracle_tree_update_key(oracle, kx, ky, kz, hit);
        assert_int_equal(occ_map_observe_key(&map, mk(kx, ky, kz), hit), OCC_OK);
        n_updates++;
        if (++step[i] == p->len) {
            todo[t] = todo[--n_todo];
        }
        if (n_updates % 20000u == 0u) {
            compare_trees(STEP_ERR * (float)(MAX_LEN + 1u) + 1e-5f, false, "random (partial)");
            checkpoints++;
        }
    }
    char what[64];
    snprintf(what, sizeof what, "random %u^3 at %u, %u patterns, %llu updates", (unsigned)edge,
             (unsigned)base, n_pat, (unsigned long long)n_updates);
    compare_trees(STEP_ERR * (float)(MAX_LEN + 1u) + 1e-5f, true, what);
    /* Each voxel's final value is its pattern's, exactly in fixed point. */
    for (uint32_t i = 0; i < nvox; i++) {
        occ_node_info_t info;
        const occ_key_t k = mk(base + i % edge, base + (i / edge) % edge, base + i / (edge * edge));
        assert_int_equal(occ_map_read_key(&map, k, 0u, &info), OCC_OK);
        if (which[i] < 0) {
            assert_false(info.observed);
        } else {
            assert_true(info.observed);
            assert_true(veq(occ_value_from_logodds(info.logodds), pat[which[i]].q));
        }
    }
    free(which);
    free(step);
    free(todo);
}

static void test_random_sequences(void **state)
{
    (void)state;
    if (!quick()) {
        init_pair(0.1f);
        run_random_sequence(5u, 32768u - 16u, 24u);
        oracle_tree_free(oracle);
    }
    init_pair(0.05f);
    run_random_sequence(4u, 100u, 40u);
    oracle_tree_free(oracle);
    init_pair(0.2f);
    run_random_sequence(quick() ? 4u : 5u, 65536u - 32u, 8u);
}

/* Arbitrary log-odds deltas (OcTree::updateNode(key, float)), per-voxel only (no pruning claim). */
static void test_random_deltas(void **state)
{
    (void)state;
    init_pair(0.1f);
    const uint32_t base = 32768u - 8u;
    unsigned n = 0;
    static uint8_t count[16 * 16 * 16];
    memset(count, 0, sizeof count);
    for (unsigned i = 0; i < 40000u; i++) {
        const uint32_t x = urand(16u), y = urand(16u), z = urand(16u);
#if OCC_VALUE_BITS == 8
        const float d = (float)((int)urand(145u) - 72) / 36.0f; /* on the 8-bit grid */
#else
        const float d = (float)((int)urand(4001u) - 2000) / 1024.0f; /* exact in both */
#endif
        oracle_tree_update_key_logodds(oracle, base + x, base + y, base + z, d);
        assert_int_equal(occ_map_update_key(&map, mk(base + x, base + y, base + z), d), OCC_OK);
        count[(z * 16u + y) * 16u + x]++;
        n++;
    }
    /* Deltas are multiples of 1/1024: only the clamp bounds are rounded, so the error stays
     * below one clamp rounding no matter how many updates. */
    compare_trees(STEP_ERR + 1e-5f, false, "random deltas");
    assert_true(n == 40000u);
}

/* ---- the real scan ------------------------------------------------------------------------------ */

static const char *scan_path(void)
{
    static const char *const candidates[] = {"build/data/scan.dat", "build/data/foundation/scan.dat"};
    struct stat sb;
    for (size_t i = 0; i < 2u; i++) {
        if (stat(candidates[i], &sb) == 0 && sb.st_size > 1000000) {
            return candidates[i];
        }
    }
    if (stat(SCAN_BZ2, &sb) != 0) {
        return NULL;
    }
    if (system("mkdir -p build/data/foundation && bzcat " SCAN_BZ2
               " > build/data/foundation/scan.dat.tmp && mv build/data/foundation/scan.dat.tmp "
               "build/data/foundation/scan.dat") != 0) {
        return NULL;
    }
    return candidates[1];
}

static void scan_at(float res)
{
    const char *const path = scan_path();
    if (path == NULL) {
        printf("SKIP: %s not found (install liboctomap-dev)\n", SCAN_BZ2);
        skip();
    }
    occ_vec3_t *pts = NULL;
    size_t n = 0;
    char msg[256] = "";
    assert_int_equal(occ_scan_read_xyz(path, &pts, &n, msg, sizeof msg), OCC_OK);
    assert_int_equal(n, 88206u);
    init_pair(res);
    size_t outside = 0;
    for (size_t i = 0; i < n; i++) {
        occ_key_t k;
        uint32_t ok[3];
        const occ_err_t e = occ_map_key(&map, pts[i], &k);
        const bool in = oracle_tree_coord_to_key(oracle, (double)pts[i].x, (double)pts[i].y,
                                                 (double)pts[i].z, ok);
        if (!in) {
            assert_int_equal(e, OCC_ERR_RANGE);
            outside++;
            continue;
        }
        if (e != OCC_OK || memcmp(ok, k.k, sizeof ok) != 0) {
#if !OCC_RAY_DOUBLE
            /* Float key arithmetic: allowed next to a border; use OctoMap's key for both. */
            assert_true(near_border(pts[i].x, res) || near_border(pts[i].y, res) ||
                        near_border(pts[i].z, res));
            memcpy(k.k, ok, sizeof ok);
#else
            fail_msg("scan point %zu: occmap key differs from OctoMap's", i);
#endif
        }
        oracle_tree_update_key(oracle, ok[0], ok[1], ok[2], true);
        assert_int_equal(occ_map_observe_key(&map, k, true), OCC_OK);
    }
    free(pts);
    assert_int_equal(outside, 0u);
    char what[64];
    snprintf(what, sizeof what, "scan.dat endpoints at %.2f m", (double)res);
    /* Only hits: at most 5 distinct steps before the clamp. */
    compare_trees(STEP_ERR * 6.0f + 1e-5f, true, what);
}

static void test_scan_endpoints_010(void **state)
{
    (void)state;
    scan_at(0.1f);
}

static void test_scan_endpoints_005(void **state)
{
    (void)state;
    scan_at(0.05f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(test_default_config_is_octomaps, teardown_maps),
        cmocka_unit_test_teardown(test_keys_vs_octomap, teardown_maps),
        cmocka_unit_test_teardown(test_random_sequences, teardown_maps),
        cmocka_unit_test_teardown(test_random_deltas, teardown_maps),
        cmocka_unit_test_teardown(test_scan_endpoints_010, teardown_maps),
        cmocka_unit_test_teardown(test_scan_endpoints_005, teardown_maps),
    };
    if (quick()) {
        /* The variant builds run the 0.1 m scan only (the 0.05 m one runs in the main test
         * binary): left out, not skipped (a skip is counted, and fails CI). */
        cmocka_set_skip_filter("test_scan_endpoints_005");
    }
    return cmocka_run_group_tests_name("tree_octomap", tests, setup_all, teardown_all);
}
