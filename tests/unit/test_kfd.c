#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include <math.h>

#include "demod_ref.h"
#include "dsp/kfd.h"
#include "demod_test_signal.h"
#include "kfd_long_run.h"


static void test_converges_to_true_amplitudes(void **state)
{
  (void)state;
  kfd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 31u);
  double sum_i = 0.0, sum_q = 0.0;
  const uint64_t n = 40000u, skip = 1000u;
  for (uint64_t k = 0; k < n; k++) {
    const sample_t x = make_sample(k, &g);
    kfd_step(&s, x.d, x.s, x.c);
    if (k >= skip) {
      sum_i += kfd_in_phase(&s);
      sum_q += kfd_quadrature(&s);
    }
  }
  assert_true(fabs(sum_i / (double)(n - skip) - A1) < 1e-4);
  assert_true(fabs(sum_q / (double)(n - skip) - A2) < 1e-4);
  assert_int_equal(s.cov_resets, 0);
  assert_int_equal(s.skipped, 0);
}

/* Float kernel against the double Eigen Kalman filter (Joseph form, full matrices) on
 * the same float inputs: x and P within 1e-4 relative after convergence. */
static void test_agrees_with_eigen_kalman(void **state)
{
  (void)state;
  kfd_t s;
  init_default(&s);
  ref_kf_t r;
  ref_kf_init(&r, (double)KFD_Q_DEFAULT, (double)KFD_R_DEFAULT, 1.0);
  ref_rng_t g;
  ref_rng_seed(&g, 32u);
  double worst_x = 0.0, worst_p = 0.0;
  for (uint64_t k = 0; k < 10000u; k++) {
    const sample_t x = make_sample(k, &g);
    kfd_step(&s, x.d, x.s, x.c);
    ref_kf_step(&r, x.d, x.s, x.c);
    if (k >= 500u) {
      worst_x = fmax(worst_x, rel_err_x(&s, r.x));
      worst_p = fmax(worst_p, rel_err_p(&s, r.p));
    }
  }
  print_message("worst relative difference to Eigen KF: x %.2e, P %.2e\n", worst_x, worst_p);
  assert_true(worst_x < 1e-4);
  assert_true(worst_p < 1e-4);
}

/* The steady-state covariance of the averaged model (kfd.h): P ~ sqrt(2 q R) per axis,
 * i.e. the trace averaged over the 2 wc ripple is 2 sqrt(2 q R) to first order. */
static void test_steady_state_covariance_matches_analysis(void **state)
{
  (void)state;
  kfd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 33u);
  double sum_tr = 0.0;
  int m = 0;
  for (uint64_t k = 0; k < 20000u; k++) {
    const sample_t x = make_sample(k, &g);
    kfd_step(&s, x.d, x.s, x.c);
    if (k >= 5000u) {
      sum_tr += (double)(s.cov.p11 + s.cov.p22);
      m++;
    }
  }
  const double q = (double)KFD_Q_DEFAULT, r = (double)KFD_R_DEFAULT;
  /* exact scalar steady state of P = (P + q) 2R / (P + q + 2R) */
  const double p_ss = 0.5 * (-q + sqrt(q * q + 8.0 * q * r));
  print_message("mean trace %.5f, averaged-model 2 P_ss %.5f\n", sum_tr / m, 2.0 * p_ss);
  assert_true(fabs(sum_tr / m / (2.0 * p_ss) - 1.0) < 0.05);
}


/* 1e6 samples here (well under a second with ASan); the 1e7-sample run of the same
 * check is tests/slow/test_kfd_long_run.c (ctest -L slow). */
static void test_covariance_healthy_long_run(void **state)
{
  (void)state;
  run_long(1000000u);
}

/* One-direction excitation: without the trace bound p22 would random-walk upwards by
 * q per sample without limit; with it P stays bounded and the excited component is
 * estimated. */
static void test_covariance_bounded_without_excitation(void **state)
{
  (void)state;
  kfd_t s;
  assert_int_equal(kfd_init(&s, &(kfd_cfg_t){.q = 0.01f, .r = 0.3f, .p0 = 1.0f}), 0);
  for (int k = 0; k < 200000; k++) {
    kfd_step(&s, 0.01f, 1.0f, 0.0f);
    assert_true(s.cov.p11 > 0.0f && s.cov.p22 > 0.0f &&
                s.cov.p11 + s.cov.p22 <= 4.0f + 2.0f * 0.01f + 1e-5f);
  }
  assert_true(isfinite(s.x_i) && fabsf(s.x_i - 0.01f) < 1e-6f);
  assert_int_equal(s.cov_resets, 0);
}

static void test_non_finite_sample_skipped(void **state)
{
  (void)state;
  kfd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 35u);
  for (uint64_t k = 0; k < 1000u; k++) {
    const sample_t x = make_sample(k, &g);
    kfd_step(&s, x.d, x.s, x.c);
  }
  kfd_t before = s;
  kfd_step(&s, NAN, 0.6f, 0.8f);
  kfd_step(&s, -INFINITY, 0.6f, 0.8f);
  kfd_step(&s, 0.01f, 0.6f, NAN);
  assert_int_equal(s.skipped, 3);
  before.skipped = 3;
  assert_memory_equal(&s, &before, sizeof s);
}

static void test_set_noise_bumpless_reset_preset(void **state)
{
  (void)state;
  kfd_t s;
  init_default(&s);
  ref_rng_t g;
  ref_rng_seed(&g, 36u);
  for (uint64_t k = 0; k < 2000u; k++) {
    const sample_t x = make_sample(k, &g);
    kfd_step(&s, x.d, x.s, x.c);
  }
  const kfd_t before = s;
  assert_int_equal(kfd_set_noise(&s, 0.0001f, 0.9f), 0);
  assert_true(s.x_i == before.x_i && s.x_q == before.x_q && s.cov.p11 == before.cov.p11 &&
              s.cov.p12 == before.cov.p12 && s.cov.p22 == before.cov.p22);
  assert_true(s.q == 0.0001f && s.r == 0.9f);
  assert_int_equal(kfd_set_noise(&s, 0.0f, 0.9f), 0); /* q = 0: constant amplitudes */

  assert_int_equal(kfd_preset(&s, 0.02f, 0.01f), 0);
  assert_true(s.x_i == 0.02f && s.x_q == 0.01f && s.cov.p11 == before.cov.p11);
  kfd_reset(&s);
  assert_true(s.x_i == 0.0f && s.x_q == 0.0f && s.cov.p11 == 1.0f && s.cov.p12 == 0.0f &&
              s.cov.p22 == 1.0f);
  const kfd_t after = s;
  assert_int_equal(kfd_preset(&s, 0.0f, NAN), -1);
  assert_memory_equal(&s, &after, sizeof s);
}

static void test_bad_config_rejected_unchanged(void **state)
{
  (void)state;
  kfd_t s;
  memset(&s, 0x5A, sizeof s);
  const kfd_t sentinel = s;
  const kfd_cfg_t bad[] = {
      {NAN, 0.3f, 1.0f},         {-0.0002f, 0.3f, 1.0f}, {INFINITY, 0.3f, 1.0f},
      {0.0002f, 0.0f, 1.0f},     {0.0002f, -0.3f, 1.0f}, {0.0002f, NAN, 1.0f},
      {0.0002f, INFINITY, 1.0f}, {0.0002f, 0.3f, 0.0f},  {0.0002f, 0.3f, -1.0f},
      {0.0002f, 0.3f, NAN},      {0.0002f, 0.3f, 2e6f},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(kfd_init(&s, &bad[i]), -1);
    assert_memory_equal(&s, &sentinel, sizeof s);
  }
  assert_int_equal(kfd_init(&s, NULL), -1);
  assert_int_equal(kfd_init(NULL, &(kfd_cfg_t){0.0002f, 0.3f, 1.0f}), -1);
  assert_memory_equal(&s, &sentinel, sizeof s);

  init_default(&s);
  const kfd_t good = s;
  assert_int_equal(kfd_set_noise(&s, NAN, 0.3f), -1);
  assert_int_equal(kfd_set_noise(&s, -1.0f, 0.3f), -1);
  assert_int_equal(kfd_set_noise(&s, 0.0002f, -0.3f), -1);
  assert_int_equal(kfd_set_noise(&s, 0.0002f, 0.0f), -1);
  assert_int_equal(kfd_set_noise(&s, 0.0002f, INFINITY), -1);
  assert_int_equal(kfd_set_noise(NULL, 0.0002f, 0.3f), -1);
  assert_memory_equal(&s, &good, sizeof s);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_converges_to_true_amplitudes),
      cmocka_unit_test(test_agrees_with_eigen_kalman),
      cmocka_unit_test(test_steady_state_covariance_matches_analysis),
      cmocka_unit_test(test_covariance_healthy_long_run),
      cmocka_unit_test(test_covariance_bounded_without_excitation),
      cmocka_unit_test(test_non_finite_sample_skipped),
      cmocka_unit_test(test_set_noise_bumpless_reset_preset),
      cmocka_unit_test(test_bad_config_rejected_unchanged),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
