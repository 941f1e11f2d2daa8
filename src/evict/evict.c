/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * evict.c - making room in a fixed arena: sweeps that collapse subtrees far from the vehicle
 * (forgetting them, or coarsening them to one conservative value), in budgeted slices.
 *
 * A pass is a post-order walk over inner blocks with the stack kept in the caller's cursor.
 * Level-1 nodes are collapsed when visited; deeper nodes when their frame is popped and all
 * their children are already childless, so a big subtree is taken apart bottom-up, one block
 * per step, and the budget bounds the work of every call. Collapsing bottom-up gives the same
 * result as collapsing the top node at once: the rule (forget when the max is FREE but some
 * voxel is not) commutes with taking maxima. Parents are refreshed when their frame pops, and
 * what is still on the stack when a call ends is refreshed before returning.
 */
#include "occmap/occ_evict.h"

#include <float.h>
#include <string.h>

#include "../core/shared_internal.h"
#include "../core/tree_internal.h"

#define EVICT_SHRINK 0.75f    /* threshold factor per pass */
#define EVICT_FORGET_MARK 0xFFu /* cursor.coarse_level while forgetting */

enum { PHASE_IDLE = 0, PHASE_RESUME = 2 };

typedef struct {
    occ_map_t *m;
    occ_vec3_t c;
    const occ_evict_policy_t *p;
    occ_evict_cursor_t *cur;
    uint32_t need_inner, need_leaf;
    uint32_t budget;     /* 0: none */
    uint32_t visited;
    uint32_t evictions;
    float eps;           /* distances within eps of the protected region count as inside */
} ctx_t;

occ_evict_policy_t occ_evict_policy_default(void)
{
    occ_evict_policy_t p;
    p.mode = OCC_EVICT_ROBOT;
    p.shape = OCC_EVICT_SPHERE;
    p.keep_radius_m = 3.0f;
    p.keep_half_m.x = 3.0f;
    p.keep_half_m.y = 3.0f;
    p.keep_half_m.z = 3.0f;
    p.budget_blocks = 0u;
    p.coarse_min_level = 2u;
    p.coarse_max_level = 5u;
    return p;
}

void occ_evict_out_init(occ_evict_out_t *const out)
{
    if (out == NULL) {
        return;
    }
    const occ_evict_out_t zero = {0};
    *out = zero;
}

static bool finite_nonneg(const float x)
{
    return x - x < 1.0f && x >= 0.0f;
}

static bool policy_valid(const occ_map_t *const m, const occ_evict_policy_t *const p)
{
    if (p->mode != OCC_EVICT_ROBOT && p->mode != OCC_EVICT_COARSEN) {
        return false;
    }
    if (p->shape == OCC_EVICT_SPHERE) {
        if (!finite_nonneg(p->keep_radius_m)) {
            return false;
        }
    } else if (p->shape == OCC_EVICT_BOX) {
        if (!finite_nonneg(p->keep_half_m.x) || !finite_nonneg(p->keep_half_m.y) ||
            !finite_nonneg(p->keep_half_m.z)) {
            return false;
        }
    } else {
        return false;
    }
    if (p->mode == OCC_EVICT_COARSEN &&
        (p->coarse_min_level < 1u || p->coarse_min_level > m->cfg.depth_levels ||
         p->coarse_max_level < p->coarse_min_level)) {
        return false;
    }
    return true;
}

/* ---- geometry ---------------------------------------------------------------------------------- */

static float maxf(const float a, const float b)
{
    return a > b ? a : b;
}

static float absf(const float a)
{
    return a < 0.0f ? -a : a;
}

static float sqrt_f(const float x)
{
    if (!(x > 0.0f)) {
        return 0.0f;
    }
    /* No libm in the core: a bit-level first guess (within 4%) and three Newton steps. */
    uint32_t i;
    memcpy(&i, &x, sizeof i);
    i = 0x1FBD1DF5u + (i >> 1);
    float r;
    memcpy(&r, &i, sizeof r);
    r = 0.5f * (r + x / r);
    r = 0.5f * (r + x / r);
    r = 0.5f * (r + x / r);
    return r;
}

/* Distance of the node's cube from the protected region: nearest point (dmin) and farthest
 * corner (dmax); <= 0 means inside or touching. */
static void node_distance(const ctx_t *const x, const occ_code_t code, const unsigned level,
                          float *const dmin, float *const dmax)
{
    const occ_map_t *const m = x->m;
    const occ_key_t k = occ_morton_decode(code);
    const uint32_t size = (uint32_t)1 << level;
    const float cc[3] = {x->c.x, x->c.y, x->c.z};
    float gap[3], far[3];
    for (unsigned a = 0; a < 3u; a++) {
        const float lo = occ_geom_face1(m, k.k[a]);
        const float hi = occ_geom_face1(m, k.k[a] + size);
        gap[a] = maxf(maxf(lo - cc[a], cc[a] - hi), 0.0f);
        far[a] = maxf(absf(cc[a] - lo), absf(cc[a] - hi));
    }
    if (x->p->shape == OCC_EVICT_SPHERE) {
        const float r = x->p->keep_radius_m;
        *dmin = sqrt_f(gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2]) - r;
        *dmax = sqrt_f(far[0] * far[0] + far[1] * far[1] + far[2] * far[2]) - r;
    } else {
        const float h[3] = {x->p->keep_half_m.x, x->p->keep_half_m.y, x->p->keep_half_m.z};
        *dmin = maxf(maxf(gap[0] - h[0], gap[1] - h[1]), gap[2] - h[2]);
        *dmax = maxf(maxf(far[0] - h[0], far[1] - h[1]), far[2] - h[2]);
    }
}

/* ---- the walk ---------------------------------------------------------------------------------- */

static bool target_ok(const ctx_t *const x)
{
    return occi_pool_can_supply(x->m, x->need_inner, x->need_leaf);
}

static bool forgetting(const ctx_t *const x)
{
    return x->p->mode == OCC_EVICT_ROBOT || x->cur->coarse_level == EVICT_FORGET_MARK;
}

static bool collapsible_level(const ctx_t *const x, const unsigned level)
{
    return forgetting(x) || level <= x->cur->coarse_level;
}

static bool qualifies(const ctx_t *const x, const float dmin)
{
    return dmin > x->eps && dmin >= x->cur->threshold_m;
}

static occ_nodep_t frame_node(occ_map_t *const m, const occ_evict_cursor_t *const cur,
                              const unsigned i)
{
    if (i == 0u) {
        return occ_root(m);
    }
    return occ_inner_node(m, cur->block[i - 1u], (unsigned)cur->next[i - 1u] - 1u);
}

/* Replace the node's subtree by one value (see occ_evict.h for the rule). */
static void collapse(ctx_t *const x, const occ_nodep_t n, const unsigned level)
{
    occ_map_t *const m = x->m;
    occ_value_t v = OCC_VALUE_UNOBSERVED;
    if (!forgetting(x)) {
        v = *n.value;
        if (occ_value_state(m, v) == OCC_STATE_FREE && (occ_node_flags(n) & OCC_NODE_HAS_UNKNOWN) != 0u) {
            v = OCC_VALUE_UNOBSERVED;
        }
    }
    occi_tree_release_children(m, n, level);
    *n.value = v;
    occ_node_set_flags(n, occ_value_flags(m, v));
    occ_touch_node(m, n);
    x->evictions++;
}

static bool children_childless(const occ_map_t *const m, const uint32_t block)
{
    const occ_inner_block_t *const b = occ_inner_at(m, block);
    for (unsigned s = 0; s < 8u; s++) {
        if (occ_inner_child(b, s) != OCC_NONE) {
            return false;
        }
    }
    return true;
}

static void push(occ_evict_cursor_t *const cur, const uint32_t block, const occ_code_t base)
{
    OCC_ASSERT(cur->sp <= OCC_MAX_DEPTH);
    const unsigned i = cur->sp++;
    cur->block[i] = block;
    cur->next[i] = 0u;
    cur->dirty[i] = 0u;
    cur->base[i] = base;
}

/* Put the root's frame on the stack. False when the tree has nothing to walk. */
static bool begin_pass(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    cur->sp = 0u;
    if (occ_root_child(x->m) == OCC_NONE) {
        return false;
    }
    push(cur, occ_root_child(x->m), 0u);
    return true;
}

static void begin_sweep(ctx_t *const x, const unsigned coarse_level)
{
    occ_evict_cursor_t *const cur = x->cur;
    float dmin, dmax;
    cur->coarse_level = (uint8_t)coarse_level;
    node_distance(x, 0u, x->m->cfg.depth_levels, &dmin, &dmax);
    cur->threshold_m = maxf(dmax, 0.0f);
}

/* Rebuild the stack down to the node after which the last call stopped. */
static void resume(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    const unsigned depth = x->m->cfg.depth_levels;
    const occ_code_t code = cur->resume_code;
    const unsigned target = cur->resume_level;
    if (!begin_pass(x)) {
        return;
    }
    for (;;) {
        const unsigned top = cur->sp - 1u;
        const unsigned lvl = depth - top;
        const unsigned slot = occ_code_slot(code, lvl);
        if (lvl - 1u <= target) {
            cur->next[top] = (uint8_t)slot;
            return;
        }
        cur->next[top] = (uint8_t)(slot + 1u);
        const uint32_t child = occ_inner_child(occ_inner_at(x->m, cur->block[top]), slot);
        if (child == OCC_NONE) {
            return;
        }
        push(cur, child, cur->base[top] | ((occ_code_t)slot << (3u * (lvl - 1u))));
    }
}

/* Pop the top frame: refresh its node, collapse it if it qualifies. */
static void pop(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    occ_map_t *const m = x->m;
    const unsigned top = cur->sp - 1u;
    const unsigned lvl = m->cfg.depth_levels - top;
    const occ_nodep_t n = frame_node(m, cur, top);
    bool changed = false;
    if (cur->dirty[top] != 0u) {
        changed = occi_tree_refresh(m, n, lvl);
    }
    if (occ_node_child(n) != OCC_NONE && collapsible_level(x, lvl)) {
        float dmin, dmax;
        node_distance(x, cur->base[top], lvl, &dmin, &dmax);
        if (qualifies(x, dmin) && children_childless(m, occ_node_child(n))) {
            collapse(x, n, lvl);
            changed = true;
        } else if (dmax > x->eps) {
            /* Still holds a block a later pass may take (e.g. all its children are uniform). */
            cur->farthest_m = maxf(cur->farthest_m, dmax);
        }
    }
    if (changed && top > 0u) {
        cur->dirty[top - 1u] = 1u;
    }
    cur->sp--;
}

/* Refresh what is left on the stack so the map is consistent between calls. */
static void settle(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    occ_map_t *const m = x->m;
    while (cur->sp > 0u) {
        const unsigned top = cur->sp - 1u;
        if (cur->dirty[top] != 0u) {
            const occ_nodep_t n = frame_node(m, cur, top);
            if (occi_tree_refresh(m, n, m->cfg.depth_levels - top) && top > 0u) {
                cur->dirty[top - 1u] = 1u;
            }
        }
        cur->sp--;
    }
}

typedef enum { RUN_TARGET, RUN_BUDGET, RUN_EXHAUSTED } run_end_t;

/* A pass finished: pick the next threshold, level or end. True when there is more to do. */
static bool next_pass(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    const float floor_m = x->m->cfg.resolution_m;
    if (cur->threshold_m > 0.0f && cur->farthest_m > 0.0f) {
        float t = EVICT_SHRINK * (cur->farthest_m < cur->threshold_m ? cur->farthest_m
                                                                      : cur->threshold_m);
        if (t < floor_m) {
            t = 0.0f;
        }
        cur->threshold_m = t;
        return true;
    }
    /* The sweep at this level is done: go one level coarser, or forget, or stop. */
    if (forgetting(x)) {
        return false;
    }
    const unsigned top_level = x->p->coarse_max_level < x->m->cfg.depth_levels
                                   ? x->p->coarse_max_level
                                   : x->m->cfg.depth_levels;
    begin_sweep(x, cur->coarse_level < top_level ? cur->coarse_level + 1u : EVICT_FORGET_MARK);
    return true;
}

/* COARSEN's collapse level is sticky: a fresh sweep starts where the last one was, so levels
 * already exhausted are not swept again on every call. */
static unsigned first_level(const ctx_t *const x)
{
    const unsigned last = x->cur->coarse_level;
    if (x->p->mode != OCC_EVICT_COARSEN) {
        return EVICT_FORGET_MARK;
    }
    if (last == EVICT_FORGET_MARK ||
        (last >= x->p->coarse_min_level && last <= x->p->coarse_max_level &&
         last <= x->m->cfg.depth_levels)) {
        return last;
    }
    return x->p->coarse_min_level;
}

static run_end_t run(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    occ_map_t *const m = x->m;
    const unsigned depth = m->cfg.depth_levels;
    for (;;) {
        if (target_ok(x)) {
            return RUN_TARGET;
        }
        if (cur->sp == 0u) {
            if (!next_pass(x)) {
                return RUN_EXHAUSTED;
            }
            cur->farthest_m = 0.0f;
            (void)begin_pass(x);
            continue;
        }
        const unsigned top = cur->sp - 1u;
        const unsigned lvl = depth - top; /* level of the frame's node; children at lvl - 1 */
        if (cur->next[top] >= 8u) {
            pop(x);
            continue;
        }
        if (x->budget != 0u && x->visited >= x->budget) {
            return RUN_BUDGET;
        }
        const unsigned slot = cur->next[top]++;
        const unsigned lc = lvl - 1u;
        const occ_nodep_t cn = occ_inner_node(m, cur->block[top], slot);
        if (occ_node_child(cn) == OCC_NONE) {
            continue; /* uniform: holds no block */
        }
        const occ_code_t code = cur->base[top] | ((occ_code_t)slot << (3u * lc));
        float dmin, dmax;
        node_distance(x, code, lc, &dmin, &dmax);
        if (dmax <= x->eps) {
            continue; /* entirely protected */
        }
        if (dmax < cur->threshold_m) {
            cur->farthest_m = maxf(cur->farthest_m, dmax);
            continue; /* entirely nearer than this pass evicts */
        }
        if (lc == 1u) {
            if (qualifies(x, dmin) && collapsible_level(x, 1u)) {
                x->visited++;
                collapse(x, cn, 1u);
                cur->dirty[top] = 1u;
            } else {
                cur->farthest_m = maxf(cur->farthest_m, dmax);
            }
            continue;
        }
        x->visited++;
        if (!forgetting(x) && lc == cur->coarse_level + 1u && children_childless(m, occ_node_child(cn))) {
            continue; /* already coarse at this level: nothing below to collapse */
        }
        push(cur, occ_node_child(cn), code);
    }
}

/* Remember where the walk stands as a Morton code and level (blocks may move between calls).
 * False when the sweep is over (nothing more to evict at its last level). */
static bool capture(ctx_t *const x)
{
    occ_evict_cursor_t *const cur = x->cur;
    const unsigned depth = x->m->cfg.depth_levels;
    while (cur->sp > 0u && cur->next[cur->sp - 1u] >= 8u) {
        pop(x);
    }
    if (cur->sp == 0u) {
        if (!next_pass(x)) {
            return false;
        }
        cur->farthest_m = 0.0f;
        cur->resume_code = 0u;
        cur->resume_level = (uint8_t)(depth - 1u);
        return true;
    }
    const unsigned top = cur->sp - 1u;
    const unsigned lvl = depth - top;
    cur->resume_code = cur->base[top] | ((occ_code_t)cur->next[top] << (3u * (lvl - 1u)));
    cur->resume_level = (uint8_t)(lvl - 1u);
    return true;
}

static void ctx_init(ctx_t *const x, occ_map_t *const map, const occ_vec3_t *const center,
                     const occ_evict_policy_t *const policy, const uint32_t n_inner,
                     const uint32_t n_leaf, const uint32_t budget, occ_evict_out_t *const out)
{
    x->m = map;
    x->c = *center;
    x->p = policy;
    x->cur = &out->priv;
    x->need_inner = n_inner;
    x->need_leaf = n_leaf;
    x->budget = budget;
    x->visited = 0u;
    x->evictions = 0u;
    /* Cube bounds are float: near a far-away centre their rounding is ~ulp(|centre|), so the
     * protected test gets that much margin (a node that close counts as inside). */
    const float far_c = maxf(maxf(absf(center->x), absf(center->y)), absf(center->z));
    const float reach = policy->shape == OCC_EVICT_SPHERE
                            ? policy->keep_radius_m
                            : maxf(maxf(policy->keep_half_m.x, policy->keep_half_m.y),
                                   policy->keep_half_m.z);
    x->eps = map->cfg.resolution_m * 1.0e-3f + 8.0f * FLT_EPSILON * (far_c + reach);
}

/* Evict until the target is met, the budget is spent or nothing is left: the sweep left by an
 * earlier call resumes, else a new one starts. *sweep_on says on return whether a sweep is left
 * to resume. */
static run_end_t sweep(ctx_t *const x, occ_evict_out_t *const out, bool *const sweep_on)
{
    occ_evict_cursor_t *const cur = x->cur;
    run_end_t end = RUN_EXHAUSTED;
    /* A sweep continues across calls; one that started in an earlier call may have passed over
     * content added since, so without a budget "nothing left" is only believed from a sweep run
     * entirely in this call. */
    const unsigned attempts = x->budget == 0u ? 2u : 1u;
    for (unsigned attempt = 0; attempt < attempts; attempt++) {
        if (*sweep_on) {
            resume(x);
        } else {
            begin_sweep(x, first_level(x));
            cur->farthest_m = 0.0f;
            (void)begin_pass(x);
            cur->depth = x->m->cfg.depth_levels;
            out->sweeps++;
        }
        end = run(x);
        if (end != RUN_EXHAUSTED || !*sweep_on) {
            break;
        }
        *sweep_on = false;
    }
    /* Reaching the target ends the sweep: the next call starts over from the far end (farthest
     * first again, around the centre it is given). */
    *sweep_on = end == RUN_BUDGET && capture(x);
    settle(x);
    return end;
}

/* This call's outcome and the running totals into *out. */
static void report(const ctx_t *const x, const run_end_t end, const bool sweep_on,
                   const uint32_t inner_before, const uint32_t leaf_before,
                   occ_evict_out_t *const out)
{
    const occ_map_t *const map = x->m;
    const uint32_t freed_inner = inner_before - map->inner.used;
    const uint32_t freed_leaf = leaf_before - map->leaf.used;
    out->calls++;
    out->last_evictions = x->evictions;
    out->last_blocks_freed = freed_inner + freed_leaf;
    out->last_visited = x->visited;
    out->evictions += x->evictions;
    out->blocks_freed += (uint64_t)freed_inner + freed_leaf;
    out->bytes_freed += (uint64_t)freed_inner * OCC_INNER_BLOCK_BYTES +
                        (uint64_t)freed_leaf * OCC_LEAF_BLOCK_BYTES;
    out->target_reached = target_ok(x);
    out->exhausted = end == RUN_EXHAUSTED;
    out->resumable = end == RUN_BUDGET;
    out->sweep_active = sweep_on;
    occ_map_stats_t st;
    occ_map_pool_stats(map, &st);
    out->bytes_used = st.bytes_used;
    out->bytes_peak = st.bytes_peak;
}

static occ_err_t evict(occ_map_t *const map, const occ_vec3_t *const center,
                       const occ_evict_policy_t *const policy, const uint32_t n_inner,
                       const uint32_t n_leaf, const uint32_t budget, occ_evict_out_t *const out)
{
    if (map == NULL || center == NULL || policy == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    if (!(center->x - center->x < 1.0f) || !(center->y - center->y < 1.0f) ||
        !(center->z - center->z < 1.0f) || !policy_valid(map, policy)) {
        return OCC_ERR_ARG;
    }
    ctx_t x;
    ctx_init(&x, map, center, policy, n_inner, n_leaf, budget, out);
    const uint32_t inner_before = map->inner.used, leaf_before = map->leaf.used;
    run_end_t end = RUN_TARGET;
    bool sweep_on = out->priv.phase == PHASE_RESUME && out->priv.depth == map->cfg.depth_levels;
    if (!target_ok(&x)) {
        if (map->cfg.depth_levels < 2u) {
            end = RUN_EXHAUSTED; /* the root is a level-1 node: nothing to take apart */
            sweep_on = false;
        } else {
            end = sweep(&x, out, &sweep_on);
        }
    }
    if (x.evictions != 0u) {
        map->write_gen++; /* collapses are this path's only writes: handles on the map are stale */
        occi_shared_written(map);
    }
    out->priv.phase = sweep_on ? PHASE_RESUME : PHASE_IDLE;
    report(&x, end, sweep_on, inner_before, leaf_before, out);
    return OCC_OK;
}

occ_err_t occ_map_evict(occ_map_t *const map, const occ_vec3_t *const center,
                        const occ_evict_policy_t *const policy, const uint32_t target_free_blocks,
                        occ_evict_out_t *const out)
{
    if (policy == NULL) {
        return OCC_ERR_ARG;
    }
    return evict(map, center, policy, target_free_blocks, target_free_blocks,
                 policy->budget_blocks, out);
}

occ_err_t occ_map_evict_for(occ_map_t *const map, const occ_vec3_t *const center,
                            const occ_evict_policy_t *const policy, const uint32_t n_inner,
                            const uint32_t n_leaf, occ_evict_out_t *const out)
{
    const occ_err_t e = evict(map, center, policy, n_inner, n_leaf, 0u, out);
    if (e != OCC_OK) {
        return e;
    }
    return out->target_reached ? OCC_OK : OCC_ERR_NOMEM;
}
