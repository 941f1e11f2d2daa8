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
 * eight equal values leave it uniform. Returns the voxels whose value changed. */
static size_t node1_split(occ_map_t *const m, const occ_nodep_t n, const unsigned mb,
                          const unsigned hb, const occ_value_t vm, const occ_value_t vh)
{
    const occ_value_t v = *n.value;
    const size_t changed = (occ_value_eq(vm, v) ? 0u : occ_popcount64(mb)) +
                           (occ_value_eq(vh, v) ? 0u : occ_popcount64(hb));
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

/* The voxels of level-1 node n named by the byte masks mb (miss) and hb (hit); returns the
 * voxels whose value changed, and sets *dirty when n's value, flags or block changed. */
static size_t node1_step(occ_map_t *const m, const occ_nodep_t n, const unsigned mb,
                         const unsigned hb, bool *const dirty)
{
    if (occ_node_child(n) == OCC_NONE) {
        const occ_value_t v = *n.value;
        const occ_value_t vm = occ_value_apply_delta(m, v, m->priv.q_miss);
        const occ_value_t vh = occ_value_apply_delta(m, v, m->priv.q_hit);
        if ((mb == 0u || occ_value_eq(vm, v)) && (hb == 0u || occ_value_eq(vh, v))) {
            return 0u;
        }
        *dirty = true;
        return node1_split(m, n, mb, hb, vm, vh);
    }
    occ_leaf_block_t *const lb = occ_leaf_at(m, occ_node_child(n));
    size_t changed = 0;
    for (unsigned all = mb | hb; all != 0u; all &= all - 1u) {
        const unsigned k = occ_first_slot(all);
        const occ_value_t v = lb->value[k];
        const occ_value_t nv =
            occ_value_apply_delta(m, v, ((hb >> k) & 1u) != 0u ? m->priv.q_hit : m->priv.q_miss);
        if (!occ_value_eq(nv, v)) {
            lb->value[k] = nv;
            occi_shared_touch(m, &lb->value[k], sizeof nv);
            changed++;
        }
    }
    if (changed > 0u && occi_tree_refresh(m, n, 1u)) {
        *dirty = true;
    }
    return changed;
}

/* One brick from path level `start`: descend to its level-2 node or a uniform node above it,
 * split that only where a value moves, update. Returns the voxels whose value changed. */
static size_t brick_step(occ_map_t *const m, path_t *const p, const occi_brick_t *const b,
                         const unsigned start)
{
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
            return 64u;
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
            changed += node1_step(m, occ_inner_node(m, blk, j), mb, hb, &dirty);
        }
    }
    if (dirty && occi_tree_refresh(m, p->node[2], 2u)) {
        p->dirty[3] = true;
    }
    return changed;
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
        out->changed += brick_step(m, &p, &b, start);
    }
    refresh_up_to(m, &p, depth);
    occi_shared_written(m);
    return OCC_OK;
}
