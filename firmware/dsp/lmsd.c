#include "dsp/lmsd.h"

#include <math.h>
#include <stddef.h>
#include "dsp/ramfunc.h"

#include "dsp/math_const.h"

static int mu_valid(float mu)
{
  /* NaN fails both comparisons. */
  return mu > 0.0f && mu <= LMSD_MU_MAX;
}

int lmsd_init(lmsd_t *s, const lmsd_cfg_t *cfg)
{
  if (s == NULL || cfg == NULL || !mu_valid(cfg->mu)) {
    return -1;
  }
  s->two_mu = 2.0f * cfg->mu;
  lmsd_reset(s);
  return 0;
}

int lmsd_set_mu(lmsd_t *s, float mu)
{
  if (s == NULL || !mu_valid(mu)) {
    return -1;
  }
  /* W is the only state: keeping it makes the change bumpless. */
  s->two_mu = 2.0f * mu;
  return 0;
}

GYRO_RAMFUNC void lmsd_reset(lmsd_t *s)
{
  s->w_i = 0.0f;
  s->w_q = 0.0f;
}

int lmsd_preset(lmsd_t *s, float w_i, float w_q)
{
  if (s == NULL || !isfinite(w_i) || !isfinite(w_q)) {
    return -1;
  }
  s->w_i = w_i;
  s->w_q = w_q;
  return 0;
}

double lmsd_bandwidth_hz(double mu, double fs_hz)
{
  if (!(mu > 0.0 && mu <= (double)LMSD_MU_MAX) || !(fs_hz > 0.0) || !isfinite(fs_hz)) {
    return -1.0;
  }
  /* Pole radius of the exact LTI map (header): rho^2 = 1 - 2 mu. Baseband lag
   * (1 - rho)/(1 - rho z^-1) has |H|^2 = 1/2 where cos w = 1 - (1 - rho)^2 / (2 rho). */
  const double rho = sqrt(1.0 - 2.0 * mu);
  if (rho <= 0.0) {
    return fs_hz / 2.0; /* mu = 0.5: deadbeat, the whole band */
  }
  double c = 1.0 - (1.0 - rho) * (1.0 - rho) / (2.0 * rho);
  if (c < -1.0) {
    c = -1.0;
  }
  return fs_hz / (2.0 * FM_PI) * acos(c);
}
