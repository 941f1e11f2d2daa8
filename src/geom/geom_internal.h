/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * geom_internal.h - the one voxel geometry of the map: coordinate -> key, key -> centre, key
 * ranges, and the 3D-DDA set-up every ray walk starts from (integration and castRay alike).
 *
 * The resolution is the map's decimal resolution (geom.c: the shortest decimal that rounds to
 * cfg.resolution_m, 0.1f -> 0.1, computed once by occ_map_init). With OCC_RAY_DOUBLE the
 * arithmetic is OctoMap's, in double, bit for bit: key = floor(c * (1/res)) + 2^(D-1)
 * (coordToKeyChecked), centre = ((key - 2^(D-1)) + 0.5) * res (keyToCoord). The float build runs
 * the same code in float.
 */
#ifndef OCC_GEOM_INTERNAL_H_INCLUDED
#define OCC_GEOM_INTERNAL_H_INCLUDED

#include <float.h>
#include <string.h>
#include "occmap/occmap.h"

/* Keep a function out of line: a big frame that is not on every path (an exact volume test, a
 * camera set-up) then stays off the stack of its caller's deepest call chain (make cross,
 * tests/stack_budget.py: the chain is the sum of its frames). Or inline it always: a small
 * dispatcher's own frame then merges into its caller's. */
#if defined(__GNUC__)
#define OCC_NOINLINE __attribute__((noinline))
#define OCC_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define OCC_NOINLINE
#define OCC_ALWAYS_INLINE inline
#endif

#if OCC_RAY_DOUBLE
typedef double occ_real_t;
#define OCC_REAL_MAX DBL_MAX
#else
typedef float occ_real_t;
#define OCC_REAL_MAX FLT_MAX
#endif

/* THE "is finite" test of the map modules for every float a caller gives (coordinates, ranges, angles,
 * log-odds, file fields): false for NaN and +-Inf. On the bit pattern (exponent all ones), so it
 * holds under -ffinite-math-only and costs no float compare on a soft-float Cortex-M0+. */
static inline bool occ_finite(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    return (u & 0x7F800000u) != 0x7F800000u;
}

static inline bool occ_finite3(occ_vec3_t v)
{
    return occ_finite(v.x) && occ_finite(v.y) && occ_finite(v.z);
}

/* The map's decimal resolution and its inverse (OctoMap's resolution / resolution_factor). */
static inline occ_real_t occ_geom_res(const occ_map_t *m)
{
#if OCC_RAY_DOUBLE
    return m->priv.geo_res;
#else
    return m->priv.geo_res_f;
#endif
}

static inline occ_real_t occ_geom_inv(const occ_map_t *m)
{
#if OCC_RAY_DOUBLE
    return m->priv.geo_inv;
#else
    return m->priv.geo_inv_f;
#endif
}

/* 2^(D-1): the key of the voxel whose low corner is the origin. */
static inline int32_t occ_geom_half(const occ_map_t *m)
{
    return (int32_t)1 << (m->cfg.depth_levels - 1u);
}

/* floor(s) for |s| < 2^30 without a libm call: truncation, then one down for negatives. */
static inline int32_t occ_geom_floor(occ_real_t s)
{
    const int32_t t = (int32_t)s;
    return t - ((occ_real_t)t > s ? 1 : 0);
}

/* THE conversion (coordToKeyChecked): key of coordinate c with inverse resolution `inv`; false
 * outside [0, 2 half) (NaN and Inf fail the range test). */
static inline bool occ_geom_key_of(occ_real_t inv, int32_t half, float c, uint32_t *key)
{
    const occ_real_t s = inv * (occ_real_t)c;
    if (!(s >= -(occ_real_t)half) || !(s < (occ_real_t)half)) {
        return false;
    }
    *key = (uint32_t)(occ_geom_floor(s) + half);
    return true;
}

static inline bool occ_geom_key1(const occ_map_t *m, float c, uint32_t *key)
{
    return occ_geom_key_of(occ_geom_inv(m), occ_geom_half(m), c, key);
}

/* Centre coordinate (keyToCoord) of the node at `level` whose first key is `base` (low
 * `level` bits clear): ((base - half) + 2^level / 2) * res, one rounding, which equals OctoMap's
 * (floor((k - half) / 2^L) + 0.5) * nodeSize(L) (power-of-two scalings are exact). The root
 * (level D, base 0) is centred at 0. */
static inline occ_real_t occ_geom_center_of(occ_real_t res, int32_t half, uint32_t base,
                                            unsigned level)
{
    return ((occ_real_t)((int32_t)base - half) +
            (occ_real_t)((uint32_t)1 << level) * (occ_real_t)0.5) * res;
}

/* Low face (metres) of the voxel k, i.e. (k - half) * res: node boxes from k to k + 2^level. */
static inline float occ_geom_face1(const occ_map_t *m, uint32_t k)
{
    return (float)((occ_real_t)((int32_t)k - occ_geom_half(m)) * occ_geom_res(m));
}

static inline float occ_geom_center1(const occ_map_t *m, uint32_t base, unsigned level)
{
    return (float)occ_geom_center_of(occ_geom_res(m), occ_geom_half(m), base, level);
}

/* Centre (metres) of the node at `level` whose first voxel key is `base` (in the map; off-map
 * keys: occ_map_key_center). */
static inline occ_vec3_t occ_geom_center(const occ_map_t *m, occ_key_t base, unsigned level)
{
    occ_vec3_t c;
    c.x = occ_geom_center1(m, base.k[0], level);
    c.y = occ_geom_center1(m, base.k[1], level);
    c.z = occ_geom_center1(m, base.k[2], level);
    return c;
}

/* Keys [lo, hi] of the voxels holding a coordinate of [lo_m, hi_m] widened by `slack` voxels
 * on each side, clamped to the map: the same conversion as occ_geom_key_of (slack 0: exactly
 * the keys of lo_m and hi_m). False when the interval misses the map or is empty / NaN. */
bool occi_geom_key_range(const occ_map_t *m, float lo_m, float hi_m, occ_real_t slack,
                         uint32_t *lo, uint32_t *hi);

/* Shortest decimal (as a double, OCC_RAY_DOUBLE) that rounds to the float r > 0. */
double occi_geom_decimal(float r);
/* Set the map's geometry fields from cfg.resolution_m (occ_map_init). */
void occi_geom_init(occ_map_t *m);

/* ---- 3D-DDA (Amanatides & Woo, as OctoMap) ---------------------------------------------------
 * The set-up both walks share: from the origin o (in voxel key[]) along the float unit vector
 * dir, tMax = distance along the ray to the first border per axis, tDelta = one voxel. OctoMap
 * rounds the half-voxel step to float in computeRayKeys and not in castRay: `half_in_float`. */
typedef struct {
    occ_real_t tmax[3], tdelta[3];
    int32_t step[3];
} occ_dda_t;

static inline void occ_dda_start(occ_dda_t *d, occ_real_t res, int32_t half, const float o[3],
                                 const float dir[3], const uint32_t key[3], bool half_in_float)
{
    for (unsigned i = 0; i < 3u; i++) {
        d->step[i] = dir[i] > 0.0f ? 1 : (dir[i] < 0.0f ? -1 : 0);
        if (d->step[i] != 0) {
            occ_real_t hstep = (occ_real_t)d->step[i] * res * (occ_real_t)0.5;
            if (half_in_float) {
                hstep = (occ_real_t)(float)hstep;
            }
            const occ_real_t border = occ_geom_center_of(res, half, key[i], 0u) + hstep;
            d->tmax[i] = (border - (occ_real_t)o[i]) / (occ_real_t)dir[i];
            d->tdelta[i] = res / (occ_real_t)(dir[i] < 0.0f ? -dir[i] : dir[i]);
        } else {
            d->tmax[i] = OCC_REAL_MAX;
            d->tdelta[i] = OCC_REAL_MAX;
        }
    }
}

/* OctoMap's axis of the next step: the smallest tMax; a tie goes to the higher axis. */
static inline unsigned occ_dda_axis(occ_real_t t0, occ_real_t t1, occ_real_t t2)
{
    if (t0 < t1 && t0 < t2) {
        return 0u;
    }
    return t1 < t2 ? 1u : 2u; /* (t0 < t1 here means t2 <= t0 < t1: z) */
}

#endif /* OCC_GEOM_INTERNAL_H_INCLUDED */
