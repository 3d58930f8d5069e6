#include "signals.h"

#include <math.h>

#include "dsp/nco.h"

static const double k_two_pi = 6.283185307179586476925;

static uint64_t splitmix64(uint64_t *x)
{
  uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t next_u64(noise_rng_t *g)
{
  uint64_t *s = g->s;
  const uint64_t result = rotl(s[1] * 5u, 7) * 9u;
  const uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = rotl(s[3], 45);
  return result;
}

/* uniform in (0, 1) */
static double uniform(noise_rng_t *g)
{
  return ((double)(next_u64(g) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

void noise_seed(noise_rng_t *g, uint64_t seed)
{
  uint64_t x = seed;
  for (int i = 0; i < 4; i++) {
    g->s[i] = splitmix64(&x);
  }
  g->has_spare = 0;
  g->spare = 0.0;
}

void noise_fill(noise_rng_t *g, float *out, size_t n, double sigma)
{
  for (size_t i = 0; i < n; i++) {
    double z;
    if (g->has_spare) {
      z = g->spare;
      g->has_spare = 0;
    } else {
      const double r = sqrt(-2.0 * log(uniform(g)));
      const double t = k_two_pi * uniform(g);
      z = r * cos(t);
      g->spare = r * sin(t);
      g->has_spare = 1;
    }
    out[i] = (float)(sigma * z);
  }
}

int refs_fill(float *ref_sin, float *ref_cos, size_t n, double fc_hz, double fs_hz)
{
  nco_t nco;
  if (nco_init(&nco, &(nco_cfg_t){.freq_hz = fc_hz, .fs_hz = fs_hz, .phase_rad = 0.0}) != 0) {
    return -1;
  }
  for (size_t k = 0; k < n; k++) {
    nco_out_t o;
    nco_step(&nco, &o);
    ref_sin[k] = o.sin_wc;
    ref_cos[k] = o.cos_wc;
  }
  return 0;
}
