/* SPDX-License-Identifier: BSD-3-Clause */
/*
 * seeded_rng.h - a test's random numbers (splitmix64), seeded once per run from OCC_SEED or the
 * time and printed, so that a failure can be repeated. Header only: each test file that
 * includes it has its own state.
 */
#ifndef OCC_SEEDED_RNG_H_INCLUDED
#define OCC_SEEDED_RNG_H_INCLUDED

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static uint64_t seeded_rng_state;

static inline uint64_t rng_next(void)
{
    uint64_t z = (seeded_rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Seed from OCC_SEED (any strtoull base) or the time; prints "<name>: seed N". */
static inline void rng_seed(const char *name)
{
    const char *const env = getenv("OCC_SEED");
    const uint64_t seed = env != NULL ? strtoull(env, NULL, 0) : (uint64_t)time(NULL);
    seeded_rng_state = seed;
    printf("%s: seed %llu (set OCC_SEED to repeat)\n", name, (unsigned long long)seed);
}

#endif
