/* SPDX-License-Identifier: BSD-3-Clause */
/* shadow_grid.c - the dense reference model of shadow_grid.h. */
#include "shadow_grid.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/tree_internal.h"

#if OCC_VALUE_FLOAT
typedef float acc_t;
#else
typedef int32_t acc_t;
#endif

static bool veq(occ_value_t a, occ_value_t b)
{
    return !(a < b) && !(b < a);
}

occ_state_t shadow_state(const shadow_grid_t *s, occ_value_t v)
{
    if (!(v > OCC_VALUE_UNOBSERVED)) {
        return OCC_STATE_UNKNOWN;
    }
    if (!(v < s->q_occ_min)) {
        return OCC_STATE_OCCUPIED;
    }
    if (v < s->q_free_max) {
        return OCC_STATE_FREE;
    }
    return OCC_STATE_UNKNOWN;
}

static uint8_t value_flags(const shadow_grid_t *s, occ_value_t v)
{
    switch (shadow_state(s, v)) {
    case OCC_STATE_OCCUPIED:
        return OCC_NODE_HAS_OCCUPIED;
    case OCC_STATE_FREE:
        return OCC_NODE_HAS_FREE;
    case OCC_STATE_UNKNOWN:
    default:
        return OCC_NODE_HAS_UNKNOWN;
    }
}

bool shadow_init(shadow_grid_t *s, const occ_map_t *map, unsigned vol_log2, const uint32_t base[3])
{
    memset(s, 0, sizeof *s);
    if (vol_log2 > map->cfg.depth_levels || vol_log2 > 8u) {
        return false;
    }
    s->depth = map->cfg.depth_levels;
    s->vol_log2 = vol_log2;
    s->edge = 1u << vol_log2;
    for (unsigned i = 0; i < 3; i++) {
        if ((base[i] & (s->edge - 1u)) != 0u ||
            (uint64_t)base[i] + s->edge > ((uint64_t)1 << s->depth)) {
            return false;
        }
        s->base[i] = base[i];
    }
    const size_t n = (size_t)s->edge * s->edge * s->edge;
    s->vox = malloc(n * sizeof *s->vox);
    if (s->vox == NULL) {
        return false;
    }
    for (unsigned l = 0; l <= vol_log2; l++) {
        const size_t e = (size_t)(s->edge >> l);
        s->lvl[l] = calloc(e * e * e, sizeof(shadow_node_t));
        if (s->lvl[l] == NULL) {
            return false;
        }
    }
    s->q_hit = occ_value_from_logodds(map->cfg.hit);
    s->q_miss = occ_value_from_logodds(map->cfg.miss);
    s->q_cmin = occ_value_from_logodds(map->cfg.clamp_min);
    s->q_cmax = occ_value_from_logodds(map->cfg.clamp_max);
    s->q_free_max = occ_value_from_logodds(map->cfg.free_max);
    s->q_occ_min = occ_value_from_logodds(map->cfg.occupied_min);
    shadow_clear(s);
    return true;
}

void shadow_free(shadow_grid_t *s)
{
    free(s->vox);
    for (unsigned l = 0; l <= OCC_MAX_DEPTH; l++) {
        free(s->lvl[l]);
    }
    memset(s, 0, sizeof *s);
}

void shadow_clear(shadow_grid_t *s)
{
    const size_t n = (size_t)s->edge * s->edge * s->edge;
    for (size_t i = 0; i < n; i++) {
        s->vox[i] = OCC_VALUE_UNOBSERVED;
    }
    s->dirty = true;
}

void shadow_copy(shadow_grid_t *dst, const shadow_grid_t *src)
{
    memcpy(dst->vox, src->vox, (size_t)src->edge * src->edge * src->edge * sizeof *src->vox);
    dst->dirty = true;
}

static size_t vidx(const shadow_grid_t *s, occ_key_t key)
{
    const size_t x = key.k[0] - s->base[0], y = key.k[1] - s->base[1], z = key.k[2] - s->base[2];
    return (z * s->edge + y) * s->edge + x;
}

static bool inside(const shadow_grid_t *s, occ_key_t key)
{
    for (unsigned i = 0; i < 3; i++) {
        if (key.k[i] < s->base[i] || key.k[i] - s->base[i] >= s->edge) {
            return false;
        }
    }
    return true;
}

occ_value_t shadow_get(const shadow_grid_t *s, occ_key_t key)
{
    return s->vox[vidx(s, key)];
}

occ_value_t shadow_apply_delta(const shadow_grid_t *s, occ_value_t v, shadow_delta_t d)
{
    acc_t acc;
    if (v > OCC_VALUE_UNOBSERVED) {
        if (!(d < 0) && !(v < s->q_cmax)) {
            return v;
        }
        if (!(d > 0) && !(v > s->q_cmin)) {
            return v;
        }
        acc = (acc_t)v + (acc_t)d;
    } else {
        acc = (acc_t)d;
    }
    if (acc < (acc_t)s->q_cmin) {
        acc = (acc_t)s->q_cmin;
    } else if (acc > (acc_t)s->q_cmax) {
        acc = (acc_t)s->q_cmax;
    }
    return (occ_value_t)acc;
}

bool shadow_update(shadow_grid_t *s, occ_key_t key, shadow_delta_t q_delta)
{
    occ_value_t *const p = &s->vox[vidx(s, key)];
    const occ_value_t nv = shadow_apply_delta(s, *p, q_delta);
    const bool changed = !veq(nv, *p);
    *p = nv;
    s->dirty = true;
    return changed;
}

bool shadow_set(shadow_grid_t *s, occ_key_t key, unsigned level, occ_value_t v)
{
    const uint32_t n = 1u << level;
    bool changed = false;
    occ_key_t k0 = occ_key_at_level(key, level);
    for (uint32_t z = 0; z < n; z++) {
        for (uint32_t y = 0; y < n; y++) {
            for (uint32_t x = 0; x < n; x++) {
                occ_key_t k;
                k.k[0] = k0.k[0] + x;
                k.k[1] = k0.k[1] + y;
                k.k[2] = k0.k[2] + z;
                occ_value_t *const p = &s->vox[vidx(s, k)];
                if (!veq(*p, v)) {
                    changed = true;
                }
                *p = v;
            }
        }
    }
    s->dirty = true;
    return changed;
}

bool shadow_forget(shadow_grid_t *s, occ_key_t key, unsigned level)
{
    return shadow_set(s, key, level, OCC_VALUE_UNOBSERVED);
}

static shadow_node_t combine8(const shadow_node_t c[8], const shadow_node_t *first)
{
    shadow_node_t r = *first;
    for (unsigned i = 0; i < 8; i++) {
        if (c[i].observed && (!r.observed || c[i].max > r.max)) {
            r.max = c[i].max;
        }
        r.observed = r.observed || c[i].observed;
        r.flags = (uint8_t)(r.flags | c[i].flags);
        r.uniform = r.uniform && c[i].uniform && veq(c[i].first, first->first);
    }
    return r;
}

static void rebuild(shadow_grid_t *s)
{
    if (!s->dirty) {
        return;
    }
    const size_t n = (size_t)s->edge * s->edge * s->edge;
    for (size_t i = 0; i < n; i++) {
        shadow_node_t *const nd = &s->lvl[0][i];
        const occ_value_t v = s->vox[i];
        nd->observed = v > OCC_VALUE_UNOBSERVED;
        nd->max = v;
        nd->first = v;
        nd->flags = value_flags(s, v);
        nd->uniform = true;
    }
    for (unsigned l = 1; l <= s->vol_log2; l++) {
        const size_t e = (size_t)(s->edge >> l), ec = e * 2u;
        for (size_t z = 0; z < e; z++) {
            for (size_t y = 0; y < e; y++) {
                for (size_t x = 0; x < e; x++) {
                    shadow_node_t c[8];
                    for (unsigned i = 0; i < 8; i++) {
                        const size_t cx = 2u * x + (i & 1u), cy = 2u * y + ((i >> 1) & 1u),
                                     cz = 2u * z + ((i >> 2) & 1u);
                        c[i] = s->lvl[l - 1][(cz * ec + cy) * ec + cx];
                    }
                    s->lvl[l][(z * e + y) * e + x] = combine8(c, &c[0]);
                }
            }
        }
    }
    s->dirty = false;
}

static shadow_node_t unobserved_node(const shadow_grid_t *s)
{
    shadow_node_t r;
    r.max = OCC_VALUE_UNOBSERVED;
    r.first = OCC_VALUE_UNOBSERVED;
    r.flags = value_flags(s, OCC_VALUE_UNOBSERVED);
    r.observed = false;
    r.uniform = true;
    return r;
}

/* Region of the level-`level` node containing `key` (rebuild() done). */
static shadow_node_t region(const shadow_grid_t *s, occ_key_t key, unsigned level)
{
    if (level <= s->vol_log2) {
        if (!inside(s, key)) {
            return unobserved_node(s);
        }
        const size_t e = (size_t)(s->edge >> level);
        const size_t x = (key.k[0] - s->base[0]) >> level, y = (key.k[1] - s->base[1]) >> level,
                     z = (key.k[2] - s->base[2]) >> level;
        return s->lvl[level][(z * e + y) * e + x];
    }
    for (unsigned i = 0; i < 3; i++) {
        if ((key.k[i] >> level) != (s->base[i] >> level)) {
            return unobserved_node(s);
        }
    }
    shadow_node_t r = s->lvl[s->vol_log2][0];
    r.flags = (uint8_t)(r.flags | OCC_NODE_HAS_UNKNOWN);
    r.uniform = r.uniform && !r.observed;
    return r;
}

static unsigned answer_level(const shadow_grid_t *s, occ_key_t key, unsigned level)
{
    if (!region(s, key, level).uniform) {
        return level;
    }
    unsigned m = level;
    while (m < s->depth && region(s, key, m + 1u).uniform) {
        m++;
    }
    return m;
}

void shadow_expect_read(shadow_grid_t *s, occ_key_t key, unsigned level, occ_node_info_t *out)
{
    rebuild(s);
    const shadow_node_t r = region(s, key, level);
    memset(out, 0, sizeof *out);
    out->observed = r.observed;
    out->logodds = r.observed ? occ_value_to_logodds(r.max) : 0.0f;
    out->state = r.observed ? shadow_state(s, r.max) : OCC_STATE_UNKNOWN;
    out->flags = (uint8_t)(r.flags | (r.uniform ? OCC_NODE_UNIFORM : 0u));
    out->level = (uint8_t)answer_level(s, key, level);
}

void shadow_need_update(shadow_grid_t *s, occ_key_t key, occ_value_t q_delta, uint32_t *n_inner,
                        uint32_t *n_leaf)
{
    rebuild(s);
    *n_inner = 0;
    *n_leaf = 0;
    const occ_value_t old = shadow_get(s, key);
    if (veq(shadow_apply_delta(s, old, q_delta), old)) {
        return;
    }
    const unsigned m = answer_level(s, key, 0);
    if (m >= 1u) {
        *n_inner = m - 1u;
        *n_leaf = 1;
    }
}

void shadow_need_set(shadow_grid_t *s, occ_key_t key, unsigned level, occ_value_t v,
                     uint32_t *n_inner, uint32_t *n_leaf)
{
    rebuild(s);
    *n_inner = 0;
    *n_leaf = 0;
    const shadow_node_t r = region(s, key, level);
    if (r.uniform && veq(r.first, v)) {
        return;
    }
    const unsigned m = answer_level(s, key, level);
    if (m == level) {
        return;
    }
    const unsigned lo = level + 1u < 2u ? 2u : level + 1u;
    *n_inner = m >= lo ? m - lo + 1u : 0u;
    *n_leaf = level == 0u ? 1u : 0u;
}

void shadow_expect_stats(shadow_grid_t *s, shadow_stats_t *out)
{
    rebuild(s);
    memset(out, 0, sizeof *out);
    for (unsigned l = 0; l <= s->vol_log2; l++) {
        const size_t e = (size_t)(s->edge >> l);
        for (size_t z = 0; z < e; z++) {
            for (size_t y = 0; y < e; y++) {
                for (size_t x = 0; x < e; x++) {
                    const shadow_node_t *const nd = &s->lvl[l][(z * e + y) * e + x];
                    bool parent_split = true;
                    if (l < s->vol_log2) {
                        const size_t ep = e / 2u;
                        parent_split = !s->lvl[l + 1u][((z / 2u) * ep + y / 2u) * ep + x / 2u].uniform;
                    }
                    if (!nd->observed || !parent_split) {
                        continue;
                    }
                    out->nodes++;
                    if (!nd->uniform) {
                        if (l >= 2u) {
                            out->inner_used++;
                        } else {
                            out->leaf_used++;
                        }
                    } else {
                        switch (shadow_state(s, nd->first)) {
                        case OCC_STATE_OCCUPIED:
                            out->occupied_leaves++;
                            break;
                        case OCC_STATE_FREE:
                            out->free_leaves++;
                            break;
                        case OCC_STATE_UNKNOWN:
                        default:
                            out->band_leaves++;
                            break;
                        }
                    }
                }
            }
        }
    }
    const bool vol_observed = s->lvl[s->vol_log2][0].observed;
    if (vol_observed) {
        for (unsigned l = s->vol_log2 + 1u; l <= s->depth; l++) {
            out->nodes++;
            if (l >= 2u) {
                out->inner_used++;
            } else {
                out->leaf_used++;
            }
        }
    }
    const size_t n = (size_t)s->edge * s->edge * s->edge;
    for (unsigned i = 0; i < 3; i++) {
        out->kmin[i] = UINT32_MAX;
    }
    for (size_t i = 0; i < n; i++) {
        const occ_value_t v = s->vox[i];
        if (!(v > OCC_VALUE_UNOBSERVED)) {
            continue;
        }
        const occ_state_t st = shadow_state(s, v);
        out->occupied_voxels += st == OCC_STATE_OCCUPIED;
        out->free_voxels += st == OCC_STATE_FREE;
        out->has_known = true;
        const uint32_t k[3] = {s->base[0] + (uint32_t)(i % s->edge),
                               s->base[1] + (uint32_t)((i / s->edge) % s->edge),
                               s->base[2] + (uint32_t)(i / ((size_t)s->edge * s->edge))};
        for (unsigned a = 0; a < 3; a++) {
            out->kmin[a] = k[a] < out->kmin[a] ? k[a] : out->kmin[a];
            out->kmax[a] = k[a] > out->kmax[a] ? k[a] : out->kmax[a];
        }
    }
}

bool shadow_pool_fits(const occ_map_t *map, uint32_t n_inner, uint32_t n_leaf)
{
    const size_t carved = (size_t)map->leaf.hwm * OCC_LEAF_BLOCK_BYTES +
                          (size_t)map->inner.hwm * OCC_INNER_BLOCK_BYTES;
    if (carved > map->arena_bytes) {
        return false;
    }
    const size_t gap = map->arena_bytes - carved;
    const size_t ni = n_inner > map->inner.free_count ? n_inner - map->inner.free_count : 0u;
    const size_t nl = n_leaf > map->leaf.free_count ? n_leaf - map->leaf.free_count : 0u;
    return ni * OCC_INNER_BLOCK_BYTES + nl * OCC_LEAF_BLOCK_BYTES <= gap;
}

static unsigned report(unsigned *bad, const char *what, const char *msg)
{
    if (*bad < 20u) {
        fprintf(stderr, "shadow mismatch [%s]: %s\n", what, msg);
    }
    return ++*bad;
}

static void compare_read(shadow_grid_t *s, const occ_map_t *map, occ_key_t key, unsigned level,
                         unsigned *bad, const char *what)
{
    occ_node_info_t want, got;
    shadow_expect_read(s, key, level, &want);
    memset(&got, 0, sizeof got);
    const occ_err_t e = occ_map_read_key(map, key, level, &got);
    if (e != OCC_OK || got.observed != want.observed || got.state != want.state ||
        got.flags != want.flags || got.level != want.level ||
        (want.observed && (got.logodds < want.logodds || got.logodds > want.logodds))) {
        char msg[300];
        snprintf(msg, sizeof msg,
                 "key (%u,%u,%u) level %u: err %d; got obs %d lo %.6f st %d fl 0x%x lvl %u; "
                 "want obs %d lo %.6f st %d fl 0x%x lvl %u",
                 (unsigned)key.k[0], (unsigned)key.k[1], (unsigned)key.k[2], level, (int)e,
                 (int)got.observed, (double)got.logodds, (int)got.state, (unsigned)got.flags,
                 (unsigned)got.level, (int)want.observed, (double)want.logodds, (int)want.state,
                 (unsigned)want.flags, (unsigned)want.level);
        report(bad, what, msg);
    }
}

static bool near(double a, double b, double tol)
{
    return fabs(a - b) <= tol;
}

unsigned shadow_compare(shadow_grid_t *s, const occ_map_t *map, unsigned n_outside,
                        const char *what)
{
    unsigned bad = 0;
    rebuild(s);
    for (unsigned l = 0; l <= s->vol_log2; l++) {
        const uint32_t e = s->edge >> l;
        for (uint32_t z = 0; z < e; z++) {
            for (uint32_t y = 0; y < e; y++) {
                for (uint32_t x = 0; x < e; x++) {
                    occ_key_t k;
                    k.k[0] = s->base[0] + (x << l);
                    k.k[1] = s->base[1] + (y << l);
                    k.k[2] = s->base[2] + (z << l);
                    compare_read(s, map, k, l, &bad, what);
                    if (l == 0u && (x + y + z) % 7u == 3u) {
                        /* A key in the middle of a coarse node answers the same as its first. */
                        compare_read(s, map, k, s->vol_log2, &bad, what);
                    }
                }
            }
        }
    }
    occ_key_t b;
    b.k[0] = s->base[0];
    b.k[1] = s->base[1];
    b.k[2] = s->base[2];
    for (unsigned l = s->vol_log2 + 1u; l <= s->depth; l++) {
        compare_read(s, map, b, l, &bad, what);
    }
    const uint32_t span = (uint32_t)((1ull << s->depth) - 1u);
    for (unsigned i = 0; i < n_outside && s->vol_log2 < s->depth; i++) {
        occ_key_t k;
        do {
            for (unsigned a = 0; a < 3; a++) {
                k.k[a] = (uint32_t)(((uint32_t)rand() << 16) ^ (uint32_t)rand()) & span;
                if (rand() % 4 == 0) { /* next to the volume */
                    k.k[a] = s->base[a] + s->edge < span ? s->base[a] + s->edge : s->base[a] - 1u;
                }
            }
        } while (inside(s, k));
        compare_read(s, map, k, 0, &bad, what);
        compare_read(s, map, k, (unsigned)rand() % (s->depth + 1u), &bad, what);
    }
    /* Statistics. */
    shadow_stats_t want;
    shadow_expect_stats(s, &want);
    occ_map_stats_t st;
    occ_map_stats(map, &st);
    char msg[400];
    if (st.inner_used != want.inner_used || st.leaf_used != want.leaf_used ||
        st.nodes != want.nodes || st.occupied_leaves != want.occupied_leaves ||
        st.free_leaves != want.free_leaves || st.unknown_band_leaves != want.band_leaves ||
        st.occupied_voxels != want.occupied_voxels || st.free_voxels != want.free_voxels ||
        st.has_known != want.has_known) {
        snprintf(msg, sizeof msg,
                 "stats: inner %u/%u leaf %u/%u nodes %llu/%llu occL %llu/%llu freeL %llu/%llu "
                 "bandL %llu/%llu occV %llu/%llu freeV %llu/%llu known %d/%d (got/want)",
                 (unsigned)st.inner_used, (unsigned)want.inner_used, (unsigned)st.leaf_used,
                 (unsigned)want.leaf_used, (unsigned long long)st.nodes,
                 (unsigned long long)want.nodes, (unsigned long long)st.occupied_leaves,
                 (unsigned long long)want.occupied_leaves, (unsigned long long)st.free_leaves,
                 (unsigned long long)want.free_leaves, (unsigned long long)st.unknown_band_leaves,
                 (unsigned long long)want.band_leaves, (unsigned long long)st.occupied_voxels,
                 (unsigned long long)want.occupied_voxels, (unsigned long long)st.free_voxels,
                 (unsigned long long)want.free_voxels, (int)st.has_known, (int)want.has_known);
        report(&bad, what, msg);
    }
    const double res = (double)map->cfg.resolution_m;
    const double vox_m3 = res * res * res;
    if (!near((double)st.occupied_volume_m3, (double)want.occupied_voxels * vox_m3,
              1e-4 * (double)want.occupied_voxels * vox_m3 + 1e-9) ||
        !near((double)st.free_volume_m3, (double)want.free_voxels * vox_m3,
              1e-4 * (double)want.free_voxels * vox_m3 + 1e-9)) {
        snprintf(msg, sizeof msg, "volumes: occ %g want %g, free %g want %g",
                 (double)st.occupied_volume_m3, (double)want.occupied_voxels * vox_m3,
                 (double)st.free_volume_m3, (double)want.free_voxels * vox_m3);
        report(&bad, what, msg);
    }
    if (want.has_known) {
        const double half = (double)(1ull << (s->depth - 1u));
        const float got_min[3] = {st.bbox_min.x, st.bbox_min.y, st.bbox_min.z};
        const float got_max[3] = {st.bbox_max.x, st.bbox_max.y, st.bbox_max.z};
        for (unsigned a = 0; a < 3; a++) {
            const double wmin = ((double)want.kmin[a] - half) * res;
            const double wmax = ((double)want.kmax[a] + 1.0 - half) * res;
            const double tol = 1e-6 * (fabs(wmin) + fabs(wmax)) + 1e-3 * res;
            if (!near((double)got_min[a], wmin, tol) || !near((double)got_max[a], wmax, tol)) {
                snprintf(msg, sizeof msg, "bbox axis %u: [%g, %g] want [%g, %g]", a,
                         (double)got_min[a], (double)got_max[a], wmin, wmax);
                report(&bad, what, msg);
            }
        }
    }
    if (st.inner_used != map->inner.used || st.leaf_used != map->leaf.used) {
        report(&bad, what, "stats pool counters differ from the pools");
    }
    return bad;
}
