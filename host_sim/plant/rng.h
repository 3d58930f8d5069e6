/* Seeded pseudo-random numbers for the plant's noise sources: xoshiro256** (Blackman &
 * Vigna) seeded through splitmix64, and standard normal deviates by the Marsaglia polar
 * method. Every noise source owns its own rng_t, seeded from the run seed and a stream
 * number, so switching one source on or off does not change the others' sequences. */
#ifndef PLANT_RNG_H
#define PLANT_RNG_H

#include <stdint.h>

typedef struct {
  uint64_t s[4];
  double spare; /* second deviate of the polar method */
  int has_spare;
} rng_t;

/* Seed from a run seed and a stream id (distinct streams are independent sequences). */
void rng_seed(rng_t *r, uint64_t seed, uint64_t stream);
uint64_t rng_next_u64(rng_t *r);
/* Uniform on [0, 1) with 53 random bits. */
double rng_uniform(rng_t *r);
/* Standard normal N(0, 1). */
double rng_gauss(rng_t *r);

#endif /* PLANT_RNG_H */
