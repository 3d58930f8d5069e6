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

#include "app/app.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"
#include "plant/plant.h"

static plant_t plant;
static app_t app;

static void start(int fb_mode)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.fb_mode = fb_mode;
  if (plant_init(&plant, &pc, 31u) != 0) fail_msg("plant: %s", plant_error(&plant));
  assert_int_equal(hal_flash_host_configure(NULL), 0);
  hal_uart_host_reset();
  hal_host_attach(plant_step_hal, &plant);
  assert_int_equal(app_init(&app), 0);
  assert_int_equal(hal_sample_timer_start(50000u, app_sample_isr, &app), 0);
}

static void run_s(double s) { hal_host_run((uint64_t)(s * 50000.0)); }

static const char *cmd(const char *line)
{
  static char reply[4096];
  hal_uart_host_rx_push((const uint8_t *)line, strlen(line));
  app_poll(&app);
  const size_t n = hal_uart_host_tx_pop((uint8_t *)reply, sizeof reply - 1u);
  reply[n] = '\0';
  return reply;
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
