/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * shared.c - single writer / many readers by published snapshots (occ_shared.h has the design).
 * The writer owns its arena; a version is copied into a snapshot no reader pins and published
 * by one 32-bit store. Readers pin a snapshot in their slot and read only it.
 */
#include <string.h>

#include "sat_internal.h"
#include "shared_internal.h"
#include "tree_internal.h"

#define SLOT_IDLE 0u
#define SLOT_ENTERING 1u
#define SLOT_HOLDS(b) (2u + (b)) /* slot value while a view pins snapshot b */
#define SHARED_MAGIC 0x53484152u

typedef struct {
    uint32_t magic;
    unsigned n_readers;
    uint32_t version;           /* latest completed version of the writer's content */
    uint32_t published_version;
    uint32_t hold;              /* open write sections */
    bool dirty;                 /* a write succeeded inside the open section */
    bool pending;               /* `version` is newer than what is published */
    uint32_t publishes, deferred;
    size_t copied_last;
    /* Granules (16 bytes of the arena) written since the last publish (cur) and between the two
     * before (prev): a snapshot, refreshed every second publish, needs both. */
    uint64_t *dirty_cur, *dirty_prev;
    size_t dirty_words;
    unsigned full;              /* publishes still to copy every carved byte (share, loads) */
    uint8_t *snap[OCC_SHARED_SNAPSHOTS];   /* arena-sized copies */
    occ_map_t head[OCC_SHARED_SNAPSHOTS];  /* the header of the version each holds */
    uint32_t head_version[OCC_SHARED_SNAPSHOTS];
    uint32_t latest;                       /* atomic: `version`, for readers */
    uint32_t pub;                          /* atomic: index of the published snapshot */
    uint32_t slot[OCC_SHARED_MAX_READERS]; /* atomic: SLOT_* per reader */
} shared_t;

/* OCC_SHARED_BYTES() promises the state fits OCC_SHARED_STATE_BYTES (with both alignments). */
typedef char occ_shared_state_fits[sizeof(shared_t) + 2u * OCC_ARENA_ALIGN <= OCC_SHARED_STATE_BYTES
                                       ? 1
                                       : -1];

/* The state rounded up to 8 bytes, so the copies after it are aligned like the arena (i386
 * aligns doubles to 4 inside structs). */
static size_t head_bytes(void)
{
    return (sizeof(shared_t) + OCC_ARENA_ALIGN - 1u) / OCC_ARENA_ALIGN * OCC_ARENA_ALIGN;
}

static shared_t *shared_of(const occ_map_t *const m)
{
    shared_t *const sh = (shared_t *)m->priv.shared;
    OCC_ASSERT(sh == NULL || sh->magic == SHARED_MAGIC);
    return sh;
}

#define GRANULE 16u

/* 64-bit words of one dirty bitmap for an arena of `arena_bytes`. */
static size_t bitmap_words(const size_t arena_bytes)
{
    const size_t granules = arena_bytes / GRANULE + 1u;
    return granules / 64u + 1u;
}

size_t occ_shared_bytes(const occ_map_t *const map, const unsigned n_readers)
{
    if (map == NULL || n_readers == 0u || n_readers > OCC_SHARED_MAX_READERS) {
        return 0u;
    }
    const size_t copies = occ_sat_mul(OCC_SHARED_SNAPSHOTS, map->arena_bytes);
    const size_t maps = occ_sat_mul(2u * sizeof(uint64_t), bitmap_words(map->arena_bytes));
    const size_t fixed = head_bytes() + OCC_ARENA_ALIGN;
    const size_t total = occ_sat_add(occ_sat_add(copies, maps), fixed);
    return total == SIZE_MAX ? 0u : total;
}

void occi_shared_mark(occ_map_t *const m, const void *const p, const size_t bytes)
{
    shared_t *const sh = shared_of(m);
    const uint8_t *const q = (const uint8_t *)p;
    if (sh == NULL || bytes == 0u || q < m->priv.arena || q >= m->priv.arena + m->arena_bytes) {
        return; /* the root's fields live in the map struct: the header copy carries them */
    }
    const size_t off = (size_t)(q - m->priv.arena);
    const size_t last = (off + bytes - 1u) / GRANULE;
    for (size_t g = off / GRANULE; g <= last; g++) {
        sh->dirty_cur[g / 64u] |= (uint64_t)1 << (g % 64u);
    }
}

/* Copy granule g of the arena into snapshot b when it holds carved bytes. */
static size_t copy_granule(shared_t *const sh, const occ_map_t *const m, const unsigned b,
                           const size_t g, const size_t leaf_end, const size_t inner_start)
{
    const size_t off = g * GRANULE;
    if (off >= m->arena_bytes || (off >= leaf_end && off + GRANULE <= inner_start)) {
        return 0u; /* in the gap between the pools: nothing reachable */
    }
    const size_t n = m->arena_bytes - off < GRANULE ? m->arena_bytes - off : GRANULE;
    memcpy(sh->snap[b] + off, m->priv.arena + off, n);
    return n;
}

/* The granules written since snapshot b was last refreshed (the last two publish intervals). */
static size_t copy_dirty(shared_t *const sh, const occ_map_t *const m, const unsigned b,
                         const size_t leaf_end, const size_t inner_start)
{
    size_t copied = 0u;
    for (size_t w = 0; w < sh->dirty_words; w++) {
        uint64_t bits = sh->dirty_cur[w] | sh->dirty_prev[w];
        while (bits != 0u) {
            const unsigned i = (unsigned)__builtin_ctzll(bits);
            bits &= bits - 1u;
            copied += copy_granule(sh, m, b, w * 64u + i, leaf_end, inner_start);
        }
    }
    return copied;
}

/* Bring snapshot b to the writer's content: every carved byte (after share or a load), else the
 * granules written since b was last refreshed; then the header. */
static void copy_into(shared_t *const sh, const occ_map_t *const m, const unsigned b)
{
    const size_t leaf_bytes = (size_t)m->leaf.hwm * sizeof(occ_leaf_block_t);
    const size_t inner_bytes = (size_t)m->inner.hwm * sizeof(occ_inner_block_t);
    OCC_ASSERT(leaf_bytes + inner_bytes <= m->arena_bytes);
    const size_t top = m->arena_bytes - inner_bytes;
    if (sh->full > 0u) {
        if (leaf_bytes > 0u) {
            memcpy(sh->snap[b], m->priv.arena, leaf_bytes);
        }
        if (inner_bytes > 0u) {
            memcpy(sh->snap[b] + top, m->priv.arena + top, inner_bytes);
        }
        sh->copied_last = leaf_bytes + inner_bytes;
        sh->full--;
    } else {
        sh->copied_last = copy_dirty(sh, m, b, leaf_bytes, top);
    }
    /* The other snapshot now lags by the interval just ended: it becomes `prev`. */
    uint64_t *const t = sh->dirty_prev;
    sh->dirty_prev = sh->dirty_cur;
    sh->dirty_cur = t;
    memset(sh->dirty_cur, 0, sh->dirty_words * sizeof(uint64_t));
    sh->head[b] = *m;
    sh->head_version[b] = sh->version;
}

/* Publish the writer's latest version into a snapshot neither published nor pinned. */
static bool try_publish(shared_t *const sh, const occ_map_t *const m)
{
    const uint32_t cur = occi_atomic_load(&sh->pub);
    bool pinned[OCC_SHARED_SNAPSHOTS] = {false};
    for (unsigned r = 0; r < sh->n_readers; r++) {
        const uint32_t s = occi_atomic_load(&sh->slot[r]);
        if (s == SLOT_ENTERING) {
            sh->deferred++; /* it may pin any snapshot: publish at the next chance */
            return false;
        }
        if (s >= SLOT_HOLDS(0u) && s < SLOT_HOLDS(OCC_SHARED_SNAPSHOTS)) {
            pinned[s - SLOT_HOLDS(0u)] = true;
        }
    }
    for (unsigned b = 0; b < OCC_SHARED_SNAPSHOTS; b++) {
        if (b != cur && !pinned[b]) {
            copy_into(sh, m, b);
            occi_atomic_store(&sh->pub, (uint32_t)b);
            sh->published_version = sh->version;
            sh->publishes++;
            sh->pending = false;
            return true;
        }
    }
    sh->deferred++;
    return false;
}

/* One version completed: publish it unless a section is open. */
static void complete(shared_t *const sh, const occ_map_t *const m)
{
    sh->version++;
    occi_atomic_store(&sh->latest, sh->version); /* before the publish: latest >= any view */
    sh->pending = true;
    (void)try_publish(sh, m);
}

void occi_shared_commit(occ_map_t *const m)
{
    shared_t *const sh = shared_of(m);
    if (sh->hold == 0u) {
        complete(sh, m);
    } else {
        sh->dirty = true;
    }
}

void occi_shared_rebuilt(occ_map_t *const m)
{
    shared_t *const sh = shared_of(m);
    sh->full = OCC_SHARED_SNAPSHOTS;
    occi_shared_commit(m);
}

void occi_map_replace(occ_map_t *const dst, const occ_map_t *const src)
{
    /* priv.shared is the struct's last field: everything before it is the map. */
    memcpy(dst, src, offsetof(occ_map_t, priv.shared));
}

occ_err_t occ_map_share(occ_map_t *const map, void *const mem, const size_t mem_bytes,
                        const unsigned n_readers)
{
#if !OCC_SHARED
    (void)map;
    (void)mem;
    (void)mem_bytes;
    (void)n_readers;
    return OCC_ERR_UNSUPPORTED;
#else
    if (map == NULL || mem == NULL || n_readers == 0u || n_readers > OCC_SHARED_MAX_READERS) {
        return OCC_ERR_ARG;
    }
    if (map->priv.shared != NULL) {
        return OCC_ERR_STATE;
    }
    const size_t need = occ_shared_bytes(map, n_readers);
    if (need == 0u || mem_bytes < need) {
        return OCC_ERR_SCRATCH;
    }
    const uintptr_t misalign = (uintptr_t)mem % OCC_ARENA_ALIGN;
    uint8_t *const base = (uint8_t *)mem + (misalign != 0u ? OCC_ARENA_ALIGN - misalign : 0u);
    shared_t *const sh = (shared_t *)(void *)base;
    memset(sh, 0, sizeof *sh);
    sh->magic = SHARED_MAGIC;
    sh->n_readers = n_readers;
    sh->dirty_words = bitmap_words(map->arena_bytes);
    sh->dirty_cur = (uint64_t *)(void *)(base + head_bytes());
    sh->dirty_prev = sh->dirty_cur + sh->dirty_words;
    memset(sh->dirty_cur, 0, 2u * sh->dirty_words * sizeof(uint64_t));
    sh->full = OCC_SHARED_SNAPSHOTS; /* both snapshots start from a whole copy */
    uint8_t *const snaps = (uint8_t *)(sh->dirty_prev + sh->dirty_words);
    for (unsigned b = 0; b < OCC_SHARED_SNAPSHOTS; b++) {
        sh->snap[b] = snaps + (size_t)b * map->arena_bytes;
    }
    sh->pub = OCC_SHARED_SNAPSHOTS - 1u; /* so the first publish takes snapshot 0 */
    for (unsigned r = 0; r < OCC_SHARED_MAX_READERS; r++) {
        sh->slot[r] = SLOT_IDLE;
    }
    const bool ok = try_publish(sh, map); /* version 0: no reader can hold a slot yet */
    OCC_ASSERT(ok);
    (void)ok;
    map->priv.shared = sh; /* before any reader starts (contract): thread start orders it */
    return OCC_OK;
#endif
}

/* What a view that holds nothing reads: an empty, unobserved map (fail closed). */
static void view_close(occ_view_t *const view)
{
    occ_root_set_child(&view->map, OCC_NONE);
    view->map.priv.root_value = OCC_VALUE_UNOBSERVED;
    occ_root_set_flags(&view->map, (uint8_t)OCC_NODE_HAS_UNKNOWN);
    view->map.priv.shared = NULL;
    view->map.inner.hwm = 0u;
    view->map.leaf.hwm = 0u;
    view->map.write_gen++;
    view->reader = OCC_SHARED_MAX_READERS;
}

/* A refused view: a valid map with no arena (default geometry), unobserved everywhere. */
static void view_refused(occ_view_t *const view)
{
    const occ_map_config_t cfg = occ_map_config_default();
    const occ_err_t e = occ_map_init(&view->map, &cfg, NULL, 0u);
    OCC_ASSERT(e == OCC_OK);
    (void)e;
    view->version = 0u;
    view->reader = OCC_SHARED_MAX_READERS;
}

occ_err_t occ_read_begin(occ_map_t *const map, const unsigned reader, occ_view_t *const view)
{
    if (view == NULL) {
        return OCC_ERR_ARG;
    }
    shared_t *const sh = map != NULL ? shared_of(map) : NULL;
    if (sh == NULL || reader >= sh->n_readers) {
        view_refused(view);
        return map == NULL || sh != NULL ? OCC_ERR_ARG : OCC_ERR_STATE;
    }
    if (occi_atomic_load(&sh->slot[reader]) != SLOT_IDLE) {
        return OCC_ERR_STATE; /* the open view keeps its slot; `view` is not touched */
    }
    occi_atomic_store(&sh->slot[reader], SLOT_ENTERING);
    const uint32_t b = occi_atomic_load(&sh->pub);
    OCC_ASSERT(b < OCC_SHARED_SNAPSHOTS);
    occi_atomic_store(&sh->slot[reader], SLOT_HOLDS(b));
    view->map = sh->head[b];
    view->map.priv.arena = sh->snap[b];
    view->map.priv.shared = NULL;
    view->version = sh->head_version[b];
    view->reader = reader;
    return OCC_OK;
}

const occ_map_t *occ_view_map(const occ_view_t *const view)
{
    return view == NULL ? NULL : &view->map;
}

void occ_read_end(occ_map_t *const map, occ_view_t *const view)
{
    if (map == NULL || view == NULL) {
        return;
    }
    shared_t *const sh = shared_of(map);
    if (sh == NULL || view->reader >= sh->n_readers) {
        return;
    }
    const unsigned r = view->reader;
    view_close(view); /* no read of the snapshot after the slot lets it go */
    occi_atomic_store(&sh->slot[r], SLOT_IDLE);
}

occ_err_t occ_map_write_begin(occ_map_t *const map)
{
    if (map == NULL) {
        return OCC_ERR_ARG;
    }
    shared_t *const sh = shared_of(map);
    if (sh == NULL) {
        return OCC_ERR_STATE;
    }
    sh->hold++;
    return OCC_OK;
}

occ_err_t occ_map_write_end(occ_map_t *const map)
{
    if (map == NULL) {
        return OCC_ERR_ARG;
    }
    shared_t *const sh = shared_of(map);
    if (sh == NULL || sh->hold == 0u) {
        return OCC_ERR_STATE;
    }
    sh->hold--;
    if (sh->hold == 0u && sh->dirty) {
        sh->dirty = false;
        complete(sh, map);
    }
    return OCC_OK;
}

bool occ_map_publish(occ_map_t *const map)
{
    shared_t *const sh = map != NULL ? shared_of(map) : NULL;
    if (sh == NULL || sh->hold != 0u) {
        return false;
    }
    return !sh->pending || try_publish(sh, map);
}

uint32_t occ_map_version(const occ_map_t *const map)
{
    const shared_t *const sh = map != NULL ? shared_of(map) : NULL;
    if (sh == NULL) {
        return 0u;
    }
    return sh->version + (sh->hold > 0u && sh->dirty ? 1u : 0u);
}

uint32_t occ_shared_latest_version(const occ_map_t *const map)
{
    const shared_t *const sh = map != NULL ? shared_of(map) : NULL;
    return sh == NULL ? 0u : occi_atomic_load(&sh->latest);
}

occ_err_t occ_shared_info(const occ_map_t *const map, occ_shared_info_t *const out)
{
    if (map == NULL || out == NULL) {
        return OCC_ERR_ARG;
    }
    const shared_t *const sh = shared_of(map);
    if (sh == NULL) {
        return OCC_ERR_STATE;
    }
    out->version = sh->version;
    out->published_version = sh->published_version;
    out->publishes = sh->publishes;
    out->deferred = sh->deferred;
    out->n_readers = sh->n_readers;
    out->copied_bytes_last = sh->copied_last;
    out->open_views = 0u;
    for (unsigned r = 0; r < sh->n_readers; r++) {
        out->open_views += occi_atomic_load(&sh->slot[r]) != SLOT_IDLE ? 1u : 0u;
    }
    return OCC_OK;
}
