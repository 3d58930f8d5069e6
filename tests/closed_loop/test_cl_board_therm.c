/* The board thermometer (board.fuse, board_therm.h) on the default part through the host
 * HAL and the plant's TMP117 (board_sensor.h): the firmware takes each conversion (status
 * board_c is the sensor's result); fused, the compensation's bias becomes the model's
 * (a model held at a constant here: the fit is the flow's, gyrotools/boardcal.py) after
 * the crossover; the hand-over's weight is 0 until board.start_s; and a sensor that stops
 * answering, or a board without one, makes the fused rate not valid (BOARD_TEMP), while
 * before the hand-over P's compensation alone stays valid. The model's accuracy on parts
 * is the calibration flow's verification (README, "Board thermometer"). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"
#include "gyro/rate_valid.h"

#define MODEL_DPS 1.5f /* the held model's bias */

/* s seconds with the background polled every 20 ms, as gyro-sim polls it; the fraction of
 * those polls at which the rate was valid, and the latest reasons. */
static double run_polled_s(double s)
{
  const uint64_t n = (uint64_t)(s / 0.02 + 0.5);
  uint64_t valid = 0u;
  for (uint64_t k = 0u; k < n; k++) {
    hal_host_run(1000u);
    app_poll(&app);
    valid += app.gyro.out.rate_valid != 0u ? 1u : 0u;
  }
  return n > 0u ? (double)valid / (double)n : 0.0;
}

/* The default part's calibration with the fusion on and the model held at MODEL_DPS
 * (c0; the rest 0), handed over start_s after power-on. */
static void fused_values(param_values_t *v, float start_s)
{
  default_part_values(v);
  v->board_fuse = 1u;
  v->board_c0_dps = MODEL_DPS;
  v->board_start_s = start_s;
  v->board_fade_s = 0.0f;
  v->board_agree_dps = 1000.0f;
}

static void start_part(const param_values_t *v, int sensor, double fault_s)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.board_sensor = sensor;
  pc.board_sensor_fault_s = fault_s;
  app_plant_start(&pc, 5u, v);
}

static const char *status_word(const char *key)
{
  static char word[32];
  char pat[64];
  snprintf(pat, sizeof pat, "%s ", key);
  const char *r = strstr(cmd("status\n"), pat);
  assert_non_null(r);
  assert_int_equal(sscanf(r + strlen(pat), "%31s", word), 1);
  return word;
}

static void test_the_firmware_reads_the_sensor(void **state)
{
  (void)state;
  start_part(NULL, 1, -1.0);
  (void)run_polled_s(3.5);
  assert_string_equal(status_word("board_temp"), "off");
  assert_true(app.board.readings >= 2u);
  /* the plant's latest result, as the firmware took it (one poll later at most) */
  assert_float_equal(app.gyro.out.board_c, plant_truth(&plant)->board_meas_c, 1e-6);
  assert_true(fabs((double)app.board.x_c - (plant_truth(&plant)->board_k - 273.15)) < 0.2);
}

static void test_fused_bias_is_the_models_below_the_crossover(void **state)
{
  (void)state;
  param_values_t v;
  fused_values(&v, 0.0f);
  start_part(&v, 1, -1.0);
  const double valid = run_polled_s(12.0);
  printf("fused from power-on: valid %.3f of the polls; bias %.4f deg/s (model %.2f), "
         "correction %.4f deg/s\n",
         valid, (double)app.gyro.rate.comp_bias_dps, (double)MODEL_DPS,
         (double)app.board.corr_dps);
  assert_string_equal(status_word("board_temp"), "ok");
  assert_float_equal(app.gyro.rate.comp_bias_dps, MODEL_DPS, 0.01f);
  assert_true(app.gyro.out.rate_valid != 0u);
}

static void test_no_weight_before_the_hand_over(void **state)
{
  (void)state;
  param_values_t v;
  fused_values(&v, 100.0f);
  start_part(&v, 1, -1.0);
  (void)run_polled_s(8.0);
  assert_float_equal(app.board.w, 0.0f, 0.0f);
  assert_float_equal(app.gyro.board_corr_applied_dps, 0.0f, 0.0f);
  assert_true(app.gyro.out.rate_valid != 0u);
}

/* The sensor stops answering at 6 s: board.stale_s (3 s) later the fused rate is not
 * valid, for the reason BOARD_TEMP. Without the verdict (board_therm_invalid held at 0)
 * the rate stays valid on the held correction, and this test and the next fail: nothing
 * else reads the sensor. Before the hand-over, the same fault leaves P's
 * compensation valid. */
static void test_a_silent_sensor_is_not_trusted(void **state)
{
  (void)state;
  param_values_t v;
  fused_values(&v, 0.0f);
  start_part(&v, 1, 6.0);
  assert_true(run_polled_s(8.0) > 0.5);
  assert_true(app.gyro.out.rate_valid != 0u);
  (void)run_polled_s(1.5); /* 9.5 s: 3.5 s after the fault */
  assert_string_equal(status_word("board_temp"), "stale");
  assert_int_equal(app.gyro.out.rate_valid, 0u);
  assert_true((app.gyro.out.rate_invalid & RATE_INVALID_BOARD_TEMP) != 0u);
  assert_true(run_polled_s(2.0) == 0.0);

  fused_values(&v, 100.0f);
  start_part(&v, 1, 6.0);
  (void)run_polled_s(10.0);
  assert_string_equal(status_word("board_temp"), "stale");
  assert_true(app.gyro.out.rate_valid != 0u);
}

static void test_a_board_without_a_sensor(void **state)
{
  (void)state;
  param_values_t v;
  fused_values(&v, 0.0f);
  start_part(&v, 0, -1.0);
  assert_true(run_polled_s(5.0) == 0.0);
  assert_string_equal(status_word("board_temp"), "absent");
  assert_true((app.gyro.out.rate_invalid & RATE_INVALID_BOARD_TEMP) != 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_the_firmware_reads_the_sensor),
      cmocka_unit_test(test_fused_bias_is_the_models_below_the_crossover),
      cmocka_unit_test(test_no_weight_before_the_hand_over),
      cmocka_unit_test(test_a_silent_sensor_is_not_trusted),
      cmocka_unit_test(test_a_board_without_a_sensor),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
