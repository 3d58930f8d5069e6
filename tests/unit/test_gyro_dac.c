/* gyro_volts_to_dac: volts to the offset-binary code of the 14-bit +-15 V DAC, judged
 * against the converter's definition evaluated in double precision (nearest code of
 * v / LSB + mid, clamped to 0 .. max), and its behaviour outside the range and for
 * non-finite input (NaN: the mid code, 0 V). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "gyro/gyro.h"

static const double lsb_v = 30.0 / 16384.0; /* board.h: +-15 V, 14 bits */

/* The reference code, and whether x lies so close to a half-integer that either
 * neighbour is right (the float product v / LSB carries a relative rounding of 6e-8,
 * 5e-4 codes at full scale). */
static int ref_code(float v, int *tie)
{
  const double x = (double)v / lsb_v + 8192.0;
  *tie = fabs(x - floor(x) - 0.5) < 2e-3;
  if (x <= 0.0) return 0;
  if (x >= 16383.0) return 16383;
  return (int)floor(x + 0.5);
}

static void check(float v)
{
  int tie;
  const int want = ref_code(v, &tie);
  const int got = gyro_volts_to_dac(v);
  if (tie) {
    assert_true(got == want || got == want - 1 || (want == 16383 && got == 16383));
  } else {
    if (got != want) fprintf(stderr, "v = %.9g: code %d, want %d\n", (double)v, got, want);
    assert_int_equal(got, want);
  }
}

/* Every code of the range, its centre and both edges of its interval. */
static void test_every_code(void **state)
{
  (void)state;
  for (int c = 0; c <= 16383; c++) {
    const double centre = (c - 8192) * lsb_v;
    check((float)centre);
    check((float)(centre - 0.49 * lsb_v));
    check((float)(centre + 0.49 * lsb_v));
    assert_int_equal(gyro_volts_to_dac((float)centre), c);
  }
}

/* A dense sweep beyond both ends: monotonic, clamped, matching the reference. */
static void test_sweep_monotonic(void **state)
{
  (void)state;
  int last = -1;
  for (int i = 0; i <= 400000; i++) {
    const float v = -20.0f + 40.0f * (float)i / 400000.0f;
    check(v);
    const int c = gyro_volts_to_dac(v);
    assert_true(c >= last);
    last = c;
  }
  assert_int_equal(gyro_volts_to_dac(-15.0f), 0);
  assert_int_equal(gyro_volts_to_dac(15.0f), 16383);
  assert_int_equal(gyro_volts_to_dac(0.0f), 8192);
  assert_int_equal(gyro_volts_to_dac(-0.0f), 8192);
}

/* Far outside the range, through every binade down to the smallest subnormal, both
 * signs: the rail codes (and the mid code for tiny values). */
static void test_far_out_of_range(void **state)
{
  (void)state;
  for (float m = FLT_MAX; m > 0.0f; m *= 0.5f) {
    check(m);
    check(-m);
  }
  assert_int_equal(gyro_volts_to_dac(FLT_MAX), 16383);
  assert_int_equal(gyro_volts_to_dac(-FLT_MAX), 0);
  assert_int_equal(gyro_volts_to_dac(INFINITY), 16383);
  assert_int_equal(gyro_volts_to_dac(-INFINITY), 0);
  assert_int_equal(gyro_volts_to_dac(1e-45f), 8192);
  assert_int_equal(gyro_volts_to_dac(-1e-45f), 8192);
  /* Where v / LSB + mid + 1.5 * 2^23 leaves [2^23, 2^24) or turns negative. */
  check(-23000.0f);
  check(-23100.0f);
  check(-15400.0f);
  check(15400.0f);
  check(-7700.0f);
}

/* Every NaN, whatever its sign and payload, gives the mid code: 0 V on the electrodes. */
static void test_nan_is_mid(void **state)
{
  (void)state;
  const uint32_t pats[] = {0x7FC00000u, 0xFFC00000u, 0x7F800001u, 0xFF800001u,
                           0x7FFFFFFFu, 0xFFFFFFFFu, 0x7FA5A5A5u, 0xFFBFFFFFu};
  for (size_t i = 0; i < sizeof pats / sizeof pats[0]; i++) {
    float v;
    memcpy(&v, &pats[i], sizeof v);
    assert_true(isnan(v));
    assert_int_equal(gyro_volts_to_dac(v), 8192);
  }
  assert_int_equal(gyro_volts_to_dac(NAN), 8192);
  assert_int_equal(gyro_volts_to_dac(-NAN), 8192);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_every_code),
      cmocka_unit_test(test_sweep_monotonic),
      cmocka_unit_test(test_far_out_of_range),
      cmocka_unit_test(test_nan_is_mid),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
