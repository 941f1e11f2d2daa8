// SPDX-License-Identifier: BSD-3-Clause
/* test_integrate_chunks.c - occ_map_insert_cloud() in bounded scratch (issue 22). The scan's voxel
 * set (32^3-voxel chunks, vset.c) is traced once and read back in pieces when its codes do not fit
 * one batch; when the set itself does not fit, SIMPLE and DISCRETE run in Morton-range windows.
 * Every result must equal the one-shot batch voxel for voxel (and OctoMap), at scratch sizes from
 * the documented minimum of the windows, over the set's exact threshold (occ_integrate.h), up to
 * scan.dat at 0.05 m in 8 MiB; below the minimum OCC_ERR_SCRATCH and a pool too small
 * OCC_ERR_NOMEM, both with the map unchanged. The set's reader and its block count are checked
 * against a reference merge and occi_coarse_need() on random sets. Real data: OctoMap's scan.dat.
 * Which way a call ran is read from the test build's probe (occi_insert_probe). */
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
#include "integrate/integrate_internal.h"
#include "integrate/coarse_internal.h"
#include "support/oracle_rays.h"
#include "support/integrate_fixture.h"

#define ARENA_BYTES ((size_t)160 << 20)
#define SCRATCH_BYTES ((size_t)96 << 20)
/* Every 3rd point at 0.1 m for the sizes that take a few windows or many pieces; every 160th at
 * 0.2 m for the windows' minimum (hundreds of windows, each a traversal of the scan). */
#define RES 0.1f
#define EVERY 3u
#define RES_MIN 0.2f
#define EVERY_MIN 160u

static uint8_t *arena_a, *arena_b, *scratch;

/* The windows' documented minimum (occ_integrate.h): the fixed term, DISCRETE's end voxels, and
 * 16 bytes per code for the longest ray's bound plus one (DISCRETE: at least n_points codes). */
static size_t min_scratch(const occ_map_t *m, const it_cloud_t *c, const occ_insert_params_t *p)
{
    size_t worst = 0;
    for (size_t i = 0; i < c->n; i++) {
        const size_t b = occ_insert_scratch_bytes_scan(m, &c->origin, &c->p[i], 1u, p) -
                         OCC_INSERT_SCRATCH_FIXED_BYTES;
        worst = b > worst ? b : worst; /* 8 + 16 * (keys + 1) */
    }
    const size_t codes = (worst - 8u) / 16u + 1u; /* keys of the ray + its hit + one */
    if (p->method == OCC_INSERT_DISCRETE) {
        return OCC_INSERT_SCRATCH_FIXED_BYTES + 8u * c->n + 16u * (codes > c->n ? codes : c->n);
    }
    return OCC_INSERT_SCRATCH_FIXED_BYTES + 16u * codes;
}

static int cmp_code(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a, y = *(const occ_code_t *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* By voxel (the hit bit last), so a voxel's entries are neighbours. */
static int cmp_voxel(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a, y = *(const occ_code_t *)b;
    const occ_code_t vx = x & ~OCC_CODE_HIT_BIT, vy = y & ~OCC_CODE_HIT_BIT;
    return vx != vy ? (vx < vy ? -1 : 1) : cmp_code(a, b);
}

/* The 32^3-voxel chunks the scan's rays traverse (DISCRETE: to the end voxels' centres), by the
 * library's own DDA: what the voxel set takes. */
static size_t ray_chunks(const occ_map_t *m, const it_cloud_t *c, const bool discrete)
{
    occ_raygeo_t g;
    occi_raygeo_init(&g, m);
    const float o[3] = {c->origin.x, c->origin.y, c->origin.z};
    uint32_t ko[3];
    assert_true(occi_raygeo_key(&g, o, ko));
    size_t n = 0, cap = 1u << 16, ray_cap = 1u << 16;
    occ_code_t *chunks = malloc(cap * sizeof *chunks), *ray = malloc(ray_cap * sizeof *ray);
    assert_non_null(chunks);
    assert_non_null(ray);
    for (size_t i = 0; i < c->n; i++) {
        float e[3] = {c->p[i].x, c->p[i].y, c->p[i].z};
        uint32_t ke[3];
        assert_true(occi_raygeo_key(&g, e, ke));
        if (discrete) {
            for (unsigned a = 0; a < 3u; a++) {
                e[a] = occi_raygeo_center(&g, ke[a]);
            }
        }
        const size_t k = occi_dda_codes(&g, o, e, ko, ke, ray, ray_cap);
        assert_true(k <= ray_cap);
        for (size_t j = 0; j < k; j++) {
            if (n > 0u && chunks[n - 1u] == ray[j] >> 15) {
                continue; /* consecutive keys of a ray share their chunk */
            }
            if (n == cap) {
                cap *= 2u;
                chunks = realloc(chunks, cap * sizeof *chunks);
                assert_non_null(chunks);
            }
            chunks[n++] = ray[j] >> 15;
        }
    }
    qsort(chunks, n, sizeof *chunks, cmp_code);
    size_t u = 0;
    for (size_t i = 0; i < n; i++) {
        u += i == 0u || chunks[i] != chunks[i - 1u];
    }
    free(chunks);
    free(ray);
    return u;
}

/* The least scratch with which the voxel set holds the whole scan (occ_integrate.h, "one
 * trace"): the fixed term, DISCRETE's end voxels, the hits and the room at x->b, and
 * OCC_VSET_CHUNK_BYTES per chunk. */
static size_t set_min(const it_cloud_t *c, const size_t chunks, const bool discrete)
{
    const size_t hits = c->n + 1u, work = hits > 1024u ? hits : 1024u;
    return OCC_INSERT_SCRATCH_FIXED_BYTES + (discrete ? 8u * c->n : 0u) + 8u * (hits + work) +
           chunks * OCC_VSET_CHUNK_BYTES;
}

typedef enum {
    WAY_ONE_SHOT,
    WAY_SORTED_ONE_SHOT,
    WAY_PIECES,
    WAY_SET,
    WAY_WINDOWS,
    WAY_BRICKS,
    WAY_ANY
} way_t;

/* How the last insert ran: one trace into the voxel set and one batch, one trace as sorted
 * codes and one batch, one trace into the set and several batches (or any number), more
 * traces as sorted codes (windows, after a set that ran full or without one), or one trace
 * into the set applied by bricks (no batch of codes). */
static void assert_way(const way_t way)
{
    const occi_insert_probe_t p = occi_insert_probe;
    if (way == WAY_ONE_SHOT) {
        assert_true(p.traces == 1u && p.set_traces == 1u && p.pieces == 1u);
    } else if (way == WAY_SORTED_ONE_SHOT) {
        assert_true(p.traces == 1u && p.set_traces == 0u && p.pieces == 1u);
    } else if (way == WAY_PIECES) {
        assert_true(p.traces == 1u && p.set_traces == 1u && p.pieces > 1u);
    } else if (way == WAY_SET) {
        assert_true(p.traces == 1u && p.set_traces == 1u && p.pieces >= 1u);
    } else if (way == WAY_WINDOWS) {
        assert_true(p.traces > 1u && p.set_traces <= 1u);
    } else if (way == WAY_BRICKS) {
        assert_true(p.traces == 1u && p.set_traces == 1u && p.pieces == 0u && p.bricks == 1u);
    }
    if (way != WAY_BRICKS && way != WAY_ANY) {
        assert_int_equal(p.bricks, 0);
    }
}

/* Scratch, the way expected, and whether bricks may be taken (else the set goes the way of
 * the codes: occi_insert_bricks_off). */
typedef struct {
    size_t bytes;
    way_t way;
    bool bricks;
} size_case_t;

/* The scan into a cleared map with `bytes` of scratch: the result, the one-shot map's and
 * OctoMap's, voxel for voxel. */
static void check_size(occ_map_t *m, const occ_map_t *ref, void *oracle, const it_cloud_t *c,
                       const occ_insert_params_t *p, const occ_insert_result_t *r0,
                       const size_case_t sc)
{
    occ_insert_result_t r;
    occ_map_clear(m);
    occi_insert_bricks_off = !sc.bricks;
    const occ_err_t e = occ_map_insert_cloud(m, &c->origin, c->p, c->n, p, scratch, sc.bytes, &r);
    occi_insert_bricks_off = false;
    assert_int_equal(e, OCC_OK);
    printf("  method %d scratch %zu (one-shot used %zu): %zu voxels, %u traces (%u into the set), "
           "%u batches, %u by bricks\n",
           (int)p->method, sc.bytes, r0->scratch_used, r.voxels_updated, occi_insert_probe.traces,
           occi_insert_probe.set_traces, occi_insert_probe.pieces, occi_insert_probe.bricks);
    assert_way(sc.way);
    assert_true(r.scratch_used <= sc.bytes);
    assert_int_equal(r.voxels_updated, r0->voxels_updated);
    assert_int_equal(r.voxels_occupied, r0->voxels_occupied);
    assert_int_equal(r.voxels_free, r0->voxels_free);
    assert_int_equal(r.voxels_changed, r0->voxels_changed);
    assert_int_equal(r.voxel_visits, r0->voxel_visits);
    assert_int_equal(r.points_integrated, r0->points_integrated);
    assert_int_equal(it_diff_maps(ref, m), 0);
    assert_int_equal(it_diff_maps(m, ref), 0);
    assert_int_equal(it_diff_oracle(m, oracle, 0.002f), 0);
    assert_true(occ_map_check(m) == OCC_OK);
}

/* Below the windows' minimum: OCC_ERR_SCRATCH, map unchanged (it holds the last scan). */
static void check_below_min(occ_map_t *m, const it_cloud_t *c, const occ_insert_params_t *p,
                            const size_t lo)
{
    occ_insert_result_t r;
    size_t nodes0, nodes1;
    const uint64_t d0 = it_map_digest(m, &nodes0);
    const uint32_t oom0 = m->oom_count;
    assert_int_equal(occ_map_insert_cloud(m, &c->origin, c->p, c->n, p, scratch, lo - 40u, &r),
                     OCC_ERR_SCRATCH);
    assert_int_equal(it_map_digest(m, &nodes1), d0);
    assert_int_equal(nodes0, nodes1);
    assert_int_equal(m->oom_count, oom0);
}

/* The scan (every `every`-th point) at `res` with `method`: the one-shot map in ref with its
 * result r0, OctoMap's tree for the same scan (ref checked equal to it), m initialised empty. */
typedef struct {
    it_cloud_t c;
    occ_map_t ref, m;
    occ_insert_params_t p;
    occ_insert_result_t r0;
    void *oracle;
} fixture_t;

static bool fixture_begin(fixture_t *f, const occ_insert_method_t method, const float res,
                          const size_t every)
{
    if (!it_load_scan(&f->c, every)) {
        return false;
    }
    it_init_map(&f->ref, arena_a, ARENA_BYTES, res);
    it_init_map(&f->m, arena_b, ARENA_BYTES, res);
    f->p = occ_insert_params_default();
    f->p.method = method;
    assert_int_equal(occ_map_insert_cloud(&f->ref, &f->c.origin, f->c.p, f->c.n, &f->p, scratch,
                                          SCRATCH_BYTES, &f->r0),
                     OCC_OK);
    assert_way(WAY_BRICKS);
    f->oracle = oracle_ins_new((double)res);
    const float o[3] = {f->c.origin.x, f->c.origin.y, f->c.origin.z};
    oracle_ins_cloud(f->oracle, (const float *)(const void *)f->c.p, f->c.n, o, -1.0,
                     method == OCC_INSERT_DISCRETE);
    assert_int_equal(it_diff_oracle(&f->ref, f->oracle, 0.002f), 0);
    return true;
}

static void fixture_end(fixture_t *f)
{
    oracle_ins_delete(f->oracle);
    free(f->c.p);
}

static void check_method(const occ_insert_method_t method, const float res, const size_t every,
                         const bool at_min)
{
    static fixture_t f;
    if (!fixture_begin(&f, method, res, every)) {
        skip();
    }
    const bool discrete = method == OCC_INSERT_DISCRETE;
    const size_t lo = min_scratch(&f.m, &f.c, &f.p);
    const size_t sm = set_min(&f.c, ray_chunks(&f.m, &f.c, discrete), discrete);
    /* The windows' minimum, the set's exact threshold and 8 bytes under it (one chunk short:
     * the set runs full, the scan goes to windows), the set with little and with much room. */
    const size_case_t cases[] = {{lo, WAY_WINDOWS, false},
                                 {lo + 4096u, WAY_WINDOWS, false},
                                 {sm - 8u, WAY_WINDOWS, false},
                                 {sm, WAY_PIECES, false},
                                 {sm + 65536u, WAY_PIECES, false},
                                 {f.r0.scratch_used / 3u, WAY_ANY, false}};
    for (size_t i = at_min ? 0u : 2u; i < (at_min ? 2u : 6u); i++) {
        size_case_t sc = cases[i];
        sc.bytes = sc.bytes > lo ? sc.bytes : lo;
        check_size(&f.m, &f.ref, f.oracle, &f.c, &f.p, &f.r0, sc);
    }
    check_below_min(&f.m, &f.c, &f.p, lo);
    fixture_end(&f);
}

static void test_simple_chunks(void **state)
{
    (void)state;
    check_method(OCC_INSERT_SIMPLE, RES, EVERY, false);
}

static void test_discrete_chunks(void **state)
{
    (void)state;
    check_method(OCC_INSERT_DISCRETE, RES, EVERY, false);
}

static void test_simple_min(void **state)
{
    (void)state;
    check_method(OCC_INSERT_SIMPLE, RES_MIN, EVERY_MIN, true);
}

static void test_discrete_min(void **state)
{
    (void)state;
    check_method(OCC_INSERT_DISCRETE, RES_MIN, EVERY_MIN, true);
}

/* Issue 22's case: all of scan.dat at 0.05 m in 8 MiB of scratch - one trace, applied in
 * pieces of codes (one batch of codes would take the set and 8 bytes a voxel, ~35 MB) and by
 * bricks (no codes: the set alone, ~4.2 MB), equal to the one-shot map and to OctoMap's.
 * SIMPLE here (DISCRETE in pieces above at 0.1 m; make bench-scratch compares both at
 * 0.05 m). */
static void check_8mib(const occ_insert_method_t method)
{
    static fixture_t f;
    if (!fixture_begin(&f, method, 0.05f, 1u)) {
        skip();
    }
    assert_true(8u * f.r0.voxels_updated > ((size_t)8 << 20));
    const size_case_t sc = {(size_t)8 << 20, WAY_PIECES, false};
    check_size(&f.m, &f.ref, f.oracle, &f.c, &f.p, &f.r0, sc);
    const size_case_t sb = {(size_t)8 << 20, WAY_BRICKS, true};
    check_size(&f.m, &f.ref, f.oracle, &f.c, &f.p, &f.r0, sb);
    fixture_end(&f);
}

/* The sorted path when it surely runs as one batch (16 bytes per code of the rays' bound after
 * the fixed term) and the set is not sure to fit (the chunks of its box do not): no trace is
 * risked on a set that could run full. 8 bytes less, the set is tried (and fits). 1/160 of
 * scan.dat at 0.05 m. */
static void test_sorted_when_one_batch(void **state)
{
    (void)state;
    static fixture_t f;
    if (!fixture_begin(&f, OCC_INSERT_SIMPLE, 0.05f, EVERY_MIN)) {
        skip();
    }
    /* occ_insert_scratch_bytes_scan(): the fixed term, 8 per point, 16 per code */
    const size_t one = occ_insert_scratch_bytes_scan(&f.m, &f.c.origin, f.c.p, f.c.n, &f.p) -
                       8u * f.c.n;
    const size_t sm = set_min(&f.c, ray_chunks(&f.m, &f.c, false), false);
    printf("  sorted codes in one batch from %zu, the set's threshold %zu\n", one, sm);
    assert_true(sm + 65536u < one);
    const size_case_t cases[] = {{one, WAY_SORTED_ONE_SHOT, false}, {one - 8u, WAY_SET, false},
                                 {sm + 65536u, WAY_PIECES, false}};
    for (size_t i = 0; i < 3u; i++) {
        check_size(&f.m, &f.ref, f.oracle, &f.c, &f.p, &f.r0, cases[i]);
    }
    fixture_end(&f);
}

static void test_simple_8mib(void **state)
{
    (void)state;
    check_8mib(OCC_INSERT_SIMPLE);
}

/* A pool that holds half the scan: the call refuses with OCC_ERR_NOMEM before its first write
 * (map unchanged, oom_count bumped), in windows and with the set in pieces. */
static void test_pool_full_unchanged(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, EVERY)) {
        skip();
    }
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, RES);
    occ_insert_params_t p = occ_insert_params_default();
    occ_insert_result_t r0, r;
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          &r0),
                     OCC_OK);
    occ_map_stats_t ps;
    occ_map_pool_stats(&m, &ps);
    const size_t half = ps.bytes_used / 2u;
    const size_t sm = set_min(&c, ray_chunks(&m, &c, false), false);
    occ_map_t small;
    it_init_map(&small, arena_b, half, RES);
    /* Something in the map first: the scan's first tenth. */
    assert_int_equal(occ_map_insert_cloud(&small, &c.origin, c.p, c.n / 10u, &p, scratch,
                                          SCRATCH_BYTES, &r),
                     OCC_OK);
    const size_case_t sizes[] = {{sm - 8u, WAY_WINDOWS, false}, {sm + 65536u, WAY_PIECES, false}};
    for (size_t i = 0; i < 2u; i++) {
        size_t n0, n1;
        const uint64_t d0 = it_map_digest(&small, &n0);
        const uint32_t oom0 = small.oom_count;
        assert_int_equal(occ_map_insert_cloud(&small, &c.origin, c.p, c.n, &p, scratch,
                                              sizes[i].bytes, &r),
                         OCC_ERR_NOMEM);
        assert_int_equal(occi_insert_probe.pieces, 0);
        if (sizes[i].way == WAY_PIECES) {
            assert_int_equal(occi_insert_probe.traces, 1);
        } else {
            assert_true(occi_insert_probe.traces > 1u);
        }
        assert_int_equal(it_map_digest(&small, &n1), d0);
        assert_int_equal(n0, n1);
        assert_int_equal(small.oom_count, oom0 + 1u);
        assert_true(occ_map_check(&small) == OCC_OK);
    }
    free(c.p);
}

/* ---- the voxel set alone: random voxels and hits -------------------------------------------- */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint32_t rnd(const uint32_t n)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)((rng_state >> 11) % n);
}

/* Clustered random voxels of a (span)^3 region at `base` per axis into the set (and the
 * reference list); returns how many were added (with repeats). */
static size_t fill_set(occ_vset_t *vs, const uint32_t base, const uint32_t span,
                       occ_code_t *ref, const size_t cap)
{
    size_t n = 0;
    for (unsigned walk = 0; walk < 24u && n < cap; walk++) {
        uint32_t k[3] = {rnd(span), rnd(span), rnd(span)};
        for (unsigned step = 0; step < 400u && n < cap; step++) {
            const unsigned a = rnd(3u);
            k[a] = rnd(2u) != 0u ? (k[a] + 1u) % span : (k[a] + span - 1u) % span;
            const occ_key_t key = {{base + k[0], base + k[1], base + k[2]}};
            uint64_t *const w = occi_vset_chunk(vs, key.k[0] >> 5, key.k[1] >> 5, key.k[2] >> 5);
            assert_non_null(w);
            const uint32_t local = (uint32_t)occi_spread5[key.k[0] & 31u] |
                                   ((uint32_t)occi_spread5[key.k[1] & 31u] << 1) |
                                   ((uint32_t)occi_spread5[key.k[2] & 31u] << 2);
            w[local >> 6] |= (uint64_t)1 << (local & 63u);
            ref[n++] = occ_morton_encode(key);
        }
    }
    return n;
}

/* Sorted, unique hits: some on the set's voxels, some elsewhere in the region. */
static size_t make_hits(const occ_code_t *set, const size_t n_set, const uint32_t base,
                        const uint32_t span, occ_code_t *hits, const size_t cap)
{
    size_t n = 0;
    for (; n < cap / 2u; n++) {
        hits[n] = set[rnd((uint32_t)n_set)];
    }
    for (; n < cap; n++) {
        const occ_key_t key = {{base + rnd(span), base + rnd(span), base + rnd(span)}};
        hits[n] = occ_morton_encode(key);
    }
    qsort(hits, n, sizeof *hits, cmp_code);
    size_t u = 0;
    for (size_t i = 0; i < n; i++) {
        if (u == 0u || hits[i] != hits[u - 1u]) {
            hits[u++] = hits[i];
        }
    }
    for (size_t i = 0; i < u; i++) {
        hits[i] |= OCC_CODE_HIT_BIT;
    }
    return u;
}

/* The reference: the set's voxels and the hits, sorted, one entry per voxel, hit bit if a hit. */
static size_t reference(occ_code_t *set, const size_t n_set, const occ_code_t *hits,
                        const size_t n_hits, occ_code_t *out)
{
    memcpy(out, set, n_set * sizeof *out);
    memcpy(out + n_set, hits, n_hits * sizeof *out);
    qsort(out, n_set + n_hits, sizeof *out, cmp_voxel);
    size_t u = 0;
    for (size_t i = 0; i < n_set + n_hits; i++) {
        const occ_code_t c = out[i];
        if (u > 0u && (out[u - 1u] & ~OCC_CODE_HIT_BIT) == (c & ~OCC_CODE_HIT_BIT)) {
            out[u - 1u] |= c;
        } else {
            out[u++] = c;
        }
    }
    return u;
}

/* Read the set in pieces of at most cap (occi_dense_read): the concatenation is the reference,
 * pieces end at brick borders, and occi_dense_need() is occi_coarse_need() summed over the
 * pieces. */
static void check_pieces(const occ_vset_t *vs, const occ_code_t *hits, const size_t n_hits,
                         const occ_code_t *want, const size_t n_want, const size_t cap,
                         const unsigned depth)
{
    occ_code_t *const piece = malloc(cap * sizeof *piece);
    assert_non_null(piece);
    occi_dense_t d;
    occi_vset_dense(vs, hits, n_hits, &d);
    occi_dense_cursor_t cur = {0u, 0u, 0u};
    size_t got = 0, m;
    uint64_t in = 0, lf = 0;
    occ_code_t last = 0;
    while ((m = occi_dense_read(&d, &cur, piece, cap)) > 0u) {
        assert_true(m <= cap);
        assert_true(got + m <= n_want);
        assert_memory_equal(piece, want + got, m * sizeof *piece);
        if (got > 0u) {
            assert_true((last & ~OCC_CODE_HIT_BIT) >> 6 != (piece[0] & ~OCC_CODE_HIT_BIT) >> 6);
        }
        last = piece[m - 1u];
        got += m;
        uint64_t pi, pl;
        occi_coarse_need(piece, m, 0, depth, &pi, &pl);
        in += pi;
        lf += pl;
    }
    assert_int_equal(got, n_want);
    uint64_t vi, vl;
    size_t voxels;
    occi_dense_need(&d, cap, depth, &vi, &vl, &voxels);
    assert_int_equal(vi, in);
    assert_int_equal(vl, lf);
    assert_int_equal(voxels, n_want);
    free(piece);
}

static void check_vset(const unsigned depth)
{
    const uint32_t span = depth >= 7u ? 100u : (uint32_t)1 << depth;
    const uint32_t base = depth >= 7u ? ((uint32_t)1 << (depth - 1u)) - 37u : 0u;
    const size_t bytes = 256u * OCC_VSET_CHUNK_BYTES + 7u, max_set = 9600u, max_hits = 600u;
    uint64_t *const mem = malloc(bytes);
    occ_code_t *const set = malloc(max_set * sizeof *set);
    occ_code_t *const hits = malloc(max_hits * sizeof *hits);
    occ_code_t *const want = malloc((max_set + max_hits) * sizeof *want);
    uint32_t *const hist = malloc(OCC_KS_HIST_WORDS * sizeof *hist);
    assert_true(mem != NULL && set != NULL && hits != NULL && want != NULL && hist != NULL);
    occ_vset_t vs;
    assert_true(occi_vset_init(&vs, (uint8_t *)mem, bytes, SIZE_MAX, depth));
    assert_int_equal(vs.cap, 256);
    const size_t n_set = fill_set(&vs, base, span, set, max_set);
    const size_t n_hits = make_hits(set, n_set, base, span, hits, max_hits);
    const size_t n_want = reference(set, n_set, hits, n_hits, want);
    occi_vset_sort(&vs, hist);
    printf("  depth %u: %zu chunks, %zu voxels, %zu hits, %zu codes\n", depth, vs.n,
           occi_vset_count(&vs), n_hits, n_want);
    const size_t caps[] = {64u, 65u, 127u, 1000u, n_want, n_want + 1u};
    for (size_t i = 0; i < sizeof caps / sizeof caps[0]; i++) {
        check_pieces(&vs, hits, n_hits, want, n_want, caps[i], depth);
    }
    /* The map's edge (chunk coordinates at or past 2^depth / 32) and a full set give NULL. */
    const uint32_t cmax = depth >= 5u ? (uint32_t)1 << (depth - 5u) : 1u;
    assert_null(occi_vset_chunk(&vs, cmax, 0, 0));
    assert_null(occi_vset_chunk(&vs, 0, UINT32_MAX, 0));
    if (depth >= 12u) { /* fill the set with chunks far from the voxels' */
        const uint32_t first = cmax - 1u - (uint32_t)vs.n;
        while (vs.n < vs.cap) {
            assert_non_null(occi_vset_chunk(&vs, cmax - 1u - (uint32_t)vs.n, cmax - 1u, 0));
        }
        assert_null(occi_vset_chunk(&vs, 0, 0, cmax - 1u));
        assert_non_null(occi_vset_chunk(&vs, first, cmax - 1u, 0)); /* taken: still found */
    }
    free(mem);
    free(set);
    free(hits);
    free(want);
    free(hist);
}

/* One insert into a fresh map: its error, result and map digest. */
typedef struct {
    occ_err_t e;
    occ_insert_result_t r;
    uint64_t digest;
    size_t nodes;
} lanes_run_t;

static lanes_run_t lanes_run(const it_cloud_t *c, const float res, const occ_insert_method_t meth,
                             const size_t bytes, const bool lanes_off)
{
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, res);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = meth;
    lanes_run_t out;
    memset(&out, 0, sizeof out);
    occi_insert_lanes_off = lanes_off;
    out.e = occ_map_insert_cloud(&m, &c->origin, c->p, c->n, &p, scratch, bytes, &out.r);
    occi_insert_lanes_off = false;
    out.digest = it_map_digest(&m, &out.nodes);
    return out;
}

/* The 8-lane walk (raycast_lanes.c, where the CPU has AVX-512) against the scalar walk on the
 * same scans: the same error, every counter (visits, rays, scratch used: the set's chunks),
 * the same map; with all the scratch, and with so little that the voxel set runs full (its
 * overflow, then the sorted path or windows). Where the lanes cannot run (no AVX-512, the
 * i386 build) there is nothing to compare: it says so and returns. */
static void test_lanes_equal_scalar(void **state)
{
    (void)state;
#if OCC_MARK_LANES
    if (!occi_mwalk_lanes_ok(16u)) {
        printf("  no AVX-512 on this CPU: every walk is the scalar one, nothing to compare\n");
        return;
    }
#else
    printf("  the 8-lane walk is not built here: nothing to compare\n");
    return;
#endif
    it_cloud_t scan, tum;
    if (!it_load_scan(&scan, 7) || !it_load_tum(&tum, 4u, 3u)) {
        skip();
    }
    const occ_insert_method_t meths[3] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                          OCC_INSERT_SUPER_RAYS};
    const it_cloud_t *const clouds[2] = {&scan, &tum};
    const float res[2] = {0.05f, 0.1f};
    for (unsigned k = 0; k < 12u; k++) { /* cloud, method, resolution */
        const it_cloud_t *const c = clouds[k / 6u];
        const occ_insert_method_t meth = meths[(k / 2u) % 3u];
        const float r = res[k % 2u];
        const lanes_run_t full = lanes_run(c, r, meth, SCRATCH_BYTES, true);
        assert_int_equal(full.e, OCC_OK);
        /* so little that the set cannot hold the scan's chunks */
        const size_t sizes[2] = {SCRATCH_BYTES, full.r.scratch_used / 2u};
        for (unsigned si = 0; si < 2u; si++) {
            const lanes_run_t a = lanes_run(c, r, meth, sizes[si], false);
            const lanes_run_t b = lanes_run(c, r, meth, sizes[si], true);
            printf("  %s %.2f m method %d scratch %zu: %s, %zu visits, %zu rays, %zu bytes used, "
                   "%zu nodes\n",
                   k < 6u ? "scan.dat" : "tum", (double)r, (int)meth, sizes[si], occ_err_str(a.e),
                   a.r.voxel_visits, a.r.rays_cast, a.r.scratch_used, a.nodes);
            assert_int_equal(a.e, b.e);
            assert_memory_equal(&a.r, &b.r, sizeof a.r);
            assert_true(a.digest == b.digest);
            assert_int_equal(a.nodes, b.nodes);
        }
    }
    free(scan.p);
    free(tum.p);
}

static void test_vset_dense_read_need(void **state)
{
    (void)state;
    check_vset(16u);
    check_vset(21u);
    check_vset(5u);
    check_vset(3u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vset_dense_read_need),
        cmocka_unit_test_setup_teardown(test_simple_chunks, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_discrete_chunks, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_simple_min, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_discrete_min, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_sorted_when_one_batch, it_timer_setup,
                                        it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_simple_8mib, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_pool_full_unchanged, it_timer_setup,
                                        it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_lanes_equal_scalar, it_timer_setup,
                                        it_timer_teardown),
    };
    const it_buffers_t b = {&arena_a, &arena_b, &scratch, ARENA_BYTES, SCRATCH_BYTES};
    return it_run_tests("test_integrate_chunks", tests, sizeof tests / sizeof tests[0], b);
}
