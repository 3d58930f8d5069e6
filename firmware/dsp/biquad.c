#include "dsp/biquad.h"

#include <math.h>
#include <stddef.h>
#include "dsp/ramfunc.h"

static int coeffs_finite(const biquad_coeffs_t *c)
{
  return isfinite(c->b0) && isfinite(c->b1) && isfinite(c->b2) && isfinite(c->a1) &&
         isfinite(c->a2);
}

int biquad_cascade_init(biquad_cascade_t *bq, const biquad_coeffs_t *sections, uint32_t n)
{
  if (bq == NULL || sections == NULL || n == 0u || n > BIQUAD_MAX_SECTIONS) {
    return -1;
  }
  for (uint32_t i = 0; i < n; i++) {
    if (!coeffs_finite(&sections[i])) {
      return -1;
    }
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
  /* A non-finite level would poison the state until the next init: clear instead. */
  float x = isfinite(x_steady) ? x_steady : 0.0f;
  /* Steady state of one section for constant input x: y = g x with the section's DC gain
   * g = (b0 + b1 + b2) / (1 + a1 + a2); then s2 = b2 x - a2 y and s1 = y - b0 x. */
  for (uint32_t i = 0; i < bq->num_sections; i++) {
    const biquad_coeffs_t *c = &bq->coeffs[i];
    const float den = 1.0f + c->a1 + c->a2;
    const float y = (x == 0.0f || den == 0.0f) ? 0.0f : x * (c->b0 + c->b1 + c->b2) / den;
    bq->state[i].s2 = c->b2 * x - c->a2 * y;
    bq->state[i].s1 = y - c->b0 * x;
    x = y;
  }
}
