/* SPDX-License-Identifier: BSD-3-Clause */
/* integrate_fixture.h - what the integration tests share (tests/support/integrate_fixture.c). */
#ifndef INTEGRATE_FIXTURE_H
#define INTEGRATE_FIXTURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "occmap/occmap.h"

typedef struct {
    occ_vec3_t *p;
    size_t n;
    occ_vec3_t origin;
} it_cloud_t;

/* OctoMap's sensor model exactly: logit(0.7), logit(0.4), clamps logit(0.1192), logit(0.971). */
occ_map_config_t it_octo_cfg(float res);
/* occ_map_init() with it_octo_cfg(res); a failure fails the test. */
void it_init_map(occ_map_t *m, uint8_t *arena, size_t bytes, float res);
/* build/data/scan.dat, every `every`-th point, origin 0 (false with a SKIP line if unreadable;
 * the caller frees c->p). */
bool it_load_scan(it_cloud_t *c, size_t every);
/* Frame `frame` of the TUM fr2 pioneer_slam2 depth sequence at pixel stride `stride` (false with
 * a SKIP line when ../shared is absent; the caller frees c->p). */
bool it_load_tum(it_cloud_t *c, size_t frame, unsigned stride);
/* Observed leaves of x that y does not hold with the same value (exact). */
size_t it_diff_into(const occ_map_t *x, const occ_map_t *y);
/* Differences between two of our maps (exact values). */
size_t it_diff_maps(const occ_map_t *a, const occ_map_t *b);
/* Differences between our map and OctoMap's tree t (oracle_rays.h), both ways: every OctoMap
 * leaf read from ours at its level, every leaf of ours searched in t; values within tol (the
 * 8-bit mode: its documented rounding), states equal. Prints the first five. */
size_t it_diff_oracle(const occ_map_t *m, void *t, float tol);
/* Checksum of everything a walk reports; *nodes = nodes walked. */
uint64_t it_map_digest(const occ_map_t *m, size_t *nodes);
/* CMocka setup/teardown that print each test's CPU time. */
int it_timer_setup(void **state);
int it_timer_teardown(void **state);
/* A test file's buffers: two map arenas and a scratch buffer (malloc'd by it_run_tests). */
typedef struct {
    uint8_t **arena_a, **arena_b, **scratch;
    size_t arena_bytes, scratch_bytes;
} it_buffers_t;
struct CMUnitTest;
/* Allocate the buffers, run the n tests as one CMocka group, free them: CMocka's result, or 1
 * when the buffers cannot be allocated. */
int it_run_tests(const char *name, const struct CMUnitTest *tests, size_t n, it_buffers_t b);

#endif
