#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "plant/rng.h"

/* Moments of N(0,1) from 10^6 deviates: mean, variance, kurtosis within ~5 standard
 * errors of their exact values (0, 1, 3). */
static void test_gauss_moments(void **state)
{
  (void)state;
  rng_t r;
  rng_seed(&r, 12345u, 0u);
  const int n = 1000000;
  double s1 = 0, s2 = 0, s4 = 0;
  for (int i = 0; i < n; i++) {
    const double g = rng_gauss(&r);
    s1 += g;
    s2 += g * g;
    s4 += g * g * g * g;
  }
  const double mean = s1 / n, var = s2 / n - mean * mean, kurt = (s4 / n) / (var * var);
  assert_true(fabs(mean) < 5.0 / sqrt(n));
  assert_true(fabs(var - 1.0) < 5.0 * sqrt(2.0 / n));
  assert_true(fabs(kurt - 3.0) < 5.0 * sqrt(24.0 / n));
}

/* Same (seed, stream) reproduces; different streams or seeds differ. */
static void test_streams(void **state)
{
  (void)state;
  rng_t a, b, c, d;
  rng_seed(&a, 7u, 1u);
  rng_seed(&b, 7u, 1u);
  rng_seed(&c, 7u, 2u);
  rng_seed(&d, 8u, 1u);
  int same_ab = 1, same_ac = 0, same_ad = 0;
  for (int i = 0; i < 1000; i++) {
    const uint64_t va = rng_next_u64(&a), vb = rng_next_u64(&b);
    same_ab &= (va == vb);
    same_ac += (va == rng_next_u64(&c));
    same_ad += (va == rng_next_u64(&d));
  }
  assert_true(same_ab);
  assert_int_equal(same_ac, 0);
  assert_int_equal(same_ad, 0);
}

/* Uniform deviates: mean 1/2 and adjacent-pair correlation ~0. */
static void test_uniform(void **state)
{
  (void)state;
  rng_t r;
  rng_seed(&r, 99u, 3u);
  const int n = 1000000;
  double s = 0, sxy = 0, prev = rng_uniform(&r);
  for (int i = 0; i < n; i++) {
    const double u = rng_uniform(&r);
    assert_true(u >= 0.0 && u < 1.0);
    s += u;
    sxy += (u - 0.5) * (prev - 0.5);
    prev = u;
  }
  assert_true(fabs(s / n - 0.5) < 5.0 * sqrt(1.0 / 12.0 / n));
  assert_true(fabs(sxy / n) < 5.0 / 12.0 / sqrt(n));
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gauss_moments),
      cmocka_unit_test(test_streams),
      cmocka_unit_test(test_uniform),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
