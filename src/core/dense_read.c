/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * dense_read.c - reading a scan's voxel set (occi_dense_t: 32^3-voxel chunks of 4x4x4-brick
 * words in Morton order, and the sorted hits) a brick at a time, the hits merged in and winning:
 * the one reader behind the update by bricks (tree_dense.c), the codes read back in pieces and
 * the pools' bound for them (integrate.c's code paths).
 */
#include "tree_path.h"

#define NONE (~(occ_code_t)0)

/* The set's next non-empty word (its brick code), or NONE after the last. */
static occ_code_t next_word(const occi_dense_t *const d, occi_dense_cursor_t *const c)
{
    for (; c->ci < d->n_chunks; c->ci++, c->wi = 0u) {
        const uint64_t *const w = d->words + ((size_t)d->slots[c->ci] << 9);
        while (c->wi < 512u && w[c->wi] == 0u) {
            c->wi++;
        }
        if (c->wi < 512u) {
            return ((occ_code_t)d->chunks[c->ci] << 9) | c->wi;
        }
    }
    return NONE;
}

bool occi_dense_next(const occi_dense_t *const d, occi_dense_cursor_t *const c,
                     occi_brick_t *const b)
{
    const occ_code_t wb = next_word(d, c);
    const occ_code_t hb = c->h < d->n_hits ? (d->hits[c->h] & ~OCC_CODE_HIT_BIT) >> 6 : NONE;
    const occ_code_t bc = wb < hb ? wb : hb;
    if (bc == NONE) {
        return false;
    }
    b->miss = 0u;
    if (wb == bc) {
        b->miss = d->words[((size_t)d->slots[c->ci] << 9) + c->wi];
        c->wi++;
    }
    b->hit = 0u;
    while (c->h < d->n_hits && (d->hits[c->h] & ~OCC_CODE_HIT_BIT) >> 6 == bc) {
        b->hit |= (uint64_t)1 << (d->hits[c->h] & 63u);
        c->h++;
    }
    b->miss &= ~b->hit; /* hits win */
    b->code = bc << 6;
    return true;
}

size_t occi_dense_read(const occi_dense_t *const d, occi_dense_cursor_t *const c,
                       occ_code_t *const out, const size_t cap)
{
    OCC_ASSERT(cap >= 64u);
    size_t n = 0;
    occi_dense_cursor_t before = *c;
    occi_brick_t b;
    while (occi_dense_next(d, c, &b)) {
        uint64_t all = b.miss | b.hit;
        if (occ_popcount64(all) > cap - n) {
            *c = before; /* the brick starts the next piece */
            break;
        }
        for (; all != 0u; all &= all - 1u) {
            const unsigned k = occ_first_slot64(all);
            out[n++] = (b.code | k) | (((b.hit >> k) & 1u) != 0u ? OCC_CODE_HIT_BIT : 0u);
        }
        before = *c;
    }
    return n;
}

void occi_dense_need(const occi_dense_t *const d, const size_t cap, const unsigned depth,
                     uint64_t *const inner, uint64_t *const leaf, size_t *const voxels)
{
    /* Per piece, as if none of its nodes existed: the first brick under a node at a level of
     * 2 .. its split from the previous brick of the piece counts that node's inner block (a
     * piece's first brick: every level up to the root's child); a non-empty byte (a level-1
     * node) counts its leaf block. */
    occi_dense_cursor_t c = {0u, 0u, 0u};
    occi_brick_t b;
    occ_code_t prev = 0;
    size_t fill = 0;
    *inner = 0u;
    *leaf = 0u;
    *voxels = 0u;
    while (occi_dense_next(d, &c, &b)) {
        const unsigned k = occ_popcount64(b.miss | b.hit);
        const bool first = fill == 0u || k > cap - fill;
        const unsigned s = first ? depth + 1u : split_level(b.code, prev);
        fill = first ? k : fill + k;
        prev = b.code;
        *voxels += k;
        brick_need(s, b.miss | b.hit, inner, leaf);
    }
}
