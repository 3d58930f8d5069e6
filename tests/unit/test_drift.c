/* First-order Gauss-Markov drift (host_sim/plant/drift.h): start at 0, stationary rms
 * sigma, autocorrelation e^(-lag/tau), variance growing as sigma^2 (1 - e^(-2t/tau));
 * off at zero; bad specs refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/drift.h"

/* sigma 2, tau 100 steps: over 2e6 steps (2e4 correlation times) the rms within 3 % of
 * sigma (the estimate's sd is about sqrt(tau / N) = 0.7 %), the lag-tau correlation
 * within 0.03 of 1/e; and across 4000 independent runs, the variance after tau / 2
 * within 6 % of sigma^2 (1 - 1/e) (sd of a variance estimate sqrt(2 / N) = 2.2 %). */
static void test_gauss_markov_statistics(void **state)
{
  (void)state;
  const drift_cfg_t c = {2.0, 100.0, 1.0};
  drift_t d;
  assert_int_equal(drift_init(&d, &c, 5u, 1u), 0);
  assert_true(d.x == 0.0);
  const long n = 2000000, lag = 100;
  double *x = malloc(sizeof(double) * (size_t)n);
  assert_non_null(x);
  for (long k = 0; k < 1000; k++) (void)drift_step(&d);
  double s2 = 0.0;
  for (long k = 0; k < n; k++) {
    x[k] = drift_step(&d);
    s2 += x[k] * x[k];
  }
  double sl = 0.0;
  for (long k = 0; k + lag < n; k++) sl += x[k] * x[k + lag];
  const double var = s2 / (double)n, rho = sl / (double)(n - lag) / var;
  print_message("Gauss-Markov: rms %.4f (sigma 2), correlation at tau %.4f (1/e %.4f)\n",
                sqrt(var), rho, exp(-1.0));
  assert_true(fabs(sqrt(var) / 2.0 - 1.0) < 0.03);
  assert_true(fabs(rho - exp(-1.0)) < 0.03);
  free(x);
  double v = 0.0;
  const int runs = 4000;
  for (int r = 0; r < runs; r++) {
    assert_int_equal(drift_init(&d, &c, (uint64_t)r, 1u), 0);
    double y = 0.0;
    for (int k = 0; k < 50; k++) y = drift_step(&d);
    v += y * y;
  }
  const double want = 4.0 * (1.0 - exp(-1.0));
  print_message("after tau/2 from 0: variance %.4f (law %.4f)\n", v / runs, want);
  assert_true(fabs(v / runs / want - 1.0) < 0.06);
}

/* Off at zero: stays 0, nothing drawn; bad specs refused, d unchanged. */
static void test_off_and_validation(void **state)
{
  (void)state;
  const drift_cfg_t off = {0.0, 10.0, 1e-3};
  drift_t d, before;
  assert_int_equal(drift_init(&d, &off, 1u, 1u), 0);
  const rng_t r0 = d.rng;
  for (int k = 0; k < 10; k++) assert_true(drift_step(&d) == 0.0);
  assert_memory_equal(&d.rng, &r0, sizeof r0);
  before = d;
  const drift_cfg_t bad[] = {{-1.0, 1.0, 1.0}, {1.0, 0.0, 1.0}, {1.0, 1.0, 0.0}, {NAN, 1.0, 1.0}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(drift_check(&bad[i]), -1);
    assert_int_equal(drift_init(&d, &bad[i], 1u, 1u), -1);
    assert_memory_equal(&d, &before, sizeof d);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gauss_markov_statistics),
      cmocka_unit_test(test_off_and_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
