/* The RLSD long-run check shared by the unit test (10^6 samples) and the slow test
 * (10^7 samples): the same code at two lengths. Header-only test code; include after
 * cmocka.h (it asserts). */
#ifndef RLSD_LONG_RUN_H
#define RLSD_LONG_RUN_H

#include <math.h>
#include <stdint.h>

#include "demod_ref.h"
#include "demod_test_signal.h"
#include "dsp/rlsd.h"

static inline double rel_err_w(const rlsd_t *s, const double w[2])
{
  return rel_err_vec(s->w_i, s->w_q, w);
}

static inline double rel_err_p(const rlsd_t *s, const double p[4])
{
  return rel_err_cov(s->cov.p11, s->cov.p12, s->cov.p22, p);
}

static inline void init_default(rlsd_t *s)
{
  assert_int_equal(rlsd_init(s, &(rlsd_cfg_t){.lambda = RLSD_LAMBDA_DEFAULT, .p0 = 1.0f}), 0);
}

/* Long run: P stays positive definite and bounded at every sample, no restart is ever
 * needed, and the state at the end is what a fresh double-precision RLS started 2000
 * samples earlier computes (P forgets its start as lambda^k: 0.982^2000 = 1.6e-16). */
static inline void run_long(uint64_t n)
{
  rlsd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 24u);
  ref_rls_t r;
  const uint64_t ref_start = n - 2000u;
  float min_det_ratio = 1.0f, max_trace = 0.0f;
  for (uint64_t k = 0; k < n; k++) {
    const sample_t x = make_sample(k, &g);
    rlsd_step(&s, x.d, x.s, x.c);
    if (k == ref_start) {
      ref_rls_init(&r, (double)RLSD_LAMBDA_DEFAULT, 1.0);
    }
    if (k >= ref_start) {
      ref_rls_step(&r, x.d, x.s, x.c);
    }
    const float det = s.cov.p11 * s.cov.p22 - s.cov.p12 * s.cov.p12;
    const float tr = s.cov.p11 + s.cov.p22;
    /* det / (trace/2)^2 is 1 for a multiple of I and 0 at the loss of definiteness */
    const float ratio = det / (0.25f * tr * tr);
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
  /* steady state P ~ 2 (1 - lambda) I = 0.036 I, with a small 2 wc ripple */
  assert_true(max_trace < 0.1f);
  assert_true(rel_err_p(&s, r.p) < 1e-4);
  assert_true(rel_err_w(&s, r.w) < 1e-4);
}

#endif /* RLSD_LONG_RUN_H */
