/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * lookup_index_bricks.c - the level-0 lookup index as 8x8x8 bricks (lookup_internal.h): one walk
 * over the tree down to the voxels, in Morton order, so the observed nodes of a brick come one
 * after the other; a brick is closed when the walk leaves it. The same walk counts the mixed
 * bricks (occ_lookup_index_need) and fills them (occ_lookup_index_build): a brick whose voxels
 * all hold one state becomes its constant brick, whatever log-odds its voxels hold.
 */
#include "lookup_internal.h"

/* The brick the walk is in, and what it found there so far. */
typedef struct {
    uint32_t key[3];  /* brick key per axis (voxel key >> 3) */
    bool open;
    uint32_t voxels;  /* voxels reported FREE or OCCUPIED */
    unsigned states;  /* bit 1 << state of each state reported */
    uint32_t *words;  /* its 32 words in the table (fill with a slot left), else NULL */
    size_t dir;       /* its directory entry (fill) */
} brick_t;

/* One run of the walk: counting (dir == NULL) or filling. */
typedef struct {
    brick_t cur;
    size_t mixed;     /* bricks closed with more than one state */
    uint32_t full;    /* voxels of a brick: 512, fewer when the whole map is smaller */
    const occ_lookup_index_t *ix;
    uint32_t *dir, *bricks;
    size_t cap;       /* mixed bricks the table holds */
} brick_run_t;

static size_t dir_at(const occ_lookup_index_t *const ix, const uint32_t k[3])
{
    return (size_t)((k[0] - ix->lo[0]) >> OCC_IDX_BRICK_SHIFT) * ix->priv.stride_x +
           (size_t)((k[1] - ix->lo[1]) >> OCC_IDX_BRICK_SHIFT) * ix->priv.stride_y +
           (size_t)((k[2] - ix->lo[2]) >> OCC_IDX_BRICK_SHIFT);
}

/* One state only, on every voxel: the constant brick of that state; else the next mixed one
 * (whose words were written in its slot). */
static void brick_close(brick_run_t *const r)
{
    brick_t *const b = &r->cur;
    if (!b->open) {
        return;
    }
    b->open = false;
    const bool one = (b->states & (b->states - 1u)) == 0u && b->voxels == r->full;
    if (r->dir != NULL) {
        OCC_ASSERT(one || b->words != NULL);
        const unsigned s = (b->states >> OCC_STATE_OCCUPIED) != 0u ? OCC_STATE_OCCUPIED
                                                                   : OCC_STATE_FREE;
        r->dir[b->dir] = one ? (uint32_t)s : (uint32_t)(OCC_IDX_CONST_BRICKS + r->mixed);
    }
    r->mixed += one ? 0u : 1u;
}

/* The walk enters the brick of key k: the next slot, cleared to UNKNOWN, when one is left (the
 * bricks after the last mixed one are all of one state: they need none). */
static void brick_open(brick_run_t *const r, const occ_key_t *const k)
{
    brick_t *const b = &r->cur;
    for (unsigned a = 0; a < 3u; a++) {
        b->key[a] = k->k[a] >> OCC_IDX_BRICK_SHIFT;
    }
    b->open = true;
    b->voxels = 0u;
    b->states = 0u;
    b->words = NULL;
    if (r->dir != NULL && r->mixed < r->cap) {
        b->dir = dir_at(r->ix, k->k);
        b->words = r->bricks + (OCC_IDX_CONST_BRICKS + r->mixed) * OCC_IDX_BRICK_WORDS;
        for (unsigned i = 0; i < OCC_IDX_BRICK_WORDS; i++) {
            b->words[i] = 0u;
        }
    } else if (r->dir != NULL) {
        b->dir = dir_at(r->ix, k->k);
    }
}

/* A node below the brick level (FREE or OCCUPIED) into its brick. */
static void brick_add(brick_run_t *const r, const occ_idx_node_t *const nd, const occ_state_t s)
{
    brick_t *const b = &r->cur;
    if (!b->open || (nd->key.k[0] >> OCC_IDX_BRICK_SHIFT) != b->key[0] ||
        (nd->key.k[1] >> OCC_IDX_BRICK_SHIFT) != b->key[1] ||
        (nd->key.k[2] >> OCC_IDX_BRICK_SHIFT) != b->key[2]) {
        brick_close(r);
        brick_open(r, &nd->key);
    }
    const uint32_t span = 1u << nd->level;
    b->voxels += span * span * span;
    b->states |= 1u << (unsigned)s;
    if (b->words == NULL) {
        return;
    }
    occ_key_t k = nd->key;
    for (uint32_t x = 0; x < span; x++) {
        k.k[0] = nd->key.k[0] + x;
        for (uint32_t y = 0; y < span; y++) {
            k.k[1] = nd->key.k[1] + y;
            for (uint32_t z = 0; z < span; z++) {
                k.k[2] = nd->key.k[2] + z;
                unsigned sh;
                const size_t w = occi_idx_brick_word(0u, &k, &sh);
                b->words[w] |= (uint32_t)s << sh;
            }
        }
    }
}

/* Every directory entry of a node at or above the brick level gets its constant brick. */
static void dir_fill(const brick_run_t *const r, const occ_idx_node_t *const nd, const occ_state_t s)
{
    const uint32_t span = 1u << (nd->level - OCC_IDX_BRICK_SHIFT);
    occi_idx_fill_cube(r->ix, r->dir, dir_at(r->ix, nd->key.k), span, (uint32_t)s);
}

/* The walk down to the voxels: FREE and OCCUPIED nodes into their bricks (UNKNOWN is what an
 * untouched voxel reads already). */
static void brick_walk(brick_run_t *const r, const occ_map_t *const m)
{
    const unsigned depth = m->cfg.depth_levels;
    r->full = depth < OCC_IDX_BRICK_SHIFT ? 1u << (3u * depth) : 1u << (3u * OCC_IDX_BRICK_SHIFT);
    occ_idx_walk_t w;
    occ_idx_node_t nd;
    occi_idx_walk_begin(&w, m, 0u);
    while (occi_idx_walk_next(&w, m, &nd)) {
        const occ_state_t s = occ_value_state(m, nd.value);
        if (s == OCC_STATE_UNKNOWN) {
            continue;
        }
        if (nd.level >= OCC_IDX_BRICK_SHIFT) {
            if (r->dir != NULL) {
                dir_fill(r, &nd, s);
            }
            continue;
        }
        brick_add(r, &nd, s);
    }
    brick_close(r);
}

size_t occi_idx_mixed(const occ_map_t *const m)
{
    brick_run_t r;
    r.cur.open = false;
    r.mixed = 0u;
    r.ix = NULL;
    r.dir = r.bricks = NULL;
    r.cap = 0u;
    brick_walk(&r, m);
    return r.mixed;
}

void occi_idx_fill_bricks(const occ_lookup_index_t *const ix, const occ_map_t *const m,
                          uint32_t *const dir, uint32_t *const bricks, const size_t mixed)
{
    const size_t n_dir = (size_t)ix->n[0] * ix->priv.stride_x;
    for (size_t i = 0; i < n_dir; i++) {
        dir[i] = (uint32_t)OCC_STATE_UNKNOWN;
    }
    /* The constant bricks: brick s holds state s in every voxel. */
    for (uint32_t s = 0; s < OCC_IDX_CONST_BRICKS; s++) {
        for (unsigned i = 0; i < OCC_IDX_BRICK_WORDS; i++) {
            bricks[s * OCC_IDX_BRICK_WORDS + i] = s * 0x55555555u;
        }
    }
    brick_run_t r;
    r.cur.open = false;
    r.mixed = 0u;
    r.ix = ix;
    r.dir = dir;
    r.bricks = bricks;
    r.cap = mixed;
    brick_walk(&r, m);
    OCC_ASSERT(r.mixed == mixed);
}
