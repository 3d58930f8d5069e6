/* Per-sample math without libm.
 *
 * fm_sqrtf: one VSQRT.F32 on the Cortex-M4F (14 cycles) and SQRTSS on x86; the firmware
 *   is built with -fno-math-errno so the builtin never falls back to a libm call.
 * fm_atan2f: octant reduction + odd minimax polynomial, max error 2e-6 rad (checked
 *   against double atan2 in tests/unit/test_fastmath.c); one divide (14 cycles).
 * fm_isfinite: exponent-field test on the bit pattern, safe under -ffast-math.
 */
#ifndef FASTMATH_H
#define FASTMATH_H

#include <stdint.h>
#include <string.h>

#include "dsp/math_const.h"


static inline float fm_sqrtf(float x) { return __builtin_sqrtf(x); }

static inline int fm_isfinite(float x)
{
  uint32_t u;
  memcpy(&u, &x, sizeof u);
  return (u & 0x7F800000u) != 0x7F800000u;
}

static inline float fm_absf(float x) { return x < 0.0f ? -x : x; }

/* |x| where only a comparison reads it: one VABS (fm_absf's compare, flag move and
 * conditional negate are four instructions). It clears the sign of -0 and of a NaN,
 * which fm_absf keeps: no comparison can tell them apart (-0 == +0, and a NaN compares
 * false either way), so either gives the same verdict. */
static inline float fm_absf_cmp(float x) { return __builtin_fabsf(x); }

static inline float fm_clampf(float x, float lo, float hi)
{
  return x < lo ? lo : (x > hi ? hi : x);
}

static inline float fm_maxf(float a, float b) { return a > b ? a : b; }

/* atan(t) for t in [-1, 1]: odd polynomial in t, minimax coefficients for
 * atan(t)/t on t^2 in [0, 1], fitted by iteratively reweighted least squares
 * (max abs error 1.7e-6 rad). */
static inline float fm_atan_unit(float t)
{
  const float t2 = t * t;
  return t * (0.99997726f +
              t2 * (-0.33262347f +
                    t2 * (0.19354346f +
                          t2 * (-0.11643287f + t2 * (0.05265332f + t2 * -0.01172120f)))));
}

/* atan2(y, x) in (-pi, pi]; returns 0 for (0, 0). */
static inline float fm_atan2f(float y, float x)
{
  const float ax = fm_absf(x), ay = fm_absf(y);
  if (ax == 0.0f && ay == 0.0f) {
    return 0.0f;
  }
  float a;
  if (ay <= ax) {
    a = fm_atan_unit(ay / ax);
  } else {
    a = 0.5f * FM_PI_F - fm_atan_unit(ax / ay);
  }
  if (x < 0.0f) {
    a = FM_PI_F - a;
  }
  return y < 0.0f ? -a : a;
}

/* Wrap an angle to (-pi, pi] for angles within a few turns (no loop over many turns). */
static inline float fm_wrap_pi(float a)
{
  while (a > FM_PI_F) a -= FM_TWO_PI_F;
  while (a <= -FM_PI_F) a += FM_TWO_PI_F;
  return a;
}

#endif /* FASTMATH_H */
