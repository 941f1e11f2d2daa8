/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * test_evict_auto.c - eviction in automatic mode (issue 9):
 *  - Automatic mode (need -> evict_for -> observe, in Morton chunks) along a straight path in
 *    arenas from a tenth of the map to all of it: no failure, invariants hold, and the map near
 *    the last position equals an unbounded map's.
 *  - The same on the real TUM depth frames at 0.05 m (../shared/data/depth), rays by
 *    occ_ray_keys with OctoMap's per-scan semantics (a voxel hit in the scan is a hit).
 * Random seed: printed, overridable with OCC_SEED. Shadow checks: test_evict.c.
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
#include <unistd.h>

#include "occmap/occmap.h"
#include "occmap/occ_evict.h"
#include "occmap/occ_integrate.h"
#include "occmap/host/occ_scan.h"
#include "core/tree_internal.h"
#include "support/evict_fixture.h"
#include "support/leak_check.h"

#define TUM_DIR "../shared/data/depth/tum_fr2_pioneer_slam2"

static uint8_t arena_a[4u << 20];
static uint8_t arena_b[4u << 20];

/* ---- automatic mode ----------------------------------------------------------------------------- */

typedef struct {
    occ_code_t *codes;
    size_t n;
    occ_vec3_t origin;
} scan_codes_t;

typedef struct {
    size_t chunks, chunk_fails, evict_calls;
    bool check_each; /* occ_map_check() after every eviction call, not only per scan */
} auto_stats_t;

/* The integrator's automatic mode as documented for occ_map_insert_cloud: apply in Morton
 * chunks; on NOMEM ask eviction for what the chunk needs and retry (the need can grow when
 * eviction prunes a node the chunk lies in, hence the loop). */
static void auto_observe(occ_map_t *m, const scan_codes_t *s, const occ_evict_policy_t *p,
                         occ_evict_out_t *ev, auto_stats_t *as)
{
    const size_t chunk = 4096u;
    for (size_t s0 = 0; s0 < s->n; s0 += chunk) {
        const size_t n = s->n - s0 < chunk ? s->n - s0 : chunk;
        occ_err_t e = occ_map_observe_codes(m, s->codes + s0, n, NULL);
        for (unsigned r = 0; r < 8u && e == OCC_ERR_NOMEM; r++) {
            uint32_t ni, nl;
            assert_int_equal(occ_map_observe_need(m, s->codes + s0, n, &ni, &nl), OCC_OK);
            as->evict_calls++;
            const occ_err_t ee = occ_map_evict_for(m, &s->origin, p, ni, nl, ev);
            if (as->check_each) {
                assert_int_equal(occ_map_check(m), OCC_OK);
            }
            if (ee != OCC_OK) {
                break;
            }
            e = occ_map_observe_codes(m, s->codes + s0, n, NULL);
        }
        as->chunks++;
        if (e != OCC_OK) {
            as->chunk_fails++;
        }
    }
}

/* Voxels within r of c read the same in both maps. */
static size_t compare_ball(const occ_map_t *a, const occ_map_t *b, const occ_vec3_t c,
                           const float r, size_t *n_known)
{
    occ_key_t kc;
    assert_int_equal(occ_map_key(a, c, &kc), OCC_OK);
    const int32_t ext = (int32_t)(r / a->cfg.resolution_m) + 1;
    size_t bad = 0, known = 0;
    for (int32_t dz = -ext; dz <= ext; dz++) {
        for (int32_t dy = -ext; dy <= ext; dy++) {
            for (int32_t dx = -ext; dx <= ext; dx++) {
                occ_key_t k = {{(uint32_t)((int32_t)kc.k[0] + dx), (uint32_t)((int32_t)kc.k[1] + dy),
                                (uint32_t)((int32_t)kc.k[2] + dz)}};
                const occ_vec3_t p = occ_map_key_center(a, k, 0u);
                const float ddx = p.x - c.x, ddy = p.y - c.y, ddz = p.z - c.z;
                if (ddx * ddx + ddy * ddy + ddz * ddz > r * r) {
                    continue;
                }
                occ_node_info_t ia, ib;
                assert_int_equal(occ_map_read_key(a, k, 0u, &ia), OCC_OK);
                assert_int_equal(occ_map_read_key(b, k, 0u, &ib), OCC_OK);
                known += ib.observed ? 1u : 0u;
                if (ia.observed != ib.observed || ia.logodds < ib.logodds ||
                    ia.logodds > ib.logodds) {
                    bad++;
                }
            }
        }
    }
    *n_known = known;
    return bad;
}

/* A straight flight: each step observes clustered voxels within 0.6 m of the position. */
static void test_auto_path(void **state)
{
    (void)state;
    const occ_map_config_t cfg = ev_cfg_res(0.1f);
    enum { STEPS = 150 };
    static scan_codes_t scans[STEPS];
    const float obs_r = 0.6f;
    occ_map_t ref;
    assert_int_equal(occ_map_init(&ref, &cfg, arena_b, sizeof arena_b), OCC_OK);
    for (unsigned t = 0; t < STEPS; t++) {
        const occ_vec3_t o = {0.2f * (float)t - 15.0f, 0.05f * (float)t, 0.0f};
        occ_code_t *c = malloc(3000u * sizeof *c);
        assert_non_null(c);
        size_t n = 0;
        while (n < 3000u) {
            const occ_vec3_t q = {o.x + (2.0f * ev_rndf() - 1.0f) * obs_r,
                                  o.y + (2.0f * ev_rndf() - 1.0f) * obs_r,
                                  o.z + (2.0f * ev_rndf() - 1.0f) * obs_r};
            const float dx = q.x - o.x, dy = q.y - o.y, dz = q.z - o.z;
            if (dx * dx + dy * dy + dz * dz > obs_r * obs_r) {
                continue;
            }
            occ_key_t k;
            assert_int_equal(occ_map_key(&ref, q, &k), OCC_OK);
            c[n++] = occ_morton_encode(k) | (fabsf(q.z - 0.3f) < 0.05f ? OCC_CODE_HIT_BIT : 0u);
        }
        scans[t].codes = c;
        scans[t].n = ev_sort_unique(c, n);
        scans[t].origin = o;
    }
    /* unbounded reference */
    for (unsigned t = 0; t < STEPS; t++) {
        assert_int_equal(occ_map_observe_codes(&ref, scans[t].codes, scans[t].n, NULL), OCC_OK);
    }
    occ_map_stats_t st;
    occ_map_pool_stats(&ref, &st);
    const size_t full = st.bytes_peak;
    printf("auto path: unbounded map %zu bytes\n", full);
    const float fracs[] = {0.1f, 0.25f, 0.5f, 1.0f, 1.2f};
    for (unsigned mode = 0; mode < 2u; mode++) {
        for (size_t f = 0; f < sizeof fracs / sizeof fracs[0]; f++) {
            const size_t bytes = (size_t)((float)full * fracs[f]);
            occ_map_t m;
            assert_int_equal(occ_map_init(&m, &cfg, arena_a, bytes), OCC_OK);
            occ_evict_policy_t p = occ_evict_policy_default();
            p.mode = (occ_evict_mode_t)mode;
            p.keep_radius_m = obs_r + 0.2f;
            occ_evict_out_t ev;
            occ_evict_out_init(&ev);
            auto_stats_t as = {0u, 0u, 0u, true};
            for (unsigned t = 0; t < STEPS; t++) {
                auto_observe(&m, &scans[t], &p, &ev, &as);
                assert_int_equal(occ_map_check(&m), OCC_OK);
                occ_map_pool_stats(&m, &st);
                assert_true(st.bytes_used <= m.arena_bytes);
            }
            size_t known;
            const size_t bad = compare_ball(&m, &ref, scans[STEPS - 1].origin, obs_r, &known);
            printf("auto path %s arena %.2f of the map (%zu B): chunks %zu failed %zu, "
                   "evictions %llu, blocks freed %llu, peak %zu B; within %.1f m of the last "
                   "position %zu known voxels, %zu differ\n",
                   mode ? "coarsen" : "robot", (double)fracs[f], bytes, as.chunks,
                   as.chunk_fails, (unsigned long long)ev.evictions,
                   (unsigned long long)ev.blocks_freed, st.bytes_peak, (double)obs_r, known, bad);
            assert_int_equal(as.chunk_fails, 0u);
            assert_int_equal(bad, 0u);
            assert_true(known > 0u);
        }
    }
    for (unsigned t = 0; t < STEPS; t++) {
        free(scans[t].codes);
    }
}

/* ---- the real depth frames ----------------------------------------------------------------------- */

static void test_tum_exhaustion(void **state)
{
    (void)state;
    if (access(TUM_DIR "/my_association.txt", R_OK) != 0) {
        printf("SKIP test_tum_exhaustion: %s absent (needs ../shared)\n", TUM_DIR);
        skip();
    }
    const occ_map_config_t cfg = ev_cfg_res(0.05f);
    occ_scan_frame_t *fr = NULL;
    size_t nf = 0;
    char msg[256];
    assert_int_equal(occ_depth_read_tum_dir(TUM_DIR, 12u, 0u, &fr, &nf, msg, sizeof msg), OCC_OK);
    assert_int_equal(nf, 10u);
    occ_map_t ref;
    assert_int_equal(occ_map_init(&ref, &cfg, arena_b, sizeof arena_b), OCC_OK);
    scan_codes_t scans[10];
    const size_t kcap = 4096u;
    occ_key_t *keys = malloc(kcap * sizeof *keys);
    assert_non_null(keys);
    for (size_t i = 0; i < nf; i++) {
        size_t cap = 1u << 18, len = 0;
        occ_code_t *c = malloc(cap * sizeof *c);
        assert_non_null(c);
        for (size_t j = 0; j < fr[i].n_points; j++) {
            size_t nk;
            if (occ_ray_keys(&ref, fr[i].origin, fr[i].points[j], keys, kcap, &nk) != OCC_OK) {
                continue;
            }
            if (len + nk + 1u > cap) {
                cap *= 2u;
                c = realloc(c, cap * sizeof *c);
                assert_non_null(c);
            }
            for (size_t k = 0; k < nk; k++) {
                c[len++] = occ_morton_encode(keys[k]);
            }
            occ_key_t ek;
            if (occ_map_key(&ref, fr[i].points[j], &ek) == OCC_OK) {
                c[len++] = occ_morton_encode(ek) | OCC_CODE_HIT_BIT;
            }
        }
        scans[i].codes = c;
        scans[i].n = ev_sort_unique(c, len);
        scans[i].origin = fr[i].origin;
        assert_int_equal(occ_map_observe_codes(&ref, c, scans[i].n, NULL), OCC_OK);
    }
    free(keys);
    occ_map_stats_t st;
    occ_map_pool_stats(&ref, &st);
    const size_t full = st.bytes_peak;
    printf("TUM: 10 frames (every 12th pixel), 0.05 m, unbounded map %zu bytes\n", full);
    /* Arenas from a tenth of the map to all of it. The protected radius must hold the map near
     * the sensor: 4 m (the camera moves 0.9 m, so every voxel within 3 m of the last origin
     * stays protected from its first observation on) fits from half the map; smaller arenas use
     * 1 m and are checked for no failure and invariants. */
    const struct { float frac, keep; occ_evict_mode_t mode; bool equal3m; } cases[] = {
        {0.10f, 1.0f, OCC_EVICT_ROBOT, false},   {0.10f, 1.0f, OCC_EVICT_COARSEN, false},
        {0.50f, 4.0f, OCC_EVICT_ROBOT, true},
        {0.50f, 4.0f, OCC_EVICT_COARSEN, true},  {1.00f, 4.0f, OCC_EVICT_ROBOT, true},
    };
    for (size_t ci = 0; ci < sizeof cases / sizeof cases[0]; ci++) {
        const size_t bytes = (size_t)((float)full * cases[ci].frac);
        occ_map_t m;
        assert_int_equal(occ_map_init(&m, &cfg, arena_a, bytes), OCC_OK);
        occ_evict_policy_t p = occ_evict_policy_default();
        p.mode = cases[ci].mode;
        p.keep_radius_m = cases[ci].keep;
        occ_evict_out_t ev;
        occ_evict_out_init(&ev);
        auto_stats_t as = {0u, 0u, 0u, ci == 0u};
        for (size_t i = 0; i < nf; i++) {
            auto_observe(&m, &scans[i], &p, &ev, &as);
            assert_int_equal(occ_map_check(&m), OCC_OK);
        }
        occ_map_pool_stats(&m, &st);
        size_t known = 0, bad = 0;
        if (cases[ci].equal3m) {
            bad = compare_ball(&m, &ref, scans[nf - 1u].origin, 3.0f, &known);
        }
        printf("TUM %s keep %.1f m arena %.2f of the map (%zu B): chunks %zu failed %zu, "
               "evictions %llu, blocks freed %llu, peak %zu B%s",
               cases[ci].mode == OCC_EVICT_ROBOT ? "robot" : "coarsen", (double)cases[ci].keep,
               (double)cases[ci].frac, bytes, as.chunks, as.chunk_fails,
               (unsigned long long)ev.evictions, (unsigned long long)ev.blocks_freed,
               st.bytes_peak, cases[ci].equal3m ? "" : "\n");
        if (cases[ci].equal3m) {
            printf("; within 3 m of the last origin %zu known voxels, %zu differ\n", known, bad);
        }
        assert_int_equal(as.chunk_fails, 0u);
        assert_true(st.bytes_peak <= m.arena_bytes);
        assert_int_equal(bad, 0u);
        if (cases[ci].equal3m) {
            assert_true(known > 1000u);
        }
    }
    for (size_t i = 0; i < nf; i++) {
        free(scans[i].codes);
    }
    occ_scan_frames_free(fr, nf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_auto_path),
        cmocka_unit_test(test_tum_exhaustion),
    };
    return cmocka_run_group_tests(tests, ev_setup_seed, NULL);
}
