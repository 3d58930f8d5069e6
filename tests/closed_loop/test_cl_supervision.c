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

#include "app/app.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"
#include "plant/plant.h"

static plant_t plant;
static app_t app;

static void start(void)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  assert_int_equal(plant_init(&plant, &pc, 11u), 0);
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
