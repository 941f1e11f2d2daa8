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
    fill(map, out, map->root_value, map->root_flags, map->root_child);
}

occ_err_t occ_map_node_child(const occ_map_t *const map, const occ_node_t *const parent,
                             const unsigned slot, occ_node_t *const out)
{
    if (map == NULL || parent == NULL || out == NULL || parent->level == 0u || slot > 7u) {
        return OCC_ERR_ARG;
    }
    const unsigned level = parent->level - 1u;
    if (!handle_fits(map, parent, level)) {
        return OCC_ERR_ARG; /* a caller's handle is range-checked, never asserted on */
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
    const occ_entry_t e = occ_entry_at(map, parent->children, level, slot);
    fill(map, out, e.value, level == 0u ? occ_value_flags(map, e.value) : e.flags, e.child);
    return OCC_OK;
}
