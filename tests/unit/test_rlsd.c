#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include <math.h>

#include "demod_ref.h"
#include "dsp/rlsd.h"
#include "demod_test_signal.h"
#include "rlsd_long_run.h"


static void test_converges_to_true_amplitudes(void **state)
{
  (void)state;
  rlsd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 21u);
  double sum_i = 0.0, sum_q = 0.0;
  const uint64_t n = 40000u, skip = 1000u;
  for (uint64_t k = 0; k < n; k++) {
    const sample_t x = make_sample(k, &g);
    rlsd_step(&s, x.d, x.s, x.c);
    if (k >= skip) {
      sum_i += rlsd_in_phase(&s);
      sum_q += rlsd_quadrature(&s);
    }
  }
  assert_true(fabs(sum_i / (double)(n - skip) - A1) < 1e-4);
  assert_true(fabs(sum_q / (double)(n - skip) - A2) < 1e-4);
  assert_int_equal(s.cov_resets, 0);
  assert_int_equal(s.skipped, 0);
}

/* Float kernel against the double Eigen RLS on the same float inputs: W within 1e-4
 * relative at every sample after convergence, P within 1e-4 relative. */
static void test_agrees_with_eigen_rls(void **state)
{
  (void)state;
  rlsd_t s;
  init_default(&s);
  ref_rls_t r;
  ref_rls_init(&r, (double)RLSD_LAMBDA_DEFAULT, 1.0);
  ref_rng_t g;
  ref_rng_seed(&g, 22u);
  double worst_w = 0.0, worst_p = 0.0;
  for (uint64_t k = 0; k < 10000u; k++) {
    const sample_t x = make_sample(k, &g);
    rlsd_step(&s, x.d, x.s, x.c);
    ref_rls_step(&r, x.d, x.s, x.c);
    if (k >= 500u) {
      worst_w = fmax(worst_w, rel_err_w(&s, r.w));
      worst_p = fmax(worst_p, rel_err_p(&s, r.p));
    }
  }
  print_message("worst relative difference to Eigen RLS: W %.2e, P %.2e\n", worst_w, worst_p);
  assert_true(worst_w < 1e-4);
  assert_true(worst_p < 1e-4);
}

/* The recursion solves (5-10): the double reference RLS equals the batch weighted
 * least-squares solution (with the P(0) prior), and the float kernel agrees with it. */
static void test_matches_batch_weighted_least_squares(void **state)
{
  (void)state;
  const size_t n = 3000u;
  double *d = malloc(n * sizeof *d), *rs = malloc(n * sizeof *rs), *rc = malloc(n * sizeof *rc);
  assert_non_null(d);
  assert_non_null(rs);
  assert_non_null(rc);
  rlsd_t s;
  init_default(&s);
  ref_rls_t r;
  ref_rls_init(&r, (double)RLSD_LAMBDA_DEFAULT, 1.0);
  ref_rng_t g;
  ref_rng_seed(&g, 23u);
  for (size_t k = 0; k < n; k++) {
    const sample_t x = make_sample(k, &g);
    d[k] = x.d;
    rs[k] = x.s;
    rc[k] = x.c;
    rlsd_step(&s, x.d, x.s, x.c);
    ref_rls_step(&r, x.d, x.s, x.c);
  }
  double w[2], p[4];
  assert_int_equal(ref_wls_solve(d, rs, rc, n, (double)RLSD_LAMBDA_DEFAULT, 1.0, w, p), 0);
  assert_true(fabs(r.w[0] - w[0]) < 1e-10 && fabs(r.w[1] - w[1]) < 1e-10);
  assert_true(fabs(r.p[0] - p[0]) < 1e-10 && fabs(r.p[1] - p[1]) < 1e-10);
  assert_true(rel_err_w(&s, w) < 1e-4);
  assert_true(rel_err_p(&s, p) < 1e-4);
  /* and the estimate is the truth within the window's noise */
  assert_true(fabs(w[0] - A1) < 1e-3 && fabs(w[1] - A2) < 1e-3);
  free(d);
  free(rs);
  free(rc);
}


/* 1e6 samples here (well under a second with ASan); the 1e7-sample run of the same
 * check is tests/slow/test_rlsd_long_run.c (ctest -L slow). */
static void test_covariance_healthy_long_run(void **state)
{
  (void)state;
  run_long(1000000u);
}

/* A reference that excites one direction only (a DC "carrier"): plain RLS would
 * grow p22 as lambda^-k and overflow within 5000 samples; the trace bound holds it,
 * and the excited component is still estimated (once forgetting pauses the kernel is a
 * growing-window least squares, whose float increments stall near 1e-4 relative). */
static void test_covariance_bounded_without_excitation(void **state)
{
  (void)state;
  rlsd_t s;
  init_default(&s);
  for (int k = 0; k < 200000; k++) {
    rlsd_step(&s, 0.01f, 1.0f, 0.0f);
    assert_true(s.cov.p11 > 0.0f && s.cov.p22 > 0.0f &&
                s.cov.p11 + s.cov.p22 <= 4.0f / 0.982f + 1e-5f);
  }
  assert_true(isfinite(s.w_i) && fabsf(s.w_i - 0.01f) < 2e-6f);
  assert_int_equal(s.cov_resets, 0);
}

static void test_non_finite_sample_skipped(void **state)
{
  (void)state;
  rlsd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 25u);
  for (uint64_t k = 0; k < 1000u; k++) {
    const sample_t x = make_sample(k, &g);
    rlsd_step(&s, x.d, x.s, x.c);
  }
  rlsd_t before = s;
  rlsd_step(&s, NAN, 0.6f, 0.8f);
  rlsd_step(&s, INFINITY, 0.6f, 0.8f);
  rlsd_step(&s, 0.01f, NAN, 0.8f);
  assert_int_equal(s.skipped, 3);
  before.skipped = 3;
  assert_memory_equal(&s, &before, sizeof s);
}

/* set_lambda keeps W and P; reset and preset do what they say. */
static void test_set_lambda_bumpless_reset_preset(void **state)
{
  (void)state;
  rlsd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 26u);
  for (uint64_t k = 0; k < 2000u; k++) {
    const sample_t x = make_sample(k, &g);
    rlsd_step(&s, x.d, x.s, x.c);
  }
  const rlsd_t before = s;
  assert_int_equal(rlsd_set_lambda(&s, 0.995f), 0);
  assert_true(s.w_i == before.w_i && s.w_q == before.w_q && s.cov.p11 == before.cov.p11 &&
              s.cov.p12 == before.cov.p12 && s.cov.p22 == before.cov.p22);
  assert_true(s.lambda == 0.995f);
  assert_int_equal(rlsd_set_lambda(&s, 1.0f), 0); /* growing window is allowed */

  assert_int_equal(rlsd_preset(&s, 0.02f, 0.01f), 0);
  assert_true(s.w_i == 0.02f && s.w_q == 0.01f && s.cov.p11 == before.cov.p11);
  rlsd_reset(&s);
  assert_true(s.w_i == 0.0f && s.w_q == 0.0f && s.cov.p11 == 1.0f && s.cov.p12 == 0.0f &&
              s.cov.p22 == 1.0f);
  const rlsd_t after = s;
  assert_int_equal(rlsd_preset(&s, NAN, 0.0f), -1);
  assert_memory_equal(&s, &after, sizeof s);
}

static void test_bad_config_rejected_unchanged(void **state)
{
  (void)state;
  rlsd_t s;
  memset(&s, 0x5A, sizeof s);
  const rlsd_t sentinel = s;
  const rlsd_cfg_t bad[] = {
      {NAN, 1.0f},   {0.0f, 1.0f},   {-0.5f, 1.0f}, {1.0001f, 1.0f}, {INFINITY, 1.0f},
      {0.98f, 0.0f}, {0.98f, -1.0f}, {0.98f, NAN},  {0.98f, 2e6f},   {0.98f, INFINITY},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(rlsd_init(&s, &bad[i]), -1);
    assert_memory_equal(&s, &sentinel, sizeof s);
  }
  assert_int_equal(rlsd_init(&s, NULL), -1);
  assert_int_equal(rlsd_init(NULL, &(rlsd_cfg_t){0.98f, 1.0f}), -1);
  assert_memory_equal(&s, &sentinel, sizeof s);

  init_default(&s);
  const rlsd_t good = s;
  const float bad_lambda[] = {NAN, 0.0f, -1.0f, 1.5f, INFINITY};
  for (size_t i = 0; i < sizeof bad_lambda / sizeof bad_lambda[0]; i++) {
    assert_int_equal(rlsd_set_lambda(&s, bad_lambda[i]), -1);
    assert_memory_equal(&s, &good, sizeof s);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_converges_to_true_amplitudes),
      cmocka_unit_test(test_agrees_with_eigen_rls),
      cmocka_unit_test(test_matches_batch_weighted_least_squares),
      cmocka_unit_test(test_covariance_healthy_long_run),
      cmocka_unit_test(test_covariance_bounded_without_excitation),
      cmocka_unit_test(test_non_finite_sample_skipped),
      cmocka_unit_test(test_set_lambda_bumpless_reset_preset),
      cmocka_unit_test(test_bad_config_rejected_unchanged),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
