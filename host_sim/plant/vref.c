/* The shared voltage reference's noise (vref.h). */
#include "plant/vref.h"

#include <stddef.h>

int vref_check(const vref_cfg_t *cfg, double fs_hz)
{
  return cfg == NULL ? -1 : flicker_check(&cfg->noise, fs_hz);
}

int vref_init(vref_t *v, const vref_cfg_t *cfg, double fs_hz, uint64_t seed)
{
  if (v == NULL || vref_check(cfg, fs_hz) != 0) return -1;
  v->active = cfg->noise.white_rthz > 0.0 || cfg->noise.flicker_1hz_rthz > 0.0;
  v->rel = 0.0;
  return flicker_init(&v->gen, &cfg->noise, fs_hz, seed, VREF_RNG_STREAM);
}

double vref_step(vref_t *v)
{
  if (!v->active) return 0.0;
  v->rel = flicker_step(&v->gen);
  return v->rel;
}
