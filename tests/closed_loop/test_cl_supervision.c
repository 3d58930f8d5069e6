/* Closed loop on the default plant, through the host HAL and the command line: a new
 * amplitude setpoint re-acquires without a fault, and a corrupted loop state (a NaN, as
 * a radiation upset or a bad coefficient would leave it) is caught, cleared and the
 * gyro re-acquires by itself. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"


static void start(void)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  app_plant_start(&pc, 11u, NULL);
}

static void test_setpoint_change_relocks(void **state)
{
  (void)state;
  start();
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  const double a0 = plant_truth(&plant)->drive_amp_m;
  assert_true(strncmp(cmd("set drive.amp_set_v 0.25\n"), "ok", 2) == 0);
  run_s(0.5);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  /* The true motion follows the pickoff setpoint: 0.25 / 0.349 of the 10 um. */
  const double a1 = plant_truth(&plant)->drive_amp_m;
  assert_true(fabs(a1 / a0 - 0.25 / 0.349) < 0.01);
}

static void test_nan_caught_and_reacquired(void **state)
{
  (void)state;
  start();
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  app.gyro.lmsd_drive.w_i = NAN; /* corrupt the demodulator state */
  run_s(0.001);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_FAULT);
  assert_int_equal(app.gyro.sup.fault, GYRO_FAULT_NAN);
  assert_true(isfinite(app.gyro.lmsd_drive.w_i));
  /* Drive off for sup.retry_s (0.3 s), then acquisition from rest. */
  run_s(1.0);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_int_equal(app.gyro.sup.fault_count, 1u);
  assert_true(fabs(plant_truth(&plant)->drive_amp_m / 10.0e-6 - 1.0) < 0.01);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_setpoint_change_relocks),
      cmocka_unit_test(test_nan_caught_and_reacquired),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
