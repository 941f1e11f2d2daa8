/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * castray.c - OctoMap's castRay (3D-DDA, Amanatides & Woo) and line of sight.
 * The voxel sequence, the tie rule and the arithmetic are OctoMap's (double on hosts when
 * OCC_RAY_DOUBLE), from the DDA set-up and tie rule shared with computeRayKeys (geom_internal.h)
 * on the map's one key conversion; what differs is the lookup: instead of a search from the root per voxel, a
 * cursor keeps the path to the current voxel and re-descends only below the highest key bit that
 * changed, and not at all while the ray stays inside a node it can pass whole: a uniform (pruned)
 * one, or one whose indicators say nothing below stops the ray (UFOMap's use of the inner nodes).
 */
#include "query_internal.h"

typedef occ_real_t real_t;
#if OCC_RAY_DOUBLE
#define RSQRT sqrt
#else
#define RSQRT sqrtf
#endif

/* The path from the root to the node holding the current voxel. The descent ends early at a
 * passable node (no voxel below has a state in `stop`, read from the indicators): the walk can
 * then step through all of it without looking anything up, as through a uniform node. */
typedef struct {
    const occ_map_t *m;
    const occ_inner_block_t *inner_top; /* inner block 0 (blocks grow down from the arena end) */
    const occ_leaf_block_t *leaf_base;  /* leaf block 0 */
    uint32_t key[3];
    uint8_t stop;     /* OCC_NODE_HAS_* flags of the states the walk stops at */
    unsigned lu;      /* level of the deepest node on the path: passable, uniform, or a voxel */
    occ_value_t val;  /* its value (a passable node's max: passable too) */
    uint32_t blk[OCC_MAX_DEPTH + 1u]; /* blk[L]: child block of the path node at level L > lu */
} cursor_t;

static void descend(cursor_t *c, unsigned level)
{
    /* Locals: the stores to c->blk must not make the compiler reload keys and bases. */
    const uint32_t k0 = c->key[0];
    const uint32_t k1 = c->key[1];
    const uint32_t k2 = c->key[2];
    const occ_inner_block_t *const top = c->inner_top;
    const unsigned stop = c->stop;
    OCC_ASSERT(level >= 1u && level <= c->m->cfg.depth_levels);
    uint32_t b = c->blk[level];
    while (level > 1u) {
        const unsigned l = level - 1u;
        const unsigned slot = ((k0 >> l) & 1u) | (((k1 >> l) & 1u) << 1) | (((k2 >> l) & 1u) << 2);
        OCC_ASSERT(b < c->m->inner.hwm);
        const occ_inner_block_t *const ib = top - b; /* occ_inner_at(m, b) */
        const uint32_t ch = occ_inner_child(ib, slot);
        if (ch == OCC_NONE || (occ_inner_flags(ib, slot) & stop) == 0u) {
            c->lu = l;
            c->val = ib->value[slot];
            return;
        }
        c->blk[l] = ch;
        b = ch;
        level = l;
    }
    c->lu = 0;
    OCC_ASSERT(b < c->m->leaf.hwm);
    c->val = c->leaf_base[b].value[(k0 & 1u) | ((k1 & 1u) << 1) | ((k2 & 1u) << 2)];
}

static void cursor_init(cursor_t *c, const occ_map_t *m, const uint32_t key[3], uint8_t stop)
{
    c->m = m;
    c->stop = stop;
    c->inner_top = occ_inner_base(m);
    c->leaf_base = occ_leaf_base(m);
    c->key[0] = key[0];
    c->key[1] = key[1];
    c->key[2] = key[2];
    const unsigned d = m->cfg.depth_levels;
    if (occ_root_child(m) == OCC_NONE || (occ_root_flags(m) & stop) == 0u) {
        c->lu = d;
        c->val = m->priv.root_value;
        return;
    }
    c->blk[d] = occ_root_child(m);
    descend(c, d);
}

/* key[dim] changed from `old`: refresh the path below the highest changed bit. */
static inline void cursor_moved(cursor_t *c, unsigned dim, uint32_t old)
{
    const uint32_t x = old ^ c->key[dim];
    if ((x >> c->lu) == 0u) {
        return; /* still inside the same passable or uniform node */
    }
    descend(c, occ_bit_length32(x)); /* from the node above the highest changed bit */
}

/* The origin's key: the map's one conversion (geom_internal.h). */
static occ_err_t ray_key(const occ_map_t *m, occ_vec3_t p, uint32_t key[3])
{
    return occ_geom_key1(m, p.x, &key[0]) && occ_geom_key1(m, p.y, &key[1]) &&
                   occ_geom_key1(m, p.z, &key[2])
               ? OCC_OK
               : OCC_ERR_RANGE;
}

static occ_err_t check_policy(occ_unknown_policy_t policy)
{
    return (policy == OCC_UNKNOWN_UNSAFE || policy == OCC_UNKNOWN_SAFE) ? OCC_OK : OCC_ERR_ARG;
}

/* OctoMap's keyToCoord for one axis. */
static inline real_t key_coord(real_t res, int32_t tmv, uint32_t k)
{
    return occ_geom_center_of(res, tmv, k, 0u);
}

static void set_result(const cursor_t *c, real_t res, int32_t tmv, occ_ray_result_t *out,
                       bool hit, occ_ray_stop_t stop)
{
    out->hit = hit;
    out->stop = stop;
    out->key.k[0] = c->key[0];
    out->key.k[1] = c->key[1];
    out->key.k[2] = c->key[2];
    out->end.x = (float)key_coord(res, tmv, c->key[0]);
    out->end.y = (float)key_coord(res, tmv, c->key[1]);
    out->end.z = (float)key_coord(res, tmv, c->key[2]);
}

/* The shared DDA set-up (geom_internal.h); castRay keeps the half-voxel step in double. */
typedef occ_dda_t dda_t;

static inline void dda_init(dda_t *d, const cursor_t *c, real_t res, int32_t tmv, const float o[3],
                            const float dir[3])
{
    occ_dda_start(d, res, tmv, o, dir, c->key, false);
}

/* The unsafe answer an error leaves in a caller's result: an obstacle at the origin, in no voxel
 * (key OCC_NONE on every axis). */
static void set_unsafe(occ_ray_result_t *out, occ_vec3_t origin)
{
    out->hit = true;
    out->stop = OCC_RAY_HIT;
    out->key.k[0] = OCC_NONE;
    out->key.k[1] = OCC_NONE;
    out->key.k[2] = OCC_NONE;
    out->end = origin;
}

/* The ray is in a node of level lu >= 1 that it passes through (passable or uniform): step on
 * without looking anything up while the next voxel is still in the node and (when the range is
 * bounded) entered before `safe_t`, where the centre distance test cannot fail. Same events, same
 * order, same arithmetic as stepping. */
/* Steps left on one axis before the walk leaves the aligned node of edge `size` holding `key`. */
static inline int32_t coast_room(int32_t step, uint32_t key, uint32_t size)
{
    const uint32_t base = key & ~(size - 1u);
    return step > 0 ? (int32_t)(base + size - 1u - key) : (step < 0 ? (int32_t)(key - base) : 0);
}

static inline void dda_coast(dda_t *d, uint32_t key[3], unsigned lu, bool bounded, real_t safe_t)
{
    const uint32_t size = (uint32_t)1 << lu;
    const int32_t room0 = coast_room(d->step[0], key[0], size);
    const int32_t room1 = coast_room(d->step[1], key[1], size);
    const int32_t room2 = coast_room(d->step[2], key[2], size);
    /* Registers only: the loop-carried chain is one add and two compares per step. */
    real_t t0 = d->tmax[0];
    real_t t1 = d->tmax[1];
    real_t t2 = d->tmax[2];
    const real_t dt0 = d->tdelta[0];
    const real_t dt1 = d->tdelta[1];
    const real_t dt2 = d->tdelta[2];
    const real_t stop = bounded ? safe_t : OCC_REAL_MAX;
    int32_t n0 = 0;
    int32_t n1 = 0;
    int32_t n2 = 0;
    for (;;) {
        const unsigned dim = occ_dda_axis(t0, t1, t2);
        if (dim == 0u) {
            if (n0 == room0 || !(t0 < stop)) {
                break;
            }
            n0++;
            t0 += dt0;
        } else if (dim == 1u) {
            if (n1 == room1 || !(t1 < stop)) {
                break;
            }
            n1++;
            t1 += dt1;
        } else {
            if (n2 == room2 || !(t2 < stop)) {
                break;
            }
            n2++;
            t2 += dt2;
        }
    }
    d->tmax[0] = t0;
    d->tmax[1] = t1;
    d->tmax[2] = t2;
    key[0] = (uint32_t)((int32_t)key[0] + n0 * d->step[0]);
    key[1] = (uint32_t)((int32_t)key[1] + n1 * d->step[1]);
    key[2] = (uint32_t)((int32_t)key[2] + n2 * d->step[2]);
}

static bool normalize(const occ_vec3_t v, float out[3])
{
    const float sq = v.x * v.x + v.y * v.y + v.z * v.z;
    const real_t len = RSQRT((real_t)sq);
    if (!(len > (real_t)0)) {
        return false;
    }
    const float lf = (float)len;
    out[0] = v.x / lf;
    out[1] = v.y / lf;
    out[2] = v.z / lf;
    return true;
}

/* The fixed numbers of one walk: the map's grid, the origin, and (castRay only) the range. */
typedef struct {
    real_t res;
    int32_t tmv;
    float o[3];
    bool range_set; /* max_range_m > 0 */
    real_t range_sq;
    real_t safe_t;  /* entry parameter below which the range test cannot fail */
} walk_t;

static void walk_set(walk_t *w, const occ_map_t *map, occ_vec3_t origin)
{
    w->res = occ_geom_res(map);
    w->tmv = occ_geom_half(map);
    w->o[0] = origin.x;
    w->o[1] = origin.y;
    w->o[2] = origin.z;
}

/* castRay's range (0: none). */
static void walk_range(walk_t *w, float max_range_m)
{
    w->range_set = max_range_m > 0.0f;
    w->range_sq = (real_t)max_range_m * (real_t)max_range_m;
    /* A voxel entered at ray parameter t has its centre within t + 0.87 res of the origin, so
     * OctoMap's exact centre-distance test can only fail once t passes this (with margin). */
    w->safe_t = (real_t)max_range_m - w->res * (real_t)1.01 - (real_t)1e-5 * (real_t)max_range_m;
}

/* castRay's arguments checked, its direction normalized into dir and the origin's key into k.
 * On error *out keeps the unsafe answer. */
static occ_err_t cast_args(const occ_map_t *map, occ_vec3_t origin, occ_vec3_t direction,
                           float max_range_m, occ_ray_result_t *out, float dir[3], uint32_t k[3])
{
    if (out == NULL) {
        return OCC_ERR_ARG;
    }
    set_unsafe(out, origin); /* until the walk decides */
    if (map == NULL || !occ_finite3(origin) || !occ_finite3(direction) ||
        !occ_finite(max_range_m) || !normalize(direction, dir)) {
        return OCC_ERR_ARG;
    }
    return ray_key(map, origin, k);
}

/* OctoMap's centre-distance test for the voxel at key: float centre minus float origin, squared
 * in float, summed in double. */
static inline bool beyond_range(const walk_t *w, const uint32_t key[3])
{
    real_t dist_sq = (real_t)0;
    for (unsigned j = 0; j < 3u; j++) {
        const float ej = (float)key_coord(w->res, w->tmv, key[j]);
        const float dj = ej - w->o[j];
        dist_sq += (real_t)(dj * dj);
    }
    return dist_sq > w->range_sq;
}

/* castRay's walk from the origin's voxel (already let through) to the first voxel that stops it:
 * occupied, unknown (unless ignored), the range or the map's edge. The one hot loop: the node
 * tests are inline here, and a node the cursor lets through is coasted without lookups. */
static void cast_walk(const occ_map_t *map, cursor_t *c, dda_t *d, const walk_t *w,
                      bool ignore_unknown, occ_ray_result_t *out)
{
    const uint32_t kmax = ((uint32_t)1 << map->cfg.depth_levels) - 1u;
    const occ_value_t occ_min = map->priv.q_occ_min;
    const occ_value_t free_max = map->priv.q_free_max;
    /* The last key a step may leave from, per axis (never reached for a zero step). */
    const uint32_t lim[3] = {d->step[0] > 0 ? kmax : 0u, d->step[1] > 0 ? kmax : 0u,
                             d->step[2] > 0 ? kmax : 0u};
    bool entered = true; /* in a node the ray passes through, not yet coasted */
    for (;;) {
        if (entered && c->lu > 0u) {
            dda_coast(d, c->key, c->lu, w->range_set, w->safe_t);
        }
        entered = false;
        const unsigned dim = occ_dda_axis(d->tmax[0], d->tmax[1], d->tmax[2]);
        const real_t t_entry = d->tmax[dim];
        const uint32_t old = c->key[dim];
        if (old == lim[dim]) {
            set_result(c, w->res, w->tmv, out, false, OCC_RAY_MAP_EDGE);
            return;
        }
        c->key[dim] = (uint32_t)((int32_t)old + d->step[dim]);
        d->tmax[dim] += d->tdelta[dim];
        if (w->range_set && !(t_entry < w->safe_t) && beyond_range(w, c->key)) {
            set_result(c, w->res, w->tmv, out, false, OCC_RAY_MAX_RANGE);
            return;
        }
        if (((old ^ c->key[dim]) >> c->lu) == 0u) {
            continue; /* same node, already let through */
        }
        cursor_moved(c, dim, old);
        const occ_value_t v = c->val;
        if (v >= occ_min && occ_is_observed(v)) {
            set_result(c, w->res, w->tmv, out, true, OCC_RAY_HIT);
            return;
        }
        if (!(v < free_max && occ_is_observed(v)) && !ignore_unknown) {
            set_result(c, w->res, w->tmv, out, false, OCC_RAY_UNKNOWN);
            return;
        }
        entered = true;
    }
}

occ_err_t occ_cast_ray(const occ_map_t *map, occ_vec3_t origin, occ_vec3_t direction,
                       bool ignore_unknown, float max_range_m, occ_ray_result_t *out)
{
    float dir[3];
    occ_key_t k0;
    const occ_err_t e = cast_args(map, origin, direction, max_range_m, out, dir, k0.k);
    if (e != OCC_OK) {
        return e;
    }
    walk_t w;
    walk_set(&w, map, origin);
    walk_range(&w, max_range_m);
    cursor_t c;
    const unsigned states = OCC_PRED_OCCUPIED | (ignore_unknown ? 0u : OCC_PRED_UNKNOWN);
    cursor_init(&c, map, k0.k, (uint8_t)occ_q_has_bits(states));
    const occ_state_t s = occ_value_state(map, c.val);
    if (s == OCC_STATE_OCCUPIED) {
        set_result(&c, w.res, w.tmv, out, true, OCC_RAY_HIT);
        return OCC_OK;
    }
    if (s == OCC_STATE_UNKNOWN && !ignore_unknown) {
        set_result(&c, w.res, w.tmv, out, false, OCC_RAY_UNKNOWN);
        return OCC_OK;
    }
    dda_t d;
    dda_init(&d, &c, w.res, w.tmv, w.o, dir);
    if (d.step[0] == 0 && d.step[1] == 0 && d.step[2] == 0) {
        return OCC_ERR_ARG; /* direction too small to normalize to a non-zero float vector */
    }
    cast_walk(map, &c, &d, &w, ignore_unknown, out);
    return OCC_OK;
}

/* Nothing blocks: the blocker (if asked for) names no voxel. */
static occ_err_t set_visible(bool *visible, occ_ray_result_t *blocker)
{
    if (blocker != NULL) {
        blocker->hit = false;
    }
    *visible = true;
    return OCC_OK;
}

static bool blocks(const occ_map_t *map, occ_value_t v, occ_unknown_policy_t policy)
{
    return (occ_q_state_bit(occ_value_state(map, v)) & occ_q_blocking_states(policy)) != 0u;
}

/* Line of sight's arguments checked and both end keys into ka, kb; fail closed until then: not
 * visible, blocked at a. */
static occ_err_t los_args(const occ_map_t *map, occ_vec3_t a, occ_vec3_t b,
                          occ_unknown_policy_t policy, bool *visible, occ_ray_result_t *blocker,
                          uint32_t ka[3], uint32_t kb[3])
{
    if (visible != NULL) {
        *visible = false;
    }
    if (blocker != NULL) {
        set_unsafe(blocker, a);
    }
    if (map == NULL || visible == NULL || check_policy(policy) != OCC_OK || !occ_finite3(a) ||
        !occ_finite3(b)) {
        return OCC_ERR_ARG;
    }
    const occ_err_t e = ray_key(map, a, ka);
    return e == OCC_OK ? ray_key(map, b, kb) : e;
}

static inline bool same_key(const uint32_t p[3], const uint32_t q[3])
{
    return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
}

/* How a walk from a towards b ended. */
typedef enum { LOS_BLOCKED, LOS_AT_B, LOS_PAST_B } los_end_t;

/* The walk from a's voxel (already let through) to b's: LOS_BLOCKED at the first voxel that
 * blocks (the cursor on it), LOS_AT_B when b's voxel was reached and let through, LOS_PAST_B when
 * the walk passed b (or the map's border) by rounding without checking b's voxel. The one hot
 * loop, as in cast_walk. */
static los_end_t los_walk(const occ_map_t *map, cursor_t *c, dda_t *d, const uint32_t kb[3],
                          real_t len, bool unknown_blocks)
{
    const uint32_t kmax = ((uint32_t)1 << map->cfg.depth_levels) - 1u;
    const occ_value_t occ_min = map->priv.q_occ_min;
    const occ_value_t free_max = map->priv.q_free_max;
    bool entered = true;
    for (;;) {
        if (entered && c->lu > 0u) {
            /* b inside this pass-through node: the rest of the segment is in it too (convex),
             * and b's voxel has this node's (passable) value. */
            const uint32_t sh = c->lu;
            if (((c->key[0] ^ kb[0]) >> sh) == 0u && ((c->key[1] ^ kb[1]) >> sh) == 0u &&
                ((c->key[2] ^ kb[2]) >> sh) == 0u) {
                return LOS_AT_B;
            }
            dda_coast(d, c->key, c->lu, false, (real_t)0);
        }
        entered = false;
        const unsigned dim = occ_dda_axis(d->tmax[0], d->tmax[1], d->tmax[2]);
        if (d->tmax[dim] > len) {
            return LOS_PAST_B;
        }
        const uint32_t old = c->key[dim];
        if ((d->step[dim] < 0 && old == 0u) || (d->step[dim] > 0 && old == kmax)) {
            return LOS_PAST_B; /* rounding at the map border: nothing beyond */
        }
        c->key[dim] = (uint32_t)((int32_t)old + d->step[dim]);
        d->tmax[dim] += d->tdelta[dim];
        const bool at_b = same_key(c->key, kb);
        if (((old ^ c->key[dim]) >> c->lu) == 0u) {
            if (at_b) {
                return LOS_AT_B;
            }
            continue; /* same node, already let through */
        }
        cursor_moved(c, dim, old);
        const occ_value_t v = c->val;
        const bool obs = occ_is_observed(v);
        if ((obs && v >= occ_min) || (unknown_blocks && !(obs && v < free_max))) {
            return LOS_BLOCKED;
        }
        if (at_b) {
            return LOS_AT_B;
        }
        entered = true;
    }
}

occ_err_t occ_line_of_sight(const occ_map_t *map, occ_vec3_t a, occ_vec3_t b,
                            occ_unknown_policy_t policy, bool *visible,
                            occ_ray_result_t *blocker)
{
    occ_key_t ka;
    occ_key_t kb;
    const occ_err_t e = los_args(map, a, b, policy, visible, blocker, ka.k, kb.k);
    if (e != OCC_OK) {
        return e;
    }
    walk_t w; /* no range: los_walk stops at b */
    walk_set(&w, map, a);
    occ_ray_result_t scratch;
    /* cppcheck-suppress uninitvar ; only its address is taken here (cppcheck 2.10 flags &x of a fresh local) */
    occ_ray_result_t *const res_out = blocker != NULL ? blocker : &scratch;
    const uint8_t stop = (uint8_t)occ_q_has_bits(occ_q_blocking_states(policy));
    cursor_t c;
    cursor_init(&c, map, ka.k, stop);
    if (blocks(map, c.val, policy)) {
        set_result(&c, w.res, w.tmv, res_out, true, OCC_RAY_HIT);
        return OCC_OK;
    }
    const occ_vec3_t dv = {b.x - a.x, b.y - a.y, b.z - a.z};
    float dir[3];
    if (!normalize(dv, dir) || same_key(ka.k, kb.k)) {
        return set_visible(visible, blocker);
    }
    const real_t len = RSQRT((real_t)dv.x * (real_t)dv.x + (real_t)dv.y * (real_t)dv.y +
                             (real_t)dv.z * (real_t)dv.z);
    dda_t d;
    dda_init(&d, &c, w.res, w.tmv, w.o, dir);
    const los_end_t end = los_walk(map, &c, &d, kb.k, len, policy == OCC_UNKNOWN_UNSAFE);
    if (end == LOS_PAST_B) {
        cursor_init(&c, map, kb.k, stop); /* the walk is over: reuse its cursor for b's voxel */
    }
    if (end == LOS_BLOCKED || (end == LOS_PAST_B && blocks(map, c.val, policy))) {
        set_result(&c, w.res, w.tmv, res_out, true, OCC_RAY_HIT);
        return OCC_OK;
    }
    return set_visible(visible, blocker);
}
