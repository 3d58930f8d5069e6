/* The KFD long-run check shared by the unit test (10^6 samples) and the slow test
 * (10^7 samples): the same code at two lengths. Header-only test code; include after
 * cmocka.h (it asserts). */
#ifndef KFD_LONG_RUN_H
#define KFD_LONG_RUN_H

#include <math.h>
#include <stdint.h>

#include "demod_ref.h"
#include "demod_test_signal.h"
#include "dsp/kfd.h"

static inline double rel_err_x(const kfd_t *s, const double x[2])
{
  return rel_err_vec(s->x_i, s->x_q, x);
}

static inline double rel_err_p(const kfd_t *s, const double p[4])
{
  return rel_err_cov(s->cov.p11, s->cov.p12, s->cov.p22, p);
}

static inline void init_default(kfd_t *s)
{
  assert_int_equal(kfd_init(s, &(kfd_cfg_t){.q = KFD_Q_DEFAULT, .r = KFD_R_DEFAULT, .p0 = 1.0f}),
                   0);
}

/* Long run: P positive definite and bounded at every sample, never restarted, and the
 * end state equals a fresh double-precision Kalman filter started 2000 samples earlier
 * (the filter forgets its start at the rate of its pole, 0.982^2000 = 1.6e-16). */
static inline void run_long(uint64_t n)
{
  kfd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 34u);
  ref_kf_t r;
  const uint64_t ref_start = n - 2000u;
  float min_det_ratio = 1.0f, max_trace = 0.0f;
  for (uint64_t k = 0; k < n; k++) {
    const sample_t x = make_sample(k, &g);
    kfd_step(&s, x.d, x.s, x.c);
    if (k == ref_start) {
      ref_kf_init(&r, (double)KFD_Q_DEFAULT, (double)KFD_R_DEFAULT, 1.0);
    }
    if (k >= ref_start) {
      ref_kf_step(&r, x.d, x.s, x.c);
    }
    const float tr = s.cov.p11 + s.cov.p22;
    const float ratio = (s.cov.p11 * s.cov.p22 - s.cov.p12 * s.cov.p12) / (0.25f * tr * tr);
    if (!(s.cov.p11 > 0.0f && s.cov.p22 > 0.0f && ratio > 0.0f)) {
      fail_msg("P not positive definite at sample %llu", (unsigned long long)k);
    }
    if (k > 1000u) { /* steady state: the 2 wc ripple makes P mildly anisotropic */
      min_det_ratio = fminf(min_det_ratio, ratio);
      max_trace = fmaxf(max_trace, tr);
    }
  }
  print_message("%llu samples: min det/(tr/2)^2 %.3f, max trace %.4g, end P %.4g %.4g %.4g\n",
                (unsigned long long)n, (double)min_det_ratio, (double)max_trace,
                (double)s.cov.p11, (double)s.cov.p12, (double)s.cov.p22);
  assert_int_equal(s.cov_resets, 0);
  assert_int_equal(s.skipped, 0);
  assert_true(min_det_ratio > 0.9f);
  assert_true(max_trace < 0.05f);
  assert_true(rel_err_p(&s, r.p) < 1e-4);
  assert_true(rel_err_x(&s, r.x) < 1e-4);
}

#endif /* KFD_LONG_RUN_H */
