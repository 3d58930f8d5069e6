#include "dsp/kfd.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

static int noise_valid(float q, float r)
{
  /* NaN fails every comparison; the upper bounds reject +inf. */
  return q >= 0.0f && q <= FLT_MAX && r > 0.0f && r <= FLT_MAX;
}

int kfd_init(kfd_t *s, const kfd_cfg_t *cfg)
{
  if (s == NULL || cfg == NULL || !noise_valid(cfg->q, cfg->r) || !cov2_p0_valid(cfg->p0)) {
    return -1;
  }
  s->q = cfg->q;
  s->r = cfg->r;
  s->p0 = cfg->p0;
  s->trace_max = 4.0f * cfg->p0;
  s->cov_resets = 0u;
  s->skipped = 0u;
  kfd_reset(s);
  return 0;
}

int kfd_set_noise(kfd_t *s, float q, float r)
{
  if (s == NULL || !noise_valid(q, r)) {
    return -1;
  }
  s->q = q;
  s->r = r;
  return 0;
}

void kfd_reset(kfd_t *s)
{
  s->x_i = 0.0f;
  s->x_q = 0.0f;
  cov2_restart(&s->cov, s->p0);
}

int kfd_preset(kfd_t *s, float in_phase, float quadrature)
{
  if (s == NULL || !isfinite(in_phase) || !isfinite(quadrature)) {
    return -1;
  }
  s->x_i = in_phase;
  s->x_q = quadrature;
  return 0;
}

void kfd_step(kfd_t *s, float z, float ref_sin, float ref_cos)
{
  /* Prediction with A = I: x- = x, P- = P + Q (paused above the trace bound). */
  const float qk = (cov2_trace(&s->cov) < s->trace_max) ? s->q : 0.0f;
  const float a11 = s->cov.p11 + qk;
  const float a12 = s->cov.p12;
  const float a22 = s->cov.p22 + qk;

  const float innov = z - (s->x_i * ref_sin + s->x_q * ref_cos);
  const float g1 = a11 * ref_sin + a12 * ref_cos; /* g = P- r */
  const float g2 = a12 * ref_sin + a22 * ref_cos;
  const float sv = ref_sin * g1 + ref_cos * g2 + s->r; /* innovation variance */
  if (!cov2_usable(innov, sv)) {
    s->skipped++;
    return;
  }
  const float inv_sv = 1.0f / sv;
  const float k1 = g1 * inv_sv;
  const float k2 = g2 * inv_sv;
  s->x_i += k1 * innov;
  s->x_q += k2 * innov;

  /* Joseph form (5-11): M = I - K r', P = M P- M' + R K K'. T = M P- in full, then
   * only the upper triangle of T M'. */
  const float m11 = 1.0f - k1 * ref_sin;
  const float m12 = -k1 * ref_cos;
  const float m21 = -k2 * ref_sin;
  const float m22 = 1.0f - k2 * ref_cos;
  const float t11 = m11 * a11 + m12 * a12;
  const float t12 = m11 * a12 + m12 * a22;
  const float t21 = m21 * a11 + m22 * a12;
  const float t22 = m21 * a12 + m22 * a22;
  const float rk1 = s->r * k1;
  const float p11 = t11 * m11 + t12 * m12 + rk1 * k1;
  const float p12 = t11 * m21 + t12 * m22 + rk1 * k2;
  const float p22 = t21 * m21 + t22 * m22 + s->r * k2 * k2;
  s->cov_resets += cov2_accept(&s->cov, p11, p12, p22, s->p0);
}
