/* SPDX-License-Identifier: BSD-3-Clause */
/* walk.c - depth-first walk over observed nodes in Morton preorder, with a fixed stack. */
#include "tree_internal.h"

void occ_walk_begin(occ_walk_t *const w, const occ_map_t *const map)
{
    w->map = map;
    w->sp = 0u;
    w->started = false;
    w->pushed = false;
    w->gen = map != NULL ? map->write_gen : 0u;
}

occ_err_t occ_walk_status(const occ_walk_t *const w)
{
    if (w == NULL || w->map == NULL) {
        return OCC_ERR_ARG;
    }
    return w->gen == w->map->write_gen ? OCC_OK : OCC_ERR_STATE;
}

/* The code of child `slot` at `level` under the node whose code is `code`: the bits of the
 * levels above stay, the slot goes in at 3 * level, everything below is cleared. */
static occ_code_t child_code(const occ_code_t code, const unsigned slot, const unsigned level)
{
    const occ_code_t above = code & ~(((occ_code_t)1 << (3u * (level + 1u))) - 1u);
    return above | ((occ_code_t)slot << (3u * level));
}

static void push(occ_walk_t *const w, const uint32_t block, const unsigned level)
{
    OCC_ASSERT(w->sp <= OCC_MAX_DEPTH && level < w->map->cfg.depth_levels);
    w->stack[w->sp].block = block;
    w->stack[w->sp].level = (uint8_t)level;
    w->stack[w->sp].next = 0u;
    w->sp++;
    w->pushed = true;
}

bool occ_walk_next(occ_walk_t *const w, occ_walk_node_t *const node)
{
    const occ_map_t *const m = w->map;
    w->pushed = false;
    if (occ_walk_status(w) != OCC_OK) {
        w->sp = 0u; /* the stacked block indices may name freed or reused blocks */
        return false;
    }
    if (!w->started) {
        w->started = true;
        if (!occ_is_observed(m->priv.root_value)) {
            return false;
        }
        const occ_key_t zero = {{0u, 0u, 0u}};
        node->key = zero;
        node->level = m->cfg.depth_levels;
        node->has_children = occ_root_child(m) != OCC_NONE;
        node->value = m->priv.root_value;
        node->observed = true;
        node->flags = (uint8_t)(occ_root_flags(m) | (node->has_children ? 0u : OCC_NODE_UNIFORM));
        w->code = 0u;
        if (node->has_children) {
            push(w, occ_root_child(m), (unsigned)m->cfg.depth_levels - 1u);
        }
        return true;
    }
    while (w->sp > 0u) {
        const unsigned top = w->sp - 1u;
        if (w->stack[top].next >= 8u) {
            w->sp--;
            continue;
        }
        const unsigned slot = w->stack[top].next++;
        const unsigned level = w->stack[top].level;
        const occ_code_t code = child_code(w->code, slot, level);
        const occ_entry_t e = occ_entry_at(m, w->stack[top].block, level, slot);
        const occ_value_t v = e.value;
        const uint32_t child = e.child;
        const uint8_t flags = level == 0u ? occ_value_flags(m, v) : e.flags;
        if (!occ_is_observed(v)) {
            continue; /* nothing observed below */
        }
        w->code = code;
        node->key = occ_morton_decode(code);
        node->level = (uint8_t)level;
        node->has_children = child != OCC_NONE;
        node->value = v;
        node->observed = true;
        node->flags = (uint8_t)(flags | (child == OCC_NONE ? OCC_NODE_UNIFORM : 0u));
        if (child != OCC_NONE) {
            push(w, child, level - 1u);
        }
        return true;
    }
    return false;
}

void occ_walk_skip_children(occ_walk_t *const w)
{
    if (w->pushed) {
        w->sp--;
        w->pushed = false;
    }
}
