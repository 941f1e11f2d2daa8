/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * tree_dense.c - a scan's voxel updates straight from the integrator's dense set, one 4x4x4
 * brick (a level-2 node) at a time in Morton order: the path is descended once per brick, a
 * level-1 node once per 8 voxels, and a uniform node that every voxel below updates alike (a
 * free brick or byte of a fresh or uniform region) takes the update as a whole, where the
 * voxel batch expanded it and pruned it back. Same tree, values and counts as that batch
 * (occ_map_observe_codes on the set's codes): the voxels end with the same values, and a
 * refreshed tree is the one pruned tree of its voxels.
 */
#include "tree_path.h"
#if defined(__SSE2__) && !OCC_VALUE_FLOAT && OCC_VALUE_BITS == 16
#include <emmintrin.h>
#endif

/* A uniform node takes `delta` on all its voxels: it stays uniform. */
static void set_uniform(occ_map_t *const m, const occ_nodep_t n, const occ_value_t v)
{
    *n.value = v;
    occ_node_set_flags(n, occ_value_flags(m, v));
    occ_touch_node(m, n);
}

/* A uniform level-1 node n (value v) whose voxels mb take the miss (vm) and hb the hit (vh),
 * some of them changing: its leaf block is written once with the three values, and the node's
 * summary follows from the values present (what expanding, updating and refreshing it gives);
 * eight equal values leave it uniform. Returns the voxels of cb whose value changed. */
static size_t node1_split(occ_map_t *const m, const occ_nodep_t n, const unsigned mb,
                          const unsigned hb, const unsigned cb, const occ_value_t vm,
                          const occ_value_t vh)
{
    const occ_value_t v = *n.value;
    const size_t changed = (occ_value_eq(vm, v) ? 0u : occ_popcount8(mb & cb)) +
                           (occ_value_eq(vh, v) ? 0u : occ_popcount8(hb & cb));
    /* the values present: untouched (pu), missed (pm), hit (ph) */
    const bool pu = (mb | hb) != 0xFFu, pm = mb != 0u, ph = hb != 0u;
    const bool same = (!pu || occ_value_eq(v, ph ? vh : vm)) && (!pm || !ph || occ_value_eq(vm, vh));
    if (same) {
        set_uniform(m, n, ph ? vh : vm);
        return changed;
    }
    occ_value_t mx = pu ? v : vm; /* not uniform: two values present at least */
    mx = pm && vm > mx ? vm : mx;
    mx = ph && vh > mx ? vh : mx;
    const uint8_t f = (uint8_t)((pu ? occ_value_flags(m, v) : 0u) |
                                (pm ? occ_value_flags(m, vm) : 0u) |
                                (ph ? occ_value_flags(m, vh) : 0u));
    const uint32_t idx = occi_pool_alloc_leaf(m);
    OCC_ASSERT(idx != OCC_NONE);
    occ_leaf_block_t *const lb = occ_leaf_at(m, idx);
    for (unsigned k = 0; k < 8u; k++) {
        const occ_value_t vk = ((mb >> k) & 1u) != 0u ? vm : v;
        lb->value[k] = ((hb >> k) & 1u) != 0u ? vh : vk;
    }
    occ_node_set_child(n, idx);
    *n.value = mx;
    occ_node_set_flags(n, f);
    occ_touch_node(m, n);
    return changed;
}

/* The values of leaf block lb with the miss on the voxels of mb and the hit on those of hb
 * (disjoint), occ_value_apply_delta per voxel; returns the voxels whose value moved (each
 * write marked for a shared map). With SSE2 and 16-bit values the eight lanes are one register,
 * updated without a branch (a saturating add then the clamp: the values of the 32-bit sum
 * clamped); elsewhere (firmware) a loop over the named voxels only. */
#if defined(__SSE2__) && !OCC_VALUE_FLOAT && OCC_VALUE_BITS == 16
static OCC_ALWAYS_INLINE __m128i lanes_of(const unsigned bits)
{
    const __m128i lane = _mm_set_epi16(128, 64, 32, 16, 8, 4, 2, 1);
    return _mm_cmpeq_epi16(_mm_and_si128(_mm_set1_epi16((short)bits), lane), lane);
}

static OCC_ALWAYS_INLINE __m128i select16(const __m128i mask, const __m128i a, const __m128i b)
{
    return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
}

static OCC_ALWAYS_INLINE unsigned leaf_update(occ_map_t *const m, occ_leaf_block_t *const lb,
                                              const unsigned mb, const unsigned hb)
{
    const __m128i vv = _mm_loadu_si128((const __m128i *)(const void *)lb->value);
    const __m128i cmin = _mm_set1_epi16(m->priv.q_clamp_min);
    const __m128i cmax = _mm_set1_epi16(m->priv.q_clamp_max);
    const __m128i d = select16(lanes_of(hb), _mm_set1_epi16(m->priv.q_hit),
                               _mm_set1_epi16(m->priv.q_miss));
    const __m128i observed = _mm_cmpgt_epi16(vv, _mm_set1_epi16(OCC_VALUE_UNOBSERVED));
    const __m128i up = _mm_andnot_si128(_mm_cmpgt_epi16(_mm_setzero_si128(), d),
                                        _mm_cmpgt_epi16(vv, _mm_subs_epi16(cmax, _mm_set1_epi16(1))));
    const __m128i down = _mm_andnot_si128(_mm_cmpgt_epi16(d, _mm_setzero_si128()),
                                          _mm_cmpgt_epi16(_mm_adds_epi16(cmin, _mm_set1_epi16(1)), vv));
    const __m128i keep = _mm_and_si128(observed, _mm_or_si128(up, down)); /* at a bound already */
    const __m128i sum = _mm_adds_epi16(_mm_and_si128(observed, vv), d);
    const __m128i moved_to = _mm_min_epi16(_mm_max_epi16(sum, cmin), cmax);
    const __m128i r = select16(_mm_andnot_si128(keep, lanes_of(mb | hb)), moved_to, vv);
    const __m128i same = _mm_cmpeq_epi16(r, vv);
    const unsigned moved = ~(unsigned)_mm_movemask_epi8(_mm_packs_epi16(same, same)) & 0xFFu;
    if (moved != 0u) {
        _mm_storeu_si128((__m128i *)(void *)lb->value, r);
        occi_shared_touch(m, lb, sizeof *lb);
    }
    return moved;
}
#else
static OCC_ALWAYS_INLINE unsigned leaf_update(occ_map_t *const m, occ_leaf_block_t *const lb,
                                              const unsigned mb, const unsigned hb)
{
    unsigned moved = 0;
    for (unsigned all = mb | hb; all != 0u; all &= all - 1u) {
        const unsigned k = occ_first_slot(all);
        const occ_value_t v = lb->value[k];
        const occ_value_t nv =
            occ_value_apply_delta(m, v, ((hb >> k) & 1u) != 0u ? m->priv.q_hit : m->priv.q_miss);
        if (!occ_value_eq(nv, v)) {
            lb->value[k] = nv;
            occi_shared_touch(m, &lb->value[k], sizeof nv);
            moved |= 1u << k;
        }
    }
    return moved;
}
#endif

/* The voxels of level-1 node n named by the byte masks mb (miss) and hb (hit); returns the
 * voxels of cb whose value changed, and sets *dirty when n's value, flags or block changed. */
static OCC_ALWAYS_INLINE size_t node1_step(occ_map_t *const m, const occ_nodep_t n, const unsigned mb,
                         const unsigned hb, const unsigned cb, bool *const dirty)
{
    if (occ_node_child(n) == OCC_NONE) {
        const occ_value_t v = *n.value;
        const occ_value_t vm = occ_value_apply_delta(m, v, m->priv.q_miss);
        const occ_value_t vh = occ_value_apply_delta(m, v, m->priv.q_hit);
        if ((mb == 0u || occ_value_eq(vm, v)) && (hb == 0u || occ_value_eq(vh, v))) {
            return 0u;
        }
        *dirty = true;
        return node1_split(m, n, mb, hb, cb, vm, vh);
    }
    const unsigned moved = leaf_update(m, occ_leaf_at(m, occ_node_child(n)), mb, hb);
    const size_t changed = occ_popcount8(moved & cb);
    if (moved != 0u && occi_tree_refresh(m, n, 1u)) {
        *dirty = true;
    }
    return changed;
}

/* occi_tree_brick_step, inline: the update by bricks counts every voxel (count all ones, which
 * the compiler folds away on that path). */
static OCC_ALWAYS_INLINE size_t brick_update(occ_map_t *const m, path_t *const p,
                                             const occi_brick_t *const b, const unsigned start,
                                             const uint64_t count)
{
    if (m->cfg.depth_levels < 2u) { /* the root is the one level-1 node: the brick's first byte */
        OCC_ASSERT(b->code == 0u && ((b->miss | b->hit) >> 8) == 0u);
        bool dirty = false;
        p->low = 1u;
        return node1_step(m, p->node[1], (unsigned)b->miss, (unsigned)b->hit,
                          (unsigned)count & 0xFFu, &dirty);
    }
    unsigned l = start;
    while (l > 2u && occ_node_child(p->node[l]) != OCC_NONE) {
        p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(b->code, l));
        l--;
    }
    p->low = l;
    if (occ_node_child(p->node[l]) == OCC_NONE) {
        const occ_value_t v = *p->node[l].value;
        const occ_value_t vm = occ_value_apply_delta(m, v, m->priv.q_miss);
        const bool cm = b->miss != 0u && !occ_value_eq(vm, v);
        if (!cm && (b->hit == 0u || occ_value_eq(occ_value_apply_delta(m, v, m->priv.q_hit), v))) {
            return 0u;
        }
        for (; l > 2u; l--) {
            occi_tree_expand(m, p->node[l], l);
            p->node[l - 1u] = occ_inner_node(m, occ_node_child(p->node[l]), occ_code_slot(b->code, l));
        }
        p->low = 2u;
        if (b->miss == ~(uint64_t)0) { /* the whole brick alike: it stays uniform */
            set_uniform(m, p->node[2], vm);
            p->dirty[3] = true;
            return occ_popcount64(count);
        }
        occi_tree_expand(m, p->node[2], 2u);
    }
    const uint32_t blk = occ_node_child(p->node[2]);
    size_t changed = 0;
    bool dirty = false;
    for (unsigned j = 0; j < 8u; j++) {
        const unsigned mb = (unsigned)(b->miss >> (8u * j)) & 0xFFu;
        const unsigned hb = (unsigned)(b->hit >> (8u * j)) & 0xFFu;
        if ((mb | hb) != 0u) {
            const unsigned cb = (unsigned)(count >> (8u * j)) & 0xFFu;
            changed += node1_step(m, occ_inner_node(m, blk, j), mb, hb, cb, &dirty);
        }
    }
    if (dirty && occi_tree_refresh(m, p->node[2], 2u)) {
        p->dirty[3] = true;
    }
    return changed;
}

size_t occi_tree_brick_step(occ_map_t *const m, path_t *const p, const occi_brick_t *const b,
                            const unsigned start, const uint64_t count)
{
    return brick_update(m, p, b, start, count);
}

occ_err_t occi_tree_apply_dense(occ_map_t *const m, const occi_dense_t *const d,
                                occi_dense_out_t *const out)
{
    out->changed = 0u;
    out->voxels = 0u;
    if (m->cfg.depth_levels < 2u) { /* no level-2 nodes below the root */
        return OCC_ERR_NOMEM;
    }
    uint64_t inner, leaf;
    occi_dense_need(d, SIZE_MAX, m->cfg.depth_levels, &inner, &leaf, &out->voxels);
    if (inner > OCC_NONE || leaf > OCC_NONE ||
        !occi_pool_can_supply(m, (uint32_t)inner, (uint32_t)leaf)) {
        return OCC_ERR_NOMEM;
    }
    path_t p;
    path_begin(m, &p);
    const unsigned depth = m->cfg.depth_levels;
    occi_dense_cursor_t c = {0u, 0u, 0u};
    occi_brick_t b;
    occ_code_t prev = 0;
    bool first = true;
    while (occi_dense_next(d, &c, &b)) {
        const unsigned start = path_start(m, &p, b.code, prev, first);
        first = false;
        prev = b.code;
        out->changed += brick_update(m, &p, &b, start, ~(uint64_t)0);
    }
    refresh_up_to(m, &p, depth);
    occi_shared_written(m);
    return OCC_OK;
}
