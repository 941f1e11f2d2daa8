/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * fastdiscrete.c - UFOMap's fast discrete integrator (Duberg & Jensfelt 2020, IV-B3): march from
 * the origin in steps of a level-d node's edge, marking the level-d nodes the samples fall in,
 * until n such nodes before the end; from there the exact voxel DDA to the end voxel. With n = 0
 * the end's level-d node is cleared too (space just behind the hit, as in the paper's Fig. 4).
 */
#include <string.h>

#include "integrate_internal.h"

static void mark_coarse(occ_ictx_t *const x, const uint32_t k[3])
{
    const unsigned d = x->cd;
    if (!occ_bitset_add(x->cbs, k[0] >> d, k[1] >> d, k[2] >> d)) {
        x->cbs->overflow = true;
    }
}

void occi_fast_ray(occ_ictx_t *const x, const float e[3], const uint32_t ke[3])
{
    const float step = (float)(x->g.res * (occ_rr_t)((uint32_t)1 << x->cd));
    const float len = (float)occi_raygeo_dist(x->o, e);
    float u[3] = {0.0f, 0.0f, 0.0f};
    if (len > 0.0f) {
        for (unsigned i = 0; i < 3u; i++) {
            u[i] = (e[i] - x->o[i]) / len;
        }
    }
    const float t_fine = x->cn == 0u ? len : len - (float)x->cn * step;
    /* Samples t = 0, step, 2 step, ... < t_fine, walked in level-d node units: one node edge per
     * sample, so the node key is the integer part (coordinates are positive inside the map). */
    size_t samples = t_fine > 0.0f ? (size_t)(t_fine / step) : 0u;
    samples += (float)samples * step < t_fine ? 1u : 0u;
    const occ_rr_t scale = x->g.rf / (occ_rr_t)((uint32_t)1 << x->cd);
    const occ_rr_t off = (occ_rr_t)((uint32_t)x->g.tmv >> x->cd);
    occ_rr_t c[3];
    for (unsigned i = 0; i < 3u; i++) {
        c[i] = (occ_rr_t)x->o[i] * scale + off;
    }
    const occ_rr_t v0 = (occ_rr_t)u[0], v1 = (occ_rr_t)u[1], v2 = (occ_rr_t)u[2];
    const uint32_t kmax = (uint32_t)x->g.tmv >> (x->cd - 1u);
    for (size_t i = 0; i < samples; i++) {
        if (c[0] >= (occ_rr_t)0 && c[1] >= (occ_rr_t)0 && c[2] >= (occ_rr_t)0) {
            const uint32_t kx = (uint32_t)c[0], ky = (uint32_t)c[1], kz = (uint32_t)c[2];
            if (kx < kmax && ky < kmax && kz < kmax && !occ_bitset_add(x->cbs, kx, ky, kz)) {
                x->cbs->overflow = true;
            }
        }
        c[0] += v0;
        c[1] += v1;
        c[2] += v2;
    }
    x->r->voxel_visits += samples;
    x->r->rays_cast++;
    if (x->cn == 0u) {
        mark_coarse(x, ke);
        return;
    }
    /* Exact voxels from where the marching stopped. */
    float s[3] = {x->o[0], x->o[1], x->o[2]};
    if (t_fine > 0.0f) {
        for (unsigned i = 0; i < 3u; i++) {
            s[i] = x->o[i] + u[i] * t_fine;
        }
    }
    uint32_t ks[3];
    if (!occi_raygeo_key(&x->g, s, ks)) {
        return;
    }
    if (x->bs != NULL) {
        x->r->voxel_visits += occi_dda_mark(&x->g, s, e, ks, ke, x->bs);
        return;
    }
    if (!occi_ictx_reserve(x, occi_dda_bound(ks, ke))) {
        x->cbs->overflow = true; /* reported as out of scratch by the caller */
        return;
    }
    const size_t m = occi_dda_codes(&x->g, s, e, ks, ke, x->a + x->n, x->cap - x->n);
    x->r->voxel_visits += m;
    x->n += m;
}
