/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * query_internal.h - helpers shared by the query modules (query, nearest, collide, castray,
 * infogain): node geometry from keys and the state of a stored value, inline for speed.
 */
#ifndef OCC_QUERY_INTERNAL_H_INCLUDED
#define OCC_QUERY_INTERNAL_H_INCLUDED

#include <math.h>
#include <string.h>
#include "../core/tree_internal.h"

static inline uint8_t occ_q_state_bit(occ_state_t s)
{
    switch (s) {
    case OCC_STATE_OCCUPIED:
        return (uint8_t)OCC_PRED_OCCUPIED;
    case OCC_STATE_FREE:
        return (uint8_t)OCC_PRED_FREE;
    case OCC_STATE_UNKNOWN:
        return (uint8_t)OCC_PRED_UNKNOWN;
    default:
        return 0u;
    }
}

/* The OCC_NODE_HAS_* indicator bits of the states in `states` (OCC_PRED_* bits). */
static inline unsigned occ_q_has_bits(unsigned states)
{
    return ((states & OCC_PRED_FREE) != 0u ? OCC_NODE_HAS_FREE : 0u) |
           ((states & OCC_PRED_UNKNOWN) != 0u ? OCC_NODE_HAS_UNKNOWN : 0u) |
           ((states & OCC_PRED_OCCUPIED) != 0u ? OCC_NODE_HAS_OCCUPIED : 0u);
}

/* Does a node with children (indicators `flags`) contain a state in `states`? The indicators
 * say it: they are the OR of the children's, HAS_OCCUPIED included (tree invariants). */
static inline bool occ_q_contains(uint8_t flags, unsigned states)
{
    return (flags & occ_q_has_bits(states)) != 0u;
}

/* Does a node hold a state in `states`: a node without children (voxel or uniform) by its own
 * state, one with children by its indicators? */
static inline bool occ_q_node_wanted(const occ_map_t *m, occ_value_t v, uint8_t flags,
                                     bool uniform, unsigned states)
{
    return uniform ? (states & occ_q_state_bit(occ_value_state(m, v))) != 0u
                   : occ_q_contains(flags, states);
}

/* The states (OCC_PRED_*) that make a volume or a line unsafe under `policy`. */
static inline unsigned occ_q_blocking_states(occ_unknown_policy_t policy)
{
    return OCC_PRED_OCCUPIED | (policy == OCC_UNKNOWN_UNSAFE ? OCC_PRED_UNKNOWN : 0u);
}

static inline float occ_q_half(const occ_map_t *m, unsigned level)
{
    return (float)(1u << level) * 0.5f * m->cfg.resolution_m;
}

/* Little-endian targets test the 8 flag bytes of a block as one 64-bit word. */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__)
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define OCC_Q_SWAR_FLAGS 1
#endif
#endif

/* Which of the 8 entries of a stored block match `states` (OCC_PRED_* bits): bit s for slot s.
 * Inner blocks: the indicators say it (a uniform child's flags follow from its value, a mixed
 * child's are the OR of its children's: tree invariants), so one formula serves both kinds.
 * Branch-free: neighbouring states are random. */
static inline unsigned occ_q_inner_match(const occ_inner_block_t *b, unsigned states)
{
    const unsigned wf = occ_q_has_bits(states);
#if OCC_INNER_PACKED
    /* Byte j holds indicator bit j of the 8 entries: OR the wanted bytes. */
    return ((wf & 1u) != 0u ? b->flags[0] : 0u) | ((wf & 2u) != 0u ? b->flags[1] : 0u) |
           ((wf & 4u) != 0u ? b->flags[2] : 0u);
#elif defined(OCC_Q_SWAR_FLAGS)
    /* The 8 flag bytes at once: a byte with a wanted bit (wf < 0x10) gets its top bit, and the
     * multiply gathers the 8 top bits into bits 56..63. */
    uint64_t f;
    memcpy(&f, b->flags, sizeof f);
    f = ((f & ((uint64_t)wf * 0x0101010101010101ull)) + 0x7F7F7F7F7F7F7F7Full) &
        0x8080808080808080ull;
    return (unsigned)(((f >> 7) * 0x0102040810204080ull) >> 56);
#else
    unsigned pm = 0u;
    for (unsigned s = 0; s < 8u; s++) {
        pm |= (unsigned)((occ_inner_flags(b, s) & wf) != 0u) << s;
    }
    return pm;
#endif
}

static inline unsigned occ_q_leaf_match(const occ_map_t *m, const occ_leaf_block_t *b,
                                        unsigned states)
{
    const occ_value_t occ_min = m->priv.q_occ_min;
    const occ_value_t free_max = m->priv.q_free_max;
    unsigned occ = 0u;
    unsigned fr = 0u;
    for (unsigned s = 0; s < 8u; s++) {
        const occ_value_t v = b->value[s];
        occ |= (unsigned)(v >= occ_min) << s;
        fr |= ((unsigned)(v < free_max) & (unsigned)occ_is_observed(v)) << s;
    }
    const unsigned unk = ~(occ | fr) & 0xFFu;
    return ((states & OCC_PRED_OCCUPIED) != 0u ? occ : 0u) |
           ((states & OCC_PRED_FREE) != 0u ? fr : 0u) |
           ((states & OCC_PRED_UNKNOWN) != 0u ? unk : 0u);
}

/* max(d, 0) for finite d, without a branch: compilers turn `d > 0 ? d : 0` into a jump here,
 * and the sign of a neighbour's distance is a coin toss for the predictor. */
static OCC_ALWAYS_INLINE float occ_q_pos(float d)
{
    return (d + fabsf(d)) * 0.5f;
}

/* occ_q_inner_match for a block a walk opens: its child indices are asked for at once, so that on
 * a cold map their cache line loads while the flags pick the child, instead of after (a 56-byte
 * block has its flags on another line than its child indices in 6 of 8 positions). */
static inline unsigned occ_q_open_inner(const occ_map_t *m, uint32_t block, unsigned states)
{
    const occ_inner_block_t *const b = occ_inner_at(m, block);
    OCC_PREFETCH(&b->child[0]);
    OCC_PREFETCH(&b->child[sizeof b->child / sizeof b->child[0] - 1u]);
    return occ_q_inner_match(b, states);
}

/* volume.c: key range [lo, hi] per axis of the voxels that can touch the volume's closed bounds
 * (one voxel of slack for faces on a border); false when the bounds miss the map. */
bool occi_q_bounds_keys(const occ_map_t *m, const occ_volume_t *v, uint32_t lo[3], uint32_t hi[3]);
/* volume.c: which of the 8 children (at `level`) of the node with first voxel `pkey` touch a
 * sphere / a box volume: all 8 at once in closed form. */
unsigned occi_q_touch_mask_sphere(const occ_map_t *m, const occ_volume_t *v, occ_key_t pkey,
                                  unsigned level);
unsigned occi_q_touch_mask_aabb(const occ_map_t *m, const occ_volume_t *v, occ_key_t pkey,
                                unsigned level);
/* volume.c: the same for the other kinds, child by child (those in `want` only) with the exact
 * cube tests. */
unsigned occi_q_touch_mask_cubes(const occ_map_t *m, const occ_volume_t *v, occ_key_t pkey,
                                 unsigned level, unsigned want);

/* Which of the children in `want` (at `level`, bit s for child slot s) of the node with first
 * voxel `pkey` touch the volume (exact, as occ_volume_hits_box). The other kinds test only the
 * wanted children: their exact tests cost more than the mask that picks them. The dispatch is
 * inline and the tests out of line, so that a walk's deepest call chain holds only one of them
 * (make cross; on the host the sphere and box masks were already a call). */
static OCC_ALWAYS_INLINE unsigned occ_q_touch_mask(const occ_map_t *m, const occ_volume_t *v,
                                                   occ_key_t pkey, unsigned level, unsigned want)
{
    if (v->kind == OCC_VOL_SPHERE) {
        return want & occi_q_touch_mask_sphere(m, v, pkey, level);
    }
    if (v->kind == OCC_VOL_AABB) {
        return want & occi_q_touch_mask_aabb(m, v, pkey, level);
    }
    return occi_q_touch_mask_cubes(m, v, pkey, level, want);
}

/* The cells a walk over a volume starts from: at most 8, at the smallest level (>= min_level)
 * whose cells are as wide as the volume's key range, in Morton order. Kept as the first cell
 * and the axes the others step along (20 B, not 96: the collision walk holds it on every
 * check's call chain): cell t is one cell further on axis ax[j] when bit (na - 1 - j) of t is
 * set. n = 0 when the volume misses the map; level = depth_levels with the root as the one
 * start. */
typedef struct {
    occ_key_t first;
    uint8_t n, level, na;
    uint8_t ax[3];
} occi_q_starts_t;

/* query.c: the start cells of `vol`. */
void occi_q_starts(const occ_map_t *map, const occ_volume_t *vol, unsigned min_level,
                   occi_q_starts_t *s);

/* Start cell t < s->n. */
static inline occ_key_t occi_q_start_key(const occi_q_starts_t *s, unsigned t)
{
    occ_key_t k = s->first;
    for (unsigned j = 0; j < s->na; j++) {
        k.k[s->ax[j]] += ((t >> (s->na - 1u - j)) & 1u) << s->level;
    }
    return k;
}

/* collide.c: the answer of a collision check that has not decided yet or failed: not safe,
 * not outside, an unobserved UNKNOWN node. Every collision entry point starts with it. */
void occi_q_collision_unsafe(occ_collision_t *out);

/* Fill a reported node. */
void occi_q_fill_node(const occ_map_t *m, occ_key_t key, unsigned level, occ_value_t v,
                      uint8_t flags, bool uniform, occ_query_node_t *out);

#endif /* OCC_QUERY_INTERNAL_H_INCLUDED */
