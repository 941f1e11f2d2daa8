/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * vset.c - the scan's voxel set (integrate_internal.h): bricks of 4x4x4 voxels, one word each,
 * in 32^3-voxel chunks taken from the caller's scratch on first touch and found through a hash
 * directory. Its size follows the chunks a scan touches (scan.dat at 0.05 m: 605 chunks,
 * 2.4 MiB, for 14.2 M visits of 3.9 M voxels), and it is read back in Morton order in pieces
 * of whole bricks (any room from 64 codes), so the scan's codes never have to be held at once.
 */
#include <string.h>

#include "integrate_internal.h"

#define HIT OCC_CODE_HIT_BIT

bool occi_vset_init(occ_vset_t *const vs, uint8_t *const mem, const size_t bytes,
                    const size_t max_chunks, const unsigned depth)
{
    size_t cap = bytes / OCC_VSET_CHUNK_BYTES;
    cap = cap < max_chunks ? cap : max_chunks;
    if (cap == 0u || cap > UINT32_MAX / 4u) {
        return false;
    }
    unsigned tb = 1;
    while (((size_t)1 << tb) < 2u * cap) {
        tb++;
    }
    const size_t t = (size_t)1 << tb; /* < 4 cap: its 12 B per entry fit the 48 B per chunk */
    const size_t dir = t * 12u + cap * 16u;
    uint8_t *const d = mem + ((bytes - dir) & ~(size_t)7);
    vs->top = (uint64_t *)(void *)d;
    vs->keys = vs->top;
    vs->list = vs->keys + t;
    vs->ltmp = vs->list + cap;
    vs->slots = (uint32_t *)(void *)(vs->ltmp + cap);
    memset(vs->keys, 0, t * 8u);
    vs->cap = cap;
    vs->n = 0;
    vs->tbits = tb;
    vs->cmax = depth >= 5u ? (uint32_t)1 << (depth - 5u) : 1u;
    vs->overflow = false;
    return true;
}

/* The directory slot of packed key `key` (+1): its entry, or the empty entry where it goes. */
static size_t dir_find(const occ_vset_t *const vs, const uint64_t key)
{
    const size_t mask = ((size_t)1 << vs->tbits) - 1u;
    size_t h = (size_t)((key * 0x9E3779B97F4A7C15ull) >> (64u - vs->tbits));
    while (vs->keys[h] != key && vs->keys[h] != 0u) {
        h = (h + 1u) & mask;
    }
    return h;
}

static uint64_t pack(const uint32_t cx, const uint32_t cy, const uint32_t cz)
{
    return ((uint64_t)cz << 32 | (uint64_t)cy << 16 | (uint64_t)cx) + 1u;
}

uint64_t *occi_vset_chunk(occ_vset_t *const vs, const uint32_t cx, const uint32_t cy,
                          const uint32_t cz)
{
    if (cx >= vs->cmax || cy >= vs->cmax || cz >= vs->cmax) {
        return NULL;
    }
    const uint64_t key = pack(cx, cy, cz);
    const size_t h = dir_find(vs, key);
    if (vs->keys[h] == key) {
        return vs->top - ((size_t)vs->slots[h] + 1u) * OCC_VSET_WORDS;
    }
    if (vs->n == vs->cap) {
        return NULL;
    }
    const size_t s = vs->n++;
    vs->keys[h] = key;
    vs->slots[h] = (uint32_t)s;
    vs->list[s] = key; /* its Morton code in occi_vset_sort(): off the ray walk's stack */
    uint64_t *const w = vs->top - (s + 1u) * OCC_VSET_WORDS;
    memset(w, 0, OCC_VSET_WORDS * 8u);
    return w;
}

uint8_t *occi_vset_low(const occ_vset_t *const vs)
{
    return (uint8_t *)(void *)(vs->top - vs->n * OCC_VSET_WORDS);
}

size_t occi_vset_bytes(const occ_vset_t *const vs)
{
    return vs->n * (OCC_VSET_WORDS * 8u + 20u) + ((size_t)8 << vs->tbits);
}

size_t occi_vset_count(const occ_vset_t *const vs)
{
    const uint64_t *const w = vs->top - vs->n * OCC_VSET_WORDS;
    size_t c = 0;
    for (size_t i = 0; i < vs->n * OCC_VSET_WORDS; i++) {
        c += (size_t)__builtin_popcountll(w[i]);
    }
    return c;
}

void occi_vset_sort(occ_vset_t *const vs, uint32_t *const hist)
{
    for (size_t i = 0; i < vs->n; i++) { /* packed coordinates + 1 -> chunk code */
        const uint64_t p = vs->list[i] - 1u;
        const occ_key_t ck = {{(uint32_t)(p & 0xFFFFu), (uint32_t)((p >> 16) & 0xFFFFu),
                               (uint32_t)(p >> 32)}};
        vs->list[i] = occ_morton_encode(ck);
    }
    const uint64_t *const s = occi_keyset_sort(vs->list, vs->ltmp, vs->n, hist);
    if (s != vs->list) {
        memcpy(vs->list, s, vs->n * sizeof *s);
    }
}

void occi_vset_dense(occ_vset_t *const vs, const occ_code_t *const hits, const size_t n_hits,
                     occi_dense_t *const d)
{
    /* chunk s lies at top - (s + 1) 512 words: from the lowest, place n - 1 - s */
    for (size_t i = 0; i < vs->n; i++) {
        const occ_key_t ck = occ_morton_decode(vs->list[i]);
        const size_t h = dir_find(vs, pack(ck.k[0], ck.k[1], ck.k[2]));
        vs->ltmp[i] = (uint64_t)(vs->n - 1u - vs->slots[h]);
    }
    d->words = vs->top - vs->n * OCC_VSET_WORDS;
    d->chunks = vs->list;
    d->slots = vs->ltmp;
    d->n_chunks = vs->n;
    d->hits = hits;
    d->n_hits = n_hits;
}

/* Move the cursor to the next non-empty word; false after the last. */
static bool next_word(const occ_vset_t *const vs, occ_vset_cursor_t *const cur)
{
    for (;;) {
        while (cur->cw != NULL && cur->wi < OCC_VSET_WORDS) {
            const uint64_t w = cur->cw[cur->wi++];
            if (w != 0u) {
                cur->w = w;
                cur->wbase = cur->base | ((occ_code_t)(cur->wi - 1u) << 6);
                return true;
            }
        }
        if (cur->ci == vs->n) {
            cur->cw = NULL;
            return false;
        }
        const occ_code_t cc = vs->list[cur->ci++];
        const occ_key_t ck = occ_morton_decode(cc);
        const size_t h = dir_find(vs, pack(ck.k[0], ck.k[1], ck.k[2]));
        cur->cw = vs->top - ((size_t)vs->slots[h] + 1u) * OCC_VSET_WORDS;
        cur->base = cc << 15;
        cur->wi = 0;
    }
}

/* The next brick of the set and the hits merged, as the cursor's pending brick (kept until a
 * caller takes it); false after the last. */
static bool brick_peek(const occ_vset_t *const vs, occ_vset_cursor_t *const cur,
                       const occ_code_t *const hits, const size_t n_hits)
{
    if (cur->pend) {
        return true;
    }
    if (cur->w == 0u) {
        (void)next_word(vs, cur);
    }
    const occ_code_t sb = cur->w != 0u ? cur->wbase : HIT; /* HIT: above every code */
    const occ_code_t hb = cur->h < n_hits ? hits[cur->h] & ~HIT & ~(occ_code_t)63 : HIT;
    const occ_code_t b = sb < hb ? sb : hb;
    if (b == HIT) {
        return false;
    }
    uint64_t hm = 0;
    while (cur->h < n_hits && (hits[cur->h] & ~HIT & ~(occ_code_t)63) == b) {
        hm |= (uint64_t)1 << (hits[cur->h++] & 63u);
    }
    cur->pbits = hm;
    if (sb == b) {
        cur->pbits |= cur->w;
        cur->w = 0;
    }
    cur->phits = hm;
    cur->pbase = b;
    cur->pend = true;
    return true;
}

size_t occi_vset_read(const occ_vset_t *const vs, occ_vset_cursor_t *const cur,
                      const occ_code_t *const hits, const size_t n_hits, occ_code_t *const out,
                      const size_t cap)
{
    OCC_ASSERT(cap >= 64u);
    size_t n = 0;
    while (brick_peek(vs, cur, hits, n_hits)) {
        uint64_t bits = cur->pbits;
        if ((size_t)__builtin_popcountll(bits) > cap - n) {
            break; /* the brick starts the next piece */
        }
        const occ_code_t base = cur->pbase;
        const uint64_t hm = cur->phits;
        do {
            const unsigned bit = (unsigned)__builtin_ctzll(bits);
            out[n++] = base | bit | ((hm >> bit) & 1u) << 63;
            bits &= bits - 1u;
        } while (bits != 0u);
        cur->pend = false;
    }
    return n;
}

/* Level-1 nodes (2x2x2 voxels: bytes of the brick's word) with a voxel. */
static unsigned nonzero_bytes(const uint64_t w)
{
    const uint64_t lo7 = 0x7F7F7F7F7F7F7F7Full;
    return (unsigned)__builtin_popcountll((((w & lo7) + lo7) | w) & ~lo7);
}

void occi_vset_need(const occ_vset_t *const vs, const occ_code_t *const hits,
                    const size_t n_hits, const size_t cap, const unsigned depth,
                    uint64_t *const inner, uint64_t *const leaf)
{
    /* Per piece, occi_coarse_need's count by levels: level 1 the bricks' non-empty bytes,
     * level 2 the bricks, level l >= 3 one node plus one per neighbour pair of bricks whose
     * highest differing bit (brick code) hb has hb / 3 + 2 >= l. */
    occ_vset_cursor_t cur;
    memset(&cur, 0, sizeof cur);
    const unsigned up = depth >= 2u ? depth - 2u : 0u; /* levels 3..depth */
    uint64_t in = 0, lf = 0;
    size_t fill = 0;
    occ_code_t prev = 0;
    while (brick_peek(vs, &cur, hits, n_hits)) {
        const size_t k = (size_t)__builtin_popcountll(cur.pbits);
        const occ_code_t b = cur.pbase >> 6;
        if (fill == 0u || k > cap - fill) {
            fill = 0; /* the first brick of a piece: its nodes at every level are new */
            in += up;
        } else {
            const unsigned j = (63u - (unsigned)__builtin_clzll(b ^ prev)) / 3u;
            in += j < up ? j : up;
        }
        in += depth >= 2u ? 1u : 0u;
        lf += nonzero_bytes(cur.pbits);
        fill += k;
        prev = b;
        cur.pend = false;
    }
    *inner = in;
    *leaf = lf;
}
