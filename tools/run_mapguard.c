/* run_mapguard.c - the map's one writer and its readers, today behind a mutex (see the header's
 * merge note: this file alone becomes occ_shared.h calls). */
#include "run_mapguard.h"

int run_mapguard_init(run_mapguard_t *g, occ_map_t *map)
{
    g->map = map;
    g->version = 0;
    return pthread_mutex_init(&g->lock, NULL) == 0 ? 0 : -1;
}

void run_mapguard_destroy(run_mapguard_t *g)
{
    (void)pthread_mutex_destroy(&g->lock);
}

occ_map_t *run_write_begin(run_mapguard_t *g)
{
    (void)pthread_mutex_lock(&g->lock);
    return g->map;
}

void run_write_end(run_mapguard_t *g)
{
    g->version++;
    (void)pthread_mutex_unlock(&g->lock);
}

uint32_t run_write_next_version(const run_mapguard_t *g)
{
    return g->version + 1u;
}

void run_read_begin(run_mapguard_t *g, unsigned reader, run_view_t *v)
{
    (void)pthread_mutex_lock(&g->lock);
    v->map = g->map;
    v->version = g->version;
    v->reader = reader;
}

void run_read_end(run_mapguard_t *g, run_view_t *v)
{
    v->map = NULL;
    (void)pthread_mutex_unlock(&g->lock);
}
