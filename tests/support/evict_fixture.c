/* SPDX-License-Identifier: BSD-3-Clause */
/* evict_fixture.c - what the eviction tests share (test_evict.c, test_evict_auto.c): a seeded
 * random source, a map configuration and OctoMap's per-scan sort of key codes. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "evict_fixture.h"

static uint64_t rng_state;
static unsigned seed;

uint32_t ev_rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 11);
}

float ev_rndf(void)
{
    return (float)(ev_rnd() & 0xFFFFFFu) / (float)0x1000000u;
}

int ev_setup_seed(void **state)
{
    (void)state;
    const char *const env = getenv("OCC_SEED");
    seed = env != NULL ? (unsigned)strtoul(env, NULL, 0) : (unsigned)time(NULL);
    printf("seed %u (set OCC_SEED to repeat)\n", seed);
    rng_state = 0x9E3779B97F4A7C15ull ^ seed;
    return 0;
}

occ_map_config_t ev_cfg_res(const float res)
{
    occ_map_config_t c = occ_map_config_default();
    c.resolution_m = res;
    return c;
}

static int cmp_code(const void *a, const void *b)
{
    const occ_code_t x = *(const occ_code_t *)a & ~OCC_CODE_HIT_BIT;
    const occ_code_t y = *(const occ_code_t *)b & ~OCC_CODE_HIT_BIT;
    return x < y ? -1 : x > y;
}

/* Sort and de-duplicate; a code hit anywhere stays a hit (OctoMap's per-scan rule). */
size_t ev_sort_unique(occ_code_t *c, size_t n)
{
    qsort(c, n, sizeof *c, cmp_code);
    size_t u = 0;
    for (size_t i = 0; i < n; i++) {
        if (u > 0u && ((c[u - 1u] ^ c[i]) & ~OCC_CODE_HIT_BIT) == 0u) {
            c[u - 1u] |= c[i] & OCC_CODE_HIT_BIT;
        } else {
            c[u++] = c[i];
        }
    }
    return u;
}

uint64_t ev_rng_get(void)
{
    return rng_state;
}

void ev_rng_set(const uint64_t state)
{
    rng_state = state;
}
