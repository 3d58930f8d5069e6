/* Reference signals for the demodulator tests, in double (header-only, host only).
 *
 * Carrier and references of the signal model (5-1) straight from libm, and seeded
 * Gaussian noise (splitmix64 + Box-Muller), so a test's input does not depend on the
 * firmware's NCO.
 */
#ifndef REF_SIGNAL_H
#define REF_SIGNAL_H

#include <math.h>
#include <stdint.h>

#define REF_PI 3.14159265358979323846

typedef struct {
  uint64_t state;
  double spare;
  int has_spare;
} ref_rng_t;

static inline void ref_rng_seed(ref_rng_t *g, uint64_t seed)
{
  g->state = seed;
  g->has_spare = 0;
  g->spare = 0.0;
}

static inline uint64_t ref_rng_next(ref_rng_t *g)
{
  uint64_t z = (g->state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/* Uniform in (0, 1). */
static inline double ref_rng_uniform(ref_rng_t *g)
{
  return ((double)(ref_rng_next(g) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

/* Standard normal. */
static inline double ref_rng_gauss(ref_rng_t *g)
{
  if (g->has_spare) {
    g->has_spare = 0;
    return g->spare;
  }
  const double r = sqrt(-2.0 * log(ref_rng_uniform(g)));
  const double t = 2.0 * REF_PI * ref_rng_uniform(g);
  g->spare = r * sin(t);
  g->has_spare = 1;
  return r * cos(t);
}

/* Reference pair of (5-1d) at sample k for a carrier f_hz sampled at fs_hz. The phase
 * w k is formed in double: for k up to 1e8 its rounding error stays below 1e-8 rad. */
static inline void ref_carrier(uint64_t k, double f_hz, double fs_hz, double *s, double *c)
{
  const double ph = 2.0 * REF_PI * f_hz / fs_hz * (double)k;
  *s = sin(ph);
  *c = cos(ph);
}

#endif /* REF_SIGNAL_H */
