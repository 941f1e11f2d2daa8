/* run_mapguard.h - every map access of `occmap run` goes through these four calls.
 *
 * One writer (the mapping thread) and readers (the feed; the telemetry's pool counters). Today
 * the body is a pthread mutex around the map, copying nothing: a reader waits while a write
 * call runs, so the feed's deadline can slip by one integration (the telemetry reports it).
 * MERGE NOTE (issue 20): the lock-free map of occmap/occ_shared.h replaces the bodies in
 * run_mapguard.c alone: init -> occ_map_share(map, mem, occ_shared_bytes(map, 2), 2);
 * write_begin/write_end -> nothing (each write call publishes itself; version from the
 * latest view); read_begin -> occ_read_begin(map, reader, &g->view) and return
 * occ_view_map(&view) and view.version; read_end -> occ_read_end. No caller changes. */
#ifndef OCC_TOOLS_RUN_MAPGUARD_H_INCLUDED
#define OCC_TOOLS_RUN_MAPGUARD_H_INCLUDED

#include <pthread.h>

#include "occmap/occmap.h"

/* Reader slots: the feed and the telemetry. */
enum { RUN_READER_FEED = 0, RUN_READER_STATS = 1, RUN_READERS = 2 };

typedef struct {
    occ_map_t *map;
    pthread_mutex_t lock;
    uint32_t version;   /* write sections ended (each may have changed the map) */
} run_mapguard_t;

/* A read: the map to query (read only) and the version it shows. */
typedef struct {
    const occ_map_t *map;
    uint32_t version;
    unsigned reader;
} run_view_t;

/* 0, or -1 (the lock could not be made). */
int run_mapguard_init(run_mapguard_t *g, occ_map_t *map);
void run_mapguard_destroy(run_mapguard_t *g);

/* The writer only: the map to write; write_end publishes it as version + 1. */
occ_map_t *run_write_begin(run_mapguard_t *g);
void run_write_end(run_mapguard_t *g);
/* Inside a write section: the version its write_end will publish. */
uint32_t run_write_next_version(const run_mapguard_t *g);

/* Any reader slot: a view of the latest published version, until read_end. */
void run_read_begin(run_mapguard_t *g, unsigned reader, run_view_t *v);
void run_read_end(run_mapguard_t *g, run_view_t *v);

#endif
