/* SPDX-License-Identifier: BSD-3-Clause */
/* run_mapguard.h - every map access of `occmap run` goes through these calls.
 *
 * One writer (the mapping thread) and readers (the feed; the telemetry's pool counters) on the
 * single-writer / many-reader map of occmap/occ_shared.h: the map is shared with RUN_READERS
 * reader slots (two snapshot copies of the arena: memory is 3 x --arena-bytes in all), a write
 * section (occ_map_write_begin/end) makes each frame, with its evictions and partial retries, one
 * version, and a reader's view is the last published version: readers never wait for a frame
 * being integrated, and the writer never waits for readers. */
#ifndef OCC_TOOLS_RUN_MAPGUARD_H_INCLUDED
#define OCC_TOOLS_RUN_MAPGUARD_H_INCLUDED

#include "occmap/occmap.h"

/* Reader slots: the feed and the telemetry. */
enum { RUN_READER_FEED = 0, RUN_READER_STATS = 1, RUN_READERS = 2 };

typedef struct {
    occ_map_t *map;
    void *shared_mem; /* occ_shared_bytes(map, RUN_READERS), malloc'ed, owned here */
} run_mapguard_t;

/* A read: the map to query (read only) and the version it shows. */
typedef struct {
    const occ_map_t *map;
    uint32_t version;
    unsigned reader;
    occ_view_t view;
} run_view_t;

/* Share `map` (initialized or loaded; no reader running yet). 0, or -1 (no memory for the
 * snapshots, or occ_map_share refused). */
int run_mapguard_init(run_mapguard_t *g, occ_map_t *map);
/* After every thread using the map stopped: the map is left unusable as a shared map (its
 * snapshot memory is freed); only the writer's own content may be read or saved before this. */
void run_mapguard_destroy(run_mapguard_t *g);

/* The writer only: the map to write; write_end publishes what the section changed as one
 * version. */
occ_map_t *run_write_begin(run_mapguard_t *g);
void run_write_end(run_mapguard_t *g);
/* Inside a write section: the version its write_end will publish (after a write changed the
 * map; before that, the latest completed version). */
uint32_t run_write_next_version(const run_mapguard_t *g);

/* Any reader slot: a view of the latest published version, until read_end. On an error the
 * view is an empty unobserved map (every query answers UNKNOWN: fail closed). */
void run_read_begin(run_mapguard_t *g, unsigned reader, run_view_t *v);
void run_read_end(run_mapguard_t *g, run_view_t *v);
/* The telemetry's reader slot: the version a view opened now gets. */
uint32_t run_read_version(run_mapguard_t *g);

#endif
