/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * occ_shared.h - one writer, many readers on the same map (issue 20).
 *
 * Model: the thread that calls the write functions of occ_core.h / occ_integrate.h / occ_evict.h /
 * occ_io.h on `map` is the only writer. Each write call is one version (a write section,
 * occ_map_write_begin() .. occ_map_write_end(), makes several calls one version): it is either
 * applied as a whole and published at its end, or (on an error) not at all, except what the
 * call documents it keeps (an insert's automatic evictions). A reader opens a
 * view of the last published version, runs any number of read-only queries on
 * occ_view_map(view), and closes it. Readers never block and never retry; the writer never
 * waits for readers.
 *
 * Guarantee: every query on an open view answers exactly as the same query on the writer's map
 * at the end of the version the view holds (view.version): a whole write call (or section)
 * applied or not, never half, whatever the writer does meanwhile (insert, evict, clear, load).
 * The view stays that version until occ_read_end(). occ_map_check() holds on every view.
 *
 * Freshness: a view holds the version published when it opened. How far behind it is, a reader
 * learns from occ_shared_latest_version(map) - view.version (versions the writer completed
 * since; any thread or interrupt, one atomic load). Each completed version is published at once
 * unless the spare snapshot is still pinned by a view opened before the previous publish (or a
 * reader task is inside occ_read_begin() at that instant: a few instructions); it is then
 * deferred, and goes out at the writer's first write call, occ_map_write_end() or
 * occ_map_publish() after those views close. Deferrals have no bound in number (they last as
 * long as such a view stays open), only in time: if every view closes within H seconds of
 * opening and the writer calls one of those at least every P seconds, a view opened at any
 * moment holds a version that was the writer's latest less than H + P ago (a reader task
 * preempted inside occ_read_begin() adds the time until it runs again; an interrupt reader
 * never does). Keep views short, and let an idle writer call occ_map_publish().
 *
 * Design (why): published SNAPSHOTS. Shared memory holds OCC_SHARED_SNAPSHOTS (2) copies of the
 * arena; a version is published by bringing a snapshot no reader holds up to date (copying the
 * 16-byte granules of the arena written since that snapshot was last refreshed, which every
 * block write marks in a bitmap; the whole carved region after occ_map_share() and loads) with
 * the map header, then storing that
 * snapshot's index (ONE 32-bit word, so a Cortex-M0+ without LDREX loads it atomically) with a
 * sequentially consistent store. A reader pins the published snapshot in its slot and copies its
 * header: every existing query (they all take `const occ_map_t *`) runs on the view unchanged,
 * on blocks nothing writes while the slot holds them.
 * Chosen over copy-on-write of touched blocks (the brief's suggestion) because COW has to reach
 * into every write path (batch applier, set/forget, coarse updates, the resumable evictor whose
 * cursor keeps block indices across calls, the loaders) and adds per-block marks and a deferred
 * free list to the hot update loop; the snapshot leaves every algorithm and the pools as they
 * are (a plain or never-shared map pays a NULL test of map->priv.shared per block or node write
 * and per write call: see the cost below), cannot let a reader see a block the writer is
 * changing (no free-list link, no uninitialised carve, no torn root), and its cost is bounded
 * and easy to state: per published version, a copy of what the last two versions wrote (at
 * most the carved bytes). The price: memory (two arena copies).
 *
 * Reader protocol (wait-free, no loop; 4 atomic 32-bit accesses with the open-slot check):
 * slot := ENTERING; s := published; slot := s. The writer picks a snapshot that is neither
 * published nor named by a slot and, if a slot reads ENTERING, picks none this time. When no
 * snapshot is free (both pinned: a reader still holds the one before last), the version is not
 * published now but at the writer's next write call, occ_map_write_end() or occ_map_publish():
 * readers then see the previous version a little longer (deferred in occ_shared_info_t counts
 * it). The writer never waits. A reader task preempted inside occ_read_begin() (between its
 * first and last store: a few instructions) makes the writer defer until it runs again; an
 * interrupt reader never does (it completes).
 *
 * Platforms (compile-time knobs, one block below): GCC/Clang __atomic builtins by default (hosts,
 * multi-core Linux: seq_cst 32-bit loads and stores only, no read-modify-write, so no libatomic;
 * Cortex-M4 and M0+: a plain LDR/STR with DMB). OCC_SHARED_SINGLE_CORE=1 uses volatile accesses
 * and a compiler barrier instead: a single-core MCU where readers are interrupts or RTOS tasks
 * preempting the writer. OCC_SHARED=0 removes the mode (occ_map_share() then answers
 * OCC_ERR_UNSUPPORTED, the reader and section calls OCC_ERR_STATE as on a map not shared) and
 * the NULL tests.
 *
 * Cost of a map that is never shared (default build): every block or node write tests
 * map->priv.shared (a load and a branch, up to three per node: child, value, flags) and every
 * write call once more. Measured with callgrind, instructions inside occ_map_insert_cloud()
 * per scan (`make bench-shared-cost`, GCC 12 -O2 x86-64): scan.dat SIMPLE 0.1 m 663.6 M vs
 * 657.1 M with OCC_SHARED=0 (+1.00%, ~8 per voxel updated); the first TUM pioneer frame, SIMPLE
 * 0.05 m, every pixel, 1512.9 M vs 1512.1 M (+0.05%: ray walking dominates).
 *
 * Memory (exact): occ_shared_bytes() = the internal state (slots, counters and one map header
 * per snapshot: under 1 KB, rounded to 8) + 8 alignment + two dirty bitmaps of
 * 8 * (floor((arena_bytes / 16 + 1) / 64) + 1) bytes each (~arena_bytes / 64 together) +
 * OCC_SHARED_SNAPSHOTS * map->arena_bytes; OCC_SHARED_BYTES(arena bytes) bounds it at compile
 * time. The map's
 * own arena needs no headroom: a write call needs exactly the blocks it needs unshared, and
 * OCC_ERR_NOMEM leaves the map and every view unchanged (nothing is published).
 * Time: a publish scans the bitmaps (arena_bytes / 1024 words) and copies the granules written
 * in the last two versions, at most OCC_LEAF_BLOCK_BYTES * leaf.hwm + OCC_INNER_BLOCK_BYTES *
 * inner.hwm (hwm: blocks ever carved, see occ_pool_t); after a share or a load, twice that whole.
 * Each block write on a shared map sets a bit; a view copies one map header.
 *
 * What publishes (each a version when it succeeds and changed something; a refused call,
 * OCC_ERR_NOMEM included, publishes nothing): occ_map_update/observe/set/forget(_key),
 * occ_map_observe_codes, occ_map_insert_cloud / insert_rays (with their automatic evictions and
 * coarse pass: one version per call; a failed insert publishes only the evictions it made),
 * occ_map_evict / evict_for (when anything was evicted), occ_map_clear, occ_io_read (clear +
 * build: one version).
 *
 * Not allowed: writing through occ_view_map() (it aliases a snapshot readers share); calling
 * occ_map_init() or occ_io_load() on a shared map while readers run (they re-initialize the
 * struct, which unshares it: use occ_io_read()); two threads using one reader slot at once; a
 * reader slot used from an interrupt that preempts the same slot.
 */
#ifndef OCC_SHARED_H_INCLUDED
#define OCC_SHARED_H_INCLUDED

#include "occmap/occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Compile-time knobs -----------------------------------------------------------------------
 * OCC_SHARED               1: the mode is built (default). 0: occ_map_share() answers
 *                             OCC_ERR_UNSUPPORTED and the write paths skip the per-write tests
 *                             (the cost above). The struct layout does not change.
 * OCC_SHARED_SINGLE_CORE   0: __atomic builtins (default with GCC/Clang). 1: volatile + compiler
 *                             barrier (single core; readers are interrupts or preempting tasks).
 *                             Forced to 1 by a compiler without the builtins.
 * OCC_SHARED_SNAPSHOTS     2 (fixed): snapshot copies of the arena in the shared memory. */
#ifndef OCC_SHARED
#define OCC_SHARED 1
#endif
#define OCC_SHARED_SNAPSHOTS 2u

/* Most reader slots one shared map has. */
#define OCC_SHARED_MAX_READERS 16u

/* Compile-time bound of occ_shared_bytes() for a map initialized on `arena_bytes` bytes (any
 * reader count), for a static buffer: OCC_SHARED_SNAPSHOTS arena copies plus
 * arena_bytes / 64 + 32 for the dirty bitmaps plus OCC_SHARED_STATE_BYTES, a bound of the
 * internal state (slots, counters, one map header per snapshot, alignment) that the library
 * checks at compile time. */
#define OCC_SHARED_STATE_BYTES 2048u
#define OCC_SHARED_BYTES(arena_bytes)                                                         \
    ((size_t)OCC_SHARED_SNAPSHOTS * (size_t)(arena_bytes) + (size_t)(arena_bytes) / 64u + 32u + \
     (size_t)OCC_SHARED_STATE_BYTES)

/* A reader's snapshot of one published version. Caller-owned (stack is fine); valid from
 * occ_read_begin() to occ_read_end(). Its map is a read-only handle: pass occ_view_map(view) to
 * queries, never to a write function. */
typedef struct {
    occ_map_t map;     /* the version's header (root, geometry); internal */
    uint32_t version;  /* the published version this view reads (counts write calls) */
    unsigned reader;   /* the slot it holds */
} occ_view_t;

/* Bytes of the shared state occ_map_share() needs for `n_readers` reader slots on `map`
 * (exact formula at the top of this header: OCC_SHARED_SNAPSHOTS copies of map->arena_bytes, two
 * dirty bitmaps and a fixed header). 0 for NULL, n_readers 0 or > OCC_SHARED_MAX_READERS, or
 * a size that overflows size_t. O(1). */
size_t occ_shared_bytes(const occ_map_t *map, unsigned n_readers);

/* Turn `map` (initialized, possibly holding content) into a single-writer / many-reader map
 * using `mem` (mem_bytes >= occ_shared_bytes(map, n_readers), any alignment, owned by the map
 * from now on; the map stays shared until occ_map_init() on it). Publishes the current content
 * as version 0. OCC_ERR_ARG for NULL, n_readers 0 or > OCC_SHARED_MAX_READERS; OCC_ERR_SCRATCH
 * when mem is too small; OCC_ERR_STATE when `map` is shared already; OCC_ERR_UNSUPPORTED when
 * built with OCC_SHARED=0. On error nothing changes. Call before any reader starts.
 * O(carved bytes) (the first copy). */
occ_err_t occ_map_share(occ_map_t *map, void *mem, size_t mem_bytes, unsigned n_readers);

/* Open a view of the latest published version for reader slot `reader` (< n_readers; one
 * thread or interrupt uses a slot at a time). Wait-free, O(1) (no loop; four atomic 32-bit
 * accesses and a header copy). OCC_ERR_ARG for NULL or a bad slot, OCC_ERR_STATE when `map` is not
 * shared or the slot is already open. On error `view` (when non-NULL) reads as a closed view (an
 * empty, unobserved map: every query answers UNKNOWN, fail closed) and holds no slot, except for
 * a slot already open: `view` is then left as it is (it may be the open view itself). */
occ_err_t occ_read_begin(occ_map_t *map, unsigned reader, occ_view_t *view);

/* The read-only map of an open view (NULL for NULL). */
const occ_map_t *occ_view_map(const occ_view_t *view);

/* Close the view: its snapshot may be reused by the writer from now on, and the view's map
 * reads as an empty unobserved map (queries answer UNKNOWN, handles taken on it answer
 * OCC_ERR_STATE). O(1). Nothing for NULL, a map that is not shared or a view already closed. */
void occ_read_end(occ_map_t *map, occ_view_t *view);

/* ---- Writer side (the writer's thread only) ------------------------------------------------ */

/* Write section: every write between begin and the matching end is one version, published at
 * the outermost end (nests; an integrator's evict + coarse + batch calls become one version,
 * so readers never see half a scan). Outside a section each successful write call is a version
 * of its own. The outermost end completes one version when a write inside it changed the map,
 * else it publishes nothing.
 * OCC_ERR_ARG for NULL, OCC_ERR_STATE when not shared or (end) no section is open. O(1) /
 * end: one publish, O(carved bytes). */
occ_err_t occ_map_write_begin(occ_map_t *map);
occ_err_t occ_map_write_end(occ_map_t *map);

/* Publish the writer's latest version now if it was deferred (every spare snapshot pinned).
 * True when readers opening a view now get the latest version; false when still deferred, the
 * map is not shared, or a section is open. O(carved bytes) when it copies, else O(readers). */
bool occ_map_publish(occ_map_t *map);

/* The version number of the writer's content: the latest completed version, or inside a section
 * whose writes changed the map, the version its end will publish (so a writer can record what
 * readers of that version must see before it goes out). 0 for NULL or a map that is not shared.
 * O(1). */
uint32_t occ_map_version(const occ_map_t *map);

typedef struct {
    uint32_t version;           /* latest completed version (occ_map_version) */
    uint32_t published_version; /* the version a view opened now gets */
    uint32_t publishes;         /* snapshot copies made */
    uint32_t deferred;          /* publishes put off: every spare snapshot was pinned */
    uint32_t open_views;        /* reader slots open (or entering) right now */
    unsigned n_readers;
    size_t copied_bytes_last;   /* bytes the last publish copied */
} occ_shared_info_t;

/* The latest version the writer completed (published or deferred: occ_shared_info()'s
 * `version`), for any reader thread or interrupt at any time: an open view is
 * occ_shared_latest_version(map) - view.version versions behind (the freshness rule at the top).
 * Never less than the version of a view opened before the call. 0 for NULL or a map that is
 * not shared (OCC_SHARED=0 included). Wait-free, O(1): one atomic 32-bit load. */
uint32_t occ_shared_latest_version(const occ_map_t *map);

/* Counters of a shared map (writer's thread). OCC_ERR_ARG for NULL, OCC_ERR_STATE when not
 * shared. O(readers). */
occ_err_t occ_shared_info(const occ_map_t *map, occ_shared_info_t *out);

/* ---- Budgets (issue 24) -------------------------------------------------------------------
 * Worst call-chain stack, Cortex-M4F / Cortex-M0+ (GCC 12 -Os, newlib nano; make cross checks
 * every line below against -fcallgraph-info), and the work per call.
 *   occ_map_share: stack <= 128 / 128 B; work: one copy of the carved blocks into a snapshot
 *   occ_map_write_end, occ_map_publish: stack <= 128 / 128 B; work: one publish (the 16-byte
 *       pieces written since the snapshot was last brought up to date), O(readers)
 *   occ_read_begin: stack <= 192 / 256 B; work: O(1), four atomic 32-bit accesses and a header copy
 *   occ_read_end, occ_map_write_begin, occ_map_version: stack <= 192 / 256 B; work: O(1)
 *   occ_shared_latest_version: stack <= 64 / 64 B; work: O(1), one atomic 32-bit load
 *   occ_shared_bytes, occ_view_map: stack <= 64 / 64 B; work: O(1)
 *   occ_shared_info: stack <= 64 / 64 B; work: O(readers)
 */

#ifdef __cplusplus
}
#endif
#endif
