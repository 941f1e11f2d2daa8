/* SPDX-License-Identifier: BSD-3-Clause */
/* evict_fixture.h - what the eviction tests share (tests/support/evict_fixture.c). */
#ifndef EVICT_FIXTURE_H
#define EVICT_FIXTURE_H

#include <stddef.h>
#include <stdint.h>

#include "occmap/occmap.h"

/* xorshift64, seeded by ev_setup_seed (a CMocka group setup: OCC_SEED or the time, printed). */
uint32_t ev_rnd(void);
float ev_rndf(void); /* [0, 1) */
int ev_setup_seed(void **state);
/* The generator state, to replay the same draws. */
uint64_t ev_rng_get(void);
void ev_rng_set(uint64_t state);
/* The default configuration at resolution `res`. */
occ_map_config_t ev_cfg_res(float res);
/* Sort and de-duplicate codes; a code hit anywhere stays a hit (OctoMap's per-scan rule). */
size_t ev_sort_unique(occ_code_t *c, size_t n);

#endif
