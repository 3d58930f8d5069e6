/* The test signal of the RLSD/KFD tests (5-1) and their error measures: one place for
 * what the unit and the long-run tests of both demodulators share. Header-only. */
#ifndef DEMOD_TEST_SIGNAL_H
#define DEMOD_TEST_SIGNAL_H

#include <math.h>
#include <stdint.h>

#include "ref_signal.h"

#define FS_HZ 50000.0
#define FC_HZ 1750.0
#define A1 0.01
#define A2 (-0.004)
#define SIGMA 0.002

/* One sample of the test signal (5-1), rounded to float as the firmware sees it. */
typedef struct {
  float d, s, c;
} sample_t;

static inline sample_t make_sample(uint64_t k, ref_rng_t *g)
{
  double rs, rc;
  ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
  const sample_t x = {(float)(A1 * rs + A2 * rc + SIGMA * ref_rng_gauss(g)), (float)rs,
                      (float)rc};
  return x;
}

/* |estimate - reference| / |reference| of the 2-vector [in-phase, quadrature]. */
static inline double rel_err_vec(float e_i, float e_q, const double r[2])
{
  const double di = (double)e_i - r[0], dq = (double)e_q - r[1];
  return sqrt(di * di + dq * dq) / sqrt(r[0] * r[0] + r[1] * r[1]);
}

/* Frobenius relative error of a symmetric 2x2 covariance {p11, p12, p22} against the
 * row-major reference p[4]. */
static inline double rel_err_cov(float p11, float p12, float p22, const double p[4])
{
  const double e11 = (double)p11 - p[0], e12 = (double)p12 - p[1], e22 = (double)p22 - p[3];
  const double n = sqrt(p[0] * p[0] + 2.0 * p[1] * p[1] + p[3] * p[3]);
  return sqrt(e11 * e11 + 2.0 * e12 * e12 + e22 * e22) / n;
}

#endif /* DEMOD_TEST_SIGNAL_H */
