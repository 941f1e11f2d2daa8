/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * tree_internal.h - the octree's storage, shared by the map modules under src/ only
 * (integrate, query, io, evict). Feeds and tools use the public header.
 *
 * A node at level >= 1 lives in an inner block (8 siblings: child block index, value, indicator
 * flags) or is the root (fields of occ_map_t). A node at level 0 (a voxel) lives in a leaf block
 * (8 sibling values). A level-1 node's child index names a leaf block, a deeper node's an inner
 * block; OCC_NONE means no children: the node is uniform (all voxels below share its value).
 * Invariants (occ_map_check): value = max of children; flags = OR of children's flags (a uniform
 * node's flags follow from its value); no child block whose 8 entries are uniform and equal.
 */
#ifndef OCC_TREE_INTERNAL_H_INCLUDED
#define OCC_TREE_INTERNAL_H_INCLUDED

#include "occmap/occmap.h"
#include "../geom/geom_internal.h"
#include "shared_internal.h"

/* The 8-bit mode packs inner blocks (35 B, byte-aligned): child s is bytes 3s..3s+2 of child,
 * little-endian, 0xFFFFFF for OCC_NONE; bit s of flags[j] is indicator bit j (1 << j) of
 * entry s. Only the accessors below know the layout. */
#if OCC_VALUE_BITS == 8
#define OCC_INNER_PACKED 1
#else
#define OCC_INNER_PACKED 0
#endif

#if OCC_INNER_PACKED
typedef struct {
    uint8_t child[24];
    occ_value_t value[8];
    uint8_t flags[3];
} occ_inner_block_t;
#else
typedef struct {
    uint32_t child[8];
    occ_value_t value[8];
    uint8_t flags[8];
} occ_inner_block_t;
#endif

typedef struct {
    occ_value_t value[8];
} occ_leaf_block_t;

/* The public block sizes (OCC_ARENA_BYTES sizes static arenas with them) are these structs'
 * sizes: a C99 static assertion, an array of size -1 when they drift apart. */
typedef char occ_inner_block_bytes_match[sizeof(occ_inner_block_t) == OCC_INNER_BLOCK_BYTES ? 1 : -1];
typedef char occ_leaf_block_bytes_match[sizeof(occ_leaf_block_t) == OCC_LEAF_BLOCK_BYTES ? 1 : -1];

/* The unobserved value: below every value a voxel can hold. */
#if OCC_VALUE_FLOAT
#define OCC_VALUE_UNOBSERVED (-3.0e38f)
#define OCC_VALUE_MIN (-1.0e30f)
#define OCC_VALUE_MAX (1.0e30f)
#elif OCC_VALUE_BITS == 8
#define OCC_VALUE_UNOBSERVED INT8_MIN
#define OCC_VALUE_MIN (INT8_MIN + 1)
#define OCC_VALUE_MAX INT8_MAX
#else
#define OCC_VALUE_UNOBSERVED INT16_MIN
#define OCC_VALUE_MIN (INT16_MIN + 1)
#define OCC_VALUE_MAX INT16_MAX
#endif
#if OCC_INNER_PACKED
/* The compact mode's blocks really shrink: 8 x (child 3 + value 1) + 3 flag bytes, 8 x value 1. */
typedef char occ_inner_block_is_35[sizeof(occ_inner_block_t) == 35u ? 1 : -1];
typedef char occ_leaf_block_is_8[sizeof(occ_leaf_block_t) == 8u ? 1 : -1];
#endif

/* Pointers to one node's fields, wherever it lives (packed: flags points at the 3 flag bytes
 * and bit is 1 << slot). Read and write them through occ_node_*() only. */
#if OCC_INNER_PACKED
typedef struct {
    uint8_t *child;
    occ_value_t *value;
    uint8_t *flags;
    unsigned bit;
} occ_nodep_t;
#define OCC_CHILD_BYTES 3u
#define OCC_FLAG_BYTES 3u
/* The arena bytes a map uses at most: no pool can then pass OCC_POOL_MAX_BLOCKS (the leaf
 * block is the smaller one). */
#define OCC_ARENA_CAP_BYTES ((size_t)OCC_POOL_MAX_BLOCKS * OCC_LEAF_BLOCK_BYTES)
#else
typedef struct {
    uint32_t *child;
    occ_value_t *value;
    uint8_t *flags;
} occ_nodep_t;
#define OCC_CHILD_BYTES sizeof(uint32_t)
#define OCC_FLAG_BYTES 1u
#endif

/* ---- Field accessors: in the 16-bit and float modes plain array and pointer accesses. ---- */
#if OCC_INNER_PACKED
static inline uint32_t occ_child_load(const uint8_t *const p)
{
    const uint32_t c = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16;
    return c == 0xFFFFFFu ? OCC_NONE : c;
}

static inline void occ_child_store(uint8_t *const p, const uint32_t c)
{
    OCC_ASSERT(c == OCC_NONE || c < 0xFFFFFFu); /* pools hold < 2^24 blocks (map.c) */
    p[0] = (uint8_t)c;
    p[1] = (uint8_t)(c >> 8);
    p[2] = (uint8_t)(c >> 16);
}

static inline uint8_t occ_flags_load(const uint8_t *const p, const unsigned bit)
{
    return (uint8_t)(((p[0] & bit) != 0u ? 1u : 0u) | ((p[1] & bit) != 0u ? 2u : 0u) |
                     ((p[2] & bit) != 0u ? 4u : 0u));
}

static inline void occ_flags_store(uint8_t *const p, const unsigned bit, const uint8_t f)
{
    OCC_ASSERT(f <= 7u);
    for (unsigned j = 0; j < 3u; j++) {
        p[j] = (uint8_t)((p[j] & ~bit) | (((f >> j) & 1u) != 0u ? bit : 0u));
    }
}

static inline uint32_t occ_inner_child(const occ_inner_block_t *const b, const unsigned s)
{
    return occ_child_load(&b->child[3u * s]);
}

static inline void occ_inner_set_child(occ_inner_block_t *const b, const unsigned s,
                                       const uint32_t c)
{
    occ_child_store(&b->child[3u * s], c);
}

static inline uint8_t occ_inner_flags(const occ_inner_block_t *const b, const unsigned s)
{
    return occ_flags_load(b->flags, 1u << s);
}

static inline void occ_inner_set_flags(occ_inner_block_t *const b, const unsigned s,
                                       const uint8_t f)
{
    occ_flags_store(b->flags, 1u << s, f);
}

static inline uint32_t occ_node_child(const occ_nodep_t n)
{
    return occ_child_load(n.child);
}

static inline void occ_node_set_child(const occ_nodep_t n, const uint32_t c)
{
    occ_child_store(n.child, c);
}

static inline uint8_t occ_node_flags(const occ_nodep_t n)
{
    return occ_flags_load(n.flags, n.bit);
}

static inline void occ_node_set_flags(const occ_nodep_t n, const uint8_t f)
{
    occ_flags_store(n.flags, n.bit, f);
}

static inline uint32_t occ_root_child(const occ_map_t *const m)
{
    return occ_child_load(m->priv.root_child);
}

static inline uint8_t occ_root_flags(const occ_map_t *const m)
{
    return occ_flags_load(m->priv.root_flags, 1u);
}

static inline void occ_root_set_child(occ_map_t *const m, const uint32_t c)
{
    occ_child_store(m->priv.root_child, c);
}

static inline void occ_root_set_flags(occ_map_t *const m, const uint8_t f)
{
    occ_flags_store(m->priv.root_flags, 1u, f);
}

/* A free inner block has no indicator bit at all: every used entry has one (tree invariant). */
static inline bool occ_inner_is_free(const occ_inner_block_t *const b)
{
    return (b->flags[0] | b->flags[1] | b->flags[2]) == 0u;
}

static inline void occ_inner_mark_free(occ_inner_block_t *const b)
{
    b->flags[0] = b->flags[1] = b->flags[2] = 0u;
}

static inline void occ_inner_mark_used(occ_inner_block_t *const b)
{
    b->flags[1] = 0xFFu; /* every entry "has unknown" until the caller fills the block */
}

/* Whole-block forms for refresh and expand: a byte test or store per flag bit instead of eight
 * unpackings (the 8-bit mode's updates were ~50% slower without them). */
static inline uint8_t occ_inner_flags_or(const occ_inner_block_t *const b)
{
    return (uint8_t)((b->flags[0] != 0u ? 1u : 0u) | (b->flags[1] != 0u ? 2u : 0u) |
                     (b->flags[2] != 0u ? 4u : 0u));
}

static inline bool occ_inner_childless(const occ_inner_block_t *const b)
{
    unsigned all = 0xFFu;
    for (unsigned i = 0; i < sizeof b->child; i++) {
        all &= b->child[i];
    }
    return all == 0xFFu; /* only OCC_NONE is stored as 0xFFFFFF */
}

/* Eight uniform entries of value v and flags f, without children. */
static inline void occ_inner_fill(occ_inner_block_t *const b, const occ_value_t v, const uint8_t f)
{
    OCC_ASSERT(f <= 7u);
    for (unsigned i = 0; i < sizeof b->child; i++) {
        b->child[i] = 0xFFu;
    }
    for (unsigned i = 0; i < 8u; i++) {
        b->value[i] = v;
    }
    for (unsigned j = 0; j < 3u; j++) {
        b->flags[j] = ((f >> j) & 1u) != 0u ? 0xFFu : 0u;
    }
}
#else
static inline uint32_t occ_inner_child(const occ_inner_block_t *const b, const unsigned s)
{
    return b->child[s];
}

static inline void occ_inner_set_child(occ_inner_block_t *const b, const unsigned s,
                                       const uint32_t c)
{
    b->child[s] = c;
}

static inline uint8_t occ_inner_flags(const occ_inner_block_t *const b, const unsigned s)
{
    return b->flags[s];
}

static inline void occ_inner_set_flags(occ_inner_block_t *const b, const unsigned s,
                                       const uint8_t f)
{
    b->flags[s] = f;
}

/* Macros here: the node and root accessors expand to the plain dereferences this build was
 * written with, so its code stays the same (inline functions taking the struct by value moved
 * loads and inlining decisions in tree.c, tree_frame.c and map.c). */
#define occ_node_child(n) (*(n).child)
#define occ_node_set_child(n, c) ((void)(*(n).child = (c)))
#define occ_node_flags(n) (*(n).flags)
#define occ_node_set_flags(n, f) ((void)(*(n).flags = (f)))

#define occ_root_child(m) ((m)->priv.root_child)
#define occ_root_flags(m) ((m)->priv.root_flags)
#define occ_root_set_child(m, c) ((void)((m)->priv.root_child = (c)))
#define occ_root_set_flags(m, f) ((void)((m)->priv.root_flags = (f)))

/* Marker in flags[7] of an inner block on the free list (used blocks only use bits 0..2). */
#define OCC_INNER_FREE_MARK 0xA5u

static inline bool occ_inner_is_free(const occ_inner_block_t *const b)
{
    return b->flags[7] == OCC_INNER_FREE_MARK;
}

static inline void occ_inner_mark_free(occ_inner_block_t *const b)
{
    b->flags[7] = OCC_INNER_FREE_MARK;
}

static inline void occ_inner_mark_used(occ_inner_block_t *const b)
{
    b->flags[7] = 0u;
}

/* Eight uniform entries of value v and flags f, without children. */
static inline void occ_inner_fill(occ_inner_block_t *const b, const occ_value_t v, const uint8_t f)
{
    for (unsigned i = 0; i < 8u; i++) {
        b->child[i] = OCC_NONE;
        b->value[i] = v;
        b->flags[i] = f;
    }
}
#endif

/* A shared map's snapshots need every block write (occ_shared.h): a node's three fields sit in
 * three arrays of its block, so each is marked. Nothing but a NULL test when not shared. */
static inline void occ_touch_child(occ_map_t *const m, const occ_nodep_t n)
{
    occi_shared_touch(m, n.child, OCC_CHILD_BYTES);
}

static inline void occ_touch_node(occ_map_t *const m, const occ_nodep_t n)
{
    occi_shared_touch(m, n.child, OCC_CHILD_BYTES);
    occi_shared_touch(m, n.value, sizeof *n.value);
    occi_shared_touch(m, n.flags, OCC_FLAG_BYTES);
}

/* A hint that a cache line will be read soon; nothing where the compiler has no such hint. */
#if defined(__GNUC__)
#define OCC_PREFETCH(addr) __builtin_prefetch(addr)
#else
#define OCC_PREFETCH(addr) ((void)(addr))
#endif

/* `make lint` runs gcc -fanalyzer, which cannot follow an invariant kept across calls or loop
 * iterations. A function it misreads says why next to these and is wrapped in them (nothing
 * outside gcc >= 10, which alone knows the option). */
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 10
#define OCC_ANALYZER_UNINIT_OFF                                                                  \
    _Pragma("GCC diagnostic push")                                                               \
    _Pragma("GCC diagnostic ignored \"-Wanalyzer-use-of-uninitialized-value\"")
#define OCC_ANALYZER_UNINIT_ON _Pragma("GCC diagnostic pop")
#else
#define OCC_ANALYZER_UNINIT_OFF
#define OCC_ANALYZER_UNINIT_ON
#endif

/* Block accessors. Every dereference of a block goes through them (or asserts the same itself):
 * the index names a block carved from the arena (below the pool's high-water mark). */
static inline occ_inner_block_t *occ_inner_at(const occ_map_t *m, uint32_t idx)
{
    OCC_ASSERT(idx < m->inner.hwm);
    return (occ_inner_block_t *)(void *)(m->priv.arena + m->arena_bytes -
                                         ((size_t)idx + 1u) * sizeof(occ_inner_block_t));
}

static inline occ_leaf_block_t *occ_leaf_at(const occ_map_t *m, uint32_t idx)
{
    OCC_ASSERT(idx < m->leaf.hwm);
    return (occ_leaf_block_t *)(void *)(m->priv.arena + (size_t)idx * sizeof(occ_leaf_block_t));
}

/* Where block 0 of each pool is (carved or not), for walks that index from a base pointer:
 * they assert the index against the high-water mark themselves. */
static inline const occ_inner_block_t *occ_inner_base(const occ_map_t *m)
{
    return (const occ_inner_block_t *)(const void *)(m->priv.arena + m->arena_bytes -
                                                     sizeof(occ_inner_block_t));
}

static inline const occ_leaf_block_t *occ_leaf_base(const occ_map_t *m)
{
    return (const occ_leaf_block_t *)(const void *)m->priv.arena;
}

static inline occ_nodep_t occ_root(occ_map_t *m)
{
    occ_nodep_t n;
#if OCC_INNER_PACKED
    n.child = m->priv.root_child;
    n.value = &m->priv.root_value;
    n.flags = m->priv.root_flags;
    n.bit = 1u;
#else
    n.child = &m->priv.root_child;
    n.value = &m->priv.root_value;
    n.flags = &m->priv.root_flags;
#endif
    return n;
}

static inline occ_nodep_t occ_inner_node(const occ_map_t *m, uint32_t block, unsigned slot)
{
    OCC_ASSERT(slot < 8u);
    occ_inner_block_t *const b = occ_inner_at(m, block);
    occ_nodep_t n;
#if OCC_INNER_PACKED
    n.child = &b->child[3u * slot];
    n.value = &b->value[slot];
    n.flags = b->flags;
    n.bit = 1u << slot;
#else
    n.child = &b->child[slot];
    n.value = &b->value[slot];
    n.flags = &b->flags[slot];
#endif
    return n;
}

/* One axis of occ_map_key: the map's one conversion (geom_internal.h). False off the map. */
static inline bool occ_coord_to_key(const occ_map_t *m, float c, uint32_t *key)
{
    return occ_geom_key1(m, c, key);
}

static inline bool occ_is_observed(occ_value_t v)
{
    return v > OCC_VALUE_UNOBSERVED;
}

/* Entry `slot` of the block `block` whose nodes are at `level`: value, indicator flags (0 for
 * a voxel: they follow from its value) and child block (OCC_NONE for a voxel). */
typedef struct {
    occ_value_t value;
    uint8_t flags;
    uint32_t child;
} occ_entry_t;

static inline occ_entry_t occ_entry_at(const occ_map_t *m, uint32_t block, unsigned level,
                                       unsigned slot)
{
    OCC_ASSERT(level < m->cfg.depth_levels && slot < 8u); /* blocks hold levels below the root */
    occ_entry_t e;
    if (level == 0u) {
        e.value = occ_leaf_at(m, block)->value[slot];
        e.flags = 0u;
        e.child = OCC_NONE;
    } else {
        const occ_inner_block_t *const b = occ_inner_at(m, block);
        e.value = b->value[slot];
        e.flags = occ_inner_flags(b, slot);
        e.child = occ_inner_child(b, slot);
    }
    return e;
}

/* Slot (0..7) of the child at `level` - 1 that holds key `k`: bit `level` of x, y, z. */
static inline unsigned occ_key_slot(const occ_key_t *k, unsigned level)
{
    OCC_ASSERT(level < OCC_MAX_DEPTH);
    return ((k->k[0] >> level) & 1u) | (((k->k[1] >> level) & 1u) << 1) |
           (((k->k[2] >> level) & 1u) << 2);
}

/* The lowest set bit of a non-zero child mask: the next slot in Morton order. */
static inline unsigned occ_first_slot(unsigned mask)
{
#if defined(__GNUC__)
    return (unsigned)__builtin_ctz(mask);
#else
    unsigned slot = 0;
    while (((mask >> slot) & 1u) == 0u) {
        slot++;
    }
    return slot;
#endif
}

/* The lowest set bit of a non-zero 64-bit mask (two 32-bit halves: no 64-bit count on a
 * 32-bit core). */
static inline unsigned occ_first_slot64(const uint64_t mask)
{
    const unsigned lo = (unsigned)(mask & 0xFFFFFFFFu);
    return lo != 0u ? occ_first_slot(lo) : 32u + occ_first_slot((unsigned)(mask >> 32));
}

/* Bits set (SWAR: without a popcount instruction in the build, the builtin is a library call). */
static inline unsigned occ_popcount64(uint64_t x)
{
    x = x - ((x >> 1) & 0x5555555555555555ull);
    x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return (unsigned)((x * 0x0101010101010101ull) >> 56);
}

/* Bits set in a byte (SWAR in 32 bits: cheap on a 32-bit core). */
static inline unsigned occ_popcount8(unsigned x)
{
    x = x - ((x >> 1) & 0x55u);
    x = (x & 0x33u) + ((x >> 2) & 0x33u);
    return (x + (x >> 4)) & 0x0Fu;
}

/* Number of significant bits of x (0 for 0): 1 + the highest set bit. */
static inline unsigned occ_bit_length32(uint32_t x)
{
#if defined(__GNUC__)
    return x == 0u ? 0u : 32u - (unsigned)__builtin_clz(x);
#else
    unsigned n = 0;
    for (; x != 0u; x >>= 1) {
        n++;
    }
    return n;
#endif
}

/* Child slot (0..7) of voxel `code` inside its ancestor at `level` (>= 1). */
static inline unsigned occ_code_slot(occ_code_t code, unsigned level)
{
    OCC_ASSERT(level >= 1u && level <= OCC_MAX_DEPTH);
    return (unsigned)((code >> (3u * (level - 1u))) & 7u);
}

/* State and indicator flags of a single (uniform) value. Inline: they sit on the update path. */
static inline occ_state_t occ_value_state(const occ_map_t *const m, const occ_value_t v)
{
    if (!occ_is_observed(v)) {
        return OCC_STATE_UNKNOWN;
    }
    if (v >= m->priv.q_occ_min) {
        return OCC_STATE_OCCUPIED;
    }
    return v < m->priv.q_free_max ? OCC_STATE_FREE : OCC_STATE_UNKNOWN;
}

static inline uint8_t occ_value_flags(const occ_map_t *const m, const occ_value_t v)
{
    if (!occ_is_observed(v)) {
        return (uint8_t)OCC_NODE_HAS_UNKNOWN;
    }
    if (v >= m->priv.q_occ_min) {
        return (uint8_t)OCC_NODE_HAS_OCCUPIED;
    }
    return (uint8_t)(v < m->priv.q_free_max ? OCC_NODE_HAS_FREE : OCC_NODE_HAS_UNKNOWN);
}

/* occ_value_flags without branches (for loops over a block's values). */
static inline uint8_t occ_value_flags_nb(const occ_map_t *const m, const occ_value_t v)
{
    const unsigned fr = (unsigned)occ_is_observed(v) & (unsigned)(v < m->priv.q_free_max);
    const uint8_t low = fr != 0u ? (uint8_t)OCC_NODE_HAS_FREE : (uint8_t)OCC_NODE_HAS_UNKNOWN;
    return v >= m->priv.q_occ_min ? (uint8_t)OCC_NODE_HAS_OCCUPIED : low;
}

/* An update's delta. The 8-bit mode's values span +-127 steps while a delta may need to cross
 * the whole clamp range and more (-72 .. +126 is 198 steps), so its deltas are int16 (in
 * value steps, saturated to +-32767); the other modes use the value type itself. */
#if !OCC_VALUE_FLOAT && OCC_VALUE_BITS == 8
typedef int16_t occ_delta_t;
#else
typedef occ_value_t occ_delta_t;
#endif
/* A log-odds delta in value steps, rounded to nearest and saturated (NaN: the bottom). In the
 * 8-bit mode to +-INT16_MAX steps, otherwise occ_value_from_logodds(). O(1). */
occ_delta_t occi_delta_from_logodds(float logodds);

/* OctoMap's update of one voxel value: an unobserved voxel starts at 0; a value at a clamp
 * bound is kept when the delta pushes outward; the result is clamped to [clamp_min, clamp_max]. */
static inline occ_value_t occ_value_apply_delta(const occ_map_t *const m, const occ_value_t v,
                                                const occ_delta_t delta)
{
    const bool observed = occ_is_observed(v);
    /* OctoMap's updateNode returns early when the voxel sits at a clamp bound already. */
    if (observed && ((delta >= 0 && v >= m->priv.q_clamp_max) || (delta <= 0 && v <= m->priv.q_clamp_min))) {
        return v;
    }
#if OCC_VALUE_FLOAT
    float nv = (observed ? v : 0.0f) + delta;
#else
    int32_t nv = (int32_t)(observed ? v : 0) + (int32_t)delta;
#endif
    if (nv < m->priv.q_clamp_min) {
        nv = m->priv.q_clamp_min;
    } else if (nv > m->priv.q_clamp_max) {
        nv = m->priv.q_clamp_max;
    }
    return (occ_value_t)nv;
}
/* Equality of raw values (also for the float build, where -Wfloat-equal forbids ==). */
static inline bool occ_value_eq(occ_value_t a, occ_value_t b)
{
    return !(a < b) && !(b < a);
}

/* Pools (pool.c). Alloc returns OCC_NONE when empty (and does not count an OOM: the caller
 * checked capacity first with occi_pool_can_supply). Free returns false and changes nothing for
 * an index never handed out (>= hwm) or a block already on the free list (inner: O(1) marker; leaf: a walk
 * of the free list when OCC_POOL_PARANOID, which defaults to OCC_TESTING). */
uint32_t occi_pool_alloc_inner(occ_map_t *m);
uint32_t occi_pool_alloc_leaf(occ_map_t *m);
bool occi_pool_free_inner(occ_map_t *m, uint32_t idx);
bool occi_pool_free_leaf(occ_map_t *m, uint32_t idx);
/* True when n_inner inner and n_leaf leaf blocks can be allocated now. */
bool occi_pool_can_supply(const occ_map_t *m, uint32_t n_inner, uint32_t n_leaf);
/* Release a node's whole subtree to the pools (iterative). The node's child becomes OCC_NONE. */
void occi_tree_release_children(occ_map_t *m, occ_nodep_t node, unsigned level);

/* Give a uniform node at `level` >= 1 a child block filled with its value (OctoMap's
 * expandNode). The caller made sure the pool can supply one block. */
void occi_tree_expand(occ_map_t *m, occ_nodep_t node, unsigned level);
/* Recompute a node's value and flags from its child block and prune the block when its
 * 8 entries are uniform and equal. Returns true when the node's value or flags changed. */
bool occi_tree_refresh(occ_map_t *m, occ_nodep_t node, unsigned level);

/* map.c: occ_map_init's rules for a config (resolution, depth, sensor model), without a map:
 * the file loaders check a header's config with it (a probe map and arena were 270 B on their
 * call chains, make cross). */
bool occi_map_config_ok(const occ_map_config_t *cfg);

/* Add `delta` to every voxel below the node at `level` >= 1 (tree_frame.c): a uniform node in
 * O(1), else its subtree, refreshed bottom-up (values, flags, pruning). Allocates nothing. */
void occi_tree_apply_subtree(occ_map_t *m, occ_nodep_t node, unsigned level, occ_delta_t delta);

/* One frame's updates (the projective integrator's walk), one stream in code order: a brick
 * is OCC_FRAME_BRICK_SLOTS slots: the code of a level-2 node's first voxel with
 * OCC_CODE_HIT_BIT set (the tag), then masks of its 64 voxels (bit = offset in Morton order)
 * updated by the miss (q_miss), by the hit (q_hit; disjoint from the miss: hits win), and
 * those of the miss that whole free nodes cover (not counted as changed voxels); a whole node
 * at level >= 3 is one slot: the code of its first voxel with the marker bit 3 level - 1 set,
 * every voxel below getting node_delta once. No entry lies inside an earlier one. */
#define OCC_FRAME_BRICK_SLOTS 4u
typedef struct {
    const occ_code_t *s;
    size_t n; /* slots */
    occ_delta_t node_delta;
} occi_frame_t;

/* Counters of occi_tree_apply_frame: voxel values changed. */
typedef struct {
    size_t changed;
} occi_frame_out_t;

/* Apply a frame in one pass (tree_frame.c): first a bound of the blocks it can allocate (as if
 * no node existed) against the pools: OCC_ERR_NOMEM (oom_count bumped, nothing written), else
 * every update, refreshing and pruning as it goes. O(entries x depth). */
occ_err_t occi_tree_apply_frame(occ_map_t *m, const occi_frame_t *f, occi_frame_out_t *out);

/* A scan's voxel updates as the integrator's voxel set holds them (integrate/vset.c,
 * occi_vset_dense): 32^3-voxel chunks in Morton order, 512 words each, word w of chunk i the
 * mask of the 64 voxels of brick (chunks[i] << 9 | w) (codes (brick << 6) + bit) to update by
 * the miss; and the hits, voxel codes with the hit bit, sorted and unique, which win. */
typedef struct {
    const uint64_t *words;
    const uint64_t *chunks; /* chunk codes (voxel code >> 15), sorted, unique */
    const uint64_t *slots;  /* chunk i's words are words + 512 * slots[i] */
    size_t n_chunks;
    const occ_code_t *hits;
    size_t n_hits;
} occi_dense_t;

/* ---- reading it a brick at a time, in Morton order (dense_read.c) --------------------------- */
typedef struct {
    size_t ci;   /* chunk */
    unsigned wi; /* next word in it */
    size_t h;    /* next hit */
} occi_dense_cursor_t; /* {0}: the start */

typedef struct {
    occ_code_t code; /* the brick's first voxel */
    uint64_t miss, hit; /* its voxels by the miss and by the hit (disjoint: hits win) */
} occi_brick_t;

/* The next brick holding a voxel of the set or a hit; false after the last. */
bool occi_dense_next(const occi_dense_t *d, occi_dense_cursor_t *c, occi_brick_t *b);
/* The next codes (hits with the hit bit), whole bricks only, at most cap (>= 64) of them into
 * out. Returns how many; 0 only at the end. */
size_t occi_dense_read(const occi_dense_t *d, occi_dense_cursor_t *c, occ_code_t *out,
                       size_t cap);
/* The blocks the update of the pieces occi_dense_read() makes with this cap can allocate, each
 * piece as if none of its nodes existed (codes_valid's bound per piece; SIZE_MAX: one piece),
 * summed, and the voxels the set names. O(bricks). */
void occi_dense_need(const occi_dense_t *d, size_t cap, unsigned depth, uint64_t *inner,
                     uint64_t *leaf, size_t *voxels);

/* Voxels named and voxel values changed. */
typedef struct {
    size_t voxels, changed;
} occi_dense_out_t;

/* The update occ_map_observe_codes() makes of the set's codes, in one pass by 4x4x4 bricks
 * (tree_dense.c), when the bound of the blocks it can allocate (as if no node existed) fits
 * the pools; else OCC_ERR_NOMEM with nothing written and oom_count unchanged (the caller takes
 * the exact path). Also OCC_ERR_NOMEM for depth_levels < 2. O(bricks x depth + voxels). */
occ_err_t occi_tree_apply_dense(occ_map_t *m, const occi_dense_t *d, occi_dense_out_t *out);

#endif /* OCC_TREE_INTERNAL_H_INCLUDED */
