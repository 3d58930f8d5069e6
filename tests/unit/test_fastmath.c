#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "dsp/fastmath.h"

/* fm_atan2f against double atan2 on a dense grid of directions and radii spanning
 * 1e-6..1e6: max error 2e-6 rad (plus float rounding of the quotient). */
static void test_atan2_accuracy(void **state)
{
  (void)state;
  double max_err = 0.0;
  for (int i = 0; i < 100000; i++) {
    const double ang = -M_PI + 2.0 * M_PI * (i + 0.5) / 100000.0;
    for (int k = -6; k <= 6; k += 3) {
      const double r = pow(10.0, k);
      const float x = (float)(r * cos(ang)), y = (float)(r * sin(ang));
      const double ref = atan2((double)y, (double)x);
      double err = fabs((double)fm_atan2f(y, x) - ref);
      if (err > M_PI) err = 2.0 * M_PI - err; /* +-pi are the same direction */
      if (err > max_err) max_err = err;
    }
  }
  assert_true(max_err < 2.5e-6);
}

static void test_atan2_axes_and_origin(void **state)
{
  (void)state;
  assert_true(fabsf(fm_atan2f(0.0f, 0.0f)) == 0.0f);
  assert_true(fabs((double)fm_atan2f(1.0f, 0.0f) - M_PI / 2) < 2e-6);
  assert_true(fabs((double)fm_atan2f(-1.0f, 0.0f) + M_PI / 2) < 2e-6);
  assert_true(fabs((double)fm_atan2f(0.0f, -1.0f) - M_PI) < 2e-6);
  assert_true(fabs((double)fm_atan2f(0.0f, 1.0f)) < 1e-9);
}

static void test_isfinite_and_sqrt(void **state)
{
  (void)state;
  assert_true(fm_isfinite(1.0f));
  assert_true(fm_isfinite(-3.4e38f));
  assert_false(fm_isfinite(INFINITY));
  assert_false(fm_isfinite(-INFINITY));
  assert_false(fm_isfinite(NAN));
  for (float x = 1e-6f; x < 1e6f; x *= 1.37f) {
    assert_true(fabs((double)fm_sqrtf(x) - sqrt((double)x)) <= 1e-7 * sqrt((double)x));
  }
}

static void test_wrap(void **state)
{
  (void)state;
  for (double a = -20.0; a < 20.0; a += 0.013) {
    const double w = (double)fm_wrap_pi((float)a);
    assert_true(w > -M_PI - 1e-6 && w <= M_PI + 1e-6);
    const double d = remainder(w - a, 2.0 * M_PI);
    assert_true(fabs(d) < 1e-5);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_atan2_accuracy),
      cmocka_unit_test(test_atan2_axes_and_origin),
      cmocka_unit_test(test_isfinite_and_sqrt),
      cmocka_unit_test(test_wrap),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
