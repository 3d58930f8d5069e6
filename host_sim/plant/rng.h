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
/* Next 64 bits (xoshiro256**). Inline: every noise source asks for it every sample. */
static inline uint64_t rng_next_u64(rng_t *r)
{
  uint64_t *s = r->s;
  const uint64_t m = s[1] * 5;
  const uint64_t result = ((m << 7) | (m >> 57)) * 9;
  const uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = (s[3] << 45) | (s[3] >> 19);
  return result;
}
/* Uniform on [0, 1) with 53 random bits. */
double rng_uniform(rng_t *r);
/* Standard normal N(0, 1). */
double rng_gauss(rng_t *r);

#endif /* PLANT_RNG_H */
