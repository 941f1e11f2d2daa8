/* SPDX-License-Identifier: BSD-3-Clause */
/* ranges.c - range beams (rangefinders, sonar, ToF zones) as rays of one occ_map_insert_rays()
 * scan: a return is a hit at d, "no return" clears to the beam's own max without a hit. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "occmap/occ_ranges.h"

#define TWO_PI_F 6.28318530717958647692f
#define DIR_MIN_NORM 1e-6f

typedef enum { BEAM_HIT, BEAM_NO_RETURN, BEAM_INVALID, BEAM_TOO_CLOSE, BEAM_BAD } beam_kind_t;

static bool finite3(const occ_vec3_t v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z);
}

static float norm3(const occ_vec3_t v)
{
    return sqrtf(v.x * v.x + v.y * v.y + v.z * v.z);
}

static occ_vec3_t scale3(const occ_vec3_t v, const float s)
{
    const occ_vec3_t r = {v.x * s, v.y * s, v.z * s};
    return r;
}

static occ_vec3_t cross3(const occ_vec3_t a, const occ_vec3_t b)
{
    const occ_vec3_t r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}

/* The configuration a valid beam must have (occ_ranges.h). */
static bool beam_config_ok(const occ_range_beam_t *const b)
{
    return finite3(b->dir) && norm3(b->dir) >= DIR_MIN_NORM && isfinite(b->min_m) &&
           isfinite(b->max_m) && b->min_m >= 0.0f && b->min_m < b->max_m &&
           isfinite(b->cone_half_rad) && b->cone_half_rad >= 0.0f &&
           b->cone_half_rad <= OCC_RANGES_CONE_MAX_RAD;
}

/* What a (configured) beam's reading is. */
static beam_kind_t beam_kind(const occ_range_beam_t *const b)
{
    if (!b->valid) {
        return BEAM_INVALID;
    }
    if (!isfinite(b->distance_m)) {
        return BEAM_BAD;
    }
    if (b->distance_m < b->min_m) {
        return BEAM_TOO_CLOSE;
    }
    return b->distance_m >= b->max_m ? BEAM_NO_RETURN : BEAM_HIT;
}

static size_t beam_rays(const occ_range_beam_t *const b)
{
    const beam_kind_t k = beam_kind(b);
    if (k != BEAM_HIT && k != BEAM_NO_RETURN) {
        return 0;
    }
    return b->cone_half_rad > 0.0f ? OCC_RANGES_CONE_RAYS : 1u;
}

/* The unit ring basis u, v of axis a (occ_ranges.h): e = the axis of a's smallest |component|. */
static void ring_basis(const occ_vec3_t a, occ_vec3_t *const u, occ_vec3_t *const v)
{
    const float ax = fabsf(a.x), ay = fabsf(a.y), az = fabsf(a.z);
    occ_vec3_t e = {0.0f, 0.0f, 1.0f};
    if (ax <= ay && ax <= az) {
        e.x = 1.0f;
        e.z = 0.0f;
    } else if (ay <= az) {
        e.y = 1.0f;
        e.z = 0.0f;
    }
    const occ_vec3_t c = cross3(a, e);
    *u = scale3(c, 1.0f / norm3(c));
    *v = cross3(a, *u);
}

/* A beam's rays in the sensor frame: the axis a (unit), and for a cone the ring (occ_ranges.h).
 * Returns the count written to out (1 or OCC_RANGES_CONE_RAYS). */
static unsigned cone_rays(const occ_vec3_t a, const float half_rad, occ_vec3_t *const out)
{
    out[0] = a;
    if (!(half_rad > 0.0f)) {
        return 1u;
    }
    occ_vec3_t u, v;
    ring_basis(a, &u, &v);
    const float ch = cosf(half_rad), sh = sinf(half_rad);
    for (unsigned j = 0; j < OCC_RANGES_CONE_RING; j++) {
        const float phi = TWO_PI_F * (float)j / (float)OCC_RANGES_CONE_RING;
        const float cu = sh * cosf(phi), cv = sh * sinf(phi);
        const occ_vec3_t d = {ch * a.x + cu * u.x + cv * v.x, ch * a.y + cu * u.y + cv * v.y,
                              ch * a.z + cu * u.z + cv * v.z};
        out[1u + j] = d;
    }
    return OCC_RANGES_CONE_RAYS;
}

/* Check every valid beam's configuration; count the rays and their largest max_m. false: a bad
 * configuration. */
static bool count_rays(const occ_range_beam_t *const beams, const size_t n, size_t *const rays,
                       float *const max_m)
{
    *rays = 0;
    *max_m = 0.0f;
    for (size_t i = 0; i < n; i++) {
        if (!beams[i].valid) {
            continue;
        }
        if (!beam_config_ok(&beams[i])) {
            return false;
        }
        const size_t r = beam_rays(&beams[i]);
        *rays += r;
        if (r > 0u && beams[i].max_m > *max_m) {
            *max_m = beams[i].max_m;
        }
    }
    return true;
}

/* Each beam's rays as map-frame end points and hit flags; the rays and beams_ counters into
 * out (if non-NULL). Kept out of line: inlined, its cone directions and sin/cos frame stayed on
 * the stack under the whole integration (occ_map_insert_ranges 1,736 -> 1,4xx B on Cortex-M4,
 * make cross), and so does its result when the caller passes none. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void build_rays(const occ_pose_t *const pose, const occ_range_beam_t *const beams,
                       const size_t n, occ_vec3_t *const ends, bool *const hit,
                       occ_ranges_result_t *const out)
{
    occ_ranges_result_t local;
    /* cppcheck-suppress uninitvar ; only its address is taken here (cppcheck 2.10 flags &x of a fresh local) */
    occ_ranges_result_t *const r = out != NULL ? out : &local;
    memset(r, 0, sizeof *r);
    size_t w = 0;
    for (size_t i = 0; i < n; i++) {
        const occ_range_beam_t *const b = &beams[i];
        const beam_kind_t k = beam_kind(b);
        r->beams_hit += k == BEAM_HIT ? 1u : 0u;
        r->beams_no_return += k == BEAM_NO_RETURN ? 1u : 0u;
        r->beams_invalid += k == BEAM_INVALID ? 1u : 0u;
        r->beams_too_close += k == BEAM_TOO_CLOSE ? 1u : 0u;
        r->beams_bad += k == BEAM_BAD ? 1u : 0u;
        if (k != BEAM_HIT && k != BEAM_NO_RETURN) {
            continue;
        }
        const float len = k == BEAM_HIT ? b->distance_m : b->max_m;
        occ_vec3_t dirs[OCC_RANGES_CONE_RAYS];
        const unsigned nr = cone_rays(scale3(b->dir, 1.0f / norm3(b->dir)), b->cone_half_rad, dirs);
        for (unsigned j = 0; j < nr; j++) {
            ends[w] = occ_pose_apply(pose, scale3(dirs[j], len));
            hit[w] = k == BEAM_HIT;
            w++;
        }
    }
    r->rays = w;
}

size_t occ_ranges_scratch_bytes(const occ_map_t *const map, const occ_range_beam_t *const beams,
                                const size_t n_beams, const occ_insert_params_t *const params)
{
    size_t rays = 0;
    float max_m = 0.0f;
    if (map == NULL || params == NULL || (beams == NULL && n_beams > 0u) ||
        !count_rays(beams, n_beams, &rays, &max_m)) {
        return 0;
    }
    const size_t ins = occ_insert_scratch_bytes(map, rays, max_m > 0.0f ? max_m : 1.0f, params);
    if (rays > (SIZE_MAX - 3u) / OCC_RANGES_SCRATCH_PER_RAY) {
        return SIZE_MAX;
    }
    const size_t own = 3u + rays * OCC_RANGES_SCRATCH_PER_RAY;
    return ins > SIZE_MAX - own ? SIZE_MAX : ins + own;
}

occ_err_t occ_map_insert_ranges(occ_map_t *const map, const occ_pose_t *const map_from_sensor,
                                const occ_range_beam_t *const beams, const size_t n_beams,
                                const occ_insert_params_t *const params, void *const scratch,
                                const size_t scratch_bytes, occ_ranges_result_t *const out)
{
    if (out != NULL) {
        memset(out, 0, sizeof *out);
    }
    size_t rays = 0;
    float max_m = 0.0f;
    if (map == NULL || params == NULL || (beams == NULL && n_beams > 0u) ||
        (scratch == NULL && scratch_bytes > 0u) || occ_pose_check(map_from_sensor) != OCC_OK ||
        !count_rays(beams, n_beams, &rays, &max_m)) {
        return OCC_ERR_ARG;
    }
    if (scratch == NULL) {
        return OCC_ERR_SCRATCH;
    }
    /* Carve: ends (4-aligned) | hit flags | the integrator's scratch. */
    uint8_t *const base = (uint8_t *)scratch;
    const size_t pad = base != NULL ? (size_t)((4u - ((uintptr_t)base & 3u)) & 3u) : 0u;
    const size_t own = rays * OCC_RANGES_SCRATCH_PER_RAY;
    if (rays > SIZE_MAX / OCC_RANGES_SCRATCH_PER_RAY || scratch_bytes < pad ||
        scratch_bytes - pad < own) {
        return OCC_ERR_SCRATCH;
    }
    occ_vec3_t *const ends = (occ_vec3_t *)(void *)(base + pad);
    bool *const hit = (bool *)(void *)(base + pad + rays * sizeof(occ_vec3_t));
    build_rays(map_from_sensor, beams, n_beams, ends, hit, out);
    uint8_t *const rest = base + pad + own;
    return occ_map_insert_rays(map, &map_from_sensor->p, ends, hit, rays, params, rest,
                               scratch_bytes - pad - own, out != NULL ? &out->insert : NULL);
}
