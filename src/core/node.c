/* SPDX-License-Identifier: BSD-3-Clause */
/* node.c - top-down node handles: one block read per child, no descent from the root. */
#include "tree_internal.h"

static void fill(const occ_map_t *const m, occ_node_t *const out, const occ_value_t v,
                 const uint8_t flags, const uint32_t children)
{
    out->observed = occ_is_observed(v);
    out->logodds = occ_value_to_logodds(v);
    out->state = occ_value_state(m, v);
    out->children = children;
    out->flags = (uint8_t)(flags | (children == OCC_NONE ? OCC_NODE_UNIFORM : 0u));
}

/* The handle could be a node of this map: its level is below the root's, its child block was
 * carved (a handle of another map, or forged, otherwise). */
static bool handle_fits(const occ_map_t *const m, const occ_node_t *const parent,
                        const unsigned level)
{
    const uint32_t hwm = level == 0u ? m->leaf.hwm : m->inner.hwm;
    return parent->level <= m->cfg.depth_levels &&
           (parent->children == OCC_NONE || parent->children < hwm);
}

void occ_map_node_root(const occ_map_t *const map, occ_node_t *const out)
{
    const occ_key_t zero = {{0u, 0u, 0u}};
    out->key = zero;
    out->level = map->cfg.depth_levels;
    out->gen = map->write_gen;
    fill(map, out, map->priv.root_value, occ_root_flags(map), occ_root_child(map));
}

/* What a failed child call leaves: nothing observed, no children to follow. */
static void fill_unknown(occ_node_t *const out, const occ_key_t key, const unsigned level,
                         const uint32_t gen)
{
    out->key = key;
    out->level = (uint8_t)level;
    out->observed = false;
    out->flags = (uint8_t)(OCC_NODE_HAS_UNKNOWN | OCC_NODE_UNIFORM);
    out->state = OCC_STATE_UNKNOWN;
    out->logodds = 0.0f;
    out->children = OCC_NONE;
    out->gen = gen;
}

occ_err_t occ_map_node_child(const occ_map_t *const map, const occ_node_t *const parent,
                             const unsigned slot, occ_node_t *const out)
{
    if (map == NULL || parent == NULL || out == NULL || parent->level == 0u ||
        parent->level > map->cfg.depth_levels || slot > 7u) { /* the level is shifted by below */
        if (out != NULL) { /* unknown, and stale on purpose: nothing below it is followed */
            const occ_key_t zero = {{0u, 0u, 0u}};
            fill_unknown(out, zero, 0u, map != NULL ? map->write_gen - 1u : 0u);
        }
        return OCC_ERR_ARG;
    }
    if (parent->gen != map->write_gen) { /* its child index may name a freed or reused block */
        const occ_node_t stale = *parent; /* out may alias parent */
        fill_unknown(out, stale.key, stale.level, stale.gen);
        return OCC_ERR_STATE;
    }
    const unsigned level = parent->level - 1u;
    if (!handle_fits(map, parent, level)) { /* a caller's handle is range-checked, not asserted */
        const occ_node_t bad = *parent; /* out may alias parent */
        fill_unknown(out, bad.key, bad.level, map->write_gen - 1u);
        return OCC_ERR_ARG;
    }
    occ_key_t key = parent->key;
    key.k[0] |= (uint32_t)(slot & 1u) << level;
    key.k[1] |= (uint32_t)((slot >> 1) & 1u) << level;
    key.k[2] |= (uint32_t)((slot >> 2) & 1u) << level;
    if (parent->children == OCC_NONE) {
        const occ_node_t copy = *parent; /* out may alias parent */
        *out = copy;
        out->key = key;
        out->level = (uint8_t)level;
        return OCC_OK;
    }
    out->key = key;
    out->level = (uint8_t)level;
    out->gen = parent->gen;
    const occ_entry_t e = occ_entry_at(map, parent->children, level, slot);
    fill(map, out, e.value, level == 0u ? occ_value_flags(map, e.value) : e.flags, e.child);
    return OCC_OK;
}
