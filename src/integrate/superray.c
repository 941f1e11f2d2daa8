/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * superray.c - super rays (Kim et al. 2017), exact: points ending in the same voxel whose rays
 * cross the voxel grid in the same order share one traversal. The order of an a-plane and a
 * b-plane crossing flips only where a ray passes a grid edge (the paper's mapping lines); per
 * axis pair we list the grid edges inside the bundle (between its two extreme rays) and give
 * every ray the count of those it passes on one side - its signature. Rays with equal signatures
 * in the three projections visit the same voxels; each signature is traversed once with the
 * DDA of one of its rays. The decisions use each ray's own DDA numbers (tMax, tDelta), and a
 * ray within a relative 1e-9 of a decision, or ending within 1e-4 voxel of its voxel's faces,
 * is cast singly: the result is SIMPLE's, voxel for voxel.
 */
#include <math.h>
#include <string.h>

#include "integrate_internal.h"
#include "../core/sat_internal.h"

#define SR_MAX_GROUP 4096u  /* rays handled together (a bigger cell is done in parts) */
#define SR_MAX_EDGES 4096u  /* grid edges per projection inside one bundle */

typedef struct {
    occ_rr_t sigma[3]; /* per projection (a, b): |d_b| / |d_a| of the ray's float direction */
    uint32_t point;
} sr_ray_t;

/* Signatures are numbered l0 + (ne0+1) (l1 + (ne1+1) l2); when that count fits SR_STAMPS, the
 * first ray of each is found by stamping a table (no sort). */
#define SR_STAMPS 4096u

typedef struct {
    sr_ray_t *rays;
    occ_rr_t *edges;    /* SR_MAX_EDGES critical slopes per projection, sorted */
    uint64_t *keys;     /* signature keys when the stamps do not fit */
    uint32_t *stamp;    /* SR_STAMPS entries: the bundle that last cast this signature */
    uint32_t bundle;    /* this bundle's stamp (never 0) */
} sr_ws_t;

static const unsigned PA[3] = {0u, 0u, 1u}, PB[3] = {1u, 2u, 2u};

static void cast_one(occ_ictx_t *const x, const occ_vec3_t p, const uint32_t ke[3])
{
    const float e[3] = {p.x, p.y, p.z};
    occi_ictx_set_ray(x, e, ke);
}

/* A ray's DDA takes its m_a-th a-crossing before its m_b-th b-crossing iff
 *   (dx0_a + m_a res) / |d_a| < (dx0_b + m_b res) / |d_b|  <=>  sigma_ab < s*(m_a, m_b),
 * with dx0 the distance from the origin to the first plane ahead (OctoMap's voxelBorder) and
 * s* = (dx0_b + m_b res) / (dx0_a + m_a res), the same for every ray of the bundle. The DDA's
 * own rounding is ~1e-15 relative: decisions closer than 1e-9 are left to a single cast. */
#define SR_TIE ((occ_rr_t)1e-9)

/* Critical slopes of projection (a, b) between the bundle's extreme slopes, sorted. */
static bool list_edges(const occ_rr_t lo, const occ_rr_t hi, const occ_rr_t dxa,
                       const occ_rr_t dxb, const occ_rr_t res, const uint32_t na,
                       const uint32_t nb, occ_rr_t *const out, uint32_t *const n_out)
{
    uint32_t n = 0;
    const occ_rr_t wlo = lo * ((occ_rr_t)1 - (occ_rr_t)2 * SR_TIE);
    const occ_rr_t whi = hi * ((occ_rr_t)1 + (occ_rr_t)2 * SR_TIE);
    for (uint32_t ma = 0; ma < na; ma++) {
        const occ_rr_t da = dxa + (occ_rr_t)ma * res;
        if (!(da > (occ_rr_t)0)) {
            continue; /* crossing at t = 0: same for every ray */
        }
        occ_rr_t f = (wlo * da - dxb) / res;
        occ_rr_t l = (whi * da - dxb) / res;
        f = f < (occ_rr_t)0 ? (occ_rr_t)0 : f;
        l = l > (occ_rr_t)nb ? (occ_rr_t)nb : l;
        if (!(f <= l)) {
            continue;
        }
        for (uint32_t mb = (uint32_t)f; mb <= (uint32_t)l && mb < nb; mb++) {
            const occ_rr_t sc = (dxb + (occ_rr_t)mb * res) / da;
            if (sc < wlo || sc > whi) {
                continue;
            }
            if (n == SR_MAX_EDGES) {
                return false;
            }
            size_t j = n++; /* insertion: lists are short */
            while (j > 0u && out[j - 1u] > sc) {
                out[j] = out[j - 1u];
                j--;
            }
            out[j] = sc;
        }
    }
    *n_out = n;
    return true;
}

/* Number of critical slopes below `sg` (ed[0..ne) sorted) into *l; false when sg lies within
 * the tie margin of one (then the ray is cast singly). */
static inline bool rank_of(const occ_rr_t *ed, uint32_t ne, occ_rr_t sg, uint32_t *l)
{
    if (ne == 0u) {
        *l = 0;
        return true;
    }
    uint32_t lo = 0, hi = ne; /* first edge >= sg */
    while (lo < hi) {
        const uint32_t mid = (lo + hi) / 2u;
        if (ed[mid] < sg) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    *l = lo;
    return !((lo < ne && ed[lo] - sg <= SR_TIE * ed[lo]) ||
             (lo > 0u && sg - ed[lo - 1u] <= SR_TIE * sg));
}

/* What every ray of one end voxel shares: per axis, the voxel steps from the origin's voxel
 * (nax), their direction (sgn) and the distance from the origin to the first plane ahead (dx0). */
typedef struct {
    uint32_t nax[3];
    int32_t sgn[3];
    occ_rr_t dx0[3];
    occ_rr_t margin; /* end points nearer than this (voxels) to their voxel's faces go singly */
} sr_axes_t;

static void bundle_axes(const occ_ictx_t *const x, const uint32_t ke[3], sr_axes_t *const ax)
{
    for (unsigned a = 0; a < 3u; a++) {
        ax->nax[a] = ke[a] > x->ko[a] ? ke[a] - x->ko[a] : x->ko[a] - ke[a];
        ax->sgn[a] = ke[a] > x->ko[a] ? 1 : -1;
        /* OctoMap's voxelBorder for this step direction, as a distance ahead of the origin. */
        occ_rr_t border = ((occ_rr_t)((int32_t)x->ko[a] - x->g.tmv) + (occ_rr_t)0.5) * x->g.res;
        border += (occ_rr_t)(float)((occ_rr_t)ax->sgn[a] * x->g.res * (occ_rr_t)0.5);
        ax->dx0[a] = (border - (occ_rr_t)x->o[a]) * (occ_rr_t)ax->sgn[a];
    }
    ax->margin =
        (occ_rr_t)1e-4 + (occ_rr_t)1e-6 * (occ_rr_t)(ax->nax[0] + ax->nax[1] + ax->nax[2]);
}

/* The ray to e: its DDA direction d (float difference, float length, float division), and
 * whether it may share a traversal - it steps the bundle's way on every axis, and its end lies
 * away from its voxel's faces, so the DDA reaches the end voxel by its crossings, not by the
 * length test. */
static bool ray_shareable(const occ_ictx_t *const x, const float e[3], const uint32_t ke[3],
                          const sr_axes_t *const ax, float d[3])
{
    const float len = (float)occi_raygeo_dist(x->o, e);
    bool safe = true;
    for (unsigned a = 0; a < 3u; a++) {
        d[a] = (e[a] - x->o[a]) / len;
        const int32_t st = d[a] > 0.0f ? 1 : (d[a] < 0.0f ? -1 : 0);
        if (ax->nax[a] > 0u && st != ax->sgn[a]) {
            safe = false;
        }
        /* The end voxel's key is ke, so its lower face is at ke - tmv (key units). */
        const occ_rr_t frac = x->g.rf * (occ_rr_t)e[a] - (occ_rr_t)((int32_t)ke[a] - x->g.tmv);
        if (frac < ax->margin || frac > (occ_rr_t)1 - ax->margin) {
            safe = false;
        }
    }
    return safe;
}

/* The shareable rays of idx[0..cnt) into ws->rays with their slopes, and per projection the
 * slopes' range [lo, hi]; the others are cast singly. Returns how many were kept. */
static size_t collect_rays(occ_ictx_t *const x, const occ_vec3_t *const points,
                           const uint32_t *const idx, const size_t cnt, const uint32_t ke[3],
                           const sr_axes_t *const ax, sr_ws_t *const ws, occ_rr_t lo[3],
                           occ_rr_t hi[3])
{
    size_t nr = 0;
    for (size_t j = 0; j < cnt; j++) {
        const occ_vec3_t p = points[idx[j]];
        const float e[3] = {p.x, p.y, p.z};
        float d[3];
        if (!ray_shareable(x, e, ke, ax, d)) {
            cast_one(x, p, ke);
            continue;
        }
        sr_ray_t *const r = &ws->rays[nr];
        for (unsigned q = 0; q < 3u; q++) {
            const occ_rr_t da = (occ_rr_t)fabsf(d[PA[q]]), db = (occ_rr_t)fabsf(d[PB[q]]);
            r->sigma[q] = da > (occ_rr_t)0 ? db / da : (occ_rr_t)0;
            if (nr == 0u || r->sigma[q] < lo[q]) {
                lo[q] = r->sigma[q];
            }
            if (nr == 0u || r->sigma[q] > hi[q]) {
                hi[q] = r->sigma[q];
            }
        }
        r->point = idx[j];
        nr++;
    }
    return nr;
}

/* Per projection, the critical slopes inside [lo, hi] into ws->edges, their counts into ne[].
 * False when a projection has more than SR_MAX_EDGES. */
static bool bundle_edges(const occ_ictx_t *const x, const sr_axes_t *const ax,
                         const occ_rr_t lo[3], const occ_rr_t hi[3], sr_ws_t *const ws,
                         uint32_t ne[3])
{
    for (unsigned q = 0; q < 3u; q++) {
        const unsigned a = PA[q], b = PB[q];
        if (ax->nax[a] > 0u && ax->nax[b] > 0u &&
            !list_edges(lo[q], hi[q], ax->dx0[a], ax->dx0[b], x->g.res, ax->nax[a], ax->nax[b],
                        ws->edges + q * SR_MAX_EDGES, &ne[q])) {
            return false;
        }
    }
    return true;
}

/* Each kept ray's signature (per projection, how many critical slopes lie below its slope).
 * A ray near a slope is cast singly; with few signatures the first ray of each is cast here
 * (stamp table), else its key goes to ws->keys for sorting. Returns the number of keys. */
static size_t cast_signatures(occ_ictx_t *const x, const occ_vec3_t *const points,
                              const uint32_t ke[3], const size_t nr, const uint32_t ne[3],
                              sr_ws_t *const ws)
{
    const uint32_t dim0 = ne[0] + 1u, dim1 = ne[1] + 1u;
    const bool stamped = (uint64_t)dim0 * dim1 * (ne[2] + 1u) <= SR_STAMPS;
    if (stamped) {
        ws->bundle++;
    }
    size_t nk = 0;
    for (size_t j = 0; j < nr; j++) {
        const sr_ray_t *const r = &ws->rays[j];
        uint32_t l[3];
        bool safe = true;
        for (unsigned q = 0; q < 3u && safe; q++) {
            safe = rank_of(ws->edges + q * SR_MAX_EDGES, ne[q], r->sigma[q], &l[q]);
        }
        if (!safe) {
            cast_one(x, points[r->point], ke);
        } else if (stamped) {
            const uint32_t sig = l[0] + dim0 * (l[1] + dim1 * l[2]);
            if (ws->stamp[sig] != ws->bundle) {
                ws->stamp[sig] = ws->bundle;
                cast_one(x, points[r->point], ke);
            }
        } else {
            const uint64_t sig = (uint64_t)l[0] | ((uint64_t)l[1] << 15) | ((uint64_t)l[2] << 30);
            ws->keys[nk++] = (sig << 16) | (uint64_t)j; /* 45 + 16 bits, bit 63 clear */
        }
    }
    return nk;
}

/* Shell sort: keys come at most SR_MAX_GROUP at a time. */
static void sort_keys(uint64_t *const sk, const size_t nk)
{
    static const uint16_t gaps[] = {1750, 701, 301, 132, 57, 23, 10, 4, 1};
    for (size_t gi = 0; gi < sizeof gaps / sizeof gaps[0] && nk > 1u; gi++) {
        const size_t gap = gaps[gi];
        for (size_t i = gap; i < nk; i++) {
            const uint64_t v = sk[i];
            size_t j = i;
            while (j >= gap && sk[j - gap] > v) {
                sk[j] = sk[j - gap];
                j -= gap;
            }
            sk[j] = v;
        }
    }
}

/* Rays of one end voxel (point indices idx[0..cnt), cnt <= SR_MAX_GROUP): one traversal per
 * signature. */
static void run_bundle(occ_ictx_t *const x, const occ_vec3_t *const points,
                       const uint32_t *const idx, const size_t cnt, const uint32_t ke[3],
                       sr_ws_t *const ws)
{
    sr_axes_t ax;
    bundle_axes(x, ke, &ax);
    occ_rr_t lo[3], hi[3];
    const size_t nr = collect_rays(x, points, idx, cnt, ke, &ax, ws, lo, hi);
    if (nr == 0u) {
        return;
    }
    uint32_t ne[3] = {0, 0, 0};
    /* Edges split the bundle into at most edges + 1 super rays: with too many, signatures cost
     * more than they save - cast singly. */
    if (!bundle_edges(x, &ax, lo, hi, ws, ne) || (size_t)(ne[0] + ne[1] + ne[2]) * 3u + 3u > nr) {
        for (size_t j = 0; j < nr; j++) {
            cast_one(x, points[ws->rays[j].point], ke);
        }
        return;
    }
    /* Many signatures: one traversal per distinct one, found by sorting their keys. */
    const size_t nk = cast_signatures(x, points, ke, nr, ne, ws);
    sort_keys(ws->keys, nk);
    for (size_t i = 0; i < nk; i++) {
        if (i == 0u || (ws->keys[i] >> 16) != (ws->keys[i - 1u] >> 16)) {
            cast_one(x, points[ws->rays[ws->keys[i] & 0xFFFFu].point], ke);
        }
    }
}

/* The `cnt` points idx[] ending in the box's cell `cell`: the hit, then their rays - singly when
 * the bundle is too small or too spread to share traversals. False when scratch ran out. */
static bool run_voxel(occ_ictx_t *const x, const occ_vec3_t *const points,
                      const uint32_t *const idx, const size_t cnt, const uint64_t cell,
                      const uint64_t bx, const uint64_t by, const uint16_t k_min,
                      sr_ws_t *const ws)
{
    const uint32_t ke[3] = {x->box_lo[0] + (uint32_t)(cell % bx),
                            x->box_lo[1] + (uint32_t)((cell / bx) % by),
                            x->box_lo[2] + (uint32_t)(cell / bx / by)};
    const occ_key_t kk = {{ke[0], ke[1], ke[2]}};
    if (!occi_ictx_reserve(x, 1u)) {
        return false;
    }
    occ_ictx_emit(x, occ_morton_encode(kk) | OCC_CODE_HIT_BIT);
    if (ke[0] == x->ko[0] && ke[1] == x->ko[1] && ke[2] == x->ko[2]) {
        return true; /* ends in the origin's voxel: no free voxel */
    }
    const size_t span = (size_t)(ke[0] > x->ko[0] ? ke[0] - x->ko[0] : x->ko[0] - ke[0]) +
                        (ke[1] > x->ko[1] ? ke[1] - x->ko[1] : x->ko[1] - ke[1]) +
                        (ke[2] > x->ko[2] ? ke[2] - x->ko[2] : x->ko[2] - ke[2]);
    /* A bundle that spans its voxel has ~ (crossings / 2) edges inside: with fewer points than
     * that, super rays cannot pay for themselves - cast singly right away. */
    if (cnt < (size_t)k_min || cnt <= span / 2u) {
        for (size_t j = 0; j < cnt; j++) {
            cast_one(x, points[idx[j]], ke);
        }
        return true;
    }
    for (size_t j = 0; j < cnt; j += SR_MAX_GROUP) {
        run_bundle(x, points, idx + j, cnt - j < SR_MAX_GROUP ? cnt - j : SR_MAX_GROUP, ke, ws);
    }
    return true;
}

/* The voxel set path's room at x->b, carved: end cells and point indices (sorted as pairs, with
 * room for the sort's second copy), then the per-bundle workspace. */
typedef struct {
    uint64_t *keys, *tkeys; /* end cell per point, and the sort's second buffer */
    uint32_t *vals, *tvals; /* the point's index, and the sort's second buffer */
    uint64_t bx, by;        /* the scan box's size in voxels along x and y */
} sr_cells_t;

size_t occi_superray_need(const size_t n)
{
    return occ_sat_add(occ_sat_mul(n, 24u), SR_MAX_GROUP * (sizeof(sr_ray_t) + 8u) +
                                                3u * SR_MAX_EDGES * sizeof(occ_rr_t) +
                                                SR_STAMPS * 4u + 64u);
}

static void carve_scratch(occ_ictx_t *const x, const size_t n, sr_cells_t *const c,
                          sr_ws_t *const ws)
{
    c->keys = x->b;
    c->tkeys = c->keys + n;
    c->vals = (uint32_t *)(void *)(c->tkeys + n);
    c->tvals = c->vals + n;
    c->bx = (uint64_t)(x->box_hi[0] - x->box_lo[0]) + 1u;
    c->by = (uint64_t)(x->box_hi[1] - x->box_lo[1]) + 1u;
    ws->rays = (sr_ray_t *)(void *)(c->keys + 3u * n);
    ws->edges = (occ_rr_t *)(void *)(ws->rays + SR_MAX_GROUP);
    ws->keys = (uint64_t *)(void *)(ws->edges + 3u * SR_MAX_EDGES);
    ws->stamp = (uint32_t *)(void *)(ws->keys + SR_MAX_GROUP);
    memset(ws->stamp, 0, SR_STAMPS * sizeof *ws->stamp);
    ws->bundle = 0;
}

/* Each point's end cell (its voxel's index in the scan's box: grouping needs no Morton order,
 * and the box index sorts in fewer radix passes) into c->keys / c->vals; points out of range
 * or outside the map go through occi_ictx_point() right away. False when scratch ran out. */
static bool bin_points(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n,
                       const sr_cells_t *const c, size_t *const m_out)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (!occ_finite3(points[i])) {
            x->r->points_skipped++;
            continue;
        }
        const float q[3] = {points[i].x, points[i].y, points[i].z};
        uint32_t k[3];
        if (!occ_ictx_hit(x, i) ||
            (x->max_range > 0.0f && occi_raygeo_dist(x->o, q) > x->max_range_r) ||
            !occi_raygeo_key(&x->g, q, k)) {
            /* no-hit or clipped ray, or a bad point: cast singly */
            const int rc = occi_ictx_point(x, q, occ_ictx_hit(x, i));
            if (rc < 0) {
                return false;
            }
            x->r->points_integrated += rc == 0 ? 1u : 0u;
            x->r->points_skipped += rc > 0 ? 1u : 0u;
            continue;
        }
        c->keys[m] = (uint64_t)(k[0] - x->box_lo[0]) +
                     c->bx * ((uint64_t)(k[1] - x->box_lo[1]) +
                              c->by * (uint64_t)(k[2] - x->box_lo[2]));
        c->vals[m] = (uint32_t)i;
        m++;
    }
    x->r->points_integrated += m;
    *m_out = m;
    return true;
}

/* A small box (coarse resolution): group the m binned points by counting sort, the histogram in
 * tkeys' room, then run each cell. */
static bool run_cells_counted(occ_ictx_t *const x, const occ_vec3_t *const points,
                              const sr_cells_t *const c, const size_t m, const uint64_t cells,
                              const uint16_t k_min, sr_ws_t *const ws)
{
    uint32_t *const hist = (uint32_t *)(void *)c->tkeys;
    memset(hist, 0, (size_t)cells * sizeof *hist);
    for (size_t i = 0; i < m; i++) {
        hist[c->keys[i]]++;
    }
    uint32_t sum = 0;
    for (size_t cell = 0; cell < (size_t)cells; cell++) {
        const uint32_t h = hist[cell];
        hist[cell] = sum;
        sum += h;
    }
    for (size_t i = 0; i < m; i++) {
        c->tvals[hist[c->keys[i]]++] = c->vals[i]; /* hist[cell] ends as the end of its run */
    }
    for (size_t cell = 0, s0 = 0; cell < (size_t)cells; cell++) {
        if (hist[cell] > s0 && !run_voxel(x, points, c->tvals + s0, hist[cell] - s0, cell, c->bx,
                                          c->by, k_min, ws)) {
            return false;
        }
        s0 = hist[cell];
    }
    return true;
}

/* A large box: group the m binned points by radix sort, then run each run of equal cells. */
static bool run_cells_sorted(occ_ictx_t *const x, const occ_vec3_t *const points,
                             const sr_cells_t *const c, const size_t m, const uint16_t k_min,
                             sr_ws_t *const ws)
{
    const uint64_t *const sk =
        occi_keyset_sort_pairs(c->keys, c->vals, c->tkeys, c->tvals, m, x->hist);
    const uint32_t *const sv = sk == c->keys ? c->vals : c->tvals;
    for (size_t s0 = 0; s0 < m;) {
        size_t e = s0 + 1u;
        while (e < m && sk[e] == sk[s0]) {
            e++;
        }
        if (!run_voxel(x, points, sv + s0, e - s0, sk[s0], c->bx, c->by, k_min, ws)) {
            return false;
        }
        s0 = e;
    }
    return true;
}

bool occi_superray_run(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n,
                       const uint16_t k_min)
{
    const size_t need = occi_superray_need(n);
    if (x->bs == NULL || x->b_cap < need / 8u + 1u || n >= UINT32_MAX) {
        return occi_ictx_points(x, points, n, false) == 0;
    }
    occ_ictx_note(x, 0, need / 8u + 1u);
    sr_cells_t c;
    sr_ws_t ws;
    carve_scratch(x, n, &c, &ws);
    size_t m = 0;
    occi_ictx_lanes_begin(x);
    bool ok = bin_points(x, points, n, &c, &m);
    if (ok) {
        const uint64_t cells = c.bx * c.by * ((uint64_t)(x->box_hi[2] - x->box_lo[2]) + 1u);
        ok = cells <= 2u * (uint64_t)m ? run_cells_counted(x, points, &c, m, cells, k_min, &ws)
                                       : run_cells_sorted(x, points, &c, m, k_min, &ws);
    }
    occi_ictx_lanes_end(x);
    return ok;
}
