/* sincos: table lookup + linear interpolation (5-14) against libm sin/cos in double. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <math.h>
#include <cmocka.h>

#include "dsp/sincos.h"

#define TWO_PI 6.283185307179586476925
#define TWO_POW_32 4294967296.0

static double phase_rad_f64(uint32_t phase) { return TWO_PI * (double)phase / TWO_POW_32; }

static double max_err = 0.0;

static void check_phase(uint32_t phase, double tol)
{
  float s, c;
  sincos_lut(phase, &s, &c);
  const double es = fabs((double)s - sin(phase_rad_f64(phase)));
  const double ec = fabs((double)c - cos(phase_rad_f64(phase)));
  if (es > max_err) max_err = es;
  if (ec > max_err) max_err = ec;
  if (es > tol || ec > tol) {
    fail_msg("phase 0x%08x: sin err %.3g, cos err %.3g (tol %.3g)", phase, es, ec, tol);
  }
}

/* At the table nodes the interpolation adds nothing: the result is sin/cos rounded to
 * float, within half an ulp (<= 2^-25 for |v| <= 1). This also checks the generated
 * table against libm. */
static void test_nodes_are_rounded_sin(void **state)
{
  (void)state;
  for (uint32_t k = 0; k < SINCOS_TABLE_SIZE; k++) {
    check_phase(k << (32u - SINCOS_TABLE_BITS), ldexp(1.0, -25));
  }
}

/* Dense sweep of the whole circle with a prime stride (hits every interpolation
 * position class), plus the edges of every quadrant and of the last table interval. */
static void test_dense_sweep_max_error(void **state)
{
  (void)state;
  max_err = 0.0;
  const uint32_t stride = 997u;
  for (uint64_t p = 0; p < (1ull << 32); p += stride) {
    check_phase((uint32_t)p, 1e-6);
  }
  const uint32_t edges[] = {0u,          1u,          0x3FFFFFFFu, 0x40000000u, 0x40000001u,
                            0x7FFFFFFFu, 0x80000000u, 0xBFFFFFFFu, 0xC0000000u, 0xFFF00000u,
                            0xFFF80000u, 0xFFFFFFFEu, 0xFFFFFFFFu};
  for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++) {
    check_phase(edges[i], 1e-6);
  }
  printf("sincos_lut: max |error| vs double sin/cos over %u phases: %.3g\n",
         (unsigned)((1ull << 32) / stride), max_err);
  /* The interpolation bound h^2/8 with h = 2 pi / N, plus a few float roundings. */
  const double h = TWO_PI / SINCOS_TABLE_SIZE;
  assert_true(max_err <= h * h / 8.0 + 2e-7);
}

/* Expected phase of an angle, wrapped, in double: the float angle is exact in double. */
static double expected_turns(float rad)
{
  const double t = (double)rad / TWO_PI;
  return t - floor(t);
}

/* Signed distance of two phases in counts (mod 2^32). */
static double phase_diff_counts(uint32_t a, double b_turns)
{
  double d = (double)a - b_turns * TWO_POW_32;
  d = fmod(d, TWO_POW_32);
  if (d >= 0.5 * TWO_POW_32) d -= TWO_POW_32;
  if (d < -0.5 * TWO_POW_32) d += TWO_POW_32;
  return d;
}

static void test_rad_to_phase_wraps_any_sign(void **state)
{
  (void)state;
  double worst_rel = 0.0;
  for (int i = -200000; i <= 200000; i++) {
    const float rad = (float)i * 2.5e-4f; /* -50 .. 50 rad */
    const uint32_t ph = sincos_rad_to_phase(rad);
    const double turns = fabs((double)rad) / TWO_PI;
    /* Single-precision reduction: about 2^-23 of the angle in turns, plus the last bit. */
    const double tol = 512.0 * (turns + 1.0);
    const double d = fabs(phase_diff_counts(ph, expected_turns(rad)));
    if (d > tol) fail_msg("rad %.9g: phase 0x%08x off by %.0f counts", (double)rad, ph, d);
    if (d / tol > worst_rel) worst_rel = d / tol;
  }
  /* Exact quarter turns, both signs, several turns away. */
  assert_int_equal(sincos_rad_to_phase(0.0f), 0u);
  assert_true(fabs(phase_diff_counts(sincos_rad_to_phase(-1.5707964f), 0.75)) < 64.0);
  assert_true(fabs(phase_diff_counts(sincos_rad_to_phase(3.1415927f), 0.5)) < 64.0);
  assert_true(fabs(phase_diff_counts(sincos_rad_to_phase(-3.1415927f), 0.5)) < 64.0);
  assert_true(fabs(phase_diff_counts(sincos_rad_to_phase(1000.0f), expected_turns(1000.0f))) <
              512.0 * 200.0);
  printf("sincos_rad_to_phase: worst error %.2f of its bound\n", worst_rel);
}

static void test_rad_to_phase_bad_input_is_zero(void **state)
{
  (void)state;
  assert_int_equal(sincos_rad_to_phase(NAN), 0u);
  assert_int_equal(sincos_rad_to_phase(INFINITY), 0u);
  assert_int_equal(sincos_rad_to_phase(-INFINITY), 0u);
  assert_int_equal(sincos_rad_to_phase(1e30f), 0u);
  assert_int_equal(sincos_rad_to_phase(-1e30f), 0u);
  /* 2^23 turns and more: whole turns only, the phase is 0 mod 2*pi. */
  assert_int_equal(sincos_rad_to_phase((float)(TWO_PI * 8388608.0)), 0u);
}

static void test_phase_to_rad_signed_range(void **state)
{
  (void)state;
  assert_true(sincos_phase_to_rad(0u) == 0.0f);
  assert_float_equal(sincos_phase_to_rad(0x40000000u), 1.5707963, 1e-6);
  assert_float_equal(sincos_phase_to_rad(0x80000000u), -3.1415927, 1e-6);
  assert_float_equal(sincos_phase_to_rad(0xC0000000u), -1.5707963, 1e-6);
  assert_true(sincos_phase_to_rad(0xFFFFFFFFu) < 0.0f);
  assert_true(sincos_phase_to_rad(0x7FFFFFFFu) > 3.14159f);
  for (uint64_t p = 0; p < (1ull << 32); p += 104729u) {
    const double expect = phase_rad_f64((uint32_t)p) - (p >= 0x80000000u ? TWO_PI : 0.0);
    const float got = sincos_phase_to_rad((uint32_t)p);
    assert_true(got >= -3.1415927f && got < 3.1415927f);
    assert_true(fabs((double)got - expect) <= 4e-7 * fabs(expect) + 1e-12);
    /* And back: the round trip loses only the float's resolution. */
    const double back = phase_diff_counts(sincos_rad_to_phase(got), (double)p / TWO_POW_32);
    assert_true(fabs(back) <= 1024.0);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nodes_are_rounded_sin),
      cmocka_unit_test(test_dense_sweep_max_error),
      cmocka_unit_test(test_rad_to_phase_wraps_any_sign),
      cmocka_unit_test(test_rad_to_phase_bad_input_is_zero),
      cmocka_unit_test(test_phase_to_rad_signed_range),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
