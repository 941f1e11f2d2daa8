/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * integrate.c - occ_map_insert_cloud(): OctoMap's per-scan semantics (each voxel updated once,
 * hit wins over free) with the sets in the caller's scratch: rays mark the voxel set (vset.c),
 * read back in Morton order into one occ_map_observe_codes() batch or several; or they emit
 * Morton codes through a small exact filter, one radix sort + collapse, one batch (or windows).
 */
#include <math.h>
#include <string.h>

#include "occmap/occ_evict.h"
#include "coarse_internal.h"
#include "integrate_internal.h"
#include "../core/sat_internal.h"

#define FILTER_N ((size_t)1 << OCC_INSERT_FILTER_BITS)
/* The filter and the histograms, carved at the aligned start of the scratch. */
#define FIXED_RT (FILTER_N * 8u + OCC_KS_HIST_WORDS * 4u)
/* The public sizing macro's fixed term is this carve plus the alignment, in every build. */
typedef char fixed_term_matches_header[OCC_INSERT_SCRATCH_FIXED_BYTES == 7u + FIXED_RT ? 1 : -1];
/* Scratch beyond this is not used: the sort counts codes in 32 bits (32 GiB on a 64-bit host). */
#define SCRATCH_MAX ((size_t)UINT32_MAX < SIZE_MAX / 8u ? (size_t)UINT32_MAX * 8u : SIZE_MAX)

#ifdef OCC_TESTING
occi_insert_probe_t occi_insert_probe;
bool occi_insert_bricks_off;
bool occi_insert_lanes_off;
#define BRICKS_OFF() occi_insert_bricks_off
#define LANES_OFF() occi_insert_lanes_off
#define PROBE(field) (occi_insert_probe.field++)
#define PROBE_RESET() memset(&occi_insert_probe, 0, sizeof occi_insert_probe)
#else
#define BRICKS_OFF() false
#define LANES_OFF() false
#define PROBE(field) ((void)0)
#define PROBE_RESET() ((void)0)
#endif

occ_insert_params_t occ_insert_params_default(void)
{
    occ_insert_params_t p;
    memset(&p, 0, sizeof p);
    p.method = OCC_INSERT_SIMPLE;
    p.max_range_m = -1.0f;
    p.fast_n = 0;
    p.fast_d = 2;
    p.super_k = 4;
    return p;
}

static bool uses_ends(const occ_insert_method_t m)
{
    return m != OCC_INSERT_SIMPLE;
}

size_t occ_insert_scratch_bytes(const occ_map_t *const map, const size_t n_points,
                                const float max_ray_m, const occ_insert_params_t *const params)
{
    if (map == NULL || params == NULL) {
        return 0;
    }
    const float res = map->cfg.resolution_m;
    const float edge = (float)((uint32_t)1 << map->cfg.depth_levels);
    float cells = occ_finite(max_ray_m) && max_ray_m > 0.0f ? ceilf(max_ray_m / res) : edge;
    if (!(cells < edge)) {
        cells = edge;
    }
    /* Two voxels of rounding: the float quotient above and the keys of the ray's ends. */
    const size_t per_point = OCC_INSERT_SCRATCH_BYTES(1u, (size_t)cells + 2u) -
                             OCC_INSERT_SCRATCH_FIXED_BYTES;
    return occ_sat_add(occ_sat_mul(n_points, per_point), OCC_INSERT_SCRATCH_FIXED_BYTES);
}

size_t occ_insert_scratch_bytes_scan(const occ_map_t *const map, const occ_vec3_t *const origin,
                                     const occ_vec3_t *const points, const size_t n_points,
                                     const occ_insert_params_t *const params)
{
    if (map == NULL || origin == NULL || params == NULL || (points == NULL && n_points > 0u)) {
        return 0;
    }
    occ_raygeo_t g;
    occi_raygeo_init(&g, map);
    const float o[3] = {origin->x, origin->y, origin->z};
    uint32_t ko[3];
    if (!occi_raygeo_key(&g, o, ko)) {
        return OCC_INSERT_SCRATCH_FIXED_BYTES;
    }
    const bool fast = params->method == OCC_INSERT_FAST_DISCRETE && params->fast_d > 0u &&
                      params->fast_d < map->cfg.depth_levels;
    size_t codes = 0, samples = 0;
    uint32_t lo[3] = {ko[0], ko[1], ko[2]}, hi[3] = {ko[0], ko[1], ko[2]};
    for (size_t i = 0; i < n_points; i++) {
        float p[3] = {points[i].x, points[i].y, points[i].z};
        if (params->max_range_m > 0.0f &&
            occi_raygeo_dist(o, p) > (occ_rr_t)params->max_range_m) {
            float c[3];
            occi_raygeo_clip(o, p, params->max_range_m, c);
            memcpy(p, c, sizeof p);
        }
        uint32_t k[3];
        if (occi_raygeo_key(&g, p, k)) {
            const size_t b = occi_dda_bound(ko, k);
            codes = occ_sat_add(codes, b + 1u);
            samples = occ_sat_add(samples, (b >> params->fast_d) + 2u);
            for (unsigned a = 0; a < 3u; a++) {
                lo[a] = k[a] < lo[a] ? k[a] : lo[a];
                hi[a] = k[a] > hi[a] ? k[a] : hi[a];
            }
        }
    }
    size_t bytes = occ_sat_mul(16u, codes);
    bytes = occ_sat_add(bytes, occ_sat_mul(8u, n_points));
    if (fast) {
        /* The coarse nodes' set over the scan's box at level d, and their codes. */
        size_t cbricks = 1;
        for (unsigned a = 0; a < 3u; a++) {
            const uint32_t l = ((((lo[a] >= 2u ? lo[a] - 2u : 0u) >> params->fast_d) >> 2) & ~7u);
            const uint32_t h = ((hi[a] + 2u) >> params->fast_d) >> 2;
            cbricks = occ_sat_mul(cbricks, (size_t)(((h - l) | 7u) + 1u));
        }
        bytes = occ_sat_add(bytes, occ_sat_mul(32u, cbricks));
        bytes = occ_sat_add(bytes, occ_sat_mul(16u, samples));
    }
    return occ_sat_add(bytes, OCC_INSERT_SCRATCH_FIXED_BYTES);
}

/* ---- the insert context -------------------------------------------------------------------- */
bool occi_ictx_reserve(occ_ictx_t *const x, const size_t need)
{
    if (x->cap - x->n >= need) {
        return true;
    }
    occ_ictx_note(x, x->n, x->n);
    occ_code_t *const s = occi_keyset_sort(x->a, x->b, x->n, x->hist);
    size_t m = occi_keyset_unique(s, x->n);
    if (x->chunked && x->cap - m < need && m > 0u) {
        /* Bounded scratch: keep the lowest codes and narrow the window to them; the codes
         * above are dropped now and by every later ray of this pass (a later pass takes them). */
        const size_t room = x->cap > need ? x->cap - need : 0u;
        const size_t keep = room < (m > 1u ? m / 2u : 1u) ? room : (m > 1u ? m / 2u : 1u);
        if (keep > 0u) {
            x->win_hi = keep < m ? (s[keep] & ~OCC_CODE_HIT_BIT)
                                 : (s[m - 1u] & ~OCC_CODE_HIT_BIT) + 1u;
            m = keep;
        }
    }
    if (s != x->a) {
        memcpy(x->a, s, m * sizeof *s);
    }
    x->n = m;
    return x->cap - x->n >= need;
}

static inline size_t filt_slot(const occ_code_t c)
{
    return (size_t)((c * 0x9E3779B97F4A7C15ull) >> (64u - OCC_INSERT_FILTER_BITS));
}

#if OCC_MARK_LANES
/* The queued rays into the set, 8 at a time (occi_mwalk_batch). */
static void flush_rays(occ_ictx_t *const x)
{
    x->r->voxel_visits += occi_mwalk_batch(&x->g, x->o, x->ko, x->q, x->nq, x->bs, &x->cache);
    x->r->rays_cast += x->nq;
    x->nq = 0;
}

/* One ray into the queue; a full queue is walked. */
static void queue_ray(occ_ictx_t *const x, const float e[3], const uint32_t ke[3])
{
    occi_ray_end_t *const r = &x->q[x->nq++];
    for (unsigned i = 0; i < 3u; i++) {
        r->e[i] = e[i];
        r->ke[i] = ke[i];
    }
    if (x->nq == OCC_MARK_BATCH) {
        flush_rays(x);
    }
}
#endif

/* occi_ictx_set_ray's body, inlined into ictx_ray (no call more per ray on firmware). */
static OCC_ALWAYS_INLINE void set_ray(occ_ictx_t *const x, const float e[3], const uint32_t ke[3])
{
#if OCC_MARK_LANES
    if (x->lanes) {
        queue_ray(x, e, ke);
        return;
    }
#endif
    x->r->voxel_visits += occi_dda_mark(&x->g, x->o, e, x->ko, ke, x->bs);
    x->r->rays_cast++;
}

void occi_ictx_set_ray(occ_ictx_t *const x, const float e[3], const uint32_t ke[3])
{
    set_ray(x, e, ke);
}

/* Traverse o -> e (keys ko, ke already valid) and emit its free voxels through the filter. */
static void ictx_ray(occ_ictx_t *const x, const float e[3], const uint32_t ke[3])
{
    if (x->cbs != NULL) {
        occi_fast_ray(x, e, ke);
        return;
    }
    if (x->bs != NULL) {
        set_ray(x, e, ke);
        return;
    }
    occ_code_t *const base = x->a + x->n;
    const size_t m = occi_dda_codes(&x->g, x->o, e, x->ko, ke, base, x->cap - x->n);
    x->r->voxel_visits += m;
    x->r->rays_cast++;
    occ_code_t *const filt = x->filt;
    size_t w = 0;
    for (size_t i = 0; i < m; i++) {
        const occ_code_t c = base[i];
        const size_t s = filt_slot(c);
        if (filt[s] != c && c >= x->win_lo && c < x->win_hi) {
            filt[s] = c;
            base[w++] = c;
        }
    }
    x->n += w;
}

int occi_ictx_point(occ_ictx_t *const x, const float p[3], const bool hit)
{
    if (!occ_finite(p[0]) || !occ_finite(p[1]) || !occ_finite(p[2])) {
        return 1;
    }
    uint32_t ke[3];
    const bool clip = x->max_range > 0.0f && occi_raygeo_dist(x->o, p) > x->max_range_r;
    if (clip || !hit) {
        /* OctoMap's max-range rule, or a caller's no-hit ray: clear up to e, mark nothing. */
        float e[3] = {p[0], p[1], p[2]};
        if (clip) {
            occi_raygeo_clip(x->o, p, x->max_range, e);
        }
        if (!occi_raygeo_key(&x->g, e, ke)) {
            return 1;
        }
        if (x->bs == NULL && !occi_ictx_reserve(x, occi_dda_bound(x->ko, ke))) {
            return -1;
        }
        ictx_ray(x, e, ke);
        if (clip) {
            x->r->rays_clipped++;
        } else {
            x->r->rays_no_hit++;
        }
        return 0;
    }
    if (!occi_raygeo_key(&x->g, p, ke)) {
        return 1;
    }
    if (!occi_ictx_reserve(x, (x->bs == NULL ? occi_dda_bound(x->ko, ke) : 0u) + 1u)) {
        return -1;
    }
    ictx_ray(x, p, ke);
    const occ_key_t k = {{ke[0], ke[1], ke[2]}};
    const occ_code_t c = occ_morton_encode(k);
    if (x->bs == NULL) {
        x->filt[filt_slot(c)] = c; /* later free visits of this voxel are moot: hit wins */
    }
    if (c >= x->win_lo && c < x->win_hi) {
        occ_ictx_emit(x, c | OCC_CODE_HIT_BIT);
    }
    return 0;
}

void occi_ictx_lanes_begin(occ_ictx_t *const x)
{
#if OCC_MARK_LANES
    x->lanes = x->bs != NULL && x->cbs == NULL && !LANES_OFF() &&
               occi_mwalk_lanes_ok(x->g.depth);
    x->nq = 0;
    if (x->lanes) {
        memset(&x->cache, 0, sizeof x->cache); /* the set may be new */
    }
#else
    (void)x;
#endif
}

void occi_ictx_lanes_end(occ_ictx_t *const x)
{
#if OCC_MARK_LANES
    if (x->lanes) {
        flush_rays(x);
        x->lanes = false;
    }
#else
    (void)x;
#endif
}

int occi_ictx_points(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n,
                     const bool no_hit_only)
{
    occi_ictx_lanes_begin(x);
    int rc = 0;
    for (size_t i = 0; i < n && rc >= 0; i++) {
        const bool hit = occ_ictx_hit(x, i);
        if (no_hit_only && hit) {
            continue;
        }
        const float q[3] = {points[i].x, points[i].y, points[i].z};
        rc = occi_ictx_point(x, q, hit);
        if (rc == 0) {
            x->r->points_integrated++;
        } else if (rc > 0) {
            x->r->points_skipped++;
        }
    }
    occi_ictx_lanes_end(x);
    return rc < 0 ? rc : 0;
}

/* ---- DISCRETE: one ray per distinct end voxel, to its centre ------------------------------- */
/* End voxels are de-duplicated by their index in the scan's box (no Morton order is needed:
 * rays are independent), which sorts in 2-3 radix passes instead of 5. */
static size_t discretize(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n,
                         occ_code_t *const ends)
{
    const uint64_t bx = (uint64_t)(x->box_hi[0] - x->box_lo[0]) + 1u;
    const uint64_t by = (uint64_t)(x->box_hi[1] - x->box_lo[1]) + 1u;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (!occ_ictx_hit(x, i)) {
            continue; /* a no-hit ray: cast to its own point after the end voxels */
        }
        const float p[3] = {points[i].x, points[i].y, points[i].z};
        uint32_t k[3];
        if (occi_raygeo_key(&x->g, p, k)) { /* also rejects NaN / Inf */
            if (k[0] < x->box_lo[0] || k[1] < x->box_lo[1] || k[2] < x->box_lo[2] ||
                k[0] > x->box_hi[0] || k[1] > x->box_hi[1] || k[2] > x->box_hi[2]) {
                /* beyond max range: its centre's ray is clipped, the box holds the clip */
                const occ_key_t key = {{k[0], k[1], k[2]}};
                ends[m++] = OCC_CODE_HIT_BIT | occ_morton_encode(key);
                continue;
            }
            ends[m++] = (uint64_t)(k[0] - x->box_lo[0]) +
                        bx * ((uint64_t)(k[1] - x->box_lo[1]) + by * (uint64_t)(k[2] - x->box_lo[2]));
        } else {
            x->r->points_skipped++;
        }
    }
    x->r->points_integrated = m;
    x->n_ends = m;
    /* a and b are still empty: use them as the sort's buffers. Keys outside the box carry
     * bit 63 (ignored by the sort); they are rare and may repeat, which only repeats a ray. */
    occ_ictx_note(x, m, 0);
    occ_code_t *const s = occi_keyset_sort(ends, x->a, m, x->hist);
    size_t u = 0;
    for (size_t i = 0; i < m; i++) {
        if (u == 0u || s[i] != ends[u - 1u] || (s[i] >> 63) != 0u) {
            ends[u++] = s[i];
        }
    }
    return u;
}

static int run_discrete(occ_ictx_t *const x, const occ_code_t *const ends, const size_t n)
{
    const uint64_t bx = (uint64_t)(x->box_hi[0] - x->box_lo[0]) + 1u;
    const uint64_t by = (uint64_t)(x->box_hi[1] - x->box_lo[1]) + 1u;
    occi_ictx_lanes_begin(x);
    int rc = 0;
    for (size_t i = 0; i < n && rc >= 0; i++) {
        occ_key_t k;
        if ((ends[i] >> 63) != 0u) {
            k = occ_morton_decode(ends[i] & ~OCC_CODE_HIT_BIT);
        } else {
            k.k[0] = x->box_lo[0] + (uint32_t)(ends[i] % bx);
            k.k[1] = x->box_lo[1] + (uint32_t)((ends[i] / bx) % by);
            k.k[2] = x->box_lo[2] + (uint32_t)(ends[i] / bx / by);
        }
        const float c[3] = {occi_raygeo_center(&x->g, k.k[0]), occi_raygeo_center(&x->g, k.k[1]),
                            occi_raygeo_center(&x->g, k.k[2])};
        rc = occi_ictx_point(x, c, true);
    }
    occi_ictx_lanes_end(x);
    return rc < 0 ? rc : 0;
}

/* ---- method dispatch and the scan's box ----------------------------------------------------- */
static int run_method(occ_ictx_t *const x, const occ_insert_params_t *const params,
                      const occ_vec3_t *const points, const size_t n_points,
                      occ_code_t *const ends)
{
    switch (params->method) {
    case OCC_INSERT_SIMPLE:
        return occi_ictx_points(x, points, n_points, false);
    case OCC_INSERT_DISCRETE:
    case OCC_INSERT_FAST_DISCRETE: {
        if (x->cap < n_points) {
            return -1; /* the end-voxel sort borrows a[] */
        }
        const size_t u = discretize(x, points, n_points, ends);
        const int rc = run_discrete(x, ends, u);
        return rc < 0 || x->hit == NULL ? rc : occi_ictx_points(x, points, n_points, true);
    }
    case OCC_INSERT_SUPER_RAYS:
        return occi_superray_run(x, points, n_points, params->super_k) ? 0 : -1;
    case OCC_INSERT_PROJECTIVE: /* depth images only: refused by check_args */
    default:
        return -1;
    }
}

/* The box around the origin and every (clipped) end point, padded by 2 voxels for the DDA's
 * rounding, into box_lo/box_hi; returns its 32^3-voxel chunks (saturated): no scan touches
 * more chunks of the voxel set. *codes: the codes the rays can emit on the sorted path. */
static size_t box_chunks(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n,
                         size_t *const codes)
{
    *codes = 0;
    uint32_t lo[3] = {x->ko[0], x->ko[1], x->ko[2]}, hi[3] = {x->ko[0], x->ko[1], x->ko[2]};
    for (size_t i = 0; i < n; i++) {
        if (!occ_finite3(points[i])) {
            continue;
        }
        float q[3] = {points[i].x, points[i].y, points[i].z};
        if (x->max_range > 0.0f && occi_raygeo_dist(x->o, q) > x->max_range_r) {
            float c[3];
            occi_raygeo_clip(x->o, q, x->max_range, c);
            memcpy(q, c, sizeof q);
        }
        uint32_t k[3];
        if (!occi_raygeo_key(&x->g, q, k)) {
            continue;
        }
        *codes = occ_sat_add(*codes, occi_dda_bound(x->ko, k) + 1u);
        for (unsigned a = 0; a < 3u; a++) {
            lo[a] = k[a] < lo[a] ? k[a] : lo[a];
            hi[a] = k[a] > hi[a] ? k[a] : hi[a];
        }
    }
    size_t chunks = 1;
    const uint32_t kmax = ((uint32_t)1 << x->g.depth) - 1u;
    for (unsigned a = 0; a < 3u; a++) {
        x->box_lo[a] = lo[a] >= 2u ? lo[a] - 2u : 0u;
        x->box_hi[a] = hi[a] + 2u <= kmax ? hi[a] + 2u : kmax;
        chunks = occ_sat_mul(chunks, (size_t)((x->box_hi[a] >> 5) - (x->box_lo[a] >> 5)) + 1u);
    }
    return chunks;
}

/* Can the pools supply what the coarse pass and the voxel batch need (bounds as if no node
 * existed)? In automatic mode, evict for that first (the coarse pass cannot be chunked). */
static bool coarse_fits(occ_map_t *const map, const occ_vec3_t *const origin,
                        const occ_insert_params_t *const params, const uint64_t n_inner,
                        const uint64_t n_leaf)
{
    if (n_inner > OCC_NONE || n_leaf > OCC_NONE) {
        return false;
    }
    if (occi_pool_can_supply(map, (uint32_t)n_inner, (uint32_t)n_leaf)) {
        return true;
    }
    return params->auto_evict != NULL &&
           occ_map_evict_for(map, origin, params->auto_evict, (uint32_t)n_inner,
                             (uint32_t)n_leaf, params->auto_evict_state) == OCC_OK &&
           occi_pool_can_supply(map, (uint32_t)n_inner, (uint32_t)n_leaf);
}

/* FAST_DISCRETE: the coarse nodes' codes (in `spare`), a capacity check covering them and the
 * fine codes, then the coarse update (cfg.miss / (2d + 1) on every voxel below each node). After
 * this the fine batch cannot run out of blocks. */
static occ_err_t apply_coarse(occ_ictx_t *const x, occ_bitset_t *const cbs,
                              const occ_code_t *const fine, const size_t nf,
                              occ_code_t *const spare, const size_t spare_cap,
                              const occ_vec3_t *const origin,
                              const occ_insert_params_t *const params)
{
    occ_map_t *const map = x->map;
    if (spare_cap < cbs->n_touched) {
        return OCC_ERR_SCRATCH;
    }
    const size_t nc = occi_bitset_extract(cbs, NULL, 0, spare, spare_cap, spare, x->hist);
    if (nc == SIZE_MAX) {
        return OCC_ERR_SCRATCH;
    }
    const unsigned d = x->cd;
    for (size_t i = 0; i < nc; i++) {
        spare[i] <<= 3u * d; /* the node's first voxel */
    }
    uint64_t ci, cl, fi, fl;
    occi_coarse_need(spare, nc, d, map->cfg.depth_levels, &ci, &cl);
    occi_coarse_need(fine, nf, 0, map->cfg.depth_levels, &fi, &fl);
    if (!coarse_fits(map, origin, params, ci + fi, cl + fl)) {
        map->oom_count++;
        return OCC_ERR_NOMEM;
    }
    const float delta = map->cfg.miss / (float)(2u * d + 1u);
    (void)occi_coarse_apply(map, spare, nc, d, occ_value_from_logodds(delta));
    x->r->coarse_updated = nc;
    return OCC_OK;
}

/* ---- entry point ----------------------------------------------------------------------------- */
/* Automatic mode: the pools are short for `codes`. Evict around the origin until they can
 * supply what the batch needs and retry (an eviction can prune a node holding some of the codes
 * and raise the need, hence the loop); if the whole batch never fits, apply it in Morton-ordered
 * chunks, each evicted for first. `*applied` counts the codes applied. */
#define AUTO_CHUNK 4096u
#define AUTO_TRIES 8u
static occ_err_t evict_and_apply(occ_map_t *const map, const occ_vec3_t *const origin,
                                 const occ_insert_params_t *const params,
                                 const occ_code_t *const codes, const size_t n,
                                 size_t *const changed, size_t *const applied)
{
    *applied = 0;
    *changed = 0;
    for (unsigned t = 0; t < AUTO_TRIES; t++) {
        uint32_t ni, nl;
        if (occ_map_observe_need(map, codes, n, &ni, &nl) != OCC_OK ||
            occ_map_evict_for(map, origin, params->auto_evict, ni, nl,
                              params->auto_evict_state) != OCC_OK) {
            break;
        }
        const occ_err_t e = occ_map_observe_codes(map, codes, n, changed);
        if (e != OCC_ERR_NOMEM) {
            *applied = e == OCC_OK ? n : 0u;
            return e;
        }
    }
    for (size_t i = 0; i < n; i += AUTO_CHUNK) {
        const size_t k = n - i < AUTO_CHUNK ? n - i : AUTO_CHUNK;
        size_t ch = 0;
        occ_err_t e = occ_map_observe_codes(map, codes + i, k, &ch);
        for (unsigned t = 0; e == OCC_ERR_NOMEM && t < AUTO_TRIES; t++) {
            uint32_t ni, nl;
            if (occ_map_observe_need(map, codes + i, k, &ni, &nl) != OCC_OK ||
                occ_map_evict_for(map, origin, params->auto_evict, ni, nl,
                                  params->auto_evict_state) != OCC_OK) {
                break;
            }
            e = occ_map_observe_codes(map, codes + i, k, &ch);
        }
        if (e != OCC_OK) {
            return e;
        }
        *changed += ch;
        *applied += k;
    }
    return OCC_OK;
}

static uint8_t *align8(void *const p)
{
    const uintptr_t u = (uintptr_t)p;
    return (uint8_t *)p + ((8u - (u & 7u)) & 7u);
}

/* The counts of an applied scan. */
static void set_counts(occ_insert_result_t *const r, const size_t voxels, const size_t hits,
                       const size_t changed)
{
    r->voxels_updated = voxels;
    r->voxels_occupied = hits;
    r->voxels_free = voxels - hits;
    r->voxels_changed = changed;
}

/* The scan's sorted, collapsed codes; FAST_DISCRETE's coarse pass (d > 0); then one coherent
 * batch update in Morton order (all or nothing, except in automatic mode). Out of line: inlined,
 * its locals stayed in occ_map_insert_rays' frame under the ray traversal too (make cross).
 * With the voxel set, set_prepare() showed that its codes fit x->b in one piece. */
OCC_NOINLINE static occ_err_t collapse_and_apply(occ_ictx_t *const x,
                                                 const occ_insert_params_t *const params,
                                                 const occ_vec3_t *const origin,
                                                 occ_bitset_t *const cbs)
{
    occ_insert_result_t *const r = x->r;
    occ_code_t *codes, *spare; /* spare: free scratch after the fine codes, for the coarse ones */
    size_t m, spare_cap;
    if (x->bs != NULL) { /* set_prepare() read the set into x->b */
        m = x->n;
        codes = x->b;
        spare = x->b + m;
        spare_cap = x->b_cap - m;
    } else {
        occ_ictx_note(x, x->n, x->n);
        codes = occi_keyset_sort(x->a, x->b, x->n, x->hist);
        m = occi_keyset_unique(codes, x->n);
        spare = codes == x->a ? x->b : x->a;
        spare_cap = x->cap;
    }
    size_t hits = 0;
    for (size_t i = 0; i < m; i++) {
        hits += (size_t)(codes[i] >> 63);
    }
    occ_map_t *const map = x->map;
    if (x->cbs != NULL) {
        const occ_err_t ce = apply_coarse(x, cbs, codes, m, spare, spare_cap, origin, params);
        /* The extraction wrote its sort's temporary and the coarse codes at spare. */
        const size_t sw = ce == OCC_ERR_SCRATCH
                              ? spare_cap
                              : (cbs->n_touched > r->coarse_updated ? cbs->n_touched
                                                                     : r->coarse_updated);
        const size_t off = (size_t)(spare - (spare >= x->b ? x->b : x->a));
        occ_ictx_note(x, spare >= x->b ? 0u : off + sw, spare >= x->b ? off + sw : 0u);
        if (ce != OCC_OK) {
            return ce;
        }
    }
    size_t changed = 0;
    PROBE(pieces);
    occ_err_t e = occ_map_observe_codes(map, codes, m, &changed);
    if (e == OCC_ERR_NOMEM && params->auto_evict != NULL) {
        size_t applied = 0;
        e = evict_and_apply(map, origin, params, codes, m, &changed, &applied);
        r->voxels_updated = applied;
    }
    if (e != OCC_OK) {
        return e;
    }
    set_counts(r, m, hits, changed);
    return OCC_OK;
}

/* ---- the voxel set to the tree (set_to_tree) -----------------------------------------------
 * After the scan: the hits sorted and collapsed (at x->a, x->n of them), the set's chunk list
 * sorted. Then, in this order: the set and the hits straight to the tree by 4x4x4 bricks when
 * the pools surely suffice (set_bricks); else read into x->b as codes in one piece for
 * collapse_and_apply (set_prepare); else applied in pieces (set_pieces). The core reads the
 * set a brick at a time for all three (occi_dense_t, core/dense_read.c). */
OCC_NOINLINE static void set_sort(occ_ictx_t *const x)
{
    occ_ictx_note(x, 0, x->n);
    occ_code_t *const hs = occi_keyset_sort(x->a, x->b, x->n, x->hist);
    x->n = occi_keyset_unique(hs, x->n);
    if (hs != x->a) {
        memcpy(x->a, hs, x->n * sizeof *hs);
    }
    occi_vset_sort(x->bs, x->hist);
}

/* The set to the tree by bricks (not after FAST_DISCRETE's coarse pass, which needs the codes'
 * block count): true when applied; false, with nothing written, when the pools might not
 * suffice (the code paths then check exactly and evict). Out of line: the tree walk's frame
 * stays off the ray traversal's (make cross). */
OCC_NOINLINE static bool set_bricks(occ_ictx_t *const x)
{
    if (x->cbs != NULL || BRICKS_OFF()) {
        return false;
    }
    occi_dense_t d;
    occi_vset_dense(x->bs, x->a, x->n, &d);
    occi_dense_out_t o;
    if (occi_tree_apply_dense(x->map, &d, &o) != OCC_OK) {
        return false;
    }
    PROBE(bricks);
    set_counts(x->r, o.voxels, x->n, o.changed);
    return true;
}

/* x->b_cap widened to all the room between b and the set's chunks. When the set and the hits
 * fit there in one piece, they are read into x->b (x->n codes, as the sorted path leaves them
 * for collapse_and_apply) and true is returned; else x->a keeps the x->n hits and set_pieces()
 * applies the set in pieces. Out of line: its cursor stays off the tree update's stack. */
OCC_NOINLINE static bool set_prepare(occ_ictx_t *const x)
{
    x->b_cap = (size_t)(occi_vset_low(x->bs) - (uint8_t *)(void *)x->b) / 8u;
    if (x->n > x->b_cap || occi_vset_count(x->bs) > x->b_cap - x->n) {
        return false;
    }
    occi_dense_t d;
    occi_vset_dense(x->bs, x->a, x->n, &d);
    occi_dense_cursor_t cur = {0u, 0u, 0u};
    x->n = occi_dense_read(&d, &cur, x->b, x->b_cap);
    occ_ictx_note(x, 0, x->n);
    return true;
}

/* Pass 2: read and apply each piece (the same pieces as pass 1), counting. */
OCC_NOINLINE static occ_err_t set_apply(occ_ictx_t *const x, const occi_dense_t *const d)
{
    occ_insert_result_t *const r = x->r;
    occi_dense_cursor_t cur = {0u, 0u, 0u};
    size_t m;
    while ((m = occi_dense_read(d, &cur, x->b, x->b_cap)) > 0u) {
        occ_ictx_note(x, 0, m);
        size_t ch = 0;
        PROBE(pieces);
        const occ_err_t e = occ_map_observe_codes(x->map, x->b, m, &ch);
        if (e != OCC_OK) {
            return e; /* cannot happen: pass 1 checked the pools for these pieces */
        }
        r->voxels_updated += m;
        r->voxels_changed += ch;
    }
    r->voxels_occupied = x->n; /* every hit was read once, as a hit */
    r->voxels_free = r->voxels_updated - r->voxels_occupied;
    return OCC_OK;
}

/* The set in pieces: pass 1 - the blocks each piece's update can allocate as if none of its
 * nodes existed (so that pruning by one piece cannot make the next one fail), summed, counted
 * on the set's bricks -, the pool check (evicting for it first in automatic mode), pass 2. The
 * map is written only after the check. SIMPLE and DISCRETE only (trace_scan). */
OCC_NOINLINE static occ_err_t set_pieces(occ_ictx_t *const x,
                                         const occ_insert_params_t *const params,
                                         const occ_vec3_t *const origin)
{
    occi_dense_t d;
    occi_vset_dense(x->bs, x->a, x->n, &d);
    uint64_t ni, nl;
    size_t voxels;
    occi_dense_need(&d, x->b_cap, x->map->cfg.depth_levels, &ni, &nl, &voxels);
    if (!coarse_fits(x->map, origin, params, ni, nl)) {
        x->map->oom_count++;
        return OCC_ERR_NOMEM;
    }
    return set_apply(x, &d);
}

/* The scan's voxel set to the tree: by bricks, else as codes in one batch, else in pieces. */
static occ_err_t set_to_tree(occ_ictx_t *const x, const occ_insert_params_t *const params,
                             const occ_vec3_t *const origin, occ_bitset_t *const cbs)
{
    set_sort(x);
    if (set_bricks(x)) {
        return OCC_OK;
    }
    return set_prepare(x) ? collapse_and_apply(x, params, origin, cbs)
                          : set_pieces(x, params, origin);
}

/* out->scratch_used: the bytes of scratch the call wrote - the histograms, the filter (sorted
 * path), the end voxels, the voxel set (chunks, directory), the coarse set (words and touched
 * list) and the high-water marks of the two code arrays. Memory the call reserved but never
 * wrote is not counted. */
static size_t touched_bytes(const occ_ictx_t *const x, const occ_insert_params_t *const params,
                            const size_t cbricks)
{
    size_t b = OCC_KS_HIST_WORDS * 4u;
    if (x->bs == NULL) {
        b += FILTER_N * 8u;
    } else {
        b += occi_vset_bytes(x->bs);
    }
    if (params->method == OCC_INSERT_DISCRETE || params->method == OCC_INSERT_FAST_DISCRETE) {
        b += 8u * x->n_ends;
    }
    if (x->cbs != NULL) {
        b += 8u * (cbricks + x->cbs->n_touched);
    }
    return b + 8u * (x->a_hwm + x->b_hwm);
}

/* ---- entry: the call's steps ---------------------------------------------------------------- */
static occ_err_t check_args(const occ_map_t *const map, const occ_vec3_t *const origin,
                            const occ_vec3_t *const points, const size_t n_points,
                            const occ_insert_params_t *const params, const void *const scratch,
                            const size_t scratch_bytes)
{
    if (map == NULL || origin == NULL || params == NULL || (points == NULL && n_points > 0u) ||
        (scratch == NULL && scratch_bytes > 0u)) {
        return OCC_ERR_ARG;
    }
    if ((params->auto_evict != NULL && params->auto_evict_state == NULL) ||
        (unsigned)params->method > (unsigned)OCC_INSERT_SUPER_RAYS ||
        params->fast_d >= map->cfg.depth_levels || isnan(params->max_range_m)) {
        return OCC_ERR_ARG;
    }
    return occ_finite3(*origin) ? OCC_OK : OCC_ERR_ARG;
}

/* The context for one call: geometry, origin and its key, max range. */
static occ_err_t ictx_begin(occ_ictx_t *const x, occ_map_t *const map,
                            const occ_vec3_t *const origin, const occ_insert_params_t *const params,
                            occ_insert_result_t *const r)
{
    memset(x, 0, sizeof *x);
    x->map = map;
    x->r = r;
    occi_raygeo_init(&x->g, map);
    x->o[0] = origin->x;
    x->o[1] = origin->y;
    x->o[2] = origin->z;
    if (!occi_raygeo_key(&x->g, x->o, x->ko)) {
        return OCC_ERR_RANGE;
    }
    x->max_range = params->max_range_m > 0.0f ? params->max_range_m : -1.0f;
    x->max_range_r = (occ_rr_t)x->max_range;
    x->win_lo = 0;
    x->win_hi = OCC_CODE_HIT_BIT;
    return OCC_OK;
}

/* The scratch after the fixed carve: filter | histograms | end voxels (ends_n) | rest. */
typedef struct {
    occ_code_t *ends;
    uint8_t *rest;
    size_t rest_bytes;
} carve_t;

static bool carve_scratch(occ_ictx_t *const x, void *const scratch, const size_t scratch_bytes,
                          const size_t ends_n, carve_t *const c)
{
    uint8_t *const p = scratch != NULL ? align8(scratch) : NULL;
    const size_t pad = p != NULL ? (size_t)(p - (uint8_t *)scratch) : 0u;
    const size_t usable = occ_sat_sub(scratch_bytes, pad) < SCRATCH_MAX
                              ? occ_sat_sub(scratch_bytes, pad)
                              : SCRATCH_MAX;
    const size_t ends_bytes = occ_sat_mul(ends_n, 8u);
    if (p == NULL || usable < occ_sat_add(FIXED_RT, ends_bytes)) {
        return false;
    }
    x->filt = (occ_code_t *)(void *)p;
    x->hist = (uint32_t *)(void *)(p + FILTER_N * 8u);
    c->ends = (occ_code_t *)(void *)(p + FIXED_RT);
    c->rest = p + FIXED_RT + ends_bytes;
    c->rest_bytes = usable - FIXED_RT - ends_bytes;
    return true;
}

/* FAST_DISCRETE, d > 0: the coarse nodes' set over the same box at level d (2048 bricks per
 * axis are 2^33: the product saturates, it never wraps), carved from the rest. Returns its
 * bricks, or 0 when it does not fit. */
static size_t setup_coarse(occ_ictx_t *const x, const occ_insert_params_t *const params,
                           occ_bitset_t *const cbs, carve_t *const c)
{
    x->cd = params->fast_d;
    x->cn = params->fast_n;
    size_t cbricks = 1;
    for (unsigned a = 0; a < 3u; a++) {
        cbs->b0[a] = ((x->box_lo[a] >> x->cd) >> 2) & ~7u;
        cbs->nb[a] = ((((x->box_hi[a] >> x->cd) >> 2) - cbs->b0[a]) | 7u) + 1u;
        cbricks = occ_sat_mul(cbricks, cbs->nb[a]);
    }
    cbs->stride_y = cbs->nb[0] >> 3;
    cbs->stride_z = (size_t)(cbs->nb[0] >> 3) * (cbs->nb[1] >> 3);
    if (cbricks > c->rest_bytes / 32u) {
        return 0;
    }
    cbs->words = (uint64_t *)(void *)c->rest;
    cbs->touched = cbs->words + cbricks;
    c->rest += 16u * cbricks;
    c->rest_bytes -= 16u * cbricks;
    x->cbs = cbs;
    return cbricks;
}

/* Lay out one pass on the sorted path: the two code arrays. */
static void layout_sorted(occ_ictx_t *const x, const carve_t *const c)
{
    x->n = 0;
    x->a_hwm = 0;
    x->b_hwm = 0;
    memset(x->filt, 0xFF, FILTER_N * 8u); /* bit 63 set: never a code */
    x->bs = NULL;
    x->cap = c->rest_bytes / 16u;
    x->a = (occ_code_t *)(void *)c->rest;
    x->b = x->a + x->cap;
}

/* Codes of room at x->b while the set is built (the hits' sort, the super rays' tables); after
 * the scan it also takes the room the set's chunks left, and the set is read into it. */
#define SET_MIN_WORK 1024u
static size_t set_work(const occ_insert_params_t *const params, const size_t n_points,
                       const size_t hits_cap)
{
    size_t w = hits_cap > SET_MIN_WORK ? hits_cap : SET_MIN_WORK;
    if (params->method == OCC_INSERT_SUPER_RAYS) {
        const size_t sr = occi_superray_need(n_points) / 8u + 1u;
        w = sr > w ? sr : w;
    }
    return w;
}

/* Lay out one pass with the voxel set: the hits at a, the work room at b, the set above (its
 * chunks come down from the top). False when not one chunk fits. */
static bool layout_set(occ_ictx_t *const x, const carve_t *const c, occ_vset_t *const vs,
                       const size_t hits_cap, const size_t work, const size_t max_chunks)
{
    x->n = 0;
    x->a_hwm = 0;
    x->b_hwm = 0;
    const size_t low = occ_sat_mul(occ_sat_add(hits_cap, work), 8u);
    if (low >= c->rest_bytes ||
        !occi_vset_init(vs, c->rest + low, c->rest_bytes - low, max_chunks, x->g.depth)) {
        return false;
    }
    x->bs = vs;
    x->a = (occ_code_t *)(void *)c->rest;
    x->cap = hits_cap;
    x->b = x->a + hits_cap;
    x->b_cap = work;
    return true;
}

/* Build the voxel set when it surely fits (room for every chunk of the scan's box), or when the
 * sorted codes would not fit one batch (they would need windows: a set that runs full costs one
 * more trace, windows at least four). Else the sorted path, which then surely runs as one
 * batch: no trace is ever lost to a set that runs full where one batch was possible. */
static bool prefer_set(const carve_t *const c, const occ_insert_params_t *const params,
                       const size_t n_points, const size_t chunks, const size_t codes)
{
    const size_t hits_cap = occ_sat_add(n_points, 1u);
    const size_t low =
        occ_sat_mul(occ_sat_add(hits_cap, set_work(params, n_points, hits_cap)), 8u);
    const bool sure = low < c->rest_bytes && (c->rest_bytes - low) / OCC_VSET_CHUNK_BYTES >= chunks;
    return sure || occ_sat_mul(codes, 16u) > c->rest_bytes;
}

/* After a scan into the set by SUPER_RAYS or FAST_DISCRETE (not applied in pieces): do its
 * voxels, the hits and FAST_DISCRETE's coarse codes fit the room between b and the chunks? */
static bool set_fits_once(const occ_ictx_t *const x)
{
    const size_t room = (size_t)(occi_vset_low(x->bs) - (uint8_t *)(void *)x->b) / 8u;
    const size_t coarse = x->cbs != NULL ? x->cbs->n_set : 0u;
    return occ_sat_add(occ_sat_add(occi_vset_count(x->bs), x->n), coarse) <= room;
}

/* ---- bounded scratch: the scan in Morton-range windows ---------------------------------------
 * SIMPLE and DISCRETE on the sorted path: when the codes do not fit, occi_ictx_reserve() narrows
 * the window [win_lo, win_hi) to the codes it holds, and the pass ends with exactly the scan's
 * codes in that window (every ray was traced, codes outside were dropped). Each further pass
 * traces the scan again for the next window. Windows are disjoint, so "hit wins" and "once per
 * voxel" hold per key as in one batch. */
static bool chunkable(const occ_insert_params_t *const params)
{
    return params->method == OCC_INSERT_SIMPLE || params->method == OCC_INSERT_DISCRETE;
}

static int chunk_run(occ_ictx_t *x, const occ_insert_params_t *params, const occ_vec3_t *points,
                     size_t n_points, const carve_t *c, occ_code_t lo);

/* One more pass for the window starting at lo; -1 when the scratch ran out. */
static int chunk_trace(occ_ictx_t *const x, const occ_insert_params_t *const params,
                       const occ_vec3_t *const points, const size_t n_points,
                       const carve_t *const c, const occ_code_t lo)
{
    /* The first pass (trace_scan) counted the scan in the caller's result; later passes count
     * into a local that is dropped (here, not in run_chunks: off the tree update's stack). */
    occ_insert_result_t *const keep = x->r;
    occ_insert_result_t drop;
    memset(&drop, 0, sizeof drop);
    x->r = &drop;
    const int rc = chunk_run(x, params, points, n_points, c, lo);
    x->r = keep;
    return rc;
}

static int chunk_run(occ_ictx_t *const x, const occ_insert_params_t *const params,
                     const occ_vec3_t *const points, const size_t n_points,
                     const carve_t *const c, const occ_code_t lo)
{
    PROBE(traces);
    memset(x->filt, 0xFF, FILTER_N * 8u);
    x->n = 0;
    x->win_lo = lo;
    x->win_hi = OCC_CODE_HIT_BIT;
    if (params->method == OCC_INSERT_SIMPLE) { /* not run_method: no super-ray stack here */
        return occi_ictx_points(x, points, n_points, false);
    }
    if (x->cap < n_points) {
        return -1;
    }
    const size_t u = discretize(x, points, n_points, c->ends);
    const int rc = run_discrete(x, c->ends, u);
    return rc < 0 || x->hit == NULL ? rc : occi_ictx_points(x, points, n_points, true);
}

/* The pass's sorted, collapsed codes. */
static occ_code_t *chunk_collapse(occ_ictx_t *const x, size_t *const m)
{
    occ_ictx_note(x, x->n, x->n);
    occ_code_t *const codes = occi_keyset_sort(x->a, x->b, x->n, x->hist);
    *m = occi_keyset_unique(codes, x->n);
    return codes;
}

/* Pass 1 (the first window is already traced): the blocks every window can allocate, as if none
 * of its nodes existed (so pruning by one window cannot make the next one fail), summed.
 * False when the scratch ran out. */
static bool chunk_need(occ_ictx_t *const x, const occ_insert_params_t *const params,
                       const occ_vec3_t *const points, const size_t n_points,
                       const carve_t *const c, uint64_t *const ni, uint64_t *const nl)
{
    *ni = 0;
    *nl = 0;
    for (;;) {
        size_t m;
        const occ_code_t *const codes = chunk_collapse(x, &m);
        uint64_t wi, wl;
        occi_coarse_need(codes, m, 0, x->map->cfg.depth_levels, &wi, &wl);
        *ni += wi;
        *nl += wl;
        if (x->win_hi == OCC_CODE_HIT_BIT) {
            return true;
        }
        if (chunk_trace(x, params, points, n_points, c, x->win_hi) < 0) {
            return false;
        }
    }
}

/* Pass 2: trace and apply each window, counting into the caller's result. */
static occ_err_t chunk_apply(occ_ictx_t *const x, const occ_insert_params_t *const params,
                             const occ_vec3_t *const points, const size_t n_points,
                             const carve_t *const c)
{
    occ_insert_result_t *const r = x->r;
    occ_code_t lo = 0;
    do {
        if (chunk_trace(x, params, points, n_points, c, lo) < 0) {
            return OCC_ERR_SCRATCH; /* cannot happen: pass 1 ran the same windows */
        }
        size_t m, ch = 0;
        const occ_code_t *const codes = chunk_collapse(x, &m);
        for (size_t i = 0; i < m; i++) {
            r->voxels_occupied += (size_t)(codes[i] >> 63);
        }
        PROBE(pieces);
        const occ_err_t e = occ_map_observe_codes(x->map, codes, m, &ch);
        if (e != OCC_OK) {
            return e;
        }
        r->voxels_updated += m;
        r->voxels_changed += ch;
        lo = x->win_hi;
    } while (lo != OCC_CODE_HIT_BIT);
    r->voxels_free = r->voxels_updated - r->voxels_occupied;
    return OCC_OK;
}

/* The scan in windows: pass 1, the pool check (evicting for it first in automatic mode), pass 2.
 * The map is written only after the check. */
static occ_err_t run_chunks(occ_ictx_t *const x, const occ_insert_params_t *const params,
                            const occ_vec3_t *const points, const size_t n_points,
                            const carve_t *const c, const occ_vec3_t *const origin)
{
    uint64_t ni, nl;
    if (!chunk_need(x, params, points, n_points, c, &ni, &nl)) {
        return OCC_ERR_SCRATCH;
    }
    if (!coarse_fits(x->map, origin, params, ni, nl)) {
        x->map->oom_count++;
        return OCC_ERR_NOMEM;
    }
    return chunk_apply(x, params, points, n_points, c);
}

/* Trace the scan: into the voxel set (max_chunks > 0: prefer_set()) when it fits the scratch,
 * else as sorted codes (in windows for SIMPLE and DISCRETE). A set that runs full (or a ray
 * leaving the map) means one more pass on the sorted path; so does a set too big to apply in
 * one piece by SUPER_RAYS or FAST_DISCRETE. Returns run_method's code; x->bs says which path
 * holds the result. */
static int trace_scan(occ_ictx_t *const x, const occ_insert_params_t *const params,
                      const occ_vec3_t *const points, const size_t n_points, const carve_t *c,
                      occ_vset_t *const vs, const size_t max_chunks, const size_t cbricks)
{
    const size_t hits_cap = occ_sat_add(n_points, 1u);
    /* FAST_DISCRETE with n = 0 casts no voxel rays: only hits, no voxel set needed. */
    bool set = max_chunks > 0u && !(x->cbs != NULL && x->cn == 0u);
    int rc = 0;
    for (unsigned attempt = 0; attempt < 2u; attempt++) {
        if (x->cbs != NULL) {
            memset(x->cbs->words, 0, cbricks * 8u);
            x->cbs->n_touched = 0;
            x->cbs->n_set = 0;
            x->cbs->overflow = false;
        }
        set = set && layout_set(x, c, vs, hits_cap, set_work(params, n_points, hits_cap),
                                max_chunks);
        if (!set) {
            layout_sorted(x, c);
        }
        x->chunked = !set && chunkable(params);
        PROBE(traces);
        if (set) {
            PROBE(set_traces);
        }
        rc = run_method(x, params, points, n_points, c->ends);
        if (!set || (rc == 0 && !vs->overflow && (chunkable(params) || set_fits_once(x)))) {
            break;
        }
        memset(x->r, 0, sizeof *x->r);
        set = false;
    }
    return rc;
}

occ_err_t occ_map_insert_rays(occ_map_t *const map, const occ_vec3_t *const origin,
                              const occ_vec3_t *const points, const bool *const hit,
                              const size_t n_points, const occ_insert_params_t *const params,
                              void *const scratch, const size_t scratch_bytes,
                              occ_insert_result_t *const out)
{
    occ_insert_result_t local;
    /* cppcheck-suppress uninitvar ; only its address is taken here (cppcheck 2.10 flags &x of a fresh local) */
    occ_insert_result_t *const r = out != NULL ? out : &local;
    memset(r, 0, sizeof *r);
    PROBE_RESET();
    occ_err_t e = check_args(map, origin, points, n_points, params, scratch, scratch_bytes);
    occ_ictx_t x;
    if (e != OCC_OK || (e = ictx_begin(&x, map, origin, params, r)) != OCC_OK) {
        return e;
    }
    x.hit = hit;
    carve_t c;
    if (!carve_scratch(&x, scratch, scratch_bytes, uses_ends(params->method) ? n_points : 0u,
                       &c)) {
        return OCC_ERR_SCRATCH;
    }
    occ_vset_t vs;
    occ_bitset_t cbs;
    memset(&vs, 0, sizeof vs);
    memset(&cbs, 0, sizeof cbs);
    size_t codes;
    const size_t chunks = box_chunks(&x, points, n_points, &codes);
    size_t cbricks = 0;
    if (params->method == OCC_INSERT_FAST_DISCRETE && params->fast_d > 0u &&
        (cbricks = setup_coarse(&x, params, &cbs, &c)) == 0u) {
        return OCC_ERR_SCRATCH;
    }
    const int rc = trace_scan(&x, params, points, n_points, &c, &vs,
                              prefer_set(&c, params, n_points, chunks, codes) ? chunks : 0u,
                              cbricks);
    occ_ictx_note(&x, x.n, 0);
    /* A shared map publishes the scan's evictions, coarse and voxel updates as one version. */
    const bool shared = map->priv.shared != NULL && occ_map_write_begin(map) == OCC_OK;
    if (rc < 0 || (x.cbs != NULL && cbs.overflow)) {
        e = OCC_ERR_SCRATCH;
    } else if (x.win_hi != OCC_CODE_HIT_BIT) {
        e = run_chunks(&x, params, points, n_points, &c, origin);
    } else if (x.bs != NULL) {
        e = set_to_tree(&x, params, origin, &cbs);
    } else {
        e = collapse_and_apply(&x, params, origin, &cbs);
    }
    if (shared) {
        (void)occ_map_write_end(map);
    }
    r->scratch_used = touched_bytes(&x, params, cbricks);
    return e;
}

occ_err_t occ_map_insert_cloud(occ_map_t *const map, const occ_vec3_t *const origin,
                               const occ_vec3_t *const points, const size_t n_points,
                               const occ_insert_params_t *const params, void *const scratch,
                               const size_t scratch_bytes, occ_insert_result_t *const out)
{
    return occ_map_insert_rays(map, origin, points, NULL, n_points, params, scratch,
                               scratch_bytes, out);
}
