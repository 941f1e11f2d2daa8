/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * raycast.c - OctoMap's computeRayKeys (Amanatides & Woo 3D-DDA), bit for bit: float direction
 * and length, the DDA set-up and tie rule every ray walk shares (geom_internal.h: occ_dda_start,
 * occ_dda_axis), and computeRayKeys' stop: at the end key, or when min(tMax) passes the length.
 * castray.c walks from the same set-up with castRay's stops (blocking voxel, range, map edge).
 */
#include <float.h>
#include <math.h>

#include "integrate_internal.h"

void occi_raygeo_init(occ_raygeo_t *const g, const occ_map_t *const map)
{
    g->depth = map->cfg.depth_levels;
    g->tmv = (int32_t)1 << (g->depth - 1u);
    g->tmv_r = (occ_rr_t)g->tmv;
    g->res = occ_geom_res(map);
    g->rf = occ_geom_inv(map);
}

/* Key of one coordinate; false when NaN/Inf or outside [0, 2^D). */
static bool raygeo_key1(const occ_raygeo_t *const g, const float c, uint32_t *const k)
{
    return occ_geom_key_of(g->rf, g->tmv, c, k);
}

bool occi_raygeo_key(const occ_raygeo_t *const g, const float p[3], uint32_t k[3])
{
    return raygeo_key1(g, p[0], &k[0]) && raygeo_key1(g, p[1], &k[1]) &&
           raygeo_key1(g, p[2], &k[2]);
}

float occi_raygeo_center(const occ_raygeo_t *const g, const uint32_t k)
{
    return (float)occ_geom_center_of(g->res, g->tmv, k, 0u);
}

occ_rr_t occi_raygeo_dist(const float o[3], const float p[3])
{
    const float dx = p[0] - o[0], dy = p[1] - o[1], dz = p[2] - o[2];
    const float nsq = dx * dx + dy * dy + dz * dz;
#if OCC_RAY_DOUBLE
    return sqrt((double)nsq);
#else
    return sqrtf(nsq);
#endif
}

void occi_raygeo_clip(const float o[3], const float p[3], const float range, float out[3])
{
    float d[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
    const occ_rr_t len = occi_raygeo_dist(o, p);
    if (len > (occ_rr_t)0) {
        const float lf = (float)len;
        d[0] /= lf;
        d[1] /= lf;
        d[2] /= lf;
    }
    for (unsigned i = 0; i < 3u; i++) {
        out[i] = o[i] + d[i] * range;
    }
}

size_t occi_dda_bound(const uint32_t ko[3], const uint32_t ke[3])
{
    size_t n = 4u;
    for (unsigned i = 0; i < 3u; i++) {
        n += ko[i] > ke[i] ? (size_t)(ko[i] - ke[i]) : (size_t)(ke[i] - ko[i]);
    }
    return n;
}

/* DDA state; dda_init is inlined into every user below. The set-up's tMax, tDelta and steps are
 * written in place (a copy from a temporary was 40 B more under every ray of the integration,
 * make cross). */
typedef struct {
    occ_dda_t dd;
    int32_t key[3];
    int32_t kmax;
    float length;
    occ_code_t c; /* the origin's code */
    size_t limit;
} dda_t;

/* computeRayKeys' set-up: the float direction and length of o -> e, then tMax, tDelta and
 * steps from the origin's voxel ko. Returns the length. */
static OCC_ALWAYS_INLINE float dda_start(occ_dda_t *const dd, const occ_raygeo_t *const g,
                                         const float o[3],
                              const float e[3], const uint32_t ko[3])
{
    float d[3] = {e[0] - o[0], e[1] - o[1], e[2] - o[2]};
    const float length = (float)occi_raygeo_dist(o, e);
    d[0] /= length;
    d[1] /= length;
    d[2] /= length;
    /* computeRayKeys rounds the half-voxel step to float. */
    occ_dda_start(dd, g->res, g->tmv, o, d, ko, true);
    return length;
}

/* Prepares the traversal; the first voxel (the origin's) is s->c. ko != ke. */
static inline void dda_init(dda_t *const s, const occ_raygeo_t *const g, const float o[3],
                            const float e[3], const uint32_t ko[3], const uint32_t ke[3])
{
    s->length = dda_start(&s->dd, g, o, e, ko);
    for (unsigned i = 0; i < 3u; i++) {
        s->key[i] = (int32_t)ko[i];
    }
    const occ_key_t k0 = {{ko[0], ko[1], ko[2]}};
    s->c = occ_morton_encode(k0);
    s->kmax = 2 * g->tmv;
    s->limit = occi_dda_bound(ko, ke);
}

/* The hot loop of occ_ray_keys, with the state in scalars so that it stays in registers.
 * EMIT(kx, ky, kz) is called for every voxel after the origin's. */
#define DDA_LOOP(s, EMIT)                                                                         \
    do {                                                                                          \
        occ_rr_t t0 = (s).dd.tmax[0], t1 = (s).dd.tmax[1], t2 = (s).dd.tmax[2];                     \
        const occ_rr_t d0 = (s).dd.tdelta[0], d1 = (s).dd.tdelta[1], d2 = (s).dd.tdelta[2];         \
        const int32_t s0 = (s).dd.step[0], s1 = (s).dd.step[1], s2 = (s).dd.step[2];                \
        const int32_t e0 = (int32_t)ke[0], e1 = (int32_t)ke[1], e2 = (int32_t)ke[2];             \
        int32_t k0 = (s).key[0], k1 = (s).key[1], k2 = (s).key[2];                                \
        const occ_rr_t len = (occ_rr_t)(s).length;                                                \
        const uint32_t kmax = (uint32_t)(s).kmax;                                                 \
        size_t left = (s).limit - 1u;                                                             \
        for (;;) {                                                                                \
            const unsigned dim_ = occ_dda_axis(t0, t1, t2);                                       \
            if (dim_ == 0u) {                                                                     \
                k0 += s0;                                                                         \
                t0 += d0;                                                                         \
            } else if (dim_ == 1u) {                                                              \
                k1 += s1;                                                                         \
                t1 += d1;                                                                         \
            } else {                                                                              \
                k2 += s2;                                                                         \
                t2 += d2;                                                                         \
            }                                                                                     \
            if (k0 == e0 && k1 == e1 && k2 == e2) {                                               \
                break;                                                                            \
            }                                                                                     \
            occ_rr_t dist = t1 < t0 ? t1 : t0;                                                    \
            dist = t2 < dist ? t2 : dist;                                                         \
            /* past the end by rounding (OctoMap's stop), or left the map (OctoMap wraps) */      \
            if (dist > len || ((uint32_t)k0 | (uint32_t)k1 | (uint32_t)k2) >= kmax) {             \
                break;                                                                            \
            }                                                                                     \
            EMIT((uint32_t)k0, (uint32_t)k1, (uint32_t)k2);                                       \
            if (--left == 0u) {                                                                   \
                break; /* cannot happen with finite input; bounds the work regardless */          \
            }                                                                                     \
        }                                                                                         \
    } while (0)

/* The walks below in OctoMap's order, rotated: the axis of step i + 1 is chosen right after step
 * i, so that its tMax (the minimum) serves as step i's length test, and one chain of branches
 * on the axis does both. A step moves the key and the voxel's Morton code together (dilated
 * +-1, occ_code_step), so no voxel is ever encoded. */
#define DDA_STATE(s, ke)                                                                          \
    const occ_key_t ke_ = {{(ke)[0], (ke)[1], (ke)[2]}};                                          \
    const occ_code_t ce = occ_morton_encode(ke_); /* the walk ends on it: codes equal iff keys */ \
    occ_rr_t t0 = (s).dd.tmax[0], t1 = (s).dd.tmax[1], t2 = (s).dd.tmax[2];                         \
    const occ_rr_t d0 = (s).dd.tdelta[0], d1 = (s).dd.tdelta[1], d2 = (s).dd.tdelta[2];             \
    const int32_t s0 = (s).dd.step[0], s1 = (s).dd.step[1], s2 = (s).dd.step[2];                    \
    const occ_rr_t len = (occ_rr_t)(s).length;                                                    \
    occ_code_t c = (s).c;                                                                         \
    size_t left = (s).limit - 1u

/* Step along the axis `a` of the smallest tMax (keys in k0..k2, dead where unused); the step's
 * sign in sa. */
#define DDA_STEP(a, k0, k1, k2, sa)                                                               \
    do {                                                                                          \
        if ((a) == 0u) {                                                                          \
            t0 += d0;                                                                             \
            k0 += s0;                                                                             \
            c = occ_code_step(c, 0u, s0);                                                         \
            sa = s0;                                                                              \
        } else if ((a) == 1u) {                                                                   \
            t1 += d1;                                                                             \
            k1 += s1;                                                                             \
            c = occ_code_step(c, 1u, s1);                                                         \
            sa = s1;                                                                              \
        } else {                                                                                  \
            t2 += d2;                                                                             \
            k2 += s2;                                                                             \
            c = occ_code_step(c, 2u, s2);                                                         \
            sa = s2;                                                                              \
        }                                                                                         \
    } while (0)

/* The next step's axis and its tMax, the smallest. */
#define DDA_NEXT(a, tsel)                                                                         \
    do {                                                                                          \
        a = occ_dda_axis(t0, t1, t2);                                                             \
        tsel = a == 0u ? t0 : (a == 1u ? t1 : t2);                                                \
    } while (0)

size_t occi_dda_codes(const occ_raygeo_t *const g, const float o[3], const float e[3],
                      const uint32_t ko[3], const uint32_t ke[3], occ_code_t *const out,
                      const size_t cap)
{
    if (ko[0] == ke[0] && ko[1] == ke[1] && ko[2] == ke[2]) {
        return 0;
    }
    dda_t s;
    dda_init(&s, g, o, e, ko, ke);
    DDA_STATE(s, ke);
    if (cap > 0u) {
        out[0] = c;
    }
    size_t n = 1;
    const uint32_t kmax = (uint32_t)s.kmax;
    int32_t k0 = s.key[0], k1 = s.key[1], k2 = s.key[2];
    unsigned a = occ_dda_axis(t0, t1, t2);
    for (;;) {
        int32_t sa;
        DDA_STEP(a, k0, k1, k2, sa);
        (void)sa;
        if (c == ce) {
            break;
        }
        occ_rr_t tsel;
        DDA_NEXT(a, tsel);
        /* past the end by rounding (OctoMap's stop), or left the map (OctoMap wraps) */
        if (tsel > len || ((uint32_t)k0 | (uint32_t)k1 | (uint32_t)k2) >= kmax) {
            break;
        }
        if (n < cap) {
            out[n] = c;
        }
        n++;
        if (--left == 0u) {
            break; /* cannot happen with finite input; bounds the work regardless */
        }
    }
    return n;
}

/* ---- the voxel set's walk ---------------------------------------------------------------------
 * occi_dda_mark's loop, specialised per octant (the steps' signs are constants: a step is five
 * operations on the code, no sign test). Per step one chain of branches picks the axis; the
 * length test and the 32^3 chunk crossing are tested on that axis alone and resolved off the
 * common path: the walk stops once every tMax passed the length (each only grows), and a
 * countdown per axis says when its key crosses into the next chunk (then the set is asked for
 * that chunk's words: a directory lookup per 32 steps at most).
 * Measured and dropped: a branch-free walk by slabs of the major axis (the minor steps before
 * each major one from three compares, three marks per slab, this loop at ties, chunk crossings
 * and the end). Same maps, 1.21x the time on scan.dat at 0.1 m: 96 instructions per slab (one
 * to three steps) against 29 per step here (make bench-profile), and a slab's three marks mostly
 * share a word, so each waits on the last one's store.
 * Where the CPU has AVX-512 (x86-64 GCC), the insert paths walk their rays 8 at once instead
 * (raycast_lanes.c, through occi_ictx_set_ray): the steps below, the set-up and the chunk entry
 * (occi_mwalk_*) are shared with it. */
typedef occi_mwalk_t mwalk_t;

/* Steps along axis a until its key leaves its 32-voxel row. */
static uint32_t chunk_countdown(const uint32_t k, const int step)
{
    return step < 0 ? (k & 31u) + 1u : 32u - (k & 31u);
}

/* The next chunk's words, or NULL (the walk ends): outside the map that is an overflow unless
 * OctoMap's walk ends there too (on the end key; the length test came first); a full set is
 * one. */
static OCC_ALWAYS_INLINE uint64_t *mark_enter(const mwalk_t *const w, occ_vset_t *const vs,
                                               const occ_code_t c)
{
    if (w->cc[0] >= vs->cmax || w->cc[1] >= vs->cmax || w->cc[2] >= vs->cmax) {
        vs->overflow = vs->overflow || c != w->ce;
        return NULL;
    }
    uint64_t *const cw = occi_vset_chunk(vs, w->cc[0], w->cc[1], w->cc[2]);
    if (cw == NULL) {
        vs->overflow = true;
    }
    return cw;
}

#if OCC_MARK_LANES
uint64_t *occi_mwalk_enter(const occi_mwalk_t *const w, occ_vset_t *const vs, const occ_code_t c)
{
    return mark_enter(w, vs, c);
}
#endif

/* One step on axis A (sign S, chunk countdown nA), with its rare cases: every tMax past the
 * length (stop), the next chunk (enter it, or stop). */
#define MARK_STEP(A, S, nA, tA, dA, tB, tC)                                                       \
    do {                                                                                          \
        tA += dA;                                                                                 \
        c = occ_code_step(c, A, S);                                                               \
        nA--; /* counted before any stop: the visits are the steps */                             \
        if (tA > len && tB > len && tC > len) {                                                   \
            goto done;                                                                            \
        }                                                                                         \
        if (nA == 0u) {                                                                           \
            nA = 32u;                                                                             \
            w->cc[A] += (uint32_t)(S);                                                            \
            cw = mark_enter(w, vs, c);                                                            \
            if (cw == NULL) {                                                                     \
                goto done;                                                                        \
            }                                                                                     \
        }                                                                                         \
    } while (0)

/* A voxel's bit in its brick's word, by look-up: an x86 shift by a variable count is several
 * micro-ops that also wait on the flags (the look-up made integrations 2.5 to 4 % faster; the
 * walk's time is mostly its axis branches: three micro-ops fewer per step measured no gain). */
#define BIT4(n) ((uint64_t)1 << (n)), ((uint64_t)1 << ((n) + 1)), ((uint64_t)1 << ((n) + 2)), \
    ((uint64_t)1 << ((n) + 3))
#define BIT16(n) BIT4(n), BIT4((n) + 4), BIT4((n) + 8), BIT4((n) + 12)
static const uint64_t bit64[64] = {BIT16(0), BIT16(16), BIT16(32), BIT16(48)};
#undef BIT16
#undef BIT4

static OCC_ALWAYS_INLINE void mark_walk(mwalk_t *const w, occ_vset_t *const vs, uint64_t *cw,
                                        const int s0, const int s1, const int s2)
{
    occ_rr_t t0 = w->dd.tmax[0], t1 = w->dd.tmax[1], t2 = w->dd.tmax[2];
    const occ_rr_t d0 = w->dd.tdelta[0], d1 = w->dd.tdelta[1], d2 = w->dd.tdelta[2];
    const occ_rr_t len = w->len;
    const occ_code_t ce = w->ce;
    occ_code_t c = w->c;
    uint32_t n0 = w->n[0], n1 = w->n[1], n2 = w->n[2];
    for (;;) {
        if (t0 < t1 && t0 < t2) { /* OctoMap's axis: the smallest tMax, ties to the higher */
            MARK_STEP(0u, s0, n0, t0, d0, t1, t2);
        } else if (t1 < t2) {
            MARK_STEP(1u, s1, n1, t1, d1, t0, t2);
        } else {
            MARK_STEP(2u, s2, n2, t2, d2, t0, t1);
        }
        if (c == ce) {
            break;
        }
        cw[(c >> 6) & 511u] |= bit64[c & 63u];
    }
done:
    w->c = c;
    w->n[0] = n0;
    w->n[1] = n1;
    w->n[2] = n2;
}

/* The eight octants' walks, out of line: one frame under occi_dda_mark's (make cross). */
#define MARK_OCTANT(NAME, S0, S1, S2)                                                             \
    static OCC_NOINLINE void NAME(mwalk_t *const w, occ_vset_t *const vs, uint64_t *const cw)    \
    {                                                                                             \
        mark_walk(w, vs, cw, S0, S1, S2);                                                         \
    }
MARK_OCTANT(mark_ppp, 1, 1, 1)
MARK_OCTANT(mark_npp, -1, 1, 1)
MARK_OCTANT(mark_pnp, 1, -1, 1)
MARK_OCTANT(mark_nnp, -1, -1, 1)
MARK_OCTANT(mark_ppn, 1, 1, -1)
MARK_OCTANT(mark_npn, -1, 1, -1)
MARK_OCTANT(mark_pnn, 1, -1, -1)
MARK_OCTANT(mark_nnn, -1, -1, -1)

/* occi_mwalk_start's body, inlined into occi_dda_mark (a call per ray costs the firmware's
 * 64-ray insert 0.13 %, make bench-m4). */
static OCC_ALWAYS_INLINE bool mwalk_start(occi_mwalk_t *const w, uint64_t **const cw,
                                          const occ_raygeo_t *const g, const float o[3],
                                          const float e[3], const uint32_t ko[3],
                                          const uint32_t ke[3], occ_vset_t *const vs)
{
    if (ko[0] == ke[0] && ko[1] == ke[1] && ko[2] == ke[2]) {
        return false;
    }
    for (unsigned i = 0; i < 3u; i++) {
        w->cc[i] = ko[i] >> 5;
    }
    *cw = occi_vset_chunk(vs, w->cc[0], w->cc[1], w->cc[2]);
    if (*cw == NULL) {
        vs->overflow = true;
        return false;
    }
    w->len = (occ_rr_t)dda_start(&w->dd, g, o, e, ko);
    const occ_key_t kok = {{ko[0], ko[1], ko[2]}}, kek = {{ke[0], ke[1], ke[2]}};
    w->c = occ_morton_encode(kok);
    w->ce = occ_morton_encode(kek);
    for (unsigned i = 0; i < 3u; i++) {
        w->n[i] = chunk_countdown(ko[i], w->dd.step[i]);
    }
    (*cw)[(w->c >> 6) & 511u] |= bit64[w->c & 63u];
    return true;
}

#if OCC_MARK_LANES
bool occi_mwalk_start(occi_mwalk_t *const w, uint64_t **const cw, const occ_raygeo_t *const g,
                      const float o[3], const float e[3], const uint32_t ko[3],
                      const uint32_t ke[3], occ_vset_t *const vs)
{
    return mwalk_start(w, cw, g, o, e, ko, ke, vs);
}
#endif

/* Visits: the origin and one per step but the last (the end, or past the length), i.e. the
 * steps, which the chunk countdowns and chunk moves count per axis (no decode). */
size_t occi_mwalk_visits(const occi_mwalk_t *const w, const uint32_t ko[3])
{
    size_t visits = 0;
    for (unsigned i = 0; i < 3u; i++) {
        const uint32_t c0 = ko[i] >> 5;
        const uint32_t moves = w->dd.step[i] < 0 ? c0 - w->cc[i] : w->cc[i] - c0;
        visits += (size_t)chunk_countdown(ko[i], w->dd.step[i]) - w->n[i] + 32u * (size_t)moves;
    }
    return visits;
}

size_t occi_dda_mark(const occ_raygeo_t *const g, const float o[3], const float e[3],
                     const uint32_t ko[3], const uint32_t ke[3], occ_vset_t *const vs)
{
    mwalk_t w;
    uint64_t *cw = NULL;
    if (!mwalk_start(&w, &cw, g, o, e, ko, ke, vs)) {
        return 0;
    }
    switch ((w.dd.step[0] < 0 ? 1u : 0u) | (w.dd.step[1] < 0 ? 2u : 0u) |
            (w.dd.step[2] < 0 ? 4u : 0u)) {
    case 0u: mark_ppp(&w, vs, cw); break;
    case 1u: mark_npp(&w, vs, cw); break;
    case 2u: mark_pnp(&w, vs, cw); break;
    case 3u: mark_nnp(&w, vs, cw); break;
    case 4u: mark_ppn(&w, vs, cw); break;
    case 5u: mark_npn(&w, vs, cw); break;
    case 6u: mark_pnn(&w, vs, cw); break;
    default: mark_nnn(&w, vs, cw); break;
    }
    return occi_mwalk_visits(&w, ko);
}

/* ---- public: occ_ray_keys ------------------------------------------------------------------ */

size_t occ_ray_max_keys(const occ_map_t *const map, const occ_vec3_t origin, const occ_vec3_t end)
{
    if (map == NULL) {
        return 0;
    }
    occ_raygeo_t g;
    occi_raygeo_init(&g, map);
    const float o[3] = {origin.x, origin.y, origin.z};
    const float e[3] = {end.x, end.y, end.z};
    uint32_t ko[3], ke[3];
    if (!occi_raygeo_key(&g, o, ko) || !occi_raygeo_key(&g, e, ke)) {
        return 0;
    }
    return occi_dda_bound(ko, ke);
}

occ_err_t occ_ray_keys(const occ_map_t *const map, const occ_vec3_t origin, const occ_vec3_t end,
                       occ_key_t *const keys, const size_t cap, size_t *const n_keys)
{
    if (map == NULL || n_keys == NULL || (keys == NULL && cap > 0u)) {
        return OCC_ERR_ARG;
    }
    *n_keys = 0;
    if (!occ_finite3(origin) || !occ_finite3(end)) {
        return OCC_ERR_ARG;
    }
    occ_raygeo_t g;
    occi_raygeo_init(&g, map);
    const float o[3] = {origin.x, origin.y, origin.z};
    const float e[3] = {end.x, end.y, end.z};
    uint32_t ko[3], ke[3];
    if (!occi_raygeo_key(&g, o, ko) || !occi_raygeo_key(&g, e, ke)) {
        return OCC_ERR_RANGE;
    }
    size_t n = 0;
    if (ko[0] != ke[0] || ko[1] != ke[1] || ko[2] != ke[2]) {
        dda_t s;
        dda_init(&s, &g, o, e, ko, ke);
#define EMIT_KEY(x, y, z)                                                                         \
    do {                                                                                          \
        if (n < cap) {                                                                            \
            keys[n].k[0] = (x);                                                                   \
            keys[n].k[1] = (y);                                                                   \
            keys[n].k[2] = (z);                                                                   \
        }                                                                                         \
        n++;                                                                                      \
    } while (0)
        EMIT_KEY(ko[0], ko[1], ko[2]);
        DDA_LOOP(s, EMIT_KEY);
#undef EMIT_KEY
    }
    *n_keys = n;
    return n > cap ? OCC_ERR_NOMEM : OCC_OK;
}
