/*
 * query.c - bounding volumes (construction, exact node tests) and the volume iterator.
 * The iterator is a depth-first walk in Morton order on a fixed stack; a branch is skipped as
 * soon as its cube misses the volume or its max value / indicators rule the predicate out.
 */
#include "map/query_internal.h"

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
        if (!occ_q_finite3(axes[i]) || fabsf(vdot(axes[i], axes[i]) - 1.0f) > 2e-3f) {
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
    if (v == NULL || !occ_q_finite3(min) || !occ_q_finite3(max) || min.x > max.x ||
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
    if (v == NULL || !occ_q_finite3(center) || !occ_q_finite(radius_m) || radius_m < 0.0f) {
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
    if (v == NULL || half_m == NULL || axes == NULL || !occ_q_finite3(center) || !axes_ok(axes)) {
        return OCC_ERR_ARG;
    }
    for (unsigned i = 0; i < 3u; i++) {
        if (!occ_q_finite(half_m[i]) || half_m[i] < 0.0f) {
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
    if (!occ_q_finite(yaw_rad)) {
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
    if (v == NULL || !occ_q_finite3(a) || !occ_q_finite3(b) || !occ_q_finite(r) || r < 0.0f) {
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
    if (v == NULL || axes == NULL || !occ_q_finite3(origin) || !axes_ok(axes) ||
        !occ_q_finite(hfov_rad) || !occ_q_finite(vfov_rad) || !occ_q_finite(near_m) ||
        !occ_q_finite(far_m) || !(hfov_rad > 0.0f) || !(hfov_rad < pi) || !(vfov_rad > 0.0f) ||
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
static inline float point_box_d2(occ_vec3_t p, occ_vec3_t c, float h)
{
    const float dx = maxf(fabsf(p.x - c.x) - h, 0.0f);
    const float dy = maxf(fabsf(p.y - c.y) - h, 0.0f);
    const float dz = maxf(fabsf(p.z - c.z) - h, 0.0f);
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

static bool segment_hits_box(occ_vec3_t a, occ_vec3_t b, occ_vec3_t c, float h)
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

static bool obb_hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
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

static bool frustum_hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
{
    for (unsigned i = 0; i < 6u; i++) {
        const occ_vec3_t n = v->u.frustum.n[i];
        if (vdot(n, c) - h * vabs1(n) > v->u.frustum.d[i]) {
            return false;
        }
    }
    /* Edge x edge axes: box axes x frustum edge directions (4 side edges, left, up). */
    occ_vec3_t e[6];
    for (unsigned k = 0; k < 4u; k++) {
        e[k] = vsub(v->u.frustum.corner[4u + k], v->u.frustum.corner[k]);
    }
    e[4] = v->u.frustum.left;
    e[5] = v->u.frustum.up;
    for (unsigned i = 0; i < 3u; i++) {
        const occ_vec3_t w = v3(i == 0u ? 1.0f : 0.0f, i == 1u ? 1.0f : 0.0f, i == 2u ? 1.0f : 0.0f);
        for (unsigned k = 0; k < 6u; k++) {
            const occ_vec3_t l = vcross(w, e[k]);
            const float ll = vdot(l, l);
            if (ll < 1e-10f * maxf(vdot(e[k], e[k]), 1.0f)) {
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

static inline bool hits_box(const occ_volume_t *v, occ_vec3_t c, float h)
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
        return segment_box_d2(v->u.capsule.a, v->u.capsule.b, c, h) <=
               v->u.capsule.r * v->u.capsule.r;
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

/* ---- the iterator ----------------------------------------------------------------------------- */
void occ_q_fill_node(const occ_map_t *m, occ_key_t key, unsigned level, occ_value_t v,
                     uint8_t flags, bool uniform, occ_query_node_t *out)
{
    out->key = occ_key_at_level(key, level);
    out->level = (uint8_t)level;
    out->uniform = uniform;
    out->inside = false;
    out->observed = occ_is_observed(v);
    out->state = occ_q_state(m, v);
    out->flags = uniform ? occ_q_uniform_flags(m, v) : flags;
    if (!uniform && out->observed && v >= m->q_occ_min) {
        out->flags = (uint8_t)(out->flags | OCC_NODE_HAS_OCCUPIED);
    }
    out->logodds = out->observed ? occ_value_to_logodds(v) : 0.0f;
    out->center = occ_q_center(m, out->key, level);
    out->size_m = occ_map_node_size(m, level);
}

/* Key range [lo, hi] per axis of the voxels that can touch the closed bounds (one voxel of slack
 * for faces lying exactly on a border); false when the bounds miss the map. */
static bool bounds_keys(const occ_map_t *m, const occ_volume_t *v, uint32_t lo[3], uint32_t hi[3])
{
    const float inv = 1.0f / m->cfg.resolution_m;
    const float half = (float)(1u << (m->cfg.depth_levels - 1u));
    const float top = 2.0f * half - 1.0f;
    const float bmin[3] = {v->bmin.x, v->bmin.y, v->bmin.z};
    const float bmax[3] = {v->bmax.x, v->bmax.y, v->bmax.z};
    for (unsigned i = 0; i < 3u; i++) {
        /* Clamp first (keeps the integer conversion in range), then floor by truncation. */
        float l = bmin[i] * inv + half;
        float h = bmax[i] * inv + half;
        if (!(h >= -1.0f) || !(l <= top + 1.0f)) {
            return false;
        }
        l = l < -1.0f ? -1.0f : l;
        h = h > top + 1.0f ? top + 1.0f : h;
        int32_t li = (int32_t)l;
        int32_t hi_i = (int32_t)h;
        li -= (float)li > l ? 1 : 0;
        hi_i -= (float)hi_i > h ? 1 : 0;
        li -= 1; /* one voxel of slack: faces on a border touch the next voxel, and rounding */
        hi_i += 1;
        lo[i] = li < 0 ? 0u : (uint32_t)li;
        hi[i] = hi_i > (int32_t)top ? (uint32_t)top : (uint32_t)hi_i;
        if (lo[i] > hi[i] || hi_i < 0) {
            return false;
        }
    }
    return true;
}

static bool same_above(occ_key_t a, occ_key_t b, unsigned level)
{
    return ((a.k[0] ^ b.k[0]) >> level) == 0u && ((a.k[1] ^ b.k[1]) >> level) == 0u &&
           ((a.k[2] ^ b.k[2]) >> level) == 0u;
}

occ_err_t occ_query_begin(occ_query_iter_t *it, const occ_map_t *map, const occ_volume_t *vol,
                          occ_pred_t pred)
{
    if (it == NULL || map == NULL || vol == NULL || (pred.states & ~OCC_PRED_ANY) != 0u ||
        pred.min_level > map->cfg.depth_levels || (pred.options & ~OCC_ITER_SPLIT) != 0u) {
        return OCC_ERR_ARG;
    }
    if (pred.states == 0u) {
        pred.states = (uint8_t)OCC_PRED_ANY;
    }
    const unsigned depth = map->cfg.depth_levels;
    it->map = map;
    it->vol = vol;
    it->pred = pred;
    it->sp = 0;
    it->base = 0;
    it->virt_sp = OCC_MAX_DEPTH;
    it->virt_value = OCC_VALUE_UNOBSERVED;
    it->path.k[0] = it->path.k[1] = it->path.k[2] = 0u;
    it->nstart = 0;
    it->istart = 0;
    it->start_level = (uint8_t)depth;
    it->want_flags = (uint8_t)(((pred.states & OCC_PRED_FREE) != 0u ? OCC_NODE_HAS_FREE : 0u) |
                               ((pred.states & OCC_PRED_UNKNOWN) != 0u ? OCC_NODE_HAS_UNKNOWN : 0u));
    uint32_t lo[3];
    uint32_t hi[3];
    if (!bounds_keys(map, vol, lo, hi)) {
        return OCC_OK; /* nothing of the map is near the volume */
    }
    /* Smallest level whose cells are at least as wide as the key range: the range then spans
     * at most two cells per axis. */
    uint32_t ext = 0;
    for (unsigned i = 0; i < 3u; i++) {
        ext = (hi[i] - lo[i]) > ext ? (hi[i] - lo[i]) : ext;
    }
    unsigned lc = pred.min_level; /* never start below the level nodes are reported at */
    while (lc < depth && ((uint32_t)1 << lc) <= ext) {
        lc++;
    }
    if (lc >= depth) {
        it->start[0].k[0] = it->start[0].k[1] = it->start[0].k[2] = 0u;
        it->nstart = 1;
        return OCC_OK;
    }
    it->start_level = (uint8_t)lc;
    /* The cells c0 or c0 + 1 per axis. In Morton order the axis whose +1 flips the highest bit
     * (z before y before x on ties) is the most significant, so count in that bit order. */
    uint32_t c0[3];
    unsigned ax[3];
    unsigned na = 0;
    for (unsigned i = 0; i < 3u; i++) {
        c0[i] = lo[i] >> lc;
        if ((hi[i] >> lc) != c0[i]) {
            ax[na++] = i;
        }
    }
    unsigned rank[3] = {0u, 0u, 0u};
    for (unsigned j = 0; j < na; j++) {
        const uint32_t x = c0[ax[j]] ^ (c0[ax[j]] + 1u);
        unsigned hb = 0;
        for (uint32_t y = x >> 1; y != 0u; y >>= 1) {
            hb++;
        }
        rank[j] = hb * 3u + ax[j];
    }
    for (unsigned j = 1; j < na; j++) { /* most significant first */
        for (unsigned q = j; q > 0u && rank[q] > rank[q - 1u]; q--) {
            const unsigned tr = rank[q];
            const unsigned ta = ax[q];
            rank[q] = rank[q - 1u];
            ax[q] = ax[q - 1u];
            rank[q - 1u] = tr;
            ax[q - 1u] = ta;
        }
    }
    const unsigned n = 1u << na;
    for (unsigned t = 0; t < n; t++) {
        uint32_t c[3] = {c0[0], c0[1], c0[2]};
        for (unsigned j = 0; j < na; j++) {
            c[ax[j]] += (t >> (na - 1u - j)) & 1u;
        }
        it->start[t].k[0] = c[0] << lc;
        it->start[t].k[1] = c[1] << lc;
        it->start[t].k[2] = c[2] << lc;
    }
    it->nstart = (uint8_t)n;
    return OCC_OK;
}

static occ_key_t mask_key(occ_key_t k, unsigned level)
{
    const uint32_t m = ~(((uint32_t)1 << level) - 1u);
    k.k[0] &= m;
    k.k[1] &= m;
    k.k[2] &= m;
    return k;
}

/* Does one node match the predicate (uniform: its state; with children: contains)? */
static bool pred_match(const occ_query_iter_t *it, occ_value_t v, uint8_t flags, bool uniform)
{
    if (uniform) {
        return (it->pred.states & occ_q_state_bit(occ_q_state(it->map, v))) != 0u;
    }
    return occ_q_contains(it->map, v, flags, it->pred.states);
}

/* Predicate bits of the 8 children of a stored block. A uniform child's flags follow from its
 * value (tree invariant), so one formula serves uniform and mixed children alike: occupied from
 * the max value, free and unknown from the indicators. */
static unsigned inner_pred_mask(const occ_query_iter_t *it, const occ_inner_block_t *b)
{
    const occ_value_t occ_min = it->map->q_occ_min;
    const unsigned want_occ = (it->pred.states & OCC_PRED_OCCUPIED) != 0u ? 1u : 0u;
    const unsigned wf = it->want_flags;
    unsigned pm = 0u;
    for (unsigned s = 0; s < 8u; s++) {
        const unsigned hit = (want_occ & (unsigned)(b->value[s] >= occ_min)) |
                             (unsigned)((b->flags[s] & wf) != 0u);
        pm |= hit << s;
    }
    return pm;
}

static unsigned leaf_pred_mask(const occ_query_iter_t *it, const occ_leaf_block_t *b)
{
    const occ_value_t occ_min = it->map->q_occ_min;
    const occ_value_t free_max = it->map->q_free_max;
    const unsigned st = it->pred.states;
    const unsigned w_occ = (st & OCC_PRED_OCCUPIED) != 0u ? 1u : 0u;
    const unsigned w_free = (st & OCC_PRED_FREE) != 0u ? 1u : 0u;
    const unsigned w_unk = (st & OCC_PRED_UNKNOWN) != 0u ? 1u : 0u;
    unsigned pm = 0u;
    for (unsigned s = 0; s < 8u; s++) { /* branch-free: the states of neighbours are random */
        const occ_value_t v = b->value[s];
        const unsigned occ = (unsigned)(v >= occ_min);
        const unsigned fr = (unsigned)(v < free_max) & (unsigned)occ_is_observed(v);
        const unsigned unk = (occ | fr) ^ 1u;
        pm |= ((w_occ & occ) | (w_free & fr) | (w_unk & unk)) << s;
    }
    return pm;
}

/* Which of the 8 children (level `level`) of the node with first voxel `pkey` touch the volume.
 * Spheres and boxes are done per axis (two halves each), the rest child by child. */
static inline unsigned geom_mask(const occ_query_iter_t *it, occ_key_t pkey, unsigned level)
{
    const occ_map_t *const m = it->map;
    const occ_volume_t *const v = it->vol;
    const float h = occ_q_half(m, level);
    const occ_vec3_t pc = occ_q_center(m, pkey, level + 1u);
    if (v->kind == OCC_VOL_SPHERE) {
        /* Squared distance per axis from the centre to the lower and upper half. */
        const occ_vec3_t c = v->u.sphere.c;
        const float r2 = v->u.sphere.r * v->u.sphere.r;
        float d;
        d = maxf(fabsf(c.x - (pc.x - h)) - h, 0.0f);
        const float x0 = d * d;
        d = maxf(fabsf(c.x - (pc.x + h)) - h, 0.0f);
        const float x1 = d * d;
        d = maxf(fabsf(c.y - (pc.y - h)) - h, 0.0f);
        const float y0 = d * d;
        d = maxf(fabsf(c.y - (pc.y + h)) - h, 0.0f);
        const float y1 = d * d;
        d = maxf(fabsf(c.z - (pc.z - h)) - h, 0.0f);
        const float z0 = d * d;
        d = maxf(fabsf(c.z - (pc.z + h)) - h, 0.0f);
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
    if (v->kind == OCC_VOL_AABB) {
        /* Child halves overlapping the box on each axis, combined as bit patterns. */
        const unsigned xm = (pc.x - 2.0f * h <= v->bmax.x && pc.x >= v->bmin.x ? 0x55u : 0u) |
                            (pc.x <= v->bmax.x && pc.x + 2.0f * h >= v->bmin.x ? 0xAAu : 0u);
        const unsigned ym = (pc.y - 2.0f * h <= v->bmax.y && pc.y >= v->bmin.y ? 0x33u : 0u) |
                            (pc.y <= v->bmax.y && pc.y + 2.0f * h >= v->bmin.y ? 0xCCu : 0u);
        const unsigned zm = (pc.z - 2.0f * h <= v->bmax.z && pc.z >= v->bmin.z ? 0x0Fu : 0u) |
                            (pc.z <= v->bmax.z && pc.z + 2.0f * h >= v->bmin.z ? 0xF0u : 0u);
        return xm & ym & zm;
    }
    unsigned mask = 0u;
    for (unsigned s = 0; s < 8u; s++) {
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

/* Push the children of the node with first voxel `pkey` (children at `level`, in stack entry i):
 * a stored block, or (block OCC_NONE) the virtual split of a uniform node of value `uv`. */
static inline void push(occ_query_iter_t *it, occ_key_t pkey, unsigned level, uint32_t block,
                 occ_value_t uv, unsigned i)
{
    const occ_map_t *const m = it->map;
    unsigned pm;
    if (block == OCC_NONE) {
        pm = 0xFFu; /* the uniform parent matched, so does every part of it */
        if (it->virt_sp == OCC_MAX_DEPTH) {
            it->virt_sp = (uint8_t)i;
            it->virt_value = uv;
        }
    } else if (level == 0u) {
        pm = leaf_pred_mask(it, occ_leaf_at(m, block));
    } else {
        pm = inner_pred_mask(it, occ_inner_at(m, block));
    }
    it->block[i] = block;
    it->mask[i] = pm != 0u ? (uint8_t)(pm & geom_mask(it, pkey, level)) : 0u;
    it->sp = (uint8_t)(i + 1u);
}

/* A node that matches and touches: report it (true), or push its children. */
static inline bool take(occ_query_iter_t *it, occ_key_t key, unsigned level, occ_value_t v, uint8_t flags,
                 uint32_t child, unsigned i, occ_query_node_t *out)
{
    const bool uniform = child == OCC_NONE;
    bool inside = false;
    if (level > it->pred.min_level) {
        if (!uniform) {
            push(it, key, level - 1u, child, v, i);
            return false;
        }
        if ((it->pred.options & OCC_ITER_SPLIT) != 0u) {
            inside = occ_volume_holds_box(it->vol, occ_q_center(it->map, key, level),
                                          occ_q_half(it->map, level));
            if (!inside) {
                push(it, key, level - 1u, OCC_NONE, v, i);
                return false;
            }
        }
    }
    occ_q_fill_node(it->map, key, level, v, flags, uniform, out);
    out->inside = inside;
    return true;
}

/* A start node: test it, then take it. */
static bool enter(occ_query_iter_t *it, occ_key_t key, unsigned level, occ_value_t v,
                  uint8_t flags, uint32_t child, unsigned i, occ_query_node_t *out)
{
    if (!pred_match(it, v, flags, child == OCC_NONE) ||
        !hits_box(it->vol, occ_q_center(it->map, key, level), occ_q_half(it->map, level))) {
        return false;
    }
    return take(it, key, level, v, flags, child, i, out);
}

/* Descend to the next start node and enter it. The path of the previous start is kept in
 * block[D-L] (entries above the DFS stack), so only the levels below the highest key bit in which
 * the two starts differ are walked again. */
static bool next_start(occ_query_iter_t *it, occ_query_node_t *out)
{
    const occ_map_t *const m = it->map;
    const unsigned depth = m->cfg.depth_levels;
    const occ_key_t key = it->start[it->istart];
    unsigned level = depth;
    uint32_t child = m->root_child;
    occ_value_t v = m->root_value;
    uint8_t flags = m->root_flags;
    bool check = true;
    if (it->istart > 0u) {
        const uint32_t x = (key.k[0] ^ it->path.k[0]) | (key.k[1] ^ it->path.k[1]) |
                           (key.k[2] ^ it->path.k[2]);
        unsigned hb = 0;
        for (uint32_t y = x >> 1; y != 0u; y >>= 1) {
            hb++;
        }
        if (hb + 1u < depth) {
            level = hb + 1u; /* the common ancestor, already checked */
            child = it->block[depth - level];
            check = false;
        }
    }
    it->istart++;
    const occ_code_t code = occ_morton_encode(key);
    while (level > it->start_level && child != OCC_NONE) {
        if (check && !occ_q_contains(m, v, flags, it->pred.states)) {
            break; /* nothing wanted below: skip this node */
        }
        check = true;
        it->block[depth - level] = child;
        const unsigned slot = occ_code_slot(code, level);
        level--;
        if (level == 0u) {
            v = occ_leaf_at(m, child)->value[slot];
            flags = 0u;
            child = OCC_NONE;
        } else {
            const occ_inner_block_t *const b = occ_inner_at(m, child);
            v = b->value[slot];
            flags = b->flags[slot];
            child = b->child[slot];
        }
    }
    /* Later starts inside the node reached (uniform, or without anything wanted) are this node. */
    while (it->istart < it->nstart && same_above(it->start[it->istart], key, level)) {
        it->istart++;
    }
    it->path = mask_key(key, level);
    it->virt_sp = OCC_MAX_DEPTH;
    it->base = (uint8_t)(depth - level);
    it->sp = it->base;
    return enter(it, it->path, level, v, flags, child, depth - level, out);
}

bool occ_query_next(occ_query_iter_t *it, occ_query_node_t *out)
{
    const occ_map_t *const m = it->map;
    const unsigned depth = m->cfg.depth_levels;
    for (;;) {
        while (it->sp > it->base) {
            const unsigned i = it->sp - 1u;
            const unsigned mk = it->mask[i];
            if (mk == 0u) {
                it->sp = (uint8_t)i;
                if (i == it->virt_sp) {
                    it->virt_sp = OCC_MAX_DEPTH;
                }
                continue;
            }
#if defined(__GNUC__)
            const unsigned slot = (unsigned)__builtin_ctz(mk);
#else
            unsigned slot = 0;
            while (((mk >> slot) & 1u) == 0u) {
                slot++;
            }
#endif
            it->mask[i] = (uint8_t)(mk & (mk - 1u));
            const unsigned level = depth - 1u - i;
            const uint32_t bit = 1u << level;
            it->path.k[0] = (it->path.k[0] & ~bit) | ((slot & 1u) ? bit : 0u);
            it->path.k[1] = (it->path.k[1] & ~bit) | ((slot & 2u) ? bit : 0u);
            it->path.k[2] = (it->path.k[2] & ~bit) | ((slot & 4u) ? bit : 0u);
            occ_value_t v;
            uint8_t flags = 0u;
            uint32_t child = OCC_NONE;
            if (i >= it->virt_sp) {
                v = it->virt_value;
            } else if (level == 0u) {
                v = occ_leaf_at(m, it->block[i])->value[slot];
            } else {
                const occ_inner_block_t *const b = occ_inner_at(m, it->block[i]);
                v = b->value[slot];
                flags = b->flags[slot];
                child = b->child[slot];
            }
            if (take(it, mask_key(it->path, level), level, v, flags, child, i + 1u, out)) {
                return true;
            }
        }
        if (it->istart >= it->nstart) {
            return false;
        }
        if (next_start(it, out)) {
            return true;
        }
    }
}

occ_err_t occ_query_count(const occ_map_t *map, const occ_volume_t *vol, occ_query_counts_t *out)
{
    if (map == NULL || vol == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    occ_pred_t pred;
    pred.states = (uint8_t)OCC_PRED_ANY;
    pred.min_level = 0;
    pred.options = (uint8_t)OCC_ITER_SPLIT;
    occ_query_iter_t it;
    const occ_err_t e = occ_query_begin(&it, map, vol, pred);
    if (e != OCC_OK) {
        return e;
    }
    out->occupied = out->free = out->unknown = 0u;
    occ_query_node_t n;
    while (occ_query_next(&it, &n)) {
        const uint64_t cnt = n.inside ? ((uint64_t)1 << (3u * n.level)) : 1u;
        switch (n.state) {
        case OCC_STATE_OCCUPIED:
            out->occupied += cnt;
            break;
        case OCC_STATE_FREE:
            out->free += cnt;
            break;
        case OCC_STATE_UNKNOWN:
        default:
            out->unknown += cnt;
            break;
        }
    }
    const float half = occ_map_node_size(map, map->cfg.depth_levels) * 0.5f;
    out->outside = vol->bmin.x < -half || vol->bmin.y < -half || vol->bmin.z < -half ||
                   vol->bmax.x >= half || vol->bmax.y >= half || vol->bmax.z >= half;
    return OCC_OK;
}

/* ---- cached point lookups ------------------------------------------------------------------------ */
void occ_lookup_init(occ_lookup_t *lk, const occ_map_t *map)
{
    lk->map = map;
    lk->valid = false;
    lk->lu = 0;
    lk->val = OCC_VALUE_UNOBSERVED;
    lk->key.k[0] = lk->key.k[1] = lk->key.k[2] = 0u;
}

/* occ_map_key's arithmetic for one axis, inline (NaN and Inf fail the range test). */
static inline bool lookup_key1(const occ_map_t *m, float c, int32_t half, uint32_t *key)
{
#if OCC_RAY_DOUBLE
    const double scaled = (double)c * m->inv_res_d;
    if (!(scaled >= -(double)half) || !(scaled < (double)half)) {
        return false;
    }
    double fl = (double)(int32_t)scaled;
    fl -= fl > scaled ? 1.0 : 0.0;
#else
    const float scaled = c * m->inv_res;
    if (!(scaled >= -(float)half) || !(scaled < (float)half)) {
        return false;
    }
    float fl = (float)(int32_t)scaled;
    fl -= fl > scaled ? 1.0f : 0.0f;
#endif
    *key = (uint32_t)((int32_t)fl + half);
    return true;
}

occ_state_t occ_lookup_state(occ_lookup_t *lk, occ_vec3_t p)
{
    const occ_map_t *const m = lk->map;
    const int32_t half = (int32_t)1 << (m->cfg.depth_levels - 1u);
    occ_key_t k;
    if (!lookup_key1(m, p.x, half, &k.k[0]) || !lookup_key1(m, p.y, half, &k.k[1]) ||
        !lookup_key1(m, p.z, half, &k.k[2])) {
        return OCC_STATE_UNKNOWN;
    }
    const unsigned depth = m->cfg.depth_levels;
    unsigned level;
    uint32_t b;
    if (lk->valid) {
        const uint32_t x = (k.k[0] ^ lk->key.k[0]) | (k.k[1] ^ lk->key.k[1]) |
                           (k.k[2] ^ lk->key.k[2]);
        lk->key = k;
        if ((x >> lk->lu) == 0u) {
            return occ_q_state(m, lk->val); /* same uniform node (or voxel) */
        }
#if defined(__GNUC__)
        level = 32u - (unsigned)__builtin_clz(x); /* highest changed bit + 1 */
#else
        level = 0;
        for (uint32_t y = x; y != 0u; y >>= 1) {
            level++;
        }
#endif
        b = lk->blk[level];
    } else {
        lk->key = k;
        lk->valid = true;
        if (m->root_child == OCC_NONE) {
            lk->lu = (uint8_t)depth;
            lk->val = m->root_value;
            return occ_q_state(m, lk->val);
        }
        level = depth;
        b = m->root_child;
        lk->blk[depth] = b;
    }
    while (level > 1u) {
        level--;
        const unsigned slot = ((k.k[0] >> level) & 1u) | (((k.k[1] >> level) & 1u) << 1) |
                              (((k.k[2] >> level) & 1u) << 2);
        const occ_inner_block_t *const ib = occ_inner_at(m, b);
        const uint32_t ch = ib->child[slot];
        if (ch == OCC_NONE) {
            lk->lu = (uint8_t)level;
            lk->val = ib->value[slot];
            return occ_q_state(m, lk->val);
        }
        lk->blk[level] = ch;
        b = ch;
    }
    lk->lu = 0;
    lk->val = occ_leaf_at(m, b)->value[(k.k[0] & 1u) | ((k.k[1] & 1u) << 1) | ((k.k[2] & 1u) << 2)];
    return occ_q_state(m, lk->val);
}
