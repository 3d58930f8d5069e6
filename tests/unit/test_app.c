#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app/app.h"
#include "app_cmd.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"

/* A silent plant: the ADC reads 0 whatever the DAC does (the drive never locks). */
static void quiet_plant(void *p, const hal_dac_frame_t *dac, hal_adc_frame_t *adc)
{
  (void)p;
  (void)dac;
  adc->drive = 0;
  adc->sense = 0;
}

static app_t app; /* large: keep it off the test's stack */

static void setup_app(void)
{
  const hal_flash_host_cfg_t fc = {2u, 16384u, NULL, 250000u, 16u, 0u};
  assert_int_equal(hal_flash_host_configure(&fc), 0);
  hal_uart_host_reset();
  hal_host_attach(quiet_plant, NULL);
  assert_int_equal(app_init(&app), 0);
  assert_int_equal(hal_sample_timer_start(50000u, app_sample_isr, &app), 0);
}

/* Send one line through the UART stub, run the background loop, return the reply. */
static const char *cmd(const char *line) { return app_cmd_line(&app, line); }

/* A set of a live parameter reaches the running gyro at the next tick, through the
 * bank's derived block; nothing of it is visible before that tick. */
static void test_set_applies_at_tick(void **state)
{
  (void)state;
  setup_app();
  hal_host_run(10u);
  const float before = app.gyro.design->drive.amp_set_v;
  assert_true(strncmp(cmd("set drive.amp_set_v 2.5\n"), "ok", 2) == 0);
  assert_true(app.gyro.design->drive.amp_set_v == before);
  hal_host_run(1u);
  assert_true(app.gyro.design->drive.amp_set_v == 2.5f); /* the loop's setpoint slews to it */
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  /* Designed gains follow a new model: doubling the identified gain halves Kp. */
  const float kp = app.gyro.design->drive.amp.kp;
  assert_true(strncmp(cmd("set drive.cal_gain_v_per_v2 0.0164\n"), "ok", 2) == 0);
  hal_host_run(1u);
  assert_true(fabsf(app.gyro.design->drive.amp.kp - 0.5f * kp) < 1e-6f * kp);
}

/* drive off / on through the command line, and status reports the mode. */
static void test_drive_and_status(void **state)
{
  (void)state;
  setup_app();
  hal_host_run(5u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_ACQUIRE); /* sys.autostart */
  assert_string_equal(cmd("drive off\n"), "ok drive off\r\n");
  hal_host_run(1u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_OFF);
  const char *r = cmd("status\n");
  assert_non_null(strstr(r, "- mode OFF\r\n"));
  assert_non_null(strstr(r, "ok OFF\r\n"));
  assert_non_null(strstr(cmd("drive sideways\n"), "err ARGS"));
  assert_string_equal(cmd("drive on\n"), "ok drive on\r\n");
  hal_host_run(1u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_ACQUIRE);
}

/* The health counters of status (one table in app_cmds.c): a lost sample shows in
 * samples_lost, and the counters that must stay 0 are there. */
static void test_status_health_counters(void **state)
{
  (void)state;
  setup_app();
  hal_host_lose_sample();
  char want[48];
  snprintf(want, sizeof want, "- samples_lost %u\r\n", (unsigned)*hal_sample_lost_counter());
  const char *r = cmd("status\n");
  assert_non_null(strstr(r, want));
  assert_true(*hal_sample_lost_counter() >= 1u);
  assert_non_null(strstr(r, "- rx_overflows 0\r\n- samples_lost "));
  assert_non_null(strstr(r, "- reply_lines_cut 0\r\n- store "));
}

/* A save is refused while the drive runs; with the drive off it is stored and a
 * restart loads it. */
static void test_save_and_restart(void **state)
{
  (void)state;
  setup_app();
  hal_host_run(2u);
  assert_true(strncmp(cmd("set rate.bias_c0_dps 1.25\n"), "ok", 2) == 0);
  hal_host_run(1u);
  assert_non_null(strstr(cmd("save\n"), "err BUSY"));
  cmd("drive off\n");
  hal_host_run(1u);
  assert_non_null(strstr(cmd("status\n"), "- store_now no valid parameter image\r\n"));
  const char *saved = cmd("save\n");
  assert_true(strncmp(saved, "ok", 2) == 0);
  /* status: what the boot found, and what the store holds now */
  const char *st = cmd("status\n");
  assert_non_null(strstr(st, "- store no valid parameter image\r\n"));
  assert_non_null(strstr(st, "- store_now slot A seq 1\r\n"));
  /* Restart: a new instance over the same flash. */
  hal_uart_host_reset();
  assert_int_equal(app_init(&app), 0);
  assert_int_equal(app.store_status, PARAM_STORE_OK);
  assert_true(params_current(&app.params)->rate_bias_c0_dps == 1.25f);
  assert_true(app.gyro.design->rate.bias_c_dps[0] == 1.25f);
}

/* The ISR counts its ticks; its cycles come from the HAL, which measures the whole
 * handler (the host stub has no cycle counter: 0), and status reports both. */
static void test_isr_cycles(void **state)
{
  (void)state;
  setup_app();
  hal_host_run(100u);
  assert_int_equal(app_ticks(&app), 100u);
  uint32_t last = 1u, max = 1u;
  hal_sample_isr_cycles(&last, &max);
  assert_int_equal(last, 0u);
  assert_int_equal(max, 0u);
  hal_sample_isr_cycles(NULL, NULL);
}

/* Every command's reply fits in what telemetry leaves free (APP_TLM_TX_RESERVE), so it
 * comes out whole while a stream runs; and the host ring (like the board's) holds it
 * with room for telemetry. The longest: list. */
static void test_replies_fit_the_reserve(void **state)
{
  (void)state;
  setup_app();
  hal_host_run(2u);
  /* sweep points at its longest: a full table (two placements) of failed-sweep points
   * whose every figure prints with nine significant digits and an exponent. */
  app.selfcal.state = SELFCAL_FAILED;
  app.selfcal.why = "frequency response does not fit a resonance";
  app.selfcal.cfg.fs_hz = 50000.0;
  app.selfcal.fit.q = 1.23456789e-11;
  app.selfcal.n_pts = SELFCAL_EXPORT_MAX;
  for (uint32_t i = 0; i < SELFCAL_EXPORT_MAX; i++) {
    const selfcal_export_pt_t p = {4000000000u, -1.23456791e-11f, -1.23456791e-17f,
                                   1.23456791e-30f, 2u};
    app.selfcal.pts[i] = p;
  }
  const char *pts = cmd("sweep points\n");
  assert_non_null(strstr(pts, "ok 18 points\r\n"));
  printf("# sweep points at its longest: %zu bytes\n", strlen(pts));
  const char *const lines[] = {"list\n",    "help\n",   "status\n",          "diff\n",
                               "version\n", "stream\n", "selftest status\n", "sweep points\n"};
  size_t longest = 0u;
  for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
    const char *r = cmd(lines[i]);
    const size_t n = strlen(r);
    /* whole: ends with its final ok/err line */
    assert_true(n >= 2u && r[n - 2u] == '\r' && r[n - 1u] == '\n');
    assert_true(strstr(r, "ok") != NULL || strstr(r, "err") != NULL);
    if (n > longest) longest = n;
  }
  printf("# longest reply %zu bytes, reserve %u\n", longest, (unsigned)APP_TLM_TX_RESERVE);
  assert_true(longest <= APP_TLM_TX_RESERVE);
  assert_true(longest > 3000u); /* list is the long one: the test looks at it */
}

/* A set that cannot be designed is refused with the reason naming the parameter, and
 * status reports what the loop designer achieved. */
static void test_design_reason_and_status(void **state)
{
  (void)state;
  setup_app();
  assert_string_equal(cmd("drive off\n"), "ok drive off\r\n");
  hal_host_run(1u);
  const char *e = cmd("set sup.lock_tol_rel 0.1 sup.lost_tol_rel 0.05\n");
  assert_non_null(strstr(e, "err REJECTED "));
  assert_non_null(strstr(e, gyro_design_reason(GYRO_DESIGN_LOST_TOL)));
  const char *r = cmd("status\n");
  float amp_bw = 0.0f, amp_pm = 0.0f, ph_bw = 0.0f, ph_pm = 0.0f;
  assert_int_equal(sscanf(strstr(r, "- design_amp_bw_hz "), "- design_amp_bw_hz %f", &amp_bw), 1);
  assert_int_equal(sscanf(strstr(r, "- design_amp_pm_deg "), "- design_amp_pm_deg %f", &amp_pm),
                   1);
  assert_int_equal(sscanf(strstr(r, "- design_phase_bw_hz "), "- design_phase_bw_hz %f", &ph_bw),
                   1);
  assert_int_equal(
      sscanf(strstr(r, "- design_phase_pm_deg "), "- design_phase_pm_deg %f", &ph_pm), 1);
  printf("# designed: amplitude %.2f Hz %.1f deg, phase %.2f Hz %.1f deg\n", (double)amp_bw,
         (double)amp_pm, (double)ph_bw, (double)ph_pm);
  /* the defaults ask for 30 Hz each, which the designer grants with at least 60 deg */
  assert_true(fabsf(amp_bw - 30.0f) < 0.01f && fabsf(ph_bw - 30.0f) < 0.01f);
  assert_true(amp_pm >= 60.0f && ph_pm >= 60.0f);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_set_applies_at_tick),
      cmocka_unit_test(test_drive_and_status),
      cmocka_unit_test(test_save_and_restart),
      cmocka_unit_test(test_isr_cycles),
      cmocka_unit_test(test_status_health_counters),
      cmocka_unit_test(test_replies_fit_the_reserve),
      cmocka_unit_test(test_design_reason_and_status),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
