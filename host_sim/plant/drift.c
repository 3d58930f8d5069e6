/* First-order Gauss-Markov drift (drift.h). */
#include "plant/drift.h"

#include <math.h>
#include <stddef.h>

int drift_check(const drift_cfg_t *c)
{
  if (c == NULL) return -1;
  if (!(isfinite(c->sigma) && c->sigma >= 0.0)) return -1;
  if (!(isfinite(c->tau_s) && c->tau_s > 0.0)) return -1;
  if (!(isfinite(c->dt_s) && c->dt_s > 0.0)) return -1;
  return 0;
}

int drift_init(drift_t *d, const drift_cfg_t *c, uint64_t seed, uint64_t stream)
{
  if (d == NULL || drift_check(c) != 0) return -1;
  d->active = c->sigma > 0.0;
  d->phi = exp(-c->dt_s / c->tau_s);
  /* 1 - phi^2 without cancellation for dt << tau */
  d->kick = c->sigma * sqrt(-expm1(-2.0 * c->dt_s / c->tau_s));
  d->x = 0.0;
  rng_seed(&d->rng, seed, stream);
  return 0;
}

double drift_step(drift_t *d)
{
  if (!d->active) return 0.0;
  d->x = d->phi * d->x + d->kick * rng_gauss(&d->rng);
  return d->x;
}
