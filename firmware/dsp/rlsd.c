#include "dsp/rlsd.h"

#include <math.h>
#include <stddef.h>

static int lambda_valid(float lambda)
{
  return lambda > 0.0f && lambda <= 1.0f; /* NaN fails */
}

int rlsd_init(rlsd_t *s, const rlsd_cfg_t *cfg)
{
  if (s == NULL || cfg == NULL || !lambda_valid(cfg->lambda) || !cov2_p0_valid(cfg->p0)) {
    return -1;
  }
  s->lambda = cfg->lambda;
  s->inv_lambda = 1.0f / cfg->lambda;
  s->p0 = cfg->p0;
  s->trace_max = 4.0f * cfg->p0;
  s->cov_resets = 0u;
  s->skipped = 0u;
  rlsd_reset(s);
  return 0;
}

int rlsd_set_lambda(rlsd_t *s, float lambda)
{
  if (s == NULL || !lambda_valid(lambda)) {
    return -1;
  }
  s->lambda = lambda;
  s->inv_lambda = 1.0f / lambda;
  return 0;
}

void rlsd_reset(rlsd_t *s)
{
  /* Thesis initialisation: W(0) = 0, P(0) = I (scaled by p0). */
  s->w_i = 0.0f;
  s->w_q = 0.0f;
  cov2_restart(&s->cov, s->p0);
}

int rlsd_preset(rlsd_t *s, float in_phase, float quadrature)
{
  if (s == NULL || !isfinite(in_phase) || !isfinite(quadrature)) {
    return -1;
  }
  s->w_i = in_phase;
  s->w_q = quadrature;
  return 0;
}

void rlsd_step(rlsd_t *s, float d, float ref_sin, float ref_cos)
{
  const float err = d - (s->w_i * ref_sin + s->w_q * ref_cos);
  /* g = P(k-1) phi(k), with P symmetric */
  const float g1 = s->cov.p11 * ref_sin + s->cov.p12 * ref_cos;
  const float g2 = s->cov.p12 * ref_sin + s->cov.p22 * ref_cos;
  const float den = s->lambda + ref_sin * g1 + ref_cos * g2;
  /* den >= lambda > 0 while P is positive definite; a non-finite err or den means a
   * corrupted sample or reference: leave the estimate alone. */
  if (!cov2_usable(err, den)) {
    s->skipped++;
    return;
  }
  const float inv_den = 1.0f / den;
  const float k1 = g1 * inv_den;
  const float k2 = g2 * inv_den;
  s->w_i += k1 * err;
  s->w_q += k2 * err;

  /* Forgetting only below the trace bound (header: no covariance wind-up). */
  const float f = (cov2_trace(&s->cov) < s->trace_max) ? s->inv_lambda : 1.0f;
  const float p11 = (s->cov.p11 - k1 * g1) * f;
  const float p12 = (s->cov.p12 - k1 * g2) * f;
  const float p22 = (s->cov.p22 - k2 * g2) * f;
  s->cov_resets += cov2_accept(&s->cov, p11, p12, p22, s->p0);
}
