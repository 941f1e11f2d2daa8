/* SPDX-License-Identifier: BSD-3-Clause */
/* sectors.c - nearest occupied / unknown footprint per horizontal sector (see occ_sectors.h). */
#include "occmap/occ_sectors.h"

#include <math.h>

#define PI_F 3.14159265358979f
#define TWO_PI_F 6.28318530717959f
#define DEG2RAD_F 0.0174532925199433f

enum { KIND_OCC = 0, KIND_UNK = 1 };

/* Entries the walk may use; a test build lowers it to reach the overflow path. */
#ifndef OCC_SECTORS_WALK_LIMIT
#define OCC_SECTORS_WALK_LIMIT OCC_SECTORS_STACK
#endif

/* Everything one computation needs besides `out`. Kept small: it lives on the C stack. */
typedef struct {
    float res;             /* voxel edge, metres */
    int32_t half;          /* keys per half axis: key k's lower face is (k - half) * res */
    float vol_lo, vol_hi;  /* the map volume per axis, metres */
    float px, py;          /* vehicle, map metres */
    float yaw;             /* map yaw, rad */
    float offset;          /* rad */
    float inc;             /* rad */
    float inv_inc;
    float period;          /* sector positions per turn: 2 pi / inc */
    float range;           /* search radius, metres */
    uint8_t n;
    float sgn;             /* +1 ENU (body angles run against bearings), -1 NED */
    float margin;          /* sector units within which fast_atan2f may be wrong */
    bool full;             /* the sectors cover the whole turn */
    float bound;           /* >= max over sectors of min(d_occ, d_unk); exact when !dirty */
    bool dirty;
} ctx_t;

occ_sectors_config_t occ_sectors_config_default(void)
{
    occ_sectors_config_t c;
    c.n_sectors = 72u;
    c.increment_deg = 5.0f;
    c.angle_offset_deg = 0.0f;
    c.band_below_m = 0.5f;
    c.band_above_m = 0.5f;
    c.min_distance_cm = 20u;
    c.max_distance_cm = 2000u;
    c.unknown_as_distance = false;
    c.map_ned = false;
    c.ignore_ground = true;
    c.ground_clearance_m = 0.1f;
    return c;
}

occ_err_t occ_sectors_config_check(const occ_sectors_config_t *cfg)
{
    if (cfg == NULL || cfg->n_sectors < 1u || cfg->n_sectors > OCC_SECTORS_MAX) {
        return OCC_ERR_ARG;
    }
    if (!isfinite(cfg->increment_deg) || !(cfg->increment_deg > 0.0f) ||
        cfg->increment_deg > 90.0f ||
        (float)cfg->n_sectors * cfg->increment_deg > 360.0f + 1e-3f) {
        return OCC_ERR_ARG;
    }
    if (!isfinite(cfg->angle_offset_deg) || !isfinite(cfg->band_below_m) ||
        !isfinite(cfg->band_above_m) || cfg->band_below_m < 0.0f || cfg->band_above_m < 0.0f ||
        !(cfg->band_below_m + cfg->band_above_m > 0.0f)) {
        return OCC_ERR_ARG;
    }
    if (!isfinite(cfg->ground_clearance_m) || cfg->ground_clearance_m < 0.0f) {
        return OCC_ERR_ARG;
    }
    if (cfg->min_distance_cm < 1u || cfg->min_distance_cm >= cfg->max_distance_cm ||
        cfg->max_distance_cm > OCC_SECTORS_MAX_DISTANCE_CM) {
        return OCC_ERR_ARG;
    }
    return OCC_OK;
}

/* floor() of a float well inside the int32 range, without a libm call (no SSE4.1 baseline). */
static int32_t ifloor(float v)
{
    const int32_t i = (int32_t)v;
    return (float)i > v ? i - 1 : i;
}

static float clampf(float v, float lo, float hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* Wrap a sector-unit angle into [0, period). Inputs stay within a few turns (yaw and offset are
 * normalized once per call), so a loop beats fmodf. */
static float wrap_units(float u, float period)
{
    while (u < 0.0f) {
        u += period;
    }
    while (u >= period) {
        u -= period;
    }
    return u;
}

/* atan2 within ~1e-5 rad (a minimax polynomial on [0, 1]); callers that decide sector
 * membership re-check near boundaries with exact cross products. */
static float fast_atan2f(float y, float x)
{
    const float ax = fabsf(x);
    const float ay = fabsf(y);
    const float mx = ax > ay ? ax : ay;
    const float mn = ax > ay ? ay : ax;
    if (!(mx > 0.0f)) {
        return 0.0f;
    }
    const float t = mn / mx;
    const float s = t * t;
    float r = (((0.0208351f * s - 0.0851330f) * s + 0.1801410f) * s - 0.3302995f) * s * t +
              0.9998660f * t;
    if (ay > ax) {
        r = 0.5f * PI_F - r;
    }
    if (x < 0.0f) {
        r = PI_F - r;
    }
    return y < 0.0f ? -r : r;
}

/* Sector units of a map bearing: 0 at the lower edge of sector 0, +1 per sector (clockwise). */
static float units_of_bearing(const ctx_t *c, float bearing)
{
    return wrap_units((c->sgn * (c->yaw - bearing) - c->offset) * c->inv_inc + 0.5f, c->period);
}

/* Sector holding the vehicle-relative point (x, y), or -1 when none does. Exact at the
 * boundaries: a point within `margin` of one is placed with a cross product against the same
 * boundary ray the distance code uses. */
static int32_t sector_of_point(const ctx_t *c, const occ_sectors_t *out, float x, float y)
{
    const float u = units_of_bearing(c, fast_atan2f(y, x));
    int32_t p = ifloor(u);
    const float frac = u - (float)p;
    const int32_t n = (int32_t)c->n;
    if (frac < c->margin && p <= n) {
        /* In p iff the point is at or past ray p (clockwise in ENU). */
        const float cr = c->sgn * (out->ray_c[p] * y - out->ray_s[p] * x);
        if (cr > 0.0f) {
            p = p > 0 ? p - 1 : (c->full ? n - 1 : -1);
        }
    } else if (frac > 1.0f - c->margin && p + 1 <= n) {
        const float cr = c->sgn * (out->ray_c[p + 1] * y - out->ray_s[p + 1] * x);
        if (cr <= 0.0f) {
            p = p + 1;
        }
    }
    if (p >= n) {
        p = (c->full && p == n) ? 0 : -1;
    }
    return p;
}

/* Clip [*tmin, *tmax] to the parameters where the ray component d lies in [lo, hi] (one slab of
 * the rectangle); false when the ray misses that slab. */
static bool clip_slab(float d, float lo, float hi, float *tmin, float *tmax)
{
    if (fabsf(d) < 1e-20f) {
        return !(lo > 0.0f || hi < 0.0f);
    }
    float t1 = lo / d;
    float t2 = hi / d;
    if (t1 > t2) {
        const float t = t1;
        t1 = t2;
        t2 = t;
    }
    *tmin = t1 > *tmin ? t1 : *tmin;
    *tmax = t2 < *tmax ? t2 : *tmax;
    return true;
}

/* Entry distance of boundary ray k into the rectangle (vehicle-relative), or -1 on a miss. */
static float ray_entry(const occ_sectors_t *out, unsigned k, float ax0, float ay0, float ax1,
                       float ay1)
{
    float tmin = 0.0f;
    float tmax = OCC_SECTORS_FAR;
    if (!clip_slab(out->ray_c[k], ax0, ax1, &tmin, &tmax) ||
        !clip_slab(out->ray_s[k], ay0, ay1, &tmin, &tmax)) {
        return -1.0f;
    }
    return tmin <= tmax ? tmin : -1.0f;
}

static void take(ctx_t *c, occ_sectors_t *out, int kind, unsigned s, float d)
{
    float *const best = kind == KIND_OCC ? out->d_occ_m : out->d_unk_m;
    if (d < best[s]) {
        best[s] = d;
        c->dirty = true;
    }
}

/* Fold the sectors of one linear stretch [a, b] of sector units. */
static void fold_units(ctx_t *c, occ_sectors_t *out, int kind, float a, float b, int32_t sq,
                       float dnear, const float rect[4])
{
    const int32_t s_lo = ifloor(a);
    int32_t s_hi = ifloor(b);
    if (s_hi > (int32_t)c->n - 1) {
        s_hi = (int32_t)c->n - 1;
    }
    for (int32_t s = s_lo < 0 ? 0 : s_lo; s <= s_hi; s++) {
        float d;
        if (s == sq) {
            d = dnear;
        } else {
            const float d0 = ray_entry(out, (unsigned)s, rect[0], rect[1], rect[2], rect[3]);
            const float d1 = ray_entry(out, (unsigned)s + 1u, rect[0], rect[1], rect[2], rect[3]);
            if (d0 < 0.0f && d1 < 0.0f) {
                continue; /* the padded span reached a sector the rectangle misses */
            } else if (d0 < 0.0f) {
                d = d1;
            } else if (d1 < 0.0f) {
                d = d0;
            } else {
                d = d0 < d1 ? d0 : d1;
            }
        }
        if (d < c->range) {
            take(c, out, kind, (unsigned)s, d);
        }
    }
}

/* Fold one non-free axis-aligned footprint [x0,x1] x [y0,y1] (map metres) into the sectors. */
static void fold_rect(ctx_t *c, occ_sectors_t *out, int kind, float x0, float y0, float x1,
                      float y1)
{
    float rect[4];
    rect[0] = x0 - c->px;
    rect[1] = y0 - c->py;
    rect[2] = x1 - c->px;
    rect[3] = y1 - c->py;
    const float qx = clampf(0.0f, rect[0], rect[2]);
    const float qy = clampf(0.0f, rect[1], rect[3]);
    const float dnear = sqrtf(qx * qx + qy * qy);
    if (dnear >= c->range) {
        return;
    }
    out->leaves_used++;
    if (!(dnear > 0.0f)) {
        for (unsigned s = 0; s < c->n; s++) {
            take(c, out, kind, s, 0.0f);
        }
        return;
    }
    /* The two silhouette corners, chosen by where the rectangle lies. */
    const int cx = rect[0] > 0.0f ? 1 : (rect[2] < 0.0f ? -1 : 0);
    const int cy = rect[1] > 0.0f ? 1 : (rect[3] < 0.0f ? -1 : 0);
    float e1x, e1y, e2x, e2y;
    if (cy == 0) {
        e1x = cx > 0 ? rect[0] : rect[2];
        e2x = e1x;
        e1y = rect[1];
        e2y = rect[3];
    } else if (cx == 0) {
        e1y = cy > 0 ? rect[1] : rect[3];
        e2y = e1y;
        e1x = rect[0];
        e2x = rect[2];
    } else if (cx == cy) { /* NE or SW quadrant */
        e1x = rect[0];
        e1y = rect[3];
        e2x = rect[2];
        e2y = rect[1];
    } else {               /* NW or SE quadrant */
        e1x = rect[0];
        e1y = rect[1];
        e2x = rect[2];
        e2y = rect[3];
    }
    const float b1 = fast_atan2f(e1y, e1x);
    const float b2 = fast_atan2f(e2y, e2x);
    float w = b2 - b1;
    if (w < 0.0f) {
        w += TWO_PI_F;
    }
    float hi_bearing = b2;
    if (w > PI_F) {
        w = TWO_PI_F - w;
        hi_bearing = b1;
    }
    /* ENU: body angles run against bearings, the highest bearing is the lowest body angle. */
    /* Padded by the atan error: extra sectors are rejected exactly in fold_units. */
    const float u_lo = wrap_units(
        units_of_bearing(c, c->sgn > 0.0f ? hi_bearing : hi_bearing - w) - c->margin, c->period);
    const float u_hi = u_lo + w * c->inv_inc + 2.0f * c->margin;
    const int32_t sq = sector_of_point(c, out, qx, qy);
    if (u_hi < c->period) {
        fold_units(c, out, kind, u_lo, u_hi, sq, dnear, rect);
    } else {
        fold_units(c, out, kind, u_lo, c->period, sq, dnear, rect);
        fold_units(c, out, kind, 0.0f, u_hi - c->period, sq, dnear, rect);
    }
}

static bool range_open(const ctx_t *c, const occ_sectors_t *out, float a, float b, float dmin)
{
    int32_t hi = ifloor(b);
    if (hi > (int32_t)c->n - 1) {
        hi = (int32_t)c->n - 1;
    }
    for (int32_t s = ifloor(a); s <= hi; s++) {
        if (s >= 0) {
            /* Open unless an obstacle is at or nearer than dmin (a tie cannot change it) or
             * unknown is strictly nearer (an obstacle at the same distance would win). */
            if (out->d_occ_m[s] > dmin && out->d_unk_m[s] >= dmin) {
                return true;
            }
        }
    }
    return false;
}

/* True if some sector the square (vehicle-relative corner ax0, ay0, edge `size`) may touch has
 * not yet found anything at or nearer than dmin. Conservative span: centre bearing +- the angle
 * of the circumscribed circle. */
static bool sectors_open(const ctx_t *c, const occ_sectors_t *out, float ax0, float ay0,
                         float size, float dmin)
{
    const float hs = 0.5f * size;
    const float cx = ax0 + hs;
    const float cy = ay0 + hs;
    const float dc = sqrtf(cx * cx + cy * cy);
    const float r = hs * 1.41421356f;
    if (dc <= r * 1.01f) {
        return true;
    }
    /* tan(asin(r / dc)) >= asin(r / dc): a cheap, wider half angle. */
    const float half_w = r / sqrtf(dc * dc - r * r) * c->inv_inc + 0.01f;
    const float w = 2.0f * half_w;
    if (w >= c->period) {
        return true;
    }
    const float lo = units_of_bearing(c, fast_atan2f(cy, cx)) - half_w;
    const float a = lo < 0.0f ? lo + c->period : lo;
    if (range_open(c, out, a, a + w < c->period ? a + w : c->period, dmin)) {
        return true;
    }
    return a + w > c->period && range_open(c, out, 0.0f, a + w - c->period, dmin);
}

static float refresh_bound(ctx_t *c, const occ_sectors_t *out)
{
    if (c->dirty) {
        float m = 0.0f;
        for (unsigned s = 0; s < c->n; s++) {
            const float b = out->d_occ_m[s] < out->d_unk_m[s] ? out->d_occ_m[s] : out->d_unk_m[s];
            m = b > m ? b : m;
        }
        c->bound = m;
        c->dirty = false;
    }
    return c->bound;
}

/* Keys [lo, hi] of the voxels holding [a, b] on one axis, clamped to the map: the map's own
 * conversion (occ_map_key_range), so a voxel read here is the one every map call names. */
static void key_range(const occ_map_t *map, float a, float b, int32_t *lo, int32_t *hi)
{
    uint32_t l = 0u;
    uint32_t h = 0u;
    if (occ_map_key_range(map, a, b, &l, &h) != OCC_OK) {
        /* misses the map: its edge voxel on that side (space beyond is folded in as unknown) */
        l = a > 0.0f ? ((uint32_t)1 << map->cfg.depth_levels) - 1u : 0u;
        h = l;
    }
    *lo = (int32_t)l;
    *hi = (int32_t)h;
}

static uint16_t to_cm(float d, const occ_sectors_config_t *cfg)
{
    const float cm = floorf(d * 100.0f);
    if (cm <= (float)cfg->min_distance_cm) {
        return cfg->min_distance_cm;
    }
    if (cm >= (float)cfg->max_distance_cm) {
        return cfg->max_distance_cm;
    }
    return (uint16_t)cm;
}

/* The unsafe answer every sector holds on an error: an obstacle at the minimum distance (a value
 * both autopilots act on; 0 and UINT16_MAX would be skipped by ArduPilot). */
static void fill_unsafe(occ_sectors_t *out, const occ_sectors_config_t *cfg)
{
    const uint16_t unsafe =
        (cfg != NULL && cfg->min_distance_cm >= 1u) ? cfg->min_distance_cm : 1u;
    out->n = 0;
    for (unsigned s = 0; s < OCC_SECTORS_MAX; s++) {
        out->distance_cm[s] = unsafe;
        out->d_occ_m[s] = 0.0f;
        out->d_unk_m[s] = 0.0f;
    }
}

/* ArduPilot-like ground rule: the first occupied voxel met walking down the vehicle's own column
 * (from its voxel to the band's lower edge) is the ground it stands on or flies over; the band
 * then starts ground_clearance_m above that voxel's top face. Heights here are "up" metres
 * (z in an ENU map, -z in a NED one). Returns the band's lower edge. O(band / resolution). */
static float ground_lift(const occ_map_t *map, const occ_vec3_t at,
                         const occ_sectors_config_t *cfg, float up_lo, float up_hi)
{
    occ_key_t k;
    if (!cfg->ignore_ground || occ_map_key(map, at, &k) != OCC_OK) {
        return up_lo;
    }
    const float res = map->cfg.resolution_m;
    const uint32_t kmax = ((uint32_t)1 << map->cfg.depth_levels) - 1u;
    for (;;) {
        const float z0 = occ_map_key_center(map, k, 0).z - 0.5f * res;
        const float top = cfg->map_ned ? -z0 : z0 + res; /* the face nearest the vehicle */
        occ_node_info_t info;
        if (!(top > up_lo) || occ_map_read_key(map, k, 0, &info) != OCC_OK) {
            return up_lo;
        }
        if (info.observed && info.state == OCC_STATE_OCCUPIED) {
            const float lifted = top + cfg->ground_clearance_m;
            /* A ground that would swallow the whole band stays in it (reported: fail safe). */
            return lifted > up_lo && lifted < up_hi ? lifted : up_lo;
        }
        if (cfg->map_ned ? k.k[2] >= kmax : k.k[2] == 0u) {
            return up_lo;
        }
        k.k[2] = cfg->map_ned ? k.k[2] + 1u : k.k[2] - 1u;
    }
}

/* The per-call constants of the map, the pose and the config (nothing in `out` yet). */
static void ctx_init(ctx_t *c, const occ_map_t *map, const occ_pose_t *map_from_body,
                     const occ_sectors_config_t *cfg)
{
    c->res = map->cfg.resolution_m;
    c->half = (int32_t)1 << (map->cfg.depth_levels - 1u);
    c->vol_lo = -(float)c->half * c->res;
    c->vol_hi = (float)c->half * c->res;
    c->px = map_from_body->p.x;
    c->py = map_from_body->p.y;
    c->yaw = occ_pose_yaw(map_from_body); /* roll and pitch do not turn the sectors */
    c->offset = fmodf(cfg->angle_offset_deg * DEG2RAD_F, TWO_PI_F);
    c->inc = cfg->increment_deg * DEG2RAD_F;
    c->inv_inc = 1.0f / c->inc;
    c->period = 360.0f / cfg->increment_deg;
    c->range = (float)cfg->max_distance_cm * 0.01f;
    c->n = cfg->n_sectors;
    c->sgn = cfg->map_ned ? -1.0f : 1.0f;
    c->margin = 3e-4f * c->inv_inc;
    c->full = c->period - (float)c->n < 1e-3f;
    c->bound = OCC_SECTORS_FAR;
    c->dirty = false;
}

static bool inside_volume(const ctx_t *c, const occ_vec3_t at)
{
    return at.x >= c->vol_lo && at.x < c->vol_hi && at.y >= c->vol_lo && at.y < c->vol_hi &&
           at.z >= c->vol_lo && at.z < c->vol_hi;
}

/* Nothing found yet, and the n + 1 boundary rays of the sectors in the map frame. */
static void start_sectors(const ctx_t *c, occ_sectors_t *out)
{
    for (unsigned s = 0; s < c->n; s++) {
        out->d_occ_m[s] = OCC_SECTORS_FAR;
        out->d_unk_m[s] = OCC_SECTORS_FAR;
    }
    for (unsigned k = 0; k <= c->n; k++) {
        /* Boundary k: body angle offset + (k - 1/2) inc, clockwise; map angle yaw - that. */
        const float a = c->yaw - c->sgn * (c->offset + ((float)k - 0.5f) * c->inc);
        out->ray_c[k] = cosf(a);
        out->ray_s[k] = sinf(a);
    }
}

/* The band [*za, *zb) in map z about the vehicle's z, its ground side lifted above the ground
 * under the vehicle ("below" is -z in an ENU map, +z in a NED one). */
static void band(const occ_map_t *map, const occ_vec3_t at, const occ_sectors_config_t *cfg,
                 float *za, float *zb)
{
    *za = at.z - (cfg->map_ned ? cfg->band_above_m : cfg->band_below_m);
    *zb = at.z + (cfg->map_ned ? cfg->band_below_m : cfg->band_above_m);
    if (cfg->map_ned) {
        *zb = -ground_lift(map, at, cfg, -*zb, -*za);
    } else {
        *za = ground_lift(map, at, cfg, *za, *zb);
    }
}

/* Space outside the map volume is unknown: the band above or below it, and the slabs beyond
 * each side the search square reaches. */
static void fold_outside_volume(ctx_t *c, occ_sectors_t *out, float za, float zb)
{
    const float r = c->range, lo = c->vol_lo, hi = c->vol_hi;
    if (za < lo || zb > hi) {
        fold_rect(c, out, KIND_UNK, c->px - r, c->py - r, c->px + r, c->py + r);
    }
    if (c->px - r < lo) {
        fold_rect(c, out, KIND_UNK, lo - 2.0f * r - 1.0f, c->py - r - 1.0f, lo, c->py + r + 1.0f);
    }
    if (c->px + r > hi) {
        fold_rect(c, out, KIND_UNK, hi, c->py - r - 1.0f, hi + 2.0f * r + 1.0f, c->py + r + 1.0f);
    }
    if (c->py - r < lo) {
        fold_rect(c, out, KIND_UNK, c->px - r - 1.0f, lo - 2.0f * r - 1.0f, c->px + r + 1.0f, lo);
    }
    if (c->py + r > hi) {
        fold_rect(c, out, KIND_UNK, c->px - r - 1.0f, hi, c->px + r + 1.0f, hi + 2.0f * r + 1.0f);
    }
}

/* Key box of the search cylinder and the band, per axis [lo, hi]. */
typedef struct {
    int32_t lo[3], hi[3];
} keybox_t;

static void search_box(const occ_map_t *map, const ctx_t *c, float za, float zb, keybox_t *box)
{
    const float r = c->range;
    key_range(map, c->px - r, c->px + r, &box->lo[0], &box->hi[0]);
    key_range(map, c->py - r, c->py + r, &box->lo[1], &box->hi[1]);
    /* The band is half-open: [za, zb) is [za, the float below zb]. */
    key_range(map, za, nextafterf(zb, za), &box->lo[2], &box->hi[2]);
    if (box->hi[2] < box->lo[2]) {
        box->hi[2] = box->lo[2];
    }
}

/* Fold a node that is one thing for the sectors: a leaf or uniform node (free: nothing), or a
 * node whose voxels are all occupied or all unknown (values may differ: the whole footprint).
 * False when its children must be read. */
static bool fold_node(ctx_t *c, occ_sectors_t *out, const occ_node_t *nd, float x0, float y0,
                      float size)
{
    if (nd->level == 0u || (nd->flags & OCC_NODE_UNIFORM) != 0u) {
        const occ_state_t st = nd->observed ? nd->state : OCC_STATE_UNKNOWN;
        if (st != OCC_STATE_FREE) {
            fold_rect(c, out, st == OCC_STATE_OCCUPIED ? KIND_OCC : KIND_UNK, x0, y0, x0 + size,
                      y0 + size);
        }
        return true;
    }
    const uint8_t kinds =
        (uint8_t)(nd->flags & (OCC_NODE_HAS_OCCUPIED | OCC_NODE_HAS_UNKNOWN | OCC_NODE_HAS_FREE));
    if ((kinds & (OCC_NODE_HAS_OCCUPIED | OCC_NODE_HAS_UNKNOWN)) == 0u) {
        return true;
    }
    if (kinds == OCC_NODE_HAS_OCCUPIED || kinds == OCC_NODE_HAS_UNKNOWN) {
        fold_rect(c, out, kinds == OCC_NODE_HAS_OCCUPIED ? KIND_OCC : KIND_UNK, x0, y0, x0 + size,
                  y0 + size);
        return true;
    }
    return false;
}

/* The children of nd worth reading - inside the key box, nearer than the search radius and the
 * bound - farthest first, with their horizontal distances; returns how many. The distance
 * depends on the x and y halves only: four values. */
static unsigned order_children(const ctx_t *c, const keybox_t *box, const occ_node_t *nd,
                               float x0, float y0, float size, uint8_t kid[8], float kid_d[8])
{
    const uint32_t step = (uint32_t)1 << (nd->level - 1u);
    const float csize = size * 0.5f;
    bool in[3][2];
    for (unsigned a = 0; a < 3u; a++) {
        for (unsigned hh = 0; hh < 2u; hh++) {
            const int32_t k0 = (int32_t)(nd->key.k[a] + (hh != 0u ? step : 0u));
            in[a][hh] = k0 <= box->hi[a] && k0 + (int32_t)step - 1 >= box->lo[a];
        }
    }
    float dxy[4];
    for (unsigned q = 0; q < 4u; q++) {
        const float cx0 = x0 + ((q & 1u) != 0u ? csize : 0.0f) - c->px;
        const float cy0 = y0 + ((q & 2u) != 0u ? csize : 0.0f) - c->py;
        const float qx = clampf(0.0f, cx0, cx0 + csize);
        const float qy = clampf(0.0f, cy0, cy0 + csize);
        dxy[q] = sqrtf(qx * qx + qy * qy);
    }
    unsigned nk = 0;
    for (unsigned ci = 0; ci < 8u; ci++) {
        const float dm = dxy[ci & 3u];
        if (!in[0][ci & 1u] || !in[1][(ci >> 1) & 1u] || !in[2][(ci >> 2) & 1u] ||
            dm >= c->range || dm > c->bound) {
            continue;
        }
        unsigned j = nk++;
        /* cppcheck-suppress uninitvar ; kid_d[0..nk) are written, j - 1 < nk */
        while (j > 0u && kid_d[j - 1u] < dm) {
            kid[j] = kid[j - 1u];
            kid_d[j] = kid_d[j - 1u];
            j--;
        }
        kid[j] = (uint8_t)ci;
        kid_d[j] = dm;
    }
    return nk;
}

/* Depth-first, nearest child first: close to best-first in the nodes it reads (a heap read 10%
 * fewer and ran slower), with a stack of at most 7 entries per level. A node is skipped when
 * it is farther than every sector it spans has already found. */
static occ_err_t walk(const occ_map_t *map, ctx_t *c, occ_sectors_t *out, const keybox_t *box)
{
    const float res = c->res; /* locals: c's address escapes, its fields would be reloaded */
    const int32_t half = c->half;
    unsigned sp = 1;
    unsigned pops = 0;
    occ_map_node_root(map, &out->stack[0].node);
    out->stack[0].dmin = 0.0f;
    while (sp > 0) {
        const occ_sectors_item_t it = out->stack[--sp];
        if ((++pops & 15u) == 0u) {
            (void)refresh_bound(c, out);
        }
        if (it.dmin > c->bound) {
            continue;
        }
        const float size = res * (float)((uint32_t)1 << it.node.level);
        const float x0 = (float)((int32_t)it.node.key.k[0] - half) * res;
        const float y0 = (float)((int32_t)it.node.key.k[1] - half) * res;
        if (it.dmin > 0.0f && !sectors_open(c, out, x0 - c->px, y0 - c->py, size, it.dmin)) {
            continue;
        }
        out->nodes_read++;
        if (fold_node(c, out, &it.node, x0, y0, size)) {
            continue;
        }
        uint8_t kid[8];
        float kid_d[8];
        const unsigned nk = order_children(c, box, &it.node, x0, y0, size, kid, kid_d);
        if (nk > OCC_SECTORS_WALK_LIMIT - sp) {
            return OCC_ERR_NOMEM; /* a skipped child could hold the nearest obstacle */
        }
        for (unsigned j = 0; j < nk; j++) {
            occ_sectors_item_t *const ch = &out->stack[sp++];
            const occ_err_t e = occ_map_node_child(map, &it.node, kid[j], &ch->node);
            if (e != OCC_OK) {
                return e;
            }
            ch->dmin = kid_d[j];
        }
    }
    return OCC_OK;
}

/* What each sector reports (occ_sectors.h): obstacle, unknown, or observed free. */
static void write_distances(const ctx_t *c, const occ_sectors_config_t *cfg, occ_sectors_t *out)
{
    for (unsigned s = 0; s < c->n; s++) {
        const float dO = out->d_occ_m[s];
        const float dU = out->d_unk_m[s];
        uint16_t v;
        if (dO <= dU && dO < c->range) {
            v = to_cm(dO, cfg);
        } else if (dU < c->range) {
            v = cfg->unknown_as_distance ? to_cm(dU, cfg) : OCC_SECTORS_UNKNOWN;
        } else {
            v = (uint16_t)(cfg->max_distance_cm + 1u); /* MAVLink's "no obstacle" */
        }
        out->distance_cm[s] = v;
    }
    out->n = c->n;
}

occ_err_t occ_sectors_compute(const occ_map_t *map, const occ_pose_t *map_from_body,
                              const occ_sectors_config_t *cfg, occ_sectors_t *out)
{
    if (out == NULL) {
        return OCC_ERR_ARG;
    }
    fill_unsafe(out, cfg); /* fail closed: every early return leaves the unsafe answer */
    out->nodes_read = 0;
    out->leaves_used = 0;
    if (map == NULL || occ_sectors_config_check(cfg) != OCC_OK ||
        occ_pose_check(map_from_body) != OCC_OK) {
        return OCC_ERR_ARG;
    }
    ctx_t c;
    ctx_init(&c, map, map_from_body, cfg);
    if (!inside_volume(&c, map_from_body->p)) {
        return OCC_ERR_RANGE;
    }
    start_sectors(&c, out);
    float za, zb;
    band(map, map_from_body->p, cfg, &za, &zb);
    fold_outside_volume(&c, out, za, zb);
    keybox_t box;
    search_box(map, &c, za, zb, &box);
    const occ_err_t e = walk(map, &c, out, &box);
    if (e != OCC_OK) {
        fill_unsafe(out, cfg);
        return e;
    }
    write_distances(&c, cfg, out);
    return OCC_OK;
}
