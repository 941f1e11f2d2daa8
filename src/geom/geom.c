/* SPDX-License-Identifier: BSD-3-Clause */
/* geom.c - the map's decimal resolution (once, at init) and key ranges; see geom_internal.h. */
#include "geom_internal.h"

/* Double arithmetic in every build: the float build calls it only for statistics (stats.c). */
double occi_geom_decimal(const float r)
{
    /* A user who writes OcTree(0.1) or cfg.resolution_m = 0.1f means 0.1: the shortest decimal
     * (1 to 9 significant digits) that rounds to the float. n / 10^p is the double nearest to
     * the decimal, as a C++ literal or a file header's text gives it. */
    const double rd = (double)r;
    double p = 1.0;
    while (rd * p < 1.0 && p < 1e12) {
        p *= 10.0;
    }
    for (unsigned digits = 0; digits < 9u; digits++, p *= 10.0) {
        const double cand = (double)(int64_t)(rd * p + 0.5) / p;
        const float back = (float)cand;
        if (!(back < r) && !(back > r)) {
            return cand;
        }
    }
    return rd;
}

void occi_geom_init(occ_map_t *const m)
{
    const float r = m->cfg.resolution_m;
#if OCC_RAY_DOUBLE
    m->priv.geo_res = occi_geom_decimal(r);
    m->priv.geo_inv = 1.0 / m->priv.geo_res;
    m->priv.geo_res_f = (float)m->priv.geo_res;
    m->priv.geo_inv_f = (float)m->priv.geo_inv;
#else
    m->priv.geo_res = 0;
    m->priv.geo_inv = 0;
    m->priv.geo_res_f = r;
    m->priv.geo_inv_f = 1.0f / r;
#endif
}

bool occi_geom_key_range(const occ_map_t *const m, const float lo_m, const float hi_m,
                         const occ_real_t slack, uint32_t *const lo, uint32_t *const hi)
{
    const occ_real_t inv = occ_geom_inv(m);
    const int32_t half = occ_geom_half(m);
    const occ_real_t h = (occ_real_t)half;
    /* slack 0 leaves the products as they are: the keys of occ_geom_key_of. */
    const occ_real_t l = inv * (occ_real_t)lo_m - slack;
    const occ_real_t u = inv * (occ_real_t)hi_m + slack;
    if (!(l <= u) || !(u >= -h) || !(l < h)) {
        return false;
    }
    *lo = l < -h ? 0u : (uint32_t)(occ_geom_floor(l) + half);
    *hi = u < h ? (uint32_t)(occ_geom_floor(u) + half) : (uint32_t)(2 * half - 1);
    return true;
}
