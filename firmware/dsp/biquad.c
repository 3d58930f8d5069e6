#include "dsp/biquad.h"

#include <math.h>
#include <stddef.h>
#include "dsp/ramfunc.h"

static int coeffs_finite(const biquad_coeffs_t *c)
{
  return isfinite(c->b0) && isfinite(c->b1) && isfinite(c->b2) && isfinite(c->a1) &&
         isfinite(c->a2);
}

int biquad_sections_ok(const biquad_coeffs_t *c, uint32_t n)
{
  if (c == NULL || n == 0u || n > BIQUAD_MAX_SECTIONS) {
    return 0;
  }
  for (uint32_t i = 0; i < n; i++) {
    if (!coeffs_finite(&c[i])) {
      return 0;
    }
  }
  return 1;
}

int biquad_cascade_init(biquad_cascade_t *bq, const biquad_coeffs_t *sections, uint32_t n)
{
  if (bq == NULL || !biquad_sections_ok(sections, n)) {
    return -1;
  }
  bq->num_sections = n;
  for (uint32_t i = 0; i < n; i++) {
    bq->coeffs[i] = sections[i];
  }
  biquad_cascade_reset(bq, 0.0f);
  return 0;
}

GYRO_RAMFUNC void biquad_cascade_reset(biquad_cascade_t *bq, float x_steady)
{
  if (bq == NULL || bq->num_sections > BIQUAD_MAX_SECTIONS) {
    return; /* not a cascade biquad_cascade_init accepted */
  }
  biquad_sections_reset(bq->coeffs, bq->state, bq->num_sections, x_steady);
}

GYRO_RAMFUNC void biquad_sections_reset(const biquad_coeffs_t *restrict c,
                                        biquad_state_t *restrict s, uint32_t n, float x_steady)
{
  /* A non-finite level would poison the state until the next init: clear instead. */
  float x = isfinite(x_steady) ? x_steady : 0.0f;
  /* Steady state of one section for constant input x: y = g x with the section's DC gain
   * g = (b0 + b1 + b2) / (1 + a1 + a2); then s2 = b2 x - a2 y and s1 = y - b0 x. */
  for (uint32_t i = 0; i < n; i++) {
    const float den = 1.0f + c[i].a1 + c[i].a2;
    const float y = (x == 0.0f || den == 0.0f) ? 0.0f : x * (c[i].b0 + c[i].b1 + c[i].b2) / den;
    s[i].s2 = c[i].b2 * x - c[i].a2 * y;
    s[i].s1 = y - c[i].b0 * x;
    x = y;
  }
}
