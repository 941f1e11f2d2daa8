/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * vset.c - the scan's voxel set (integrate_internal.h): bricks of 4x4x4 voxels, one word each,
 * in 32^3-voxel chunks taken from the caller's scratch on first touch and found through a hash
 * directory. Its size follows the chunks a scan touches (scan.dat at 0.05 m: 605 chunks,
 * 2.4 MiB, for 14.2 M visits of 3.9 M voxels). After the scan it is handed to the core as an
 * occi_dense_t (occi_vset_dense), which reads it back in Morton order a brick at a time
 * (core/dense_read.c): to the tree by bricks, or as codes in pieces of any room from 64.
 */
#include <string.h>

#include "integrate_internal.h"

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
        c += occ_popcount64(w[i]);
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
    /* chunk s lies at top - (s + 1) 512 words: its place from the lowest is n - 1 - s */
    for (size_t i = 0; i < vs->n; i++) {
        const occ_key_t ck = occ_morton_decode(vs->list[i]);
        const size_t h = dir_find(vs, pack(ck.k[0], ck.k[1], ck.k[2]));
        vs->ltmp[i] = (uint64_t)(vs->n - 1u - vs->slots[h]);
    }
}

void occi_vset_dense(const occ_vset_t *const vs, const occ_code_t *const hits,
                     const size_t n_hits, occi_dense_t *const d)
{
    d->words = vs->top - vs->n * OCC_VSET_WORDS;
    d->chunks = vs->list;
    d->slots = vs->ltmp;
    d->n_chunks = vs->n;
    d->hits = hits;
    d->n_hits = n_hits;
}
