/* KFD covariance health over 1e7 float samples (the unit test runs 1e6). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include <math.h>

#include "demod_ref.h"
#include "dsp/kfd.h"
#include "kfd_long_run.h"

static void test_covariance_healthy_1e7_samples(void **state)
{
  (void)state;
  run_long(10000000u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_covariance_healthy_1e7_samples),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
