/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_walk.c - the top-down walk of a virtual octree over the camera frustum: each
 * node's box is projected (8 corners) and compared with the pyramid over its footprint; whole
 * free nodes and voxel updates are written to the output in Morton order. No tree reads. */
#include <math.h>

#include "projective_internal.h"

/* Finite operands only (no NaN here): plain compares, no libm call. */
static inline float lo_of(const float a, const float b)
{
    return b < a ? b : a;
}

static inline float hi_of(const float a, const float b)
{
    return b > a ? b : a;
}

enum { NODE_SKIP, NODE_FREE, NODE_MIXED };

/* A node's projection: footprint pixels (clamped; valid when `proj`), camera depth range and
 * the rounding slack used for it; cap: no pixel any voxel of the node projects to has a depth
 * above it (the pyramid's max over the footprint, else the parent's cap). */
typedef struct {
    uint32_t i0, i1, j0, j1;
    bool proj;
    float zmin, zmax, eps, cap;
} foot_t;

/* Map-frame coordinate of key k's lower face. */
static float key_low(const occ_raygeo_t *g, const uint32_t k)
{
    return (float)(((occ_rr_t)k - g->tmv_r) * g->res);
}

/* Camera frame of a map-frame offset w (the header's arithmetic). */
static void to_cam(const occ_proj_camera_t *k, const float w[3], float q[3])
{
    for (unsigned a = 0; a < 3u; a++) {
        q[a] = k->r[0][a] * w[0] + k->r[1][a] * w[1] + k->r[2][a] * w[2];
    }
}

/* Squared distance from the camera to the node's box (map frame). */
static float box_dist2(const occ_proj_camera_t *k, const float lo[3], const float s)
{
    const float t[3] = {k->t.x, k->t.y, k->t.z};
    float d2 = 0.0f;
    for (unsigned a = 0; a < 3u; a++) {
        const float e = lo[a] - t[a] > 0.0f ? lo[a] - t[a] : (t[a] - (lo[a] + s) > 0.0f ? t[a] - (lo[a] + s) : 0.0f);
        d2 += e * e;
    }
    return d2;
}

/* The four side planes of the pixel grid through the camera (camera frame; inside: >= 0 on
 * all four) and their dot products with the map axes' camera-frame directions. */
static void planes_init(occ_proj_t *x)
{
    const occ_proj_camera_t *const k = x->cam;
    const float wf = (float)x->im->width, hf = (float)x->im->height;
    const float n[4][3] = {{k->fx, 0.0f, k->cx + 0.5f},
                           {-k->fx, 0.0f, wf - 0.5f - k->cx},
                           {0.0f, k->fy, k->cy + 0.5f},
                           {0.0f, -k->fy, hf - 0.5f - k->cy}};
    for (unsigned p = 0; p < 4u; p++) {
        for (unsigned a = 0; a < 3u; a++) {
            x->pn[p][a] = n[p][a];
            x->pr[p][a] = n[p][0] * k->r[a][0] + n[p][1] * k->r[a][1] + n[p][2] * k->r[a][2];
        }
    }
    for (unsigned l = 0; l <= x->g.depth && l <= OCC_MAX_DEPTH; l++) {
        const float s = (float)(x->g.res * (occ_rr_t)((uint32_t)1 << l));
        x->lv->side[l] = s;
        for (unsigned a = 0; a < 3u; a++) {
            for (unsigned b = 0; b < 3u; b++) {
                x->lv->edge[l][a][b] = s * k->r[a][b];
            }
            for (unsigned p = 0; p < 4u; p++) {
                x->lv->plane_pos[l][p][a] = x->pr[p][a] > 0.0f ? s * x->pr[p][a] : 0.0f;
            }
        }
    }
    x->tabs = fabsf(k->t.x) + fabsf(k->t.y) + fabsf(k->t.z);
    x->wf = wf;
    x->hf = hf;
    x->peps0 = 1e-5f * (k->fx + k->fy + fabsf(k->cx) + fabsf(k->cy) + wf + hf);
}

/* Does the box (camera-frame corner q0, level l) lie wholly outside one of the side planes?
 * (The corner's plane value plus the positive edge parts, added in axis order.) */
static bool outside_planes(const occ_proj_t *x, const float q0[3], const unsigned l,
                           const float peps)
{
    for (unsigned p = 0; p < 4u; p++) {
        const float *const c = x->lv->plane_pos[l][p];
        const float m = x->pn[p][0] * q0[0] + x->pn[p][1] * q0[1] + x->pn[p][2] * q0[2] + c[0] +
                        c[1] + c[2];
        if (m < -peps) {
            return true;
        }
    }
    return false;
}

/* The box's image footprint: u, v bounds of its 8 corners (all in front of the camera). */
typedef struct {
    float umin, umax, vmin, vmax;
} uv_t;

static void corner_uv(const occ_proj_camera_t *k, const float q[3], uv_t *f)
{
    const float iz = 1.0f / q[2];
    const float u = k->fx * (q[0] * iz) + k->cx, v = k->fy * (q[1] * iz) + k->cy;
    f->umin = lo_of(f->umin, u);
    f->umax = hi_of(f->umax, u);
    f->vmin = lo_of(f->vmin, v);
    f->vmax = hi_of(f->vmax, v);
}

/* Corner n is q0 + edge 0 (bit 0) + edge 1 (bit 1) + edge 2 (bit 2), summed in that order;
 * shared partial sums, the same values as summing per corner. */
static void footprint(const occ_proj_t *x, const float q0[3], const unsigned l, uv_t *f)
{
    float(*const e)[3] = x->lv->edge[l]; /* read only here */
    float c[8][3];
    for (unsigned b = 0; b < 3u; b++) {
        c[0][b] = q0[b];
        c[1][b] = q0[b] + e[0][b];
        c[2][b] = q0[b] + e[1][b];
        c[3][b] = c[1][b] + e[1][b];
        c[4][b] = q0[b] + e[2][b];
        c[5][b] = c[1][b] + e[2][b];
        c[6][b] = c[2][b] + e[2][b];
        c[7][b] = c[3][b] + e[2][b];
    }
    f->umin = f->vmin = INFINITY;
    f->umax = f->vmax = -INFINITY;
    for (unsigned n = 0; n < 8u; n++) {
        corner_uv(x->cam, c[n], f);
    }
}

/* Squared distance from the camera to the box's farthest corner (map frame). */
static float far_dist2(const occ_proj_camera_t *k, const float lo[3], const float s)
{
    const float t[3] = {k->t.x, k->t.y, k->t.z};
    float d2 = 0.0f;
    for (unsigned a = 0; a < 3u; a++) {
        const float e0 = lo[a] - t[a], e1 = lo[a] + s - t[a];
        d2 += hi_of(e0 * e0, e1 * e1);
    }
    return d2;
}

/* Pixel index range [lo, hi] of a footprint interval, padded by `pad` pixels; false when it
 * misses [0, n). *inside: the padded range lies within the image. */
static bool pix_range(const float a, const float b, const float pad, const uint32_t n,
                      uint32_t *lo, uint32_t *hi, bool *inside)
{
    const float nf = (float)n;
    /* clamped to [-1, n] first, so that +2 makes them positive and truncation is floor */
    const float ca = lo_of(hi_of(a + 0.5f - pad, -1.0f), nf);
    const float cb = lo_of(hi_of(b + 0.5f + pad, -1.0f), nf);
    const int32_t fa = (int32_t)(ca + 2.0f) - 2, fb = (int32_t)(cb + 2.0f) - 2;
    if (fb < 0 || fa >= (int32_t)n) {
        return false;
    }
    *inside = *inside && fa >= 0 && fb < (int32_t)n;
    *lo = fa < 0 ? 0u : (uint32_t)fa;
    *hi = fb >= (int32_t)n ? n - 1u : (uint32_t)fb;
    return true;
}

/* Classify the node at `level` whose first voxel has key k: SKIP (every voxel below unchanged
 * and no end point in it), FREE (every voxel below free, no end point in it) or MIXED. cap:
 * the parent's (its footprint holds this node's: a node nearer than it is behind it all). */
static int test_node(occ_proj_t *x, const uint32_t k[3], const unsigned level, const float cap,
                     foot_t *f)
{
    const occ_proj_camera_t *const cam = x->cam;
    x->r->nodes_tested++;
    const float s = x->lv->side[level];
    const float lo[3] = {key_low(&x->g, k[0]), key_low(&x->g, k[1]), key_low(&x->g, k[2])};
    const float bd2 = box_dist2(cam, lo, s);
    float mabs = x->tabs;
    for (unsigned a = 0; a < 3u; a++) {
        mabs += hi_of(fabsf(lo[a]), fabsf(lo[a] + s));
    }
    const float eps = 1e-5f * (1.0f + mabs);
    if (bd2 > x->max2 + eps * (1.0f + cam->max_range_m)) {
        return NODE_SKIP; /* beyond max range: no free voxel, no end point */
    }
    const float w[3] = {lo[0] - cam->t.x, lo[1] - cam->t.y, lo[2] - cam->t.z};
    float q0[3];
    to_cam(cam, w, q0);
    float zmin = q0[2], zmax = q0[2];
    for (unsigned a = 0; a < 3u; a++) {
        const float dz = x->lv->edge[level][a][2];
        zmin += dz < 0.0f ? dz : 0.0f;
        zmax += dz > 0.0f ? dz : 0.0f;
    }
    const float peps = x->peps0 * (1.0f + mabs);
    f->cap = cap;
    if (zmax < -eps || zmin > cap + eps || zmin > cam->max_range_m + eps ||
        outside_planes(x, q0, level, peps)) {
        return NODE_SKIP; /* outside the frustum, or behind every reading */
    }
    f->zmin = zmin;
    f->zmax = zmax;
    f->eps = eps;
    f->proj = zmin > eps;
    if (!f->proj || level == 1u) {
        /* around the camera plane: no footprint. Level 1: its 8 voxel decisions cost less than
         * the footprint and pyramid query (all 8 free: the same whole node, none: nothing) */
        return NODE_MIXED;
    }
    uv_t c;
    footprint(x, q0, level, &c);
    const float pad = 0.01f + (cam->fx + cam->fy) * eps / zmin;
    bool inside = true;
    if (!pix_range(c.umin, c.umax, pad, x->im->width, &f->i0, &f->i1, &inside) ||
        !pix_range(c.vmin, c.vmax, pad, x->im->height, &f->j0, &f->j1, &inside)) {
        return NODE_SKIP;
    }
    float mn, mx;
    occi_proj_range(x, f->i0, f->i1, f->j0, f->j1, &mn, &mx);
    if (zmin > mx + eps) {
        return NODE_SKIP;
    }
    f->cap = lo_of(mx, cap);
    if (inside && zmax + eps < occ_proj_front(x, mn) &&
        far_dist2(cam, lo, s) + eps * (1.0f + cam->max_range_m) <= x->max2) {
        return NODE_FREE;
    }
    return NODE_MIXED;
}

/* Is there an output slot left? (Else the call ends with OCC_ERR_SCRATCH.) */
static bool room(occ_proj_t *x)
{
    if (x->nh + x->nr + x->nv + x->nn >= x->cap) {
        x->overflow = true;
        return false;
    }
    return true;
}

/* Does the level-l node starting at `code` hold an end point? The walk asks in increasing code
 * order, so one cursor over the sorted hits serves the whole walk. */
static bool holds_hit(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    const occ_code_t end = code + ((occ_code_t)1 << (3u * l));
    while (x->hit_cur < x->nh && (x->out[x->hit_cur] & ~OCC_CODE_HIT_BIT) < code) {
        x->hit_cur++;
    }
    return x->hit_cur < x->nh && (x->out[x->hit_cur] & ~OCC_CODE_HIT_BIT) < end;
}

/* The end points inside the level-l node (l <= 2) at `code`, as bits of voxel offsets from
 * code: those voxels are hits, and hits win, so the walk never emits them as free voxels
 * (the tree pass's merge then meets no code in both streams). Same cursor as holds_hit. */
static uint64_t hit_bits(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    const occ_code_t end = code + ((occ_code_t)1 << (3u * l));
    uint64_t bits = 0u;
    (void)holds_hit(x, code, 0u); /* the cursor to the first hit at or past code */
    size_t i = x->hit_cur;
    for (; i < x->nh && (x->out[i] & ~OCC_CODE_HIT_BIT) < end; i++) {
        bits |= (uint64_t)1 << ((x->out[i] & ~OCC_CODE_HIT_BIT) - code);
    }
    x->hit_cur = i; /* past them: the walk asks about no code below end again */
    return bits;
}

/* The free voxels go after the hits and the near field's voxels. */
static void emit_voxel(occ_proj_t *x, const occ_code_t code)
{
    x->out[x->nh + x->nr + x->nv++] = code;
}

/* The near field's voxels below `code` to the output (the walk emits in code order, so the
 * output stays sorted); false when it is full. */
static bool flush_near(occ_proj_t *x, const occ_code_t code)
{
    for (; x->near_cur < x->nr && x->near[x->near_cur] < code; x->near_cur++) {
        if (!room(x)) {
            return false;
        }
        if (!holds_hit(x, x->near[x->near_cur], 0u)) { /* hits win */
            emit_voxel(x, x->near[x->near_cur]);
        }
    }
    return true;
}

/* Skip the near field's voxels inside the level-l node at `code`; returns their bits (voxel
 * offsets from code, level <= 2) for a node whose voxels the caller decides. */
static uint64_t take_near(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    const occ_code_t end = code + ((occ_code_t)1 << (3u * l));
    uint64_t bits = 0u;
    for (; x->near_cur < x->nr && x->near[x->near_cur] < end; x->near_cur++) {
        const occ_code_t off = x->near[x->near_cur] - code;
        bits |= l <= 2u ? (uint64_t)1 << off : 0u;
    }
    return bits;
}

/* Record a whole free node at level l >= 1 (from the back of the output), after the near
 * voxels before it; the near voxels inside it are covered by it. */
static void emit_node(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    if (flush_near(x, code) && room(x)) {
        x->nn++;
        x->out[x->cap - x->nn] = code | ((occ_code_t)1 << (3u * l - 1u)); /* level marker */
        (void)take_near(x, code, l);
    }
}

/* A byte's voxels (bit j: code cc | j) to the output in code order, without a branch per
 * voxel (the bits fall at random): all eight written, the count moving past the set ones. The
 * caller checked room for them all; the slots written past the count (rewritten later) count
 * in the high-water mark. */
static void emit_byte(occ_proj_t *x, const occ_code_t cc, const unsigned byte)
{
    const size_t at = x->nh + x->nr + x->nv;
    occ_code_t *const out = x->out + at;
    size_t k = 0;
    /* written out: as a loop gcc -O2 keeps it rolled, its exit a branch per byte */
#define EMIT_BIT(j)                                                                               \
    out[k] = cc | (j);                                                                            \
    k += (byte >> (j)) & 1u
    EMIT_BIT(0u);
    EMIT_BIT(1u);
    EMIT_BIT(2u);
    EMIT_BIT(3u);
    EMIT_BIT(4u);
    EMIT_BIT(5u);
    EMIT_BIT(6u);
    EMIT_BIT(7u);
#undef EMIT_BIT
    x->nv += k;
    const size_t hi = at + 8u + x->nn;
    x->hwm = x->hwm > hi ? x->hwm : hi;
}

/* The voxels of a MIXED node at level 1 or 2, by the rule (occi_proj_bulk; hits are
 * occi_proj_pixels'). Whole free nodes where every voxel below is free and holds no end point
 * (the same updates, fewer slots): the node itself (level 2; level 1 when may_merge) or its
 * level-1 children; the other free voxels one by one. */
static void visit_bulk(occ_proj_t *x, const uint32_t k[3], const occ_code_t code,
                       const unsigned level, const bool may_merge)
{
    if (!flush_near(x, code)) {
        return;
    }
    /* the rule's free voxels, and the near field's (free by its rays) */
    const uint64_t cand = occi_proj_bulk(x, k, level) | take_near(x, code, level);
    if (cand == 0u) {
        return;
    }
    const uint64_t mask = cand & ~hit_bits(x, code, level); /* hits win */
    const unsigned n = 1u << (3u * level);
    const uint64_t all = n == 64u ? ~(uint64_t)0 : (((uint64_t)1 << n) - 1u);
    if (mask == all && may_merge) {
        emit_node(x, code, level);
        return;
    }
    if (x->cap - x->nh - x->nr - x->nv - x->nn < n) { /* room for every voxel, checked once */
        x->overflow = true;
        return;
    }
    for (unsigned c = 0; c < n / 8u; c++) {
        const unsigned byte = (unsigned)(mask >> (8u * c)) & 0xFFu;
        const occ_code_t cc = code | ((occ_code_t)c << 3);
        if (byte == 0xFFu && (level == 2u || may_merge)) {
            emit_node(x, cc, 1u);
            continue;
        }
        emit_byte(x, cc, byte);
    }
}

void occi_proj_walk(occ_proj_t *const x)
{
    const unsigned depth = x->g.depth;
    occ_proj_frame_t *const st = x->walk; /* in the scratch, not on the stack */
    foot_t f;
    planes_init(x);
    if (depth == 1u) {
        const uint32_t k0[3] = {0u, 0u, 0u};
        if (test_node(x, k0, 1u, x->dmax, &f) != NODE_SKIP) {
            visit_bulk(x, k0, 0u, 1u, false); /* the root is no coarse node */
        }
        (void)flush_near(x, ~(occ_code_t)0);
        return;
    }
    unsigned sp = 1;
    st[0].k[0] = st[0].k[1] = st[0].k[2] = 0u;
    st[0].code = 0u;
    st[0].cap = x->dmax;
    st[0].level = (uint8_t)depth;
    st[0].next = 0u;
    while (sp > 0u && !x->overflow) {
        const unsigned t = sp - 1u;
        if (st[t].next == 8u) {
            sp--;
            continue;
        }
        const unsigned s = st[t].next++;
        const unsigned l = st[t].level - 1u;
        const uint32_t k[3] = {st[t].k[0] | ((s & 1u) << l), st[t].k[1] | (((s >> 1) & 1u) << l),
                               st[t].k[2] | (((s >> 2) & 1u) << l)};
        const occ_code_t code = st[t].code | ((occ_code_t)s << (3u * l));
        int cls = test_node(x, k, l, st[t].cap, &f);
        if (cls == NODE_FREE && holds_hit(x, code, l)) {
            cls = NODE_MIXED; /* hits win: not expected (a free node is in front of every end
                               * point of its footprint), kept exact by descending */
        }
        if (cls == NODE_FREE) {
            emit_node(x, code, l);
        } else if (cls == NODE_MIXED && l <= 2u) {
            visit_bulk(x, k, code, l, true);
        } else if (cls == NODE_MIXED) {
            OCC_ASSERT(sp <= OCC_MAX_DEPTH);
            st[sp].k[0] = k[0];
            st[sp].k[1] = k[1];
            st[sp].k[2] = k[2];
            st[sp].code = code;
            st[sp].cap = f.cap;
            st[sp].level = (uint8_t)l;
            st[sp].next = 0u;
            sp++;
        }
    }
    if (!x->overflow) {
        (void)flush_near(x, ~(occ_code_t)0); /* the near voxels after the walk's last output */
    }
}
