/* SPDX-License-Identifier: BSD-3-Clause */
/* test_rng.h - the tests' xorshift64 generator (one state per test binary, seeded by the test). */
#ifndef OCC_TEST_RNG_H_INCLUDED
#define OCC_TEST_RNG_H_INCLUDED

#include <stdint.h>

static uint64_t rng_state = 1u;

static inline uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

/* Uniform in [lo, hi). */
static inline float urand(const float lo, const float hi)
{
    return lo + (hi - lo) * (float)((double)(rnd() >> 11) / 9007199254740992.0);
}

/* Uniform in [0, n), n > 0 (as unsigned, for loops and sizes on 32-bit hosts too). */
static inline unsigned rnd_below(const unsigned n)
{
    return (unsigned)(rnd() % n);
}

#endif
