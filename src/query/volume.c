/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * volume.c - bounding volumes: construction, exact tests of node cubes against them, the key
 * range a volume can touch and which children of a node it touches. Shared by the iterator
 * (query.c) and the collision checks (collide.c).
 */
#include "query_internal.h"

/* ---- small vector helpers ------------------------------------------------------------------ */
static occ_vec3_t v3(float x, float y, float z)
{
    occ_vec3_t r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}
static occ_vec3_t vsub(occ_vec3_t a, occ_vec3_t b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static occ_vec3_t vadd(occ_vec3_t a, occ_vec3_t b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static occ_vec3_t vscale(occ_vec3_t a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static float vdot(occ_vec3_t a, occ_vec3_t b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static occ_vec3_t vcross(occ_vec3_t a, occ_vec3_t b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static float vabs1(occ_vec3_t a) { return fabsf(a.x) + fabsf(a.y) + fabsf(a.z); }
static float comp(occ_vec3_t a, unsigned i) { return i == 0u ? a.x : (i == 1u ? a.y : a.z); }
static float minf(float a, float b) { return a < b ? a : b; }
static float maxf(float a, float b) { return a > b ? a : b; }

static bool axes_ok(const occ_vec3_t axes[3])
{
    for (unsigned i = 0; i < 3u; i++) {
        if (!occ_finite3(axes[i]) || fabsf(vdot(axes[i], axes[i]) - 1.0f) > 2e-3f) {
            return false;
        }
        for (unsigned j = i + 1u; j < 3u; j++) {
            if (fabsf(vdot(axes[i], axes[j])) > 1e-3f) {
                return false;
            }
        }
    }
    return true;
}

/* ---- constructors ----------------------------------------------------------------------------- */
occ_err_t occ_volume_aabb(occ_volume_t *v, occ_vec3_t min, occ_vec3_t max)
{
    if (v == NULL || !occ_finite3(min) || !occ_finite3(max) || min.x > max.x ||
        min.y > max.y || min.z > max.z) {
        return OCC_ERR_ARG;
    }
    v->kind = OCC_VOL_AABB;
    v->bmin = min;
    v->bmax = max;
    return OCC_OK;
}

occ_err_t occ_volume_sphere(occ_volume_t *v, occ_vec3_t center, float radius_m)
{
    if (v == NULL || !occ_finite3(center) || !occ_finite(radius_m) || radius_m < 0.0f) {
        return OCC_ERR_ARG;
    }
    v->kind = OCC_VOL_SPHERE;
    v->u.sphere.c = center;
    v->u.sphere.r = radius_m;
    v->bmin = v3(center.x - radius_m, center.y - radius_m, center.z - radius_m);
    v->bmax = v3(center.x + radius_m, center.y + radius_m, center.z + radius_m);
    return OCC_OK;
}

occ_err_t occ_volume_obb(occ_volume_t *v, occ_vec3_t center, const float half_m[3],
                         const occ_vec3_t axes[3])
{
    if (v == NULL || half_m == NULL || axes == NULL || !occ_finite3(center) || !axes_ok(axes)) {
        return OCC_ERR_ARG;
    }
    for (unsigned i = 0; i < 3u; i++) {
        if (!occ_finite(half_m[i]) || half_m[i] < 0.0f) {
            return OCC_ERR_ARG;
        }
    }
    v->kind = OCC_VOL_OBB;
    v->u.obb.c = center;
    for (unsigned i = 0; i < 3u; i++) {
        v->u.obb.axis[i] = axes[i];
        v->u.obb.half[i] = half_m[i];
    }
    /* Extent along world axis k: sum_i half_i |axis_i[k]|. */
    const float ex = half_m[0] * fabsf(axes[0].x) + half_m[1] * fabsf(axes[1].x) +
                     half_m[2] * fabsf(axes[2].x);
    const float ey = half_m[0] * fabsf(axes[0].y) + half_m[1] * fabsf(axes[1].y) +
                     half_m[2] * fabsf(axes[2].y);
    const float ez = half_m[0] * fabsf(axes[0].z) + half_m[1] * fabsf(axes[1].z) +
                     half_m[2] * fabsf(axes[2].z);
    v->bmin = v3(center.x - ex, center.y - ey, center.z - ez);
    v->bmax = v3(center.x + ex, center.y + ey, center.z + ez);
    return OCC_OK;
}

occ_err_t occ_volume_obb_yaw(occ_volume_t *v, occ_vec3_t center, const float half_m[3],
                             float yaw_rad)
{
    if (!occ_finite(yaw_rad)) {
        return OCC_ERR_ARG;
    }
    const float c = cosf(yaw_rad);
    const float s = sinf(yaw_rad);
    occ_vec3_t axes[3];
    axes[0] = v3(c, s, 0.0f);
    axes[1] = v3(-s, c, 0.0f);
    axes[2] = v3(0.0f, 0.0f, 1.0f);
    return occ_volume_obb(v, center, half_m, axes);
}

static occ_err_t capsule_like(occ_volume_t *v, occ_vec3_t a, occ_vec3_t b, float r,
                              occ_volume_kind_t kind)
{
    if (v == NULL || !occ_finite3(a) || !occ_finite3(b) || !occ_finite(r) || r < 0.0f) {
        return OCC_ERR_ARG;
    }
    v->kind = kind;
    v->u.capsule.a = a;
    v->u.capsule.b = b;
    v->u.capsule.r = r;
    v->bmin = v3(minf(a.x, b.x) - r, minf(a.y, b.y) - r, minf(a.z, b.z) - r);
    v->bmax = v3(maxf(a.x, b.x) + r, maxf(a.y, b.y) + r, maxf(a.z, b.z) + r);
    return OCC_OK;
}

occ_err_t occ_volume_capsule(occ_volume_t *v, occ_vec3_t a, occ_vec3_t b, float radius_m)
{
    return capsule_like(v, a, b, radius_m, OCC_VOL_CAPSULE);
}

occ_err_t occ_volume_segment(occ_volume_t *v, occ_vec3_t a, occ_vec3_t b)
{
    return capsule_like(v, a, b, 0.0f, OCC_VOL_SEGMENT);
}

occ_err_t occ_volume_frustum(occ_volume_t *v, occ_vec3_t origin, const occ_vec3_t axes[3],
                             float hfov_rad, float vfov_rad, float near_m, float far_m)
{
    const float pi = 3.14159265f;
    if (v == NULL || axes == NULL || !occ_finite3(origin) || !axes_ok(axes) ||
        !occ_finite(hfov_rad) || !occ_finite(vfov_rad) || !occ_finite(near_m) ||
        !occ_finite(far_m) || !(hfov_rad > 0.0f) || !(hfov_rad < pi) || !(vfov_rad > 0.0f) ||
        !(vfov_rad < pi) || !(near_m >= 0.0f) || !(far_m > near_m)) {
        return OCC_ERR_ARG;
    }
    const occ_vec3_t f = axes[0];
    const occ_vec3_t l = axes[1];
    const occ_vec3_t u = axes[2];
    const float th = tanf(0.5f * hfov_rad);
    const float tv = tanf(0.5f * vfov_rad);
    v->kind = OCC_VOL_FRUSTUM;
    v->u.frustum.left = l;
    v->u.frustum.up = u;
    v->u.frustum.origin = origin;
    /* Corners: for depth dd, (+l,+u) (-l,+u) (-l,-u) (+l,-u). */
    for (unsigned face = 0; face < 2u; face++) {
        const float dd = face == 0u ? near_m : far_m;
        const occ_vec3_t mid = vadd(origin, vscale(f, dd));
        for (unsigned k = 0; k < 4u; k++) {
            const float sl = (k == 0u || k == 3u) ? 1.0f : -1.0f;
            const float su = (k < 2u) ? 1.0f : -1.0f;
            v->u.frustum.corner[face * 4u + k] =
                vadd(mid, vadd(vscale(l, sl * dd * th), vscale(u, su * dd * tv)));
        }
    }
    /* Outward normals: near, far, left, right, top, bottom. */
    occ_vec3_t n[6];
    n[0] = vscale(f, -1.0f);
    n[1] = f;
    n[2] = vsub(l, vscale(f, th)); /* plane through origin containing f + th l and u */
    n[3] = vsub(vscale(l, -1.0f), vscale(f, th));
    n[4] = vsub(u, vscale(f, tv));
    n[5] = vsub(vscale(u, -1.0f), vscale(f, tv));
    for (unsigned i = 0; i < 6u; i++) {
        const float len = sqrtf(vdot(n[i], n[i]));
        n[i] = vscale(n[i], 1.0f / len);
        v->u.frustum.n[i] = n[i];
    }
    v->u.frustum.d[0] = vdot(n[0], vadd(origin, vscale(f, near_m)));
    v->u.frustum.d[1] = vdot(n[1], vadd(origin, vscale(f, far_m)));
    for (unsigned i = 2; i < 6u; i++) {
        v->u.frustum.d[i] = vdot(n[i], origin);
    }
    v->bmin = v->u.frustum.corner[0];
    v->bmax = v->u.frustum.corner[0];
    for (unsigned k = 1; k < 8u; k++) {
        const occ_vec3_t c = v->u.frustum.corner[k];
        v->bmin = v3(minf(v->bmin.x, c.x), minf(v->bmin.y, c.y), minf(v->bmin.z, c.z));
        v->bmax = v3(maxf(v->bmax.x, c.x), maxf(v->bmax.y, c.y), maxf(v->bmax.z, c.z));
    }
    return OCC_OK;
}

/* ---- exact node tests ------------------------------------------------------------------------- */
/* Always inline: called, its vector arguments went through the stack under the capsule test,
 * the deepest of the walks' exact tests (make cross). */
static OCC_ALWAYS_INLINE float point_box_d2(occ_vec3_t p, occ_vec3_t c, float h)
{
    const float dx = occ_q_pos(fabsf(p.x - c.x) - h);
    const float dy = occ_q_pos(fabsf(p.y - c.y) - h);
    const float dz = occ_q_pos(fabsf(p.z - c.z) - h);
    return dx * dx + dy * dy + dz * dz;
}

/* Squared distance from segment a + t d (t in [0,1]) to the cube: the distance is convex and
 * piecewise quadratic in t with breaks where the segment crosses a slab plane; minimize every
 * piece in closed form. */
static float segment_box_d2(occ_vec3_t a, occ_vec3_t b, occ_vec3_t c, float h)
{
    const occ_vec3_t d = vsub(b, a);
    float t[8];
    unsigned n = 0;
    t[n++] = 0.0f;
    t[n++] = 1.0f;
    for (unsigned i = 0; i < 3u; i++) {
        const float di = comp(d, i);
        if (di > 0.0f || di < 0.0f) {
            const float ai = comp(a, i);
            const float ci = comp(c, i);
            const float t0 = (ci - h - ai) / di;
            const float t1 = (ci + h - ai) / di;
            if (t0 > 0.0f && t0 < 1.0f) {
                t[n++] = t0;
            }
            if (t1 > 0.0f && t1 < 1.0f) {
                t[n++] = t1;
            }
        }
    }
    for (unsigned i = 1; i < n; i++) { /* insertion sort, n <= 8 */
        const float x = t[i];
        unsigned j = i;
        while (j > 0u && t[j - 1u] > x) {
            t[j] = t[j - 1u];
            j--;
        }
        t[j] = x;
    }
    float best = minf(point_box_d2(a, c, h), point_box_d2(b, c, h));
    for (unsigned k = 0; k + 1u < n; k++) {
        const float lo = t[k];
        const float hi = t[k + 1u];
        const float tm = 0.5f * (lo + hi);
        /* On this piece each axis is below, inside or above its slab. */
        float qa = 0.0f;
        float qb = 0.0f;
        for (unsigned i = 0; i < 3u; i++) {
            const float ai = comp(a, i);
            const float di = comp(d, i);
            const float ci = comp(c, i);
            const float pi = ai + tm * di;
            float bound;
            if (pi < ci - h) {
                bound = ci - h;
            } else if (pi > ci + h) {
                bound = ci + h;
            } else {
                continue;
            }
            /* (ai - bound + t di)^2 */
            qa += di * di;
            qb += 2.0f * (ai - bound) * di;
        }
        float ts = lo;
        if (qa > 0.0f) {
            ts = -qb / (2.0f * qa);
            ts = ts < lo ? lo : (ts > hi ? hi : ts);
        }
        const float d2 = point_box_d2(vadd(a, vscale(d, ts)), c, h);
        best = minf(best, d2);
    }
    return best;
}

static float point_segment_d2(occ_vec3_t p, occ_vec3_t a, occ_vec3_t b)
{
    const occ_vec3_t d = vsub(b, a);
    const float dd = vdot(d, d);
    float t = 0.0f;
    if (dd > 0.0f) {
        t = vdot(vsub(p, a), d) / dd;
        t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    }
    const occ_vec3_t q = vsub(p, vadd(a, vscale(d, t)));
    return vdot(q, q);
}

OCC_NOINLINE static bool segment_hits_box(occ_vec3_t a, occ_vec3_t b, occ_vec3_t c, float h)
{
    float tmin = 0.0f;
    float tmax = 1.0f;
    for (unsigned i = 0; i < 3u; i++) {
        const float ai = comp(a, i);
        const float di = comp(b, i) - ai;
        const float lo = comp(c, i) - h;
        const float hi = comp(c, i) + h;
        if (di > 0.0f || di < 0.0f) {
            float t0 = (lo - ai) / di;
            float t1 = (hi - ai) / di;
            if (t0 > t1) {
                const float s = t0;
                t0 = t1;
                t1 = s;
            }
            tmin = maxf(tmin, t0);
            tmax = minf(tmax, t1);
            if (tmin > tmax) {
                return false;
            }
        } else if (ai < lo || ai > hi) {
            return false;
        }
    }
    return true;
}

OCC_NOINLINE static bool obb_hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    const occ_vec3_t d = vsub(c, v->u.obb.c);
    const occ_vec3_t *ax = v->u.obb.axis;
    const float *e = v->u.obb.half;
    /* World axes are covered by the bounds test; OBB axes: */
    for (unsigned j = 0; j < 3u; j++) {
        if (fabsf(vdot(d, ax[j])) > e[j] + h * vabs1(ax[j])) {
            return false;
        }
    }
    for (unsigned i = 0; i < 3u; i++) {
        const occ_vec3_t w = v3(i == 0u ? 1.0f : 0.0f, i == 1u ? 1.0f : 0.0f, i == 2u ? 1.0f : 0.0f);
        for (unsigned j = 0; j < 3u; j++) {
            const occ_vec3_t l = vcross(w, ax[j]);
            if (vdot(l, l) < 1e-10f) {
                continue;
            }
            const float rb = e[0] * fabsf(vdot(l, ax[0])) + e[1] * fabsf(vdot(l, ax[1])) +
                             e[2] * fabsf(vdot(l, ax[2]));
            if (fabsf(vdot(d, l)) > h * vabs1(l) + rb) {
                return false;
            }
        }
    }
    return true;
}

/* Edge direction k of a frustum: 0..3 its side edges (near to far corner), 4 left, 5 up. */
static occ_vec3_t frustum_edge(const occ_volume_t *v, unsigned k)
{
    return k < 4u ? vsub(v->u.frustum.corner[4u + k], v->u.frustum.corner[k])
                  : (k == 4u ? v->u.frustum.left : v->u.frustum.up);
}

OCC_NOINLINE static bool frustum_hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    for (unsigned i = 0; i < 6u; i++) {
        const occ_vec3_t n = v->u.frustum.n[i];
        if (vdot(n, c) - h * vabs1(n) > v->u.frustum.d[i]) {
            return false;
        }
    }
    /* Edge x edge axes: box axes x frustum edge directions (4 side edges, left, up), each
     * edge worked out where it is used (an array of the 6 would sit on the walks' stack). */
    for (unsigned i = 0; i < 3u; i++) {
        const occ_vec3_t w = v3(i == 0u ? 1.0f : 0.0f, i == 1u ? 1.0f : 0.0f, i == 2u ? 1.0f : 0.0f);
        for (unsigned k = 0; k < 6u; k++) {
            const occ_vec3_t e = frustum_edge(v, k);
            const occ_vec3_t l = vcross(w, e);
            const float ll = vdot(l, l);
            if (ll < 1e-10f * maxf(vdot(e, e), 1.0f)) {
                continue;
            }
            float lo = vdot(l, v->u.frustum.corner[0]);
            float hi = lo;
            for (unsigned q = 1; q < 8u; q++) {
                const float p = vdot(l, v->u.frustum.corner[q]);
                lo = minf(lo, p);
                hi = maxf(hi, p);
            }
            const float pc = vdot(l, c);
            const float r = h * vabs1(l);
            if (pc - r > hi || pc + r < lo) {
                return false;
            }
        }
    }
    return true;
}

OCC_NOINLINE static bool capsule_hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    return segment_box_d2(v->u.capsule.a, v->u.capsule.b, c, h) <= v->u.capsule.r * v->u.capsule.r;
}

/* The bounds first (most cubes fail there), then the kind's exact test. Those of the obb,
 * capsule, segment and frustum are out of line: inlined, all their frames together sat under
 * every walk that calls this (the collision checks, the iterator: make cross), where only the
 * largest of them is ever in use. */
static OCC_ALWAYS_INLINE bool hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    if (c.x - h > v->bmax.x || c.x + h < v->bmin.x || c.y - h > v->bmax.y ||
        c.y + h < v->bmin.y || c.z - h > v->bmax.z || c.z + h < v->bmin.z) {
        return false;
    }
    switch (v->kind) {
    case OCC_VOL_AABB:
        return true;
    case OCC_VOL_SPHERE:
        return point_box_d2(v->u.sphere.c, c, h) <= v->u.sphere.r * v->u.sphere.r;
    case OCC_VOL_OBB:
        return obb_hits_box(v, c, h);
    case OCC_VOL_CAPSULE:
        return capsule_hits_box(v, c, h);
    case OCC_VOL_SEGMENT:
        return segment_hits_box(v->u.capsule.a, v->u.capsule.b, c, h);
    case OCC_VOL_FRUSTUM:
        return frustum_hits_box(v, c, h);
    default:
        return false;
    }
}

bool occ_volume_hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    return hits_box(v, c, h);
}

bool occ_volume_holds_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    if (c.x - h < v->bmin.x || c.x + h > v->bmax.x || c.y - h < v->bmin.y ||
        c.y + h > v->bmax.y || c.z - h < v->bmin.z || c.z + h > v->bmax.z) {
        return false;
    }
    switch (v->kind) {
    case OCC_VOL_AABB:
        return true;
    case OCC_VOL_SPHERE: {
        const float dx = fabsf(v->u.sphere.c.x - c.x) + h;
        const float dy = fabsf(v->u.sphere.c.y - c.y) + h;
        const float dz = fabsf(v->u.sphere.c.z - c.z) + h;
        return dx * dx + dy * dy + dz * dz <= v->u.sphere.r * v->u.sphere.r;
    }
    case OCC_VOL_OBB: {
        const occ_vec3_t d = vsub(c, v->u.obb.c);
        for (unsigned j = 0; j < 3u; j++) {
            if (fabsf(vdot(d, v->u.obb.axis[j])) + h * vabs1(v->u.obb.axis[j]) >
                v->u.obb.half[j]) {
                return false;
            }
        }
        return true;
    }
    case OCC_VOL_CAPSULE: {
        const float r2 = v->u.capsule.r * v->u.capsule.r;
        for (unsigned k = 0; k < 8u; k++) {
            const occ_vec3_t p = v3(c.x + ((k & 1u) ? h : -h), c.y + ((k & 2u) ? h : -h),
                                    c.z + ((k & 4u) ? h : -h));
            if (point_segment_d2(p, v->u.capsule.a, v->u.capsule.b) > r2) {
                return false;
            }
        }
        return true;
    }
    case OCC_VOL_FRUSTUM:
        for (unsigned i = 0; i < 6u; i++) {
            const occ_vec3_t n = v->u.frustum.n[i];
            if (vdot(n, c) + h * vabs1(n) > v->u.frustum.d[i]) {
                return false;
            }
        }
        return true;
    case OCC_VOL_SEGMENT:
    default:
        return false;
    }
}

/* ---- what a volume can touch ---------------------------------------------------------------- */
/* Key range [lo, hi] per axis of the voxels that can touch the closed bounds (one voxel of slack
 * for faces lying exactly on a border); false when the bounds miss the map. */
bool occi_q_bounds_keys(const occ_map_t *m, const occ_volume_t *v, uint32_t lo[3], uint32_t hi[3])
{
    /* Slack for rounding, in voxels: the exact tests work on float node boxes, whose step at the
     * map's far corners is half * 2^-23 voxels; four of those, and a lower face on a border
     * still takes in the voxel below, whose upper face it touches. The keys themselves come
     * from the map's one conversion. */
    const occ_real_t half = (occ_real_t)occ_geom_half(m);
    const occ_real_t slack = (occ_real_t)4 * half * ((occ_real_t)1 / (occ_real_t)8388608) +
                             (occ_real_t)1e-3;
    const float bmin[3] = {v->bmin.x, v->bmin.y, v->bmin.z};
    const float bmax[3] = {v->bmax.x, v->bmax.y, v->bmax.z};
    for (unsigned i = 0; i < 3u; i++) {
        if (!occi_geom_key_range(m, bmin[i], bmax[i], slack, &lo[i], &hi[i])) {
            return false;
        }
    }
    return true;
}

/* Which children (half edge h) of a node centred at pc touch a sphere / a box: per axis the
 * squared distance to the lower and upper half (or their overlap), combined over the 8 slots. */
static inline unsigned sphere_touch(const occ_volume_t *v, occ_vec3_t pc, float h)
{
    const occ_vec3_t c = v->u.sphere.c;
    const float r2 = v->u.sphere.r * v->u.sphere.r;
    float d;
    d = occ_q_pos(fabsf(c.x - (pc.x - h)) - h);
    const float x0 = d * d;
    d = occ_q_pos(fabsf(c.x - (pc.x + h)) - h);
    const float x1 = d * d;
    d = occ_q_pos(fabsf(c.y - (pc.y - h)) - h);
    const float y0 = d * d;
    d = occ_q_pos(fabsf(c.y - (pc.y + h)) - h);
    const float y1 = d * d;
    d = occ_q_pos(fabsf(c.z - (pc.z - h)) - h);
    const float z0 = d * d;
    d = occ_q_pos(fabsf(c.z - (pc.z + h)) - h);
    const float z1 = d * d;
    const float xy00 = x0 + y0;
    const float xy10 = x1 + y0;
    const float xy01 = x0 + y1;
    const float xy11 = x1 + y1;
    return (xy00 + z0 <= r2 ? 0x01u : 0u) | (xy10 + z0 <= r2 ? 0x02u : 0u) |
           (xy01 + z0 <= r2 ? 0x04u : 0u) | (xy11 + z0 <= r2 ? 0x08u : 0u) |
           (xy00 + z1 <= r2 ? 0x10u : 0u) | (xy10 + z1 <= r2 ? 0x20u : 0u) |
           (xy01 + z1 <= r2 ? 0x40u : 0u) | (xy11 + z1 <= r2 ? 0x80u : 0u);
}

/* 1 when the closed intervals [a0, a1] and [b0, b1] overlap; & rather than && so that it
 * compiles without a jump (see occ_q_pos). */
static inline unsigned overlap(float a0, float a1, float b0, float b1)
{
    return (unsigned)(a0 <= b1) & (unsigned)(a1 >= b0);
}

static inline unsigned aabb_touch(const occ_volume_t *v, occ_vec3_t pc, float h)
{
    const float e = 2.0f * h;
    const unsigned xm = 0x55u * overlap(pc.x - e, pc.x, v->bmin.x, v->bmax.x) |
                        0xAAu * overlap(pc.x, pc.x + e, v->bmin.x, v->bmax.x);
    const unsigned ym = 0x33u * overlap(pc.y - e, pc.y, v->bmin.y, v->bmax.y) |
                        0xCCu * overlap(pc.y, pc.y + e, v->bmin.y, v->bmax.y);
    const unsigned zm = 0x0Fu * overlap(pc.z - e, pc.z, v->bmin.z, v->bmax.z) |
                        0xF0u * overlap(pc.z, pc.z + e, v->bmin.z, v->bmax.z);
    return xm & ym & zm;
}

unsigned occi_q_touch_mask_sphere(const occ_map_t *m, const occ_volume_t *v, occ_key_t pkey,
                                  unsigned level)
{
    return sphere_touch(v, occ_geom_center(m, pkey, level + 1u), occ_q_half(m, level));
}

unsigned occi_q_touch_mask_aabb(const occ_map_t *m, const occ_volume_t *v, occ_key_t pkey,
                                unsigned level)
{
    return aabb_touch(v, occ_geom_center(m, pkey, level + 1u), occ_q_half(m, level));
}

unsigned occi_q_touch_mask_cubes(const occ_map_t *m, const occ_volume_t *v, occ_key_t pkey,
                                 unsigned level, unsigned want)
{
    const float h = occ_q_half(m, level);
    const occ_vec3_t pc = occ_geom_center(m, pkey, level + 1u);
    unsigned mask = 0u;
    for (unsigned rest = want; rest != 0u; rest &= rest - 1u) {
        const unsigned s = occ_first_slot(rest);
        occ_vec3_t c;
        c.x = pc.x + ((s & 1u) ? h : -h);
        c.y = pc.y + ((s & 2u) ? h : -h);
        c.z = pc.z + ((s & 4u) ? h : -h);
        if (hits_box(v, c, h)) {
            mask |= 1u << s;
        }
    }
    return mask;
}
