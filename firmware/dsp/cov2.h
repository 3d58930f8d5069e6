/* The 2x2 covariance P of the RLS and Kalman demodulators (rlsd.h: thesis 5.4.2; kfd.h:
 * 5.4.3) and the health guards both apply to it, once each, per sample.
 *
 * P is symmetric: only its upper triangle p11, p12, p22 is kept, so symmetry holds by
 * construction. The guards (cheap compares, no effect in normal operation):
 * - a sample is used only with a finite innovation and a positive, finite innovation
 *   variance (the RLS denominator lambda + phi' P phi, the Kalman r' P- r + R); anything
 *   else is a corrupted sample or reference, and the estimate is left alone;
 * - an updated P is kept only while positive definite (p11 > 0, p22 > 0,
 *   p11 p22 > p12^2; a NaN fails each compare), else P restarts at p0 I.
 * Single precision, no libm call (fabsf is one VABS on the Cortex-M4F).
 */
#ifndef COV2_H
#define COV2_H

#include <float.h>
#include <math.h>
#include <stdint.h>

/* Largest restart value p0 of P's diagonal the demodulators accept. */
#define COV2_P0_MAX 1.0e6f

typedef struct {
  float p11, p12, p22; /* upper triangle of the symmetric P */
} cov2_t;

static inline int cov2_p0_valid(float p0) { return p0 > 0.0f && p0 <= COV2_P0_MAX; }

/* P = p0 I. */
static inline void cov2_restart(cov2_t *c, float p0)
{
  c->p11 = p0;
  c->p12 = 0.0f;
  c->p22 = p0;
}

static inline float cov2_trace(const cov2_t *c) { return c->p11 + c->p22; }

/* The sample can be used: innovation finite, its variance positive and finite. */
static inline int cov2_usable(float innovation, float variance)
{
  return fabsf(innovation) <= FLT_MAX && variance > 0.0f && variance <= FLT_MAX;
}

/* Keep the updated P if it is positive definite, else restart at p0 I. Returns 1 for a
 * restart (the caller counts them), else 0. */
static inline uint32_t cov2_accept(cov2_t *c, float p11, float p12, float p22, float p0)
{
  if (p11 > 0.0f && p22 > 0.0f && p11 * p22 > p12 * p12) {
    c->p11 = p11;
    c->p12 = p12;
    c->p22 = p22;
    return 0u;
  }
  cov2_restart(c, p0);
  return 1u;
}

#endif /* COV2_H */
