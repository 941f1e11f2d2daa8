/* SPDX-License-Identifier: BSD-3-Clause */
/* projective_walk.c - the top-down walk of a virtual octree over the camera frustum: each
 * node's box above level 2 is projected (8 corners) and compared with the pyramid over its
 * footprint, a level-2 node's 64 voxels go to the per-voxel rule at once; the updates go to the
 * output in Morton order, a level-2 node's voxels as one brick (free voxels and end points),
 * bigger whole free nodes one slot each. No tree reads. */
#include <math.h>

#include "projective_internal.h"
#include "../core/tree_internal.h"

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

/* Camera-frame component a of a map-frame offset w (the header's arithmetic). */
static inline float cam_axis(const float r[3][3], const unsigned a, const float w0, const float w1,
                             const float w2)
{
    return r[0][a] * w0 + r[1][a] * w1 + r[2][a] * w2;
}

/* Camera frame of a map-frame offset w. */
static void to_cam(const occ_proj_camera_t *k, const float w[3], float q[3])
{
    for (unsigned a = 0; a < 3u; a++) {
        q[a] = cam_axis(k->r, a, w[0], w[1], w[2]);
    }
}

/* A node's coordinate magnitude along one axis (its face farther from 0), for the rounding
 * slack: eps = 1e-5 (1 + |t| + the three of them). */
static inline float axis_abs(const float lo, const float s)
{
    return hi_of(fabsf(lo), fabsf(lo + s));
}

/* The camera-depth range of a box from its corner's depth q2 and its edges' depths dz, added
 * in axis order. */
static inline void z_range(const float q2, const float dz[3], float *zmin, float *zmax)
{
    float lo = q2, hi = q2;
    for (unsigned a = 0; a < 3u; a++) {
        lo += dz[a] < 0.0f ? dz[a] : 0.0f;
        hi += dz[a] > 0.0f ? dz[a] : 0.0f;
    }
    *zmin = lo;
    *zmax = hi;
}

/* Distance along one axis from the camera's t to the box's [lo, lo + s]. */
static inline float axis_gap(const float lo, const float t, const float s)
{
    return lo - t > 0.0f ? lo - t : (t - (lo + s) > 0.0f ? t - (lo + s) : 0.0f);
}

/* Squared distance from the camera to the node's box (map frame). */
static float box_dist2(const occ_proj_camera_t *k, const float lo[3], const float s)
{
    const float t[3] = {k->t.x, k->t.y, k->t.z};
    float d2 = 0.0f;
    for (unsigned a = 0; a < 3u; a++) {
        const float e = axis_gap(lo[a], t[a], s);
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

/* Side plane n's value at the box's corner q plus the positive edge parts c (in that order). */
static inline float plane_value(const float n[3], const float c[3], const float q0,
                                const float q1, const float q2)
{
    return n[0] * q0 + n[1] * q1 + n[2] * q2 + c[0] + c[1] + c[2];
}

/* Does the box (camera-frame corner q0, level l) lie wholly outside one of the side planes?
 * (The corner's plane value plus the positive edge parts, added in axis order.) */
static bool outside_planes(const occ_proj_t *x, const float q0[3], const unsigned l,
                           const float peps)
{
    for (unsigned p = 0; p < 4u; p++) {
        if (plane_value(x->pn[p], x->lv->plane_pos[l][p], q0[0], q0[1], q0[2]) < -peps) {
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
        mabs += axis_abs(lo[a], s);
    }
    const float eps = 1e-5f * (1.0f + mabs);
    if (bd2 > x->max2 + eps * (1.0f + cam->max_range_m)) {
        return NODE_SKIP; /* beyond max range: no free voxel, no end point */
    }
    const float w[3] = {lo[0] - cam->t.x, lo[1] - cam->t.y, lo[2] - cam->t.z};
    float q0[3];
    to_cam(cam, w, q0);
    const float dz[3] = {x->lv->edge[level][0][2], x->lv->edge[level][1][2],
                         x->lv->edge[level][2][2]};
    float zmin, zmax;
    z_range(q0[2], dz, &zmin, &zmax);
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
    if (!f->proj || level <= 2u) {
        /* around the camera plane: no footprint. Levels 1 and 2: the per-voxel rule decides
         * their 8 or 64 voxels at once (all free: the same whole node; none: nothing), and a
         * footprint and pyramid query first costs more than it saves: on the TUM frames 62 % of
         * the level-2 nodes tested came out mixed and went to the rule anyway (bench/ab_split,
         * both halves built alike: without the query 0.951 and 0.966 of the time; same maps) */
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

/* test_node's tests for the 8 level-2 children of a level-3 node at once (lanes: the child
 * slots), lane for lane the same arithmetic: a level-2 node is never FREE there (the rule
 * decides its voxels), only SKIP or MIXED. One lane loop instead of 8 calls with their
 * early exits: bench/ab_split 0.985 and 0.983 of the time (31 and 41 rounds, same maps). The
 * answers as int32 lanes: with bytes GCC vectorised by two floats (0.976 and 0.977 of that). */
OCC_PROJ_LANES static void kids_lanes(const occ_proj_kids_t *restrict in, int32_t *restrict mixed)
{
    const float s = in->s, cap = in->cap, max2 = in->max2, range = in->max_range;
    for (unsigned m = 0; m < 8u; m++) {
        const float l0 = in->lo[0][m], l1 = in->lo[1][m], l2 = in->lo[2][m];
        const float e0 = axis_gap(l0, in->t[0], s), e1 = axis_gap(l1, in->t[1], s),
                    e2 = axis_gap(l2, in->t[2], s);
        const float bd2 = ((0.0f + e0 * e0) + e1 * e1) + e2 * e2;
        const float mabs = ((in->tabs + axis_abs(l0, s)) + axis_abs(l1, s)) + axis_abs(l2, s);
        const float eps = 1e-5f * (1.0f + mabs);
        const float w0 = l0 - in->t[0], w1 = l1 - in->t[1], w2 = l2 - in->t[2];
        const float q0 = cam_axis(in->r, 0u, w0, w1, w2), q1 = cam_axis(in->r, 1u, w0, w1, w2),
                    q2 = cam_axis(in->r, 2u, w0, w1, w2);
        float zmin, zmax;
        z_range(q2, in->dz, &zmin, &zmax);
        const float peps = in->peps0 * (1.0f + mabs);
        int32_t skip = (bd2 > max2 + eps * (1.0f + range)) | (zmax < -eps) |
                       (zmin > cap + eps) | (zmin > range + eps);
        for (unsigned p = 0; p < 4u; p++) {
            skip |= plane_value(in->pn[p], in->pc[p], q0, q1, q2) < -peps;
        }
        mixed[m] = skip == 0;
    }
}

/* The MIXED ones among the 8 level-2 children of the level-3 node at key k (parent's cap), as
 * bits by child slot; the rest are SKIP. Checked against test_node where asserts are live.
 * Out of line: bench/callgrind_phases.py counts it (one call per level-3 node). */
OCC_NOINLINE static unsigned kids_mixed(occ_proj_t *x, const uint32_t k[3], const float cap)
{
    occ_proj_kids_t *const in = &x->bulk->kids;
    for (unsigned a = 0; a < 3u; a++) {
        const float lo0 = key_low(&x->g, k[a]), lo1 = key_low(&x->g, k[a] | 4u);
        for (unsigned c = 0; c < 8u; c++) {
            in->lo[a][c] = ((c >> a) & 1u) != 0u ? lo1 : lo0;
        }
        in->dz[a] = x->lv->edge[2][a][2];
    }
    in->cap = cap;
    int32_t mixed[8];
    kids_lanes(in, mixed);
    x->r->nodes_tested += 8u;
    unsigned bits = 0;
    for (unsigned c = 0; c < 8u; c++) {
        bits |= (unsigned)mixed[c] << c;
#if defined(OCC_TESTING)
        const uint32_t kc[3] = {k[0] | ((c & 1u) << 2), k[1] | (((c >> 1) & 1u) << 2),
                                k[2] | (((c >> 2) & 1u) << 2)};
        foot_t f;
        const int cls = test_node(x, kc, 2u, cap, &f);
        x->r->nodes_tested--;
        OCC_ASSERT(cls == (mixed[c] != 0 ? NODE_MIXED : NODE_SKIP));
#endif
    }
    return bits;
}

/* The per-call constants of kids_lanes. */
static void kids_init(occ_proj_t *x)
{
    occ_proj_kids_t *const in = &x->bulk->kids;
    const occ_proj_camera_t *const cam = x->cam;
    const float t[3] = {cam->t.x, cam->t.y, cam->t.z};
    for (unsigned a = 0; a < 3u; a++) {
        in->t[a] = t[a];
        for (unsigned b = 0; b < 3u; b++) {
            in->r[a][b] = cam->r[a][b];
        }
    }
    for (unsigned p = 0; p < 4u; p++) {
        for (unsigned a = 0; a < 3u; a++) {
            in->pn[p][a] = x->pn[p][a];
            in->pc[p][a] = x->lv->plane_pos[2][p][a];
        }
    }
    in->s = x->lv->side[2];
    in->tabs = x->tabs;
    in->max2 = x->max2;
    in->max_range = cam->max_range_m;
    in->peps0 = x->peps0;
}

/* ---- the output: bricks and whole nodes in code order (tree_internal.h, occi_frame_t) -----------
 * The free voxels, the end points (hits) and the near field's voxels of a level-2 node are
 * gathered in one open brick, written out when the walk moves past the node; whole free nodes
 * at level 1 and 2 are bits of their brick, higher ones one slot each. The walk emits in code
 * order, and before anything at a code it catches up with the hits and near voxels below it,
 * so the stream stays sorted. */
#define NONE (~(occ_code_t)0)

/* Is there room for k more stream slots? (Else the call ends with OCC_ERR_SCRATCH.) */
static bool room(occ_proj_t *x, const size_t k)
{
    if (x->cap - x->nh - x->nr - x->ns < k) {
        x->overflow = true;
        return false;
    }
    return true;
}

/* The open brick to the stream (hits win over the miss). */
static void brick_flush(occ_proj_t *x)
{
    if (!x->bopen) {
        return;
    }
    x->bopen = false;
    if (!room(x, OCC_FRAME_BRICK_SLOTS)) {
        return;
    }
    occ_code_t *const s = x->out + x->nh + x->nr + x->ns;
    s[0] = x->bcode | OCC_CODE_HIT_BIT;
    s[1] = x->bmiss & ~x->bhit;
    s[2] = x->bhit;
    s[3] = x->bwhole;
    x->ns += OCC_FRAME_BRICK_SLOTS;
}

/* Open the brick of the level-2 node holding `code` (the walk only moves forward). */
static void brick_at(occ_proj_t *x, const occ_code_t code)
{
    const occ_code_t base = code & ~(occ_code_t)63u;
    if (x->bopen && x->bcode == base) {
        return;
    }
    OCC_ASSERT(!x->bopen || base > x->bcode);
    brick_flush(x);
    x->bopen = true;
    x->bcode = base;
    x->bmiss = x->bhit = x->bwhole = 0u;
}

/* The next end point's code (NONE: none left): the first bit left of the record at the
 * cursor. */
static occ_code_t next_hit(const occ_proj_t *x)
{
    return x->hit_cur < x->nh ? x->out[x->hit_cur] | occ_first_slot64(x->hit_rest) : NONE;
}

/* Take `bits` (some of those left) of the record at the cursor; past it when none are left. */
static void take_hits(occ_proj_t *x, const uint64_t bits)
{
    x->hit_rest &= ~bits;
    if (x->hit_rest == 0u) {
        x->hit_cur += 2u;
        x->hit_rest = x->hit_cur < x->nh ? x->out[x->hit_cur + 1u] : 0u;
    }
}

/* The hits and the near field's voxels below `code` into their bricks, a brick at a time in
 * code order (a near voxel that is also a hit is a hit: the brick's hits below `code` are
 * taken first). */
static void catch_up(occ_proj_t *x, const occ_code_t code)
{
    for (;;) {
        const occ_code_t h = next_hit(x);
        const occ_code_t v = x->near_cur < x->nr ? x->near[x->near_cur] : NONE;
        const occ_code_t c = h < v ? h : v;
        if (c >= code) {
            return;
        }
        const occ_code_t b = c & ~(occ_code_t)63u;
        brick_at(x, b);
        if (x->hit_cur < x->nh && x->out[x->hit_cur] == b) {
            const uint64_t below = code - b >= 64u ? ~(uint64_t)0 : ((uint64_t)1 << (code - b)) - 1u;
            const uint64_t t = x->hit_rest & below;
            x->bhit |= t;
            take_hits(x, t);
        }
        for (; x->near_cur < x->nr && x->near[x->near_cur] < code &&
               (x->near[x->near_cur] & ~(occ_code_t)63u) == b;
             x->near_cur++) {
            const uint64_t bit = (uint64_t)1 << (x->near[x->near_cur] & 63u);
            if ((x->bhit & bit) == 0u) {
                x->bmiss |= bit;
                x->nv++;
            }
        }
    }
}

/* Does the level-l node starting at `code` hold an end point? (The hits below it are caught
 * up with first: the walk is at `code`.) */
static bool holds_hit(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    catch_up(x, code);
    return next_hit(x) < code + ((occ_code_t)1 << (3u * l));
}

/* The end points inside the level-l node (l <= 2) at `code`, caught up with, as bits of voxel
 * offsets from code (hits win over its free voxels); the cursor moves past them. */
static uint64_t hit_bits(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    if (x->hit_cur >= x->nh || x->out[x->hit_cur] != (code & ~(occ_code_t)63u)) {
        return 0u;
    }
    const unsigned off = (unsigned)(code & 63u), n = 1u << (3u * l);
    const uint64_t span = n == 64u ? ~(uint64_t)0 : ((uint64_t)1 << n) - 1u;
    const uint64_t t = x->hit_rest & (span << off);
    take_hits(x, t);
    return t >> off;
}

/* Skip the near field's voxels inside the level-l node at `code`; returns their bits (voxel
 * offsets from code, level <= 2) for a node whose voxels the caller decides. */
static uint64_t take_near(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    const occ_code_t end = code + ((occ_code_t)1 << (3u * l));
    uint64_t bits = 0u;
    for (; x->near_cur < x->nr && x->near[x->near_cur] < end; x->near_cur++) {
        bits |= l <= 2u ? (uint64_t)1 << (x->near[x->near_cur] - code) : 0u;
    }
    return bits;
}

/* A whole free node at level l >= 1 whose hits and near voxels below were caught up with:
 * bits of its brick (level <= 2) or a slot of its own. */
static void put_whole(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    x->nn++;
    if (l <= 2u) {
        const uint64_t bits = l == 2u ? ~(uint64_t)0 : (uint64_t)0xFFu << (code & 63u);
        brick_at(x, code);
        x->bmiss |= bits;
        x->bwhole |= bits;
        return;
    }
    brick_flush(x);
    if (room(x, 1u)) {
        x->out[x->nh + x->nr + x->ns++] = code | ((occ_code_t)1 << (3u * l - 1u)); /* marker */
    }
}

/* A whole free node found by the walk: the near voxels inside it are covered by it. */
static void emit_node(occ_proj_t *x, const occ_code_t code, const unsigned l)
{
    catch_up(x, code);
    put_whole(x, code, l);
    (void)take_near(x, code, l);
}

/* The voxels of a MIXED node at level 1 or 2, by the rule (occi_proj_bulk; hits are
 * occi_proj_pixels'). Whole free nodes where every voxel below is free and holds no end point
 * (the same updates, counted as nodes): the node itself (level 2; level 1 when may_merge) or
 * its level-1 children; the other free voxels one by one. */
/* The bytes of m whose 8 bits are all set, as 0xFF (the others 0). */
static uint64_t full_bytes(const uint64_t m)
{
    uint64_t f = m & (m >> 4);
    f &= f >> 2;
    f &= f >> 1;
    return (f & 0x0101010101010101ull) * 0xFFu;
}

static void visit_bulk(occ_proj_t *x, const uint32_t k[3], const occ_code_t code,
                       const unsigned level, const bool may_merge)
{
    catch_up(x, code);
    /* the rule's free voxels, and the near field's (free by its rays) */
    const uint64_t cand = occi_proj_bulk(x, k, level) | take_near(x, code, level);
    const uint64_t hits = hit_bits(x, code, level);
    const uint64_t mask = cand & ~hits; /* offsets from code */
    const unsigned n = 1u << (3u * level);
    const uint64_t all = n == 64u ? ~(uint64_t)0 : (((uint64_t)1 << n) - 1u);
    if ((cand | hits) == 0u) {
        return;
    }
    if (mask == all && may_merge) {
        put_whole(x, code, level);
        return;
    }
    brick_at(x, code);
    const unsigned off = (unsigned)(code & 63u);
    x->bhit |= hits << off;
    x->bmiss |= mask << off;
    /* whole free level-1 nodes: one node each in the counters, the other free voxels one each
     * (without a branch per byte: which bytes are full falls at random) */
    const uint64_t whole = level == 2u || may_merge ? full_bytes(mask) : 0u;
    x->bwhole |= whole << off;
    x->nn += occ_popcount64(whole) / 8u;
    x->nv += occ_popcount64(mask & ~whole);
}

void occi_proj_walk(occ_proj_t *const x)
{
    const unsigned depth = x->g.depth;
    occ_proj_frame_t *const st = x->walk; /* in the scratch, not on the stack */
    foot_t f;
    planes_init(x);
    if (depth >= 3u) { /* level-3 nodes exist: their children are tested at once */
        kids_init(x);
    }
    x->hit_cur = 0u;
    x->hit_rest = x->nh > 0u ? x->out[1] : 0u;
    if (depth == 1u) {
        const uint32_t k0[3] = {0u, 0u, 0u};
        if (test_node(x, k0, 1u, x->dmax, &f) != NODE_SKIP) {
            visit_bulk(x, k0, 0u, 1u, false); /* the root is no coarse node */
        }
        catch_up(x, NONE);
        brick_flush(x);
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
        if (l == 2u) { /* the children's tests at once, then the rule on the MIXED ones */
            if (s == 0u) {
                st[t].kids = (uint8_t)kids_mixed(x, st[t].k, st[t].cap);
            }
            if ((((unsigned)st[t].kids >> s) & 1u) != 0u) {
                visit_bulk(x, k, code, 2u, true);
            }
            continue;
        }
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
        catch_up(x, NONE); /* the hits and near voxels after the walk's last output */
        brick_flush(x);
    }
}
