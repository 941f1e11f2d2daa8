/* SPDX-License-Identifier: BSD-3-Clause */
/* test_integrate_limits.c - occ_map_insert_cloud() at its limits: bad points, a full arena
 * (nothing changes), the scratch bound (formula, compile-time macro, 32-bit size_t, what a call
 * writes) and automatic eviction before OCC_ERR_NOMEM. */
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

#include "occmap/occmap.h"
#include "occmap/host/occ_scan.h"
#include "occmap/occ_evict.h"
#include "integrate/coarse_internal.h"
#include "support/oracle_rays.h"
#include "support/integrate_fixture.h"
#include "support/leak_check.h"

#define ARENA_BYTES ((size_t)96 << 20)
#define SCRATCH_BYTES ((size_t)192 << 20)

static uint8_t *arena_a, *arena_b, *scratch;

static void test_bad_points(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 97)) {
        skip();
    }
    const size_t good = c.n;
    occ_vec3_t *p = malloc((good + 5u) * sizeof *p);
    memcpy(p, c.p, good * sizeof *p);
    p[good] = (occ_vec3_t){NAN, 0, 0};
    p[good + 1u] = (occ_vec3_t){1.0f, INFINITY, 0};
    p[good + 2u] = (occ_vec3_t){0, 0, -INFINITY};
    p[good + 3u] = (occ_vec3_t){1e7f, 0, 0};       /* outside the map volume */
    p[good + 4u] = (occ_vec3_t){0, -3300.0f, 0.5f}; /* outside at 0.1 m (+-3276.8 m) */
    for (int meth = 0; meth < 4; meth++) {
        occ_map_t a, b;
        it_init_map(&a, arena_a, ARENA_BYTES, 0.1f);
        it_init_map(&b, arena_b, ARENA_BYTES, 0.1f);
        occ_insert_params_t prm = occ_insert_params_default();
        prm.method = (occ_insert_method_t)meth;
        occ_insert_result_t out;
        assert_int_equal(occ_map_insert_cloud(&a, &c.origin, p, good + 5u, &prm, scratch,
                                              SCRATCH_BYTES, &out),
                         OCC_OK);
        assert_int_equal(out.points_skipped, 5);
        assert_int_equal(out.points_integrated, good);
        assert_int_equal(occ_map_insert_cloud(&b, &c.origin, p, good, &prm, scratch,
                                              SCRATCH_BYTES, NULL),
                         OCC_OK);
        assert_int_equal(it_diff_maps(&a, &b), 0);
    }
    /* Bad arguments. */
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, 0.1f);
    occ_insert_params_t prm = occ_insert_params_default();
    const occ_vec3_t bad_o = {NAN, 0, 0}, far_o = {1e6f, 0, 0};
    assert_int_equal(occ_map_insert_cloud(&m, &bad_o, p, good, &prm, scratch, SCRATCH_BYTES, NULL),
                     OCC_ERR_ARG);
    assert_int_equal(occ_map_insert_cloud(&m, &far_o, p, good, &prm, scratch, SCRATCH_BYTES, NULL),
                     OCC_ERR_RANGE);
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, NULL, 3, &prm, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_ERR_ARG);
    prm.fast_d = 16;
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, p, good, &prm, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_ERR_ARG);
    free(p);
    free(c.p);
}

/* Too little scratch (OCC_ERR_SCRATCH, oom_count untouched) or pool (OCC_ERR_NOMEM, counted): the
 * map exactly as before. */
static void test_nomem_unchanged(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 41)) {
        skip();
    }
    occ_map_t m;
    const size_t small_arena = (size_t)256 << 10;
    it_init_map(&m, arena_a, small_arena, 0.2f);
    occ_insert_params_t p = occ_insert_params_default();
    /* A first scan from elsewhere, so the map is not empty. */
    const occ_vec3_t o1 = {1.0f, 1.0f, 0.0f};
    assert_int_equal(occ_map_insert_cloud(&m, &o1, c.p, c.n / 4u, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_OK);
    size_t nodes0;
    const uint64_t d0 = it_map_digest(&m, &nodes0);
    const size_t need = occ_insert_scratch_bytes_scan(&m, &c.origin, c.p, c.n, &p);
    printf("  scratch bound for %zu points: %zu bytes\n", c.n, need);
    for (int meth = 0; meth < 4; meth++) {
        p.method = (occ_insert_method_t)meth;
        p.fast_d = meth == 2 ? 1u : 0u;
        static const size_t sizes[] = {0, 7, 64, 1000, 40000, 300000, 600000};
        for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
            const uint32_t oom0 = m.oom_count;
            const occ_err_t e = occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch,
                                                     sizes[i], NULL);
            size_t nodes;
            if (e != OCC_OK) {
                /* the small sizes are short of scratch; the larger may be short of pool */
                assert_true(e == OCC_ERR_SCRATCH || (e == OCC_ERR_NOMEM && sizes[i] >= 40000u));
                assert_int_equal(m.oom_count, oom0 + (e == OCC_ERR_NOMEM ? 1u : 0u));
                assert_true(it_map_digest(&m, &nodes) == d0);
                assert_int_equal(nodes, nodes0);
            }
            assert_int_equal(occ_map_check(&m), OCC_OK);
            if (e == OCC_OK) { /* restore: undo by re-initializing and replaying */
                it_init_map(&m, arena_a, small_arena, 0.2f);
                p.method = OCC_INSERT_SIMPLE;
                assert_int_equal(occ_map_insert_cloud(&m, &o1, c.p, c.n / 4u, &p, scratch,
                                                      SCRATCH_BYTES, NULL),
                                 OCC_OK);
                p.method = (occ_insert_method_t)meth;
            }
        }
    }
    assert_int_equal(leak_check(&m), 0); /* the refused insertions gave every block back */
    /* Pool too small: tiny arenas. */
    static const size_t arenas[] = {2048, 8192, 32768};
    for (size_t i = 0; i < sizeof arenas / sizeof arenas[0]; i++) {
        occ_map_t s;
        it_init_map(&s, arena_b, arenas[i], 0.2f);
        const occ_vec3_t one = {0.5f, 0.5f, 0.5f};
        assert_int_equal(occ_map_insert_cloud(&s, &c.origin, &one, 1, &p, scratch, SCRATCH_BYTES,
                                              NULL),
                         OCC_OK);
        size_t nodes_b;
        const uint64_t db = it_map_digest(&s, &nodes_b);
        p.method = OCC_INSERT_SIMPLE;
        const occ_err_t e = occ_map_insert_cloud(&s, &c.origin, c.p, c.n, &p, scratch,
                                                 SCRATCH_BYTES, NULL);
        assert_int_equal(e, OCC_ERR_NOMEM);
        size_t nodes_a;
        assert_true(it_map_digest(&s, &nodes_a) == db);
        assert_int_equal(nodes_a, nodes_b);
        assert_int_equal(occ_map_check(&s), OCC_OK);
        assert_true(s.oom_count > 0u);
        assert_int_equal(leak_check(&s), 0);
    }
    free(c.p);
}

static void test_scratch_formula(void **state)
{
    (void)state;
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, 0.1f);
    const occ_insert_params_t p = occ_insert_params_default();
    const size_t a = occ_insert_scratch_bytes(&m, 1000, 10.0f, &p);
    const size_t b = occ_insert_scratch_bytes(&m, 2000, 10.0f, &p);
    const size_t fixed = occ_insert_scratch_bytes(&m, 0, 10.0f, &p);
    /* n * (8 + 16 * (3 * (100 + 2) + 5)) + fixed, fixed = 7 + 2^15 * 8 + 6 * 2^11 * 4 (host) */
    assert_int_equal(fixed, (size_t)7 + 32768 * 8 + 6 * 2048 * 4);
    assert_int_equal(a - fixed, (size_t)1000 * (8 + 16 * (3 * 102 + 5)));
    assert_int_equal(a, OCC_INSERT_SCRATCH_BYTES(1000, 102));
    assert_int_equal(b - fixed, 2 * (a - fixed));
    assert_true(occ_insert_scratch_bytes(&m, 1000, -1.0f, &p) > a);
    assert_int_equal(occ_insert_scratch_bytes(&m, SIZE_MAX / 2u, 1e6f, &p), SIZE_MAX);
}

/* ---- 32-bit size_t (issue 16, section 2) ------------------------------------------------------
 * Bytes after a scratch of `bytes` are set to a pattern; true when the call left them alone. */
#define GUARD_BYTES ((size_t)4 << 20)
static void guard_set(const size_t bytes)
{
    memset(scratch + bytes, 0xA5, GUARD_BYTES);
}

static bool guard_intact(const size_t bytes)
{
    for (size_t i = 0; i < GUARD_BYTES; i++) {
        if (scratch[bytes + i] != 0xA5u) {
            printf("  scratch guard: byte %zu after the scratch was written\n", i);
            return false;
        }
    }
    return true;
}

/* FAST_DISCRETE over a box of 2048 coarse bricks per axis (d = 1 at 0.1 m): the coarse set's
 * brick count is 2^33, which wrapped to 0 in a 32-bit size_t and let the set be written far
 * outside a 1.6 MB scratch (UBSan "pointer index expression overflowed" on i386). Now the count
 * saturates: OCC_ERR_SCRATCH, nothing written past the scratch, the map unchanged. */
static void test_fast_box_2048_bricks(void **state)
{
    (void)state;
    occ_map_t m;
    it_init_map(&m, arena_a, (size_t)1 << 20, 0.1f);
    const occ_vec3_t seed = {-1276.0f, -1276.0f, -1276.0f};
    assert_int_equal(occ_map_update(&m, seed, 1.0f), OCC_OK);
    size_t nodes0;
    const uint64_t d0 = it_map_digest(&m, &nodes0);
    const occ_vec3_t origin = {-1276.8f, -1276.8f, -1276.8f};
    const occ_vec3_t pts[2] = {{-1638.2f, -1638.2f, -1638.2f}, {-4.0f, -4.0f, -4.0f}};
    occ_insert_params_t p = occ_insert_params_default();
    p.method = OCC_INSERT_FAST_DISCRETE;
    p.fast_d = 1;
    p.fast_n = 0;
    const size_t bytes = (size_t)1600 * 1000;
    guard_set(bytes);
    occ_insert_result_t r;
    const occ_err_t e = occ_map_insert_cloud(&m, &origin, pts, 2, &p, scratch, bytes, &r);
    printf("  2048^3 coarse bricks, %zu-byte size_t, 1.6 MB scratch: %s\n", sizeof(size_t),
           occ_err_str(e));
    assert_int_equal(e, OCC_ERR_SCRATCH);
    assert_true(guard_intact(bytes));
    size_t nodes;
    assert_true(it_map_digest(&m, &nodes) == d0);
    assert_int_equal(nodes, nodes0);
    assert_int_equal(m.oom_count, 0u); /* scratch is not the pool */
    assert_true(r.scratch_used <= bytes);
    assert_int_equal(occ_map_check(&m), OCC_OK);
    /* The bound says so too: 32 bytes per coarse brick alone are 256 GiB (SIZE_MAX on 32 bit). */
    const size_t need = occ_insert_scratch_bytes_scan(&m, &origin, pts, 2, &p);
    assert_true(need > bytes);
    if (sizeof(size_t) < 8u) {
        assert_true(need == SIZE_MAX);
    }
    /* The same scan at d = 4 has 256 coarse bricks per axis (2^24, 512 MiB of set): still too
     * big for 1.6 MB, and still refused cleanly. */
    p.fast_d = 4;
    guard_set(bytes);
    assert_int_equal(occ_map_insert_cloud(&m, &origin, pts, 2, &p, scratch, bytes, &r),
                     OCC_ERR_SCRATCH);
    assert_true(guard_intact(bytes));
    assert_true(it_map_digest(&m, &nodes) == d0);
}

/* ---- the scratch bound at compile time (issue 16, section 6) --------------------------------- */
/* Firmware sizes its scratch with the macro; the fixed term is this build's (6 radix passes of
 * 11 bits here, 8 of 8 bits on ARM) and equals the runtime function's. */
static uint8_t fw_scratch[OCC_INSERT_SCRATCH_BYTES(8, 100)];

/* One point 100 voxels away on every axis is the worst case of OCC_INSERT_SCRATCH_BYTES(1, 100):
 * exactly that much scratch (on a misaligned pointer, the 7 bytes of alignment lost) suffices,
 * one byte less is OCC_ERR_SCRATCH with the map unchanged and oom_count untouched. Eight such
 * rays fit OCC_INSERT_SCRATCH_BYTES(8, 100) with every method the macro covers. */
static void test_scratch_macro_worst_case(void **state)
{
    (void)state;
    assert_int_equal(OCC_INSERT_SCRATCH_FIXED_BYTES,
                     (size_t)7 + ((size_t)1 << OCC_INSERT_FILTER_BITS) * 8u +
                         (size_t)OCC_INSERT_RADIX_PASSES * ((size_t)1 << OCC_INSERT_RADIX_BITS) *
                             4u);
    assert_true(OCC_INSERT_SCRATCH_FITS(8, 100));
    assert_false(OCC_INSERT_SCRATCH_FITS(SIZE_MAX / 16u, 100));
    occ_map_t m, ref;
    it_init_map(&m, arena_a, (size_t)8 << 20, 0.1f);
    it_init_map(&ref, arena_b, (size_t)8 << 20, 0.1f);
    const occ_vec3_t o = {0.05f, 0.05f, 0.05f};    /* key 2^15 on each axis, its centre */
    const occ_vec3_t far = {10.05f, 10.05f, 10.05f}; /* key 2^15 + 100 on each axis */
    occ_key_t ko, ke;
    assert_int_equal(occ_map_key(&m, o, &ko), OCC_OK);
    assert_int_equal(occ_map_key(&m, far, &ke), OCC_OK);
    assert_int_equal(ke.k[0] - ko.k[0], 100u);
    occ_insert_params_t p = occ_insert_params_default();
    p.method = OCC_INSERT_DISCRETE;
    const size_t exact = OCC_INSERT_SCRATCH_BYTES(1, 100);
    assert_int_equal(occ_map_insert_cloud(&ref, &o, &far, 1, &p, scratch, SCRATCH_BYTES, NULL),
                     OCC_OK);
    occ_insert_result_t r;
    assert_int_equal(occ_map_insert_cloud(&m, &o, &far, 1, &p, scratch + 1, exact - 1u, &r),
                     OCC_ERR_SCRATCH);
    size_t nodes;
    (void)it_map_digest(&m, &nodes);
    assert_int_equal(nodes, 0);
    assert_int_equal(m.oom_count, 0u);
    assert_int_equal(occ_map_insert_cloud(&m, &o, &far, 1, &p, scratch + 1, exact, &r), OCC_OK);
    printf("  one ray of 100 voxels per axis: %zu bytes suffice, one less is refused; %zu "
           "written\n", exact, r.scratch_used);
    assert_true(r.scratch_used <= exact);
    assert_int_equal(it_diff_maps(&m, &ref), 0);
    /* Eight such rays (the octants), every method the macro covers, into the static buffer. */
    occ_vec3_t pts[8];
    for (unsigned i = 0; i < 8u; i++) {
        pts[i].x = o.x + ((i & 1u) ? 10.0f : -10.0f);
        pts[i].y = o.y + ((i & 2u) ? 10.0f : -10.0f);
        pts[i].z = o.z + ((i & 4u) ? 10.0f : -10.0f);
    }
    static const occ_insert_method_t methods[] = {OCC_INSERT_SIMPLE, OCC_INSERT_DISCRETE,
                                                  OCC_INSERT_FAST_DISCRETE, OCC_INSERT_SUPER_RAYS};
    for (size_t i = 0; i < 4u; i++) {
        p.method = methods[i];
        p.fast_d = 0;
        occ_map_clear(&m);
        occ_map_clear(&ref);
        assert_int_equal(occ_map_insert_cloud(&ref, &o, pts, 8, &p, scratch, SCRATCH_BYTES, NULL),
                         OCC_OK);
        assert_int_equal(occ_map_insert_cloud(&m, &o, pts, 8, &p, fw_scratch + 1,
                                              sizeof fw_scratch - 1u, NULL),
                         OCC_OK);
        assert_int_equal(it_diff_maps(&m, &ref), 0);
    }
    /* The runtime bound for a 10 m ray is the macro's with two voxels of rounding. */
    assert_int_equal(occ_insert_scratch_bytes(&m, 8, 10.0f, &p), OCC_INSERT_SCRATCH_BYTES(8, 102));
}

/* Bytes of scratch[0..n) that differ from the pattern `v`. */
static size_t bytes_changed(const size_t n, const uint8_t v)
{
    size_t c = 0;
    for (size_t i = 0; i < n; i++) {
        c += scratch[i] != v;
    }
    return c;
}

/* scratch_used reports the bytes the call wrote, not the bound it was given: on scan.dat at
 * 0.1 m FAST_DISCRETE (d = 2, n = 0) with the bound's scratch writes a few MB of the ~150 MB;
 * scratch_used is at least what changed in the buffer and at most a little more. */
static void test_scratch_used_is_written(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 1)) {
        skip();
    }
    occ_map_t m;
    it_init_map(&m, arena_a, ARENA_BYTES, 0.1f);
    static const struct {
        occ_insert_method_t method;
        uint8_t d, n;
    } cases[] = {{OCC_INSERT_FAST_DISCRETE, 2, 0}, {OCC_INSERT_FAST_DISCRETE, 2, 2},
                 {OCC_INSERT_SIMPLE, 0, 0}, {OCC_INSERT_DISCRETE, 0, 0}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        occ_insert_params_t p = occ_insert_params_default();
        p.method = cases[i].method;
        p.fast_d = cases[i].d;
        p.fast_n = cases[i].n;
        size_t need = occ_insert_scratch_bytes_scan(&m, &c.origin, c.p, c.n, &p);
        need = need < SCRATCH_BYTES ? need : SCRATCH_BYTES;
        occ_map_clear(&m);
        memset(scratch, 0x5A, need);
        occ_insert_result_t r;
        assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, need, &r),
                         OCC_OK);
        const size_t changed = bytes_changed(need, 0x5A);
        printf("  method %d d %u n %u: scratch %zu, scratch_used %zu, bytes changed %zu\n",
               (int)p.method, (unsigned)p.fast_d, (unsigned)p.fast_n, need, r.scratch_used,
               changed);
        assert_true(r.scratch_used >= changed);
        assert_true(r.scratch_used <= changed + changed / 4u + ((size_t)64 << 10));
    }
    free(c.p);
}

/* FAST_DISCRETE with d > 0 honours auto_evict: a map filled by a scan 200 m away has no room for
 * the next scan's coarse pass (OCC_ERR_NOMEM without eviction, map unchanged); with a policy the
 * far content is evicted and the scan lands exactly as on an empty map. */
static void test_fast_auto_evict(void **state)
{
    (void)state;
    it_cloud_t c;
    if (!it_load_scan(&c, 7)) {
        skip();
    }
    occ_vec3_t *const shifted = malloc(c.n * sizeof *shifted);
    assert_non_null(shifted);
    for (size_t i = 0; i < c.n; i++) {
        shifted[i] = c.p[i];
        shifted[i].x += 200.0f;
    }
    const occ_vec3_t far_origin = {c.origin.x + 200.0f, c.origin.y, c.origin.z};
    occ_insert_params_t p = occ_insert_params_default();
    p.method = OCC_INSERT_FAST_DISCRETE;
    p.fast_d = 1;
    p.fast_n = 2;
    /* The smallest arena of a ladder that holds one scan, with a fifth to spare. */
    occ_map_t ref, m;
    size_t arena = 0;
    for (size_t a = (size_t)64 << 10; a <= ARENA_BYTES && arena == 0u; a += a / 4u) {
        it_init_map(&ref, arena_b, a, 0.2f);
        if (occ_map_insert_cloud(&ref, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES, NULL) ==
            OCC_OK) {
            arena = a + a / 5u;
        }
    }
    assert_true(arena > 0u);
    it_init_map(&m, arena_a, arena, 0.2f);
    assert_int_equal(
        occ_map_insert_cloud(&m, &far_origin, shifted, c.n, &p, scratch, SCRATCH_BYTES, NULL),
        OCC_OK);
    size_t nodes0;
    const uint64_t d0 = it_map_digest(&m, &nodes0);
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_ERR_NOMEM);
    size_t nodes;
    assert_true(it_map_digest(&m, &nodes) == d0);
    const occ_evict_policy_t pol = occ_evict_policy_default();
    occ_evict_out_t ev;
    occ_evict_out_init(&ev);
    p.auto_evict = &pol;
    p.auto_evict_state = &ev;
    occ_insert_result_t r;
    assert_int_equal(occ_map_insert_cloud(&m, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          &r),
                     OCC_OK);
    printf("  arena %zu: evicted %llu nodes (%llu blocks), %zu coarse nodes, %zu voxels\n", arena,
           (unsigned long long)ev.evictions, (unsigned long long)ev.blocks_freed,
           r.coarse_updated, r.voxels_updated);
    assert_true(ev.evictions > 0u);
    assert_true(r.coarse_updated > 0u);
    assert_int_equal(occ_map_check(&m), OCC_OK);
    it_init_map(&ref, arena_b, ARENA_BYTES, 0.2f);
    p.auto_evict = NULL;
    p.auto_evict_state = NULL;
    assert_int_equal(occ_map_insert_cloud(&ref, &c.origin, c.p, c.n, &p, scratch, SCRATCH_BYTES,
                                          NULL),
                     OCC_OK);
    assert_int_equal(it_diff_into(&ref, &m), 0);
    free(shifted);
    free(c.p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_bad_points, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_nomem_unchanged, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_scratch_formula, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_fast_box_2048_bricks, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_scratch_macro_worst_case, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_scratch_used_is_written, it_timer_setup, it_timer_teardown),
        cmocka_unit_test_setup_teardown(test_fast_auto_evict, it_timer_setup, it_timer_teardown),
    };
    const it_buffers_t b = {&arena_a, &arena_b, &scratch, ARENA_BYTES, SCRATCH_BYTES};
    return it_run_tests("test_integrate_limits", tests, sizeof tests / sizeof tests[0], b);
}
