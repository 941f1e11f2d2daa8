/* SPDX-License-Identifier: BSD-3-Clause */
/* run_mapguard.c - the map's one writer and its readers on the shared map (occ_shared.h). */
#include <stdlib.h>

#include "run_mapguard.h"

int run_mapguard_init(run_mapguard_t *g, occ_map_t *map)
{
    g->map = map;
    const size_t bytes = occ_shared_bytes(map, RUN_READERS);
    g->shared_mem = bytes > 0u ? malloc(bytes) : NULL;
    if (g->shared_mem == NULL || occ_map_share(map, g->shared_mem, bytes, RUN_READERS) != OCC_OK) {
        free(g->shared_mem);
        g->shared_mem = NULL;
        return -1;
    }
    return 0;
}

void run_mapguard_destroy(run_mapguard_t *g)
{
    free(g->shared_mem);
    g->shared_mem = NULL;
}

occ_map_t *run_write_begin(run_mapguard_t *g)
{
    (void)occ_map_write_begin(g->map);
    return g->map;
}

void run_write_end(run_mapguard_t *g)
{
    (void)occ_map_write_end(g->map);
}

uint32_t run_write_next_version(const run_mapguard_t *g)
{
    return occ_map_version(g->map);
}

void run_read_begin(run_mapguard_t *g, unsigned reader, run_view_t *v)
{
    (void)occ_read_begin(g->map, reader, &v->view); /* on error: an empty map, fail closed */
    v->map = occ_view_map(&v->view);
    v->version = v->view.version;
    v->reader = reader;
}

void run_read_end(run_mapguard_t *g, run_view_t *v)
{
    occ_read_end(g->map, &v->view);
    v->map = NULL;
}

uint32_t run_read_version(run_mapguard_t *g)
{
    run_view_t v;
    run_read_begin(g, RUN_READER_STATS, &v);
    const uint32_t version = v.version;
    run_read_end(g, &v);
    return version;
}
