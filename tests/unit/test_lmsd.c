#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include <math.h>

#include "dsp/lmsd.h"
#include "ref_signal.h"

#define FS_HZ 50000.0
#define FC_HZ 1750.0

/* Noisy constant amplitudes: the average of W after convergence is [A1, A2]. */
static void test_converges_to_true_amplitudes(void **state)
{
  (void)state;
  const double a1 = 0.01, a2 = -0.004, sigma = 0.002;
  lmsd_t s;
  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = 0.034f}), 0);
  ref_rng_t g;
  ref_rng_seed(&g, 11u);
  double sum_i = 0.0, sum_q = 0.0;
  const uint64_t n = 40000u, skip = 2000u;
  for (uint64_t k = 0; k < n; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    const double d = a1 * rs + a2 * rc + sigma * ref_rng_gauss(&g);
    lmsd_step(&s, (float)d, (float)rs, (float)rc);
    if (k >= skip) {
      sum_i += lmsd_in_phase(&s);
      sum_q += lmsd_quadrature(&s);
    }
  }
  /* W's noise: std about sigma sqrt(mu) = 3.7e-4 with a 29-sample correlation time, so
   * the mean over 38000 samples has std about 1.4e-5. */
  assert_true(fabs(sum_i / (double)(n - skip) - a1) < 1e-4);
  assert_true(fabs(sum_q / (double)(n - skip) - a2) < 1e-4);
}

/* The prediction W(k-1)'r(k) is an LTI function of d (header): against the analytic
 * transfer function 2 mu (cos wc z^-1 - z^-2) / (1 - 2 (1 - mu) cos wc z^-1 +
 * (1 - 2 mu) z^-2), run in double on white noise. */
static void test_estimate_matches_adaptive_notch_transfer_function(void **state)
{
  (void)state;
  const double mu = 0.034;
  const double cw = cos(2.0 * REF_PI * FC_HZ / FS_HZ);
  const double b1 = 2.0 * mu * cw, b2 = -2.0 * mu;
  const double a1 = -2.0 * (1.0 - mu) * cw, a2 = 1.0 - 2.0 * mu;
  lmsd_t s;
  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = (float)mu}), 0);
  ref_rng_t g;
  ref_rng_seed(&g, 5u);
  double x1 = 0.0, x2 = 0.0, y1 = 0.0, y2 = 0.0, err2 = 0.0, ref2 = 0.0;
  for (uint64_t k = 0; k < 20000u; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    const float df = (float)ref_rng_gauss(&g);
    const float fs = (float)rs, fc = (float)rc;
    const double pred = (double)(lmsd_in_phase(&s) * fs + lmsd_quadrature(&s) * fc);
    lmsd_step(&s, df, fs, fc);
    const double y = b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2; /* direct form I */
    x2 = x1;
    x1 = (double)df;
    y2 = y1;
    y1 = y;
    err2 += (pred - y) * (pred - y);
    ref2 += y * y;
  }
  /* float against double: relative RMS error far below 1e-4 */
  assert_true(sqrt(err2 / ref2) < 1e-4);
}

/* Step response: the weight error decays with the pole radius sqrt(1 - 2 mu) of the
 * analysis in lmsd.h (about 1 - mu). Measured as the least-squares slope of
 * ln|W - A| over the transient (the 2 wc ripple averages out of the fit). */
static void check_time_constant(double mu)
{
  const double a1 = 0.01, a2 = 0.003;
  lmsd_t s;
  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = (float)mu}), 0);
  const int n = (int)(8.0 / mu); /* about 8 time constants */
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int m = 0;
  for (int k = 0; k < n; k++) {
    double rs, rc;
    ref_carrier((uint64_t)k, FC_HZ, FS_HZ, &rs, &rc);
    lmsd_step(&s, (float)(a1 * rs + a2 * rc), (float)rs, (float)rc);
    if (k >= (int)(0.5 / mu)) {
      const double ei = (double)lmsd_in_phase(&s) - a1, eq = (double)lmsd_quadrature(&s) - a2;
      const double y = 0.5 * log(ei * ei + eq * eq);
      sx += k;
      sy += y;
      sxx += (double)k * k;
      sxy += k * y;
      m++;
    }
  }
  const double slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
  const double expected = 0.5 * log(1.0 - 2.0 * mu);
  print_message("mu %.3f: measured decay %.5f/sample, analytic %.5f\n", mu, slope, expected);
  assert_true(fabs(slope / expected - 1.0) < 0.03);
}

static void test_step_response_time_constant(void **state)
{
  (void)state;
  check_time_constant(0.01);
  check_time_constant(0.034);
  check_time_constant(0.1);
}

/* Gain of the in-phase output for an AM tone A1(k) = cos(wm k), fitted by least squares
 * over whole modulation periods after the transient. */
static double am_gain(double mu, double fm_hz)
{
  lmsd_t s;
  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = (float)mu}), 0);
  const uint64_t skip = 10000u, n = 60000u;
  double sc = 0.0, ss = 0.0, cc = 0.0, sn = 0.0, cs = 0.0;
  for (uint64_t k = 0; k < n; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    const double ph = 2.0 * REF_PI * fm_hz / FS_HZ * (double)k;
    lmsd_step(&s, (float)(cos(ph) * rs), (float)rs, (float)rc);
    if (k >= skip) {
      const double y = lmsd_in_phase(&s);
      sc += y * cos(ph);
      sn += y * sin(ph);
      cc += cos(ph) * cos(ph);
      ss += sin(ph) * sin(ph);
      cs += cos(ph) * sin(ph);
    }
  }
  /* 2x2 normal equations of y ~ a cos + b sin */
  const double det = cc * ss - cs * cs;
  const double a = (sc * ss - sn * cs) / det, b = (sn * cc - sc * cs) / det;
  return sqrt(a * a + b * b);
}

/* The documented -3 dB bandwidth formula against AM tones at that frequency; and a
 * tone at a tenth of it passes almost unattenuated. */
static void test_bandwidth_formula_matches_am_tones(void **state)
{
  (void)state;
  const double mus[] = {0.01, 0.034, 0.05};
  for (size_t i = 0; i < sizeof mus / sizeof mus[0]; i++) {
    const double f3 = lmsd_bandwidth_hz(mus[i], FS_HZ);
    const double gain = am_gain(mus[i], f3);
    print_message("mu %.3f: f3 %.1f Hz, AM gain there %.4f\n", mus[i], f3, gain);
    assert_true(fabs(gain - sqrt(0.5)) < 0.01);
    assert_true(am_gain(mus[i], 0.1 * f3) > 0.99);
  }
  /* mu fs / (2 pi) is the small-mu limit */
  assert_true(fabs(lmsd_bandwidth_hz(0.001, FS_HZ) / (0.001 * FS_HZ / (2.0 * REF_PI)) - 1.0) <
              0.01);
}

/* A new mu keeps W (no step); the estimate then converges at the new rate. */
static void test_set_mu_is_bumpless(void **state)
{
  (void)state;
  lmsd_t s;
  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = 0.034f}), 0);
  uint64_t k = 0;
  for (; k < 3000u; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    lmsd_step(&s, (float)(0.01 * rs), (float)rs, (float)rc);
  }
  const float wi = lmsd_in_phase(&s), wq = lmsd_quadrature(&s);
  assert_int_equal(lmsd_set_mu(&s, 0.005f), 0);
  assert_true(lmsd_in_phase(&s) == wi && lmsd_quadrature(&s) == wq);
  /* converged, noise-free: the next samples stay where they were */
  for (uint64_t j = 0; j < 100u; j++, k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    lmsd_step(&s, (float)(0.01 * rs), (float)rs, (float)rc);
    assert_true(fabsf(lmsd_in_phase(&s) - wi) < 1e-6f);
  }
  assert_true(fabsf(s.two_mu - 0.01f) < 1e-9f);
}

static void test_preset_and_reset(void **state)
{
  (void)state;
  lmsd_t s;
  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = 0.034f}), 0);
  assert_int_equal(lmsd_preset(&s, 0.01f, -0.002f), 0);
  /* preset at the true amplitudes of a noise-free input: the error stays near zero */
  for (uint64_t k = 0; k < 1000u; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    lmsd_step(&s, (float)(0.01 * rs - 0.002 * rc), (float)rs, (float)rc);
    assert_true(fabsf(lmsd_in_phase(&s) - 0.01f) < 1e-7f);
    assert_true(fabsf(lmsd_quadrature(&s) + 0.002f) < 1e-7f);
  }
  const lmsd_t before = s;
  assert_int_equal(lmsd_preset(&s, NAN, 0.0f), -1);
  assert_int_equal(lmsd_preset(&s, 0.0f, INFINITY), -1);
  assert_memory_equal(&s, &before, sizeof s);
  lmsd_reset(&s);
  assert_true(lmsd_in_phase(&s) == 0.0f && lmsd_quadrature(&s) == 0.0f);
}

static void test_bad_config_rejected_unchanged(void **state)
{
  (void)state;
  lmsd_t s;
  memset(&s, 0xA5, sizeof s);
  const lmsd_t sentinel = s;
  const float bad[] = {NAN, 0.0f, -0.01f, 0.51f, INFINITY, -INFINITY};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = bad[i]}), -1);
    assert_memory_equal(&s, &sentinel, sizeof s);
  }
  assert_int_equal(lmsd_init(&s, NULL), -1);
  assert_int_equal(lmsd_init(NULL, &(lmsd_cfg_t){.mu = 0.03f}), -1);
  assert_memory_equal(&s, &sentinel, sizeof s);

  assert_int_equal(lmsd_init(&s, &(lmsd_cfg_t){.mu = 0.03f}), 0);
  assert_int_equal(lmsd_preset(&s, 0.5f, 0.25f), 0);
  const lmsd_t good = s;
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(lmsd_set_mu(&s, bad[i]), -1);
    assert_memory_equal(&s, &good, sizeof s);
  }
  assert_true(lmsd_bandwidth_hz(NAN, FS_HZ) < 0.0);
  assert_true(lmsd_bandwidth_hz(0.03, -1.0) < 0.0);
  assert_true(lmsd_bandwidth_hz(0.6, FS_HZ) < 0.0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_converges_to_true_amplitudes),
      cmocka_unit_test(test_estimate_matches_adaptive_notch_transfer_function),
      cmocka_unit_test(test_step_response_time_constant),
      cmocka_unit_test(test_bandwidth_formula_matches_am_tones),
      cmocka_unit_test(test_set_mu_is_bumpless),
      cmocka_unit_test(test_preset_and_reset),
      cmocka_unit_test(test_bad_config_rejected_unchanged),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
