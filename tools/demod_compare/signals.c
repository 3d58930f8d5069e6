#include "signals.h"

#include <math.h>

#include "dsp/nco.h"

void noise_seed(noise_rng_t *g, uint64_t seed) { rng_seed(g, seed, 0u); }

void noise_fill(noise_rng_t *g, float *out, size_t n, double sigma)
{
  for (size_t i = 0; i < n; i++) {
    out[i] = (float)(sigma * rng_gauss(g));
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
