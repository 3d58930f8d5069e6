/* Built-in self-test on the default plant through the command line: LOCKED, `selftest`
 * applies the known force through the sense feedback electrodes and the rate channel's
 * response matches the calibrated expectation (PASS); with the sense electrodes' force
 * gone (a broken electrode: the plant's feedback actuator switched off) the same test
 * FAILS; it is refused while not locked. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"



static void start(int fb_mode)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.fb_mode = fb_mode;
  app_plant_start(&pc, 31u, NULL);
}

static void test_pass_on_healthy_part(void **state)
{
  (void)state;
  start(2);
  assert_non_null(strstr(cmd("selftest\n"), "err BUSY")); /* not locked yet */
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_true(strncmp(cmd("selftest\n"), "ok", 2) == 0);
  run_s(0.6);
  printf("# self-test response %.4f deg/s (expected %.4f)\n", (double)app.gyro.selftest.result_dps,
         (double)params_current(&app.params)->selftest_expect_dps);
  assert_int_equal(app.gyro.selftest.state, SELFTEST_PASS);
  assert_non_null(strstr(cmd("status\n"), "- selftest PASS\r\n"));
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
}

static void test_fail_on_dead_electrode(void **state)
{
  (void)state;
  start(0);
  run_s(0.3);
  assert_true(strncmp(cmd("selftest\n"), "ok", 2) == 0);
  run_s(0.6);
  printf("# self-test response without the electrodes %.4f deg/s\n",
         (double)app.gyro.selftest.result_dps);
  assert_int_equal(app.gyro.selftest.state, SELFTEST_FAIL);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_pass_on_healthy_part),
      cmocka_unit_test(test_fail_on_dead_electrode),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
