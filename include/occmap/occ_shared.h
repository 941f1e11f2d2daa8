/*
 * occ_shared.h - one writer, many readers on the same map (issue 20).
 *
 * INTERFACE DRAFT: the signatures below are fixed (the onboard loop, issue 21, is written against
 * them); the implementation, the design note and the exact memory formula are issue 20's.
 *
 * Model: the thread that calls the write functions of occ_core.h / occ_integrate.h / occ_evict.h /
 * occ_io.h on `map` is the only writer. Each write call is one version: it is either applied as a
 * whole and published at its end, or (on any error) not at all. A reader opens a view of the last
 * published version, runs any number of read-only queries on occ_view_map(view), and closes it.
 * Readers never block and never retry; the writer never waits for readers.
 */
#ifndef OCC_SHARED_H_INCLUDED
#define OCC_SHARED_H_INCLUDED

#include "occ_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most reader slots one shared map has. */
#define OCC_SHARED_MAX_READERS 16u

/* A reader's snapshot of one published version. Caller-owned (stack is fine); valid from
 * occ_read_begin() to occ_read_end(). Its map is a read-only handle: pass occ_view_map(view) to
 * queries, never to a write function. */
typedef struct {
    occ_map_t map;     /* the version's header (root, geometry); internal */
    uint32_t version;  /* the published version this view reads (counts write calls) */
    unsigned reader;   /* the slot it holds */
} occ_view_t;

/* Bytes of the shared state occ_map_share() needs for `n_readers` reader slots on `map`
 * (its arena size decides the bookkeeping of replaced blocks). 0 for bad arguments. */
size_t occ_shared_bytes(const occ_map_t *map, unsigned n_readers);

/* Turn `map` (initialized, possibly holding content) into a single-writer / many-reader map
 * using `mem` (mem_bytes >= occ_shared_bytes(map, n_readers), owned by the map from now on).
 * OCC_ERR_ARG for NULL, n_readers 0 or > OCC_SHARED_MAX_READERS; OCC_ERR_SCRATCH when mem is too
 * small. Call before any reader starts. */
occ_err_t occ_map_share(occ_map_t *map, void *mem, size_t mem_bytes, unsigned n_readers);

/* Open a view of the latest published version for reader slot `reader` (< n_readers; one
 * thread or interrupt uses a slot at a time). Wait-free, O(1). OCC_ERR_ARG for NULL or a bad
 * slot, OCC_ERR_STATE when `map` is not shared or the slot is already open. */
occ_err_t occ_read_begin(occ_map_t *map, unsigned reader, occ_view_t *view);

/* The read-only map of an open view. */
const occ_map_t *occ_view_map(const occ_view_t *view);

/* Close the view: the blocks its version shares with nothing newer may be reused from now on.
 * O(1). */
void occ_read_end(occ_map_t *map, occ_view_t *view);

#ifdef __cplusplus
}
#endif
#endif
