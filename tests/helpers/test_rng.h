/* The one random generator of the tests: SplitMix64 (Steele, Lea, Flood 2014) - the same
 * numbers on every platform and libc, good from any seed (0 and small ones included), one
 * state per caller so that tests never share a sequence. */
#ifndef CADMORPH_TEST_RNG_H
#define CADMORPH_TEST_RNG_H

#include <stdint.h>

static inline uint64_t test_rng_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* uniform in [0, 1), 53 bits */
static inline double test_rng_uniform(uint64_t *state)
{
    return (double)(test_rng_next(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* uniform in [lo, hi) */
static inline double test_rng_range(uint64_t *state, double lo, double hi)
{
    return lo + (hi - lo) * test_rng_uniform(state);
}

#endif
