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

#define SR_MAX_GROUP 4096u  /* rays handled together (a bigger cell is done in parts) */
#define SR_MAX_EDGES 4096u  /* grid edges per projection inside one bundle */

typedef struct {
    occ_rr_t sigma[3]; /* per projection (a, b): |d_b| / |d_a| of the ray's float direction */
    uint32_t point;
} sr_ray_t;

typedef struct {
    sr_ray_t *rays;
    occ_rr_t *edges;    /* SR_MAX_EDGES critical slopes per projection, sorted */
    uint64_t *keys, *tkeys;
} sr_ws_t;

static const unsigned PA[3] = {0u, 0u, 1u}, PB[3] = {1u, 2u, 2u};

static void cast_one(occ_ictx_t *const x, const occ_vec3_t p, const uint32_t ke[3])
{
    const float e[3] = {p.x, p.y, p.z};
    x->r->voxel_visits += occ_dda_mark(&x->g, x->o, e, x->ko, ke, x->bs);
    x->r->rays_cast++;
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

/* Rays of one end voxel (point indices idx[0..cnt), cnt <= SR_MAX_GROUP). */
static void run_bundle(occ_ictx_t *const x, const occ_vec3_t *const points,
                       const uint32_t *const idx, const size_t cnt, const uint32_t ke[3],
                       sr_ws_t *const ws)
{
    uint32_t nax[3];
    int32_t sgn[3];
    occ_rr_t dx0[3];
    for (unsigned a = 0; a < 3u; a++) {
        nax[a] = ke[a] > x->ko[a] ? ke[a] - x->ko[a] : x->ko[a] - ke[a];
        sgn[a] = ke[a] > x->ko[a] ? 1 : -1;
        /* OctoMap's voxelBorder for this step direction, as a distance ahead of the origin. */
        occ_rr_t border = ((occ_rr_t)((int32_t)x->ko[a] - x->g.tmv) + (occ_rr_t)0.5) * x->g.res;
        border += (occ_rr_t)(float)((occ_rr_t)sgn[a] * x->g.res * (occ_rr_t)0.5);
        dx0[a] = (border - (occ_rr_t)x->o[a]) * (occ_rr_t)sgn[a];
    }
    const occ_rr_t margin =
        (occ_rr_t)1e-4 + (occ_rr_t)1e-6 * (occ_rr_t)(nax[0] + nax[1] + nax[2]);
    occ_rr_t lo[3], hi[3];
    size_t nr = 0;
    for (size_t j = 0; j < cnt; j++) {
        const occ_vec3_t p = points[idx[j]];
        const float e[3] = {p.x, p.y, p.z};
        /* The DDA's direction: float difference, float length, float division. */
        const float len = (float)occ_raygeo_dist(x->o, e);
        float d[3];
        bool safe = true;
        for (unsigned a = 0; a < 3u; a++) {
            d[a] = (e[a] - x->o[a]) / len;
            const int32_t st = d[a] > 0.0f ? 1 : (d[a] < 0.0f ? -1 : 0);
            if (nax[a] > 0u && st != sgn[a]) {
                safe = false;
            }
            /* The end point away from its voxel's faces: the DDA then reaches the end voxel
             * by its crossings, not by the length test. */
            const occ_rr_t f = x->g.rf * (occ_rr_t)e[a];
            const occ_rr_t fl = (occ_rr_t)(int32_t)f - (f < (occ_rr_t)(int32_t)f ? 1 : 0);
            const occ_rr_t frac = f - fl;
            if (frac < margin || frac > (occ_rr_t)1 - margin) {
                safe = false;
            }
        }
        if (!safe) {
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
    if (nr == 0u) {
        return;
    }
    uint32_t ne[3] = {0, 0, 0};
    bool ok = true;
    for (unsigned q = 0; q < 3u && ok; q++) {
        const unsigned a = PA[q], b = PB[q];
        if (nax[a] > 0u && nax[b] > 0u) {
            ok = list_edges(lo[q], hi[q], dx0[a], dx0[b], x->g.res, nax[a], nax[b],
                            ws->edges + q * SR_MAX_EDGES, &ne[q]);
        }
    }
    /* Edges split the bundle into at most edges + 1 super rays: with too many, signatures cost
     * more than they save - cast singly. */
    if (!ok || (size_t)(ne[0] + ne[1] + ne[2]) * 3u + 3u > nr) {
        for (size_t j = 0; j < nr; j++) {
            cast_one(x, points[ws->rays[j].point], ke);
        }
        return;
    }
    /* Signatures: per projection, how many critical slopes lie below the ray's slope. */
    size_t nk = 0;
    for (size_t j = 0; j < nr; j++) {
        const sr_ray_t *const r = &ws->rays[j];
        uint64_t sig = 0;
        bool safe = true;
        for (unsigned q = 0; q < 3u && safe; q++) {
            const occ_rr_t *const ed = ws->edges + q * SR_MAX_EDGES;
            const occ_rr_t sg = r->sigma[q];
            uint32_t l = 0, h = ne[q]; /* first edge >= sg */
            while (l < h) {
                const uint32_t mid = (l + h) / 2u;
                if (ed[mid] < sg) {
                    l = mid + 1u;
                } else {
                    h = mid;
                }
            }
            if ((l < ne[q] && ed[l] - sg <= SR_TIE * ed[l]) ||
                (l > 0u && sg - ed[l - 1u] <= SR_TIE * sg)) {
                safe = false;
            }
            sig |= (uint64_t)l << (15u * q);
        }
        if (!safe) {
            cast_one(x, points[r->point], ke);
            continue;
        }
        ws->keys[nk++] = (sig << 16) | (uint64_t)j; /* 45 + 16 bits, bit 63 clear */
    }
    /* One traversal per signature (Shell sort: bundles hold at most SR_MAX_GROUP rays). */
    static const uint16_t gaps[] = {1750, 701, 301, 132, 57, 23, 10, 4, 1};
    uint64_t *const sk = ws->keys;
    for (size_t gi = 0; gi < sizeof gaps / sizeof gaps[0]; gi++) {
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
    const uint64_t *const s = sk;
    for (size_t i = 0; i < nk; i++) {
        if (i == 0u || (s[i] >> 16) != (s[i - 1u] >> 16)) {
            cast_one(x, points[ws->rays[s[i] & 0xFFFFu].point], ke);
        }
    }
}

static bool run_single(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const float q[3] = {points[i].x, points[i].y, points[i].z};
        const int rc = occ_ictx_point(x, q);
        if (rc < 0) {
            return false;
        }
        if (rc == 0) {
            x->r->points_integrated++;
        } else {
            x->r->points_skipped++;
        }
    }
    return true;
}

bool occ_superray_run(occ_ictx_t *const x, const occ_vec3_t *const points, const size_t n,
                      const uint16_t k_min)
{
    /* Workspace in the dense path's free scratch: end codes and point indices (sorted as
     * pairs), per-bundle rays, edges and signature keys. */
    const size_t need = n * 24u + SR_MAX_GROUP * (sizeof(sr_ray_t) + 16u) +
                        3u * SR_MAX_EDGES * sizeof(occ_rr_t) + 64u;
    if (x->bs == NULL || x->b_cap * 8u < need || n >= UINT32_MAX) {
        return run_single(x, points, n);
    }
    uint64_t *const keys = x->b;
    uint64_t *const tkeys = keys + n;
    uint32_t *const vals = (uint32_t *)(void *)(tkeys + n);
    uint32_t *const tvals = vals + n;
    sr_ws_t ws;
    ws.rays = (sr_ray_t *)(void *)(keys + 3u * n);
    ws.edges = (occ_rr_t *)(void *)(ws.rays + SR_MAX_GROUP);
    ws.keys = (uint64_t *)(void *)(ws.edges + 3u * SR_MAX_EDGES);
    ws.tkeys = ws.keys + SR_MAX_GROUP;

    const uint64_t bx = (uint64_t)(x->box_hi[0] - x->box_lo[0]) + 1u;
    const uint64_t by = (uint64_t)(x->box_hi[1] - x->box_lo[1]) + 1u;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        const float q[3] = {points[i].x, points[i].y, points[i].z};
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
            x->r->points_skipped++;
            continue;
        }
        uint32_t k[3];
        if ((x->max_range > 0.0f && occ_raygeo_dist(x->o, q) > x->max_range_r) ||
            !occ_raygeo_key(&x->g, q, k)) {
            const int rc = occ_ictx_point(x, q); /* clipped ray, or a bad point */
            if (rc < 0) {
                return false;
            }
            x->r->points_integrated += rc == 0 ? 1u : 0u;
            x->r->points_skipped += rc > 0 ? 1u : 0u;
            continue;
        }
        /* Grouping needs no Morton order: the voxel's index in the scan's box sorts in fewer
         * radix passes. */
        keys[m] = (uint64_t)(k[0] - x->box_lo[0]) +
                  bx * ((uint64_t)(k[1] - x->box_lo[1]) + by * (uint64_t)(k[2] - x->box_lo[2]));
        vals[m] = (uint32_t)i;
        m++;
    }
    x->r->points_integrated += m;
    const uint64_t *const sk = occ_keyset_sort_pairs(keys, vals, tkeys, tvals, m, x->hist);
    const uint32_t *const sv = sk == keys ? vals : tvals;
    for (size_t s = 0; s < m;) {
        size_t e = s + 1u;
        while (e < m && sk[e] == sk[s]) {
            e++;
        }
        const uint32_t ke[3] = {x->box_lo[0] + (uint32_t)(sk[s] % bx),
                                x->box_lo[1] + (uint32_t)((sk[s] / bx) % by),
                                x->box_lo[2] + (uint32_t)(sk[s] / bx / by)};
        const occ_key_t kk = {{ke[0], ke[1], ke[2]}};
        if (!occ_ictx_reserve(x, 1u)) {
            return false;
        }
        occ_ictx_emit(x, occ_morton_encode(kk) | OCC_CODE_HIT_BIT);
        const bool same = ke[0] == x->ko[0] && ke[1] == x->ko[1] && ke[2] == x->ko[2];
        const occ_key_t dk = {{ke[0] > x->ko[0] ? ke[0] - x->ko[0] : x->ko[0] - ke[0],
                               ke[1] > x->ko[1] ? ke[1] - x->ko[1] : x->ko[1] - ke[1],
                               ke[2] > x->ko[2] ? ke[2] - x->ko[2] : x->ko[2] - ke[2]}};
        /* A bundle that spans its voxel has ~ (crossings / 2) edges inside: with fewer points
         * than that, super rays cannot pay for themselves - cast singly right away. */
        const size_t hopeless = ((size_t)dk.k[0] + dk.k[1] + dk.k[2]) / 2u;
        if (!same && (e - s < (size_t)k_min || e - s <= hopeless)) {
            for (size_t j = s; j < e; j++) {
                cast_one(x, points[sv[j]], ke);
            }
        } else if (!same) {
            for (size_t j = s; j < e; j += SR_MAX_GROUP) {
                const size_t c = e - j < SR_MAX_GROUP ? e - j : SR_MAX_GROUP;
                run_bundle(x, points, sv + j, c, ke, &ws);
            }
        }
        s = e;
    }
    return true;
}
