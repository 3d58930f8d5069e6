/* Converter integral nonlinearity (host_sim/plant/inl.h): the bow's shape, the per-code
 * pattern's end points, carries and statistics, validation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/inl.h"

/* bow_lsb at mid-scale, zero at both ends, a parabola in between; nothing else. */
static void test_bow(void **state)
{
  (void)state;
  const inl_cfg_t c = {3.0, 0.0};
  inl_t n;
  assert_int_equal(inl_init(&n, &c, 16, 1u, 1u), 0);
  assert_true(n.active && !n.pattern);
  assert_true(inl_lsb(&n, 0) == 0.0);
  assert_true(inl_lsb(&n, 32768) == 3.0);
  assert_true(fabs(inl_lsb(&n, 65535) - 3.0 * (1.0 - pow(32767.0 / 32768.0, 2))) < 1e-12);
  assert_true(fabs(inl_lsb(&n, 16384) - 3.0 * 0.75) < 1e-12); /* quarter scale: 1 - 1/4 */
  assert_true(inl_lsb(&n, -5) == 0.0 && inl_lsb(&n, 70000) == inl_lsb(&n, 65535)); /* held */
}

/* The per-code pattern of binary-weighted bits: zero at both ends (end-point line out),
 * INL(c) - INL(c - 1) the sum of the bit errors that change at c, minus the line's slope;
 * the largest step at the major carry (mid-scale). Over many parts the MSB's weight error
 * has the rms code_lsb and bit i the rms code_lsb 2^((i - 15)/2): estimated over 2000
 * parts within 10 % (sd of an rms estimate 1/sqrt(2 N) = 1.6 %). The same seed gives the
 * same part. */
static void test_code_pattern(void **state)
{
  (void)state;
  const inl_cfg_t c = {0.0, 2.0};
  inl_t n, m;
  assert_int_equal(inl_init(&n, &c, 16, 7u, 9u), 0);
  assert_int_equal(inl_init(&m, &c, 16, 7u, 9u), 0);
  assert_memory_equal(&n, &m, sizeof n);
  assert_true(fabs(inl_lsb(&n, 0)) < 1e-12 && fabs(inl_lsb(&n, 65535)) < 1e-12);
  const double carry = inl_lsb(&n, 32768) - inl_lsb(&n, 32767);
  double want = n.err_lsb[15] - n.slope_lsb;
  for (int i = 0; i < 15; i++) want -= n.err_lsb[i];
  assert_true(fabs(carry - want) < 1e-12);
  /* the nibble tables give the sum over the set bits at every code */
  for (long code = 0; code < 65536; code += 37) {
    double sum = 0.0;
    for (int i = 0; i < 16; i++)
      if ((code >> i) & 1) sum += n.err_lsb[i];
    assert_true(fabs(inl_lsb(&n, code) - (sum - (double)code * n.slope_lsb)) < 1e-12);
  }
  double s2[16] = {0};
  const int parts = 2000;
  for (int k = 0; k < parts; k++) {
    assert_int_equal(inl_init(&m, &c, 16, (uint64_t)k, 9u), 0);
    for (int i = 0; i < 16; i++) s2[i] += m.err_lsb[i] * m.err_lsb[i];
  }
  for (int i = 0; i < 16; i += 5) {
    const double rms = sqrt(s2[i] / parts), exp_rms = 2.0 * sqrt(pow(2.0, i - 15));
    print_message("bit %2d: weight error rms %.4f LSB (law %.4f)\n", i, rms, exp_rms);
    assert_true(fabs(rms / exp_rms - 1.0) < 0.1);
  }
}

/* Off at zero (no draws, INL 0 everywhere); bad values refused, n unchanged. */
static void test_off_and_validation(void **state)
{
  (void)state;
  const inl_cfg_t off = {0.0, 0.0};
  inl_t n;
  assert_int_equal(inl_init(&n, &off, 14, 1u, 1u), 0);
  assert_false(n.active);
  for (long code = 0; code < 16384; code += 97) assert_true(inl_lsb(&n, code) == 0.0);
  const inl_t before = n;
  const inl_cfg_t bad[] = {{NAN, 0.0}, {0.0, -1.0}, {1e6, 0.0}, {0.0, INFINITY}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(inl_check(&bad[i], 14), -1);
    assert_int_equal(inl_init(&n, &bad[i], 14, 1u, 1u), -1);
    assert_memory_equal(&n, &before, sizeof n);
  }
  assert_int_equal(inl_check(&off, 0), -1);
  assert_int_equal(inl_check(&off, INL_MAX_BITS + 1), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bow),
      cmocka_unit_test(test_code_pattern),
      cmocka_unit_test(test_off_and_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
