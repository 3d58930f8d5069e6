/* Self-calibration on the host plant, through the host HAL and the command line: the
 * `sweep` command identifies the drive resonance and Q through the firmware's own
 * signal chain, and the loops designed from the identified model lock; `sweep points`
 * prints the measured points, which alone identify the plant again.
 * Judged against the plant's own parameters (the resonance at the structure
 * temperature, (2-32)) and its true drive amplitude. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "selfcal_harness.h"

static void test_default_plant(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_ideal_cfg(&pc); /* the firmware identifies the linear Q: selfcal_harness.h */
  param_values_t v;
  default_part_values(&v);
  start(&pc, &v);
  /* The sweep is commanded while the drive runs locked with the stored design. */
  run_polled_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  /* No sweep yet: no points to export; a bad argument is refused. */
  assert_non_null(strstr(cmd("sweep points\n"), "err STATE no sweep has measured points"));
  assert_non_null(strstr(cmd("sweep pts\n"), "err ARGS usage: sweep [points]"));
  assert_non_null(strstr(cmd("sweep points 1\n"), "err ARGS"));
  /* A second request while the sweep runs is refused. */
  assert_true(strncmp(cmd("sweep\n"), "ok", 2) == 0);
  run_polled_s(0.01);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_SWEEP);
  assert_non_null(strstr(cmd("sweep\n"), "BUSY"));
  assert_non_null(strstr(cmd("status\n"), "selfcal QUIET_UP"));
  assert_non_null(strstr(cmd("sweep points\n"), "err STATE a sweep is in progress"));
  const double t = sweep_wait();
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  assert_true(t <= 60.0);
  check_identified(&pc);
  check_points(&pc);
  /* status reports the result */
  const char *r = cmd("status\n");
  assert_non_null(strstr(r, "selfcal DONE"));
  assert_non_null(strstr(r, "selfcal_q "));
  printf("# status with the self-calibration lines: %zu bytes\n", strlen(r));
  check_lock();
}

/* The tracking drive selected before the sweep stays selected when the sweep's own plan is
 * the stepped sine (it committed drive.track 0 over it), and locks on another part
 * (1700 Hz, Q 300, 20 K warmer). */
static void test_tracking_kept(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_ideal_cfg(&pc); /* the firmware identifies the linear Q: selfcal_harness.h */
  pc.f_drive_hz = 1700.0;
  pc.q_drive = 300.0;
  pc.temp_k += 20.0;
  param_values_t v;
  values_no_autostart(&v);
  v.drive_track = 1u;
  start(&pc, &v);
  (void)sweep();
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  check_identified(&pc);
  assert_int_equal(params_current(&app.params)->drive_track, 1u);
  check_lock();
  assert_int_equal(app.gyro.design->track, 1u);
}

static void test_low_q_plant(void **state)
{
  (void)state;
  random_plant_case(1957.3, 24.6);
}

static void test_high_q_plant(void **state)
{
  (void)state;
  random_plant_case(1342.8, 571.0);
  /* Negative control: the default part's calibration does not lock on this part. */
  assert_true(fixed_design_fails(1342.8, 571.0));
}

/* A fresh part that is not the default one (1300 Hz, Q 200, the default part's
 * imperfections and quadrature) after its own sweep: the sweep identifies the drive but
 * not the rate channel (demodulation phase, scale factor), so the part is not calibrated
 * and must say so; its rate is never valid. Before the calibration record this test
 * failed: valid 482 of the 3000 ms, up to 156 deg/s off at rest (the sign inverted). */
static void test_fresh_part_not_valid(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.f_drive_hz = 1300.0;
  pc.q_drive = 200.0;
  param_values_t v;
  values_no_autostart(&v);
  start(&pc, &v);
  (void)sweep();
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  uint32_t valid_ms = 0u, locked_ms = 0u;
  double worst_dps = 0.0;
  for (int i = 0; i < 3000; i++) {
    run_polled_s(0.001);
    locked_ms += app.gyro.sup.mode == GYRO_MODE_LOCKED ? 1u : 0u;
    if (app.gyro.out.rate_valid != 0u) {
      valid_ms++;
      worst_dps = fmax(worst_dps, fabs((double)app.gyro.out.rate_dps));
    }
  }
  printf("# fresh part after its sweep: locked %u ms, valid %u ms (worst |rate| %.1f deg/s)\n",
         locked_ms, valid_ms, worst_dps);
  assert_true(locked_ms > 2000u); /* the drive is identified: it runs */
  assert_int_equal(valid_ms, 0u);
  assert_true((app.gyro.out.flags & GYRO_FLAG_UNCALIBRATED) != 0u);
  const char *r = cmd("status\n");
  assert_non_null(strstr(r, "calibrated no"));
  assert_non_null(strstr(r, "UNCALIBRATED"));
}

/* The calibration record: the default part with its calibration says `calibrated yes`
 * and gives a valid rate; at another drive frequency (a hand change) the calibration is
 * stale and the rate not valid; back at the calibration's frequency, as the command line
 * prints it, it holds again. */
static void test_calibration_record(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  param_values_t v;
  default_part_values(&v);
  start(&pc, &v);
  run_polled_s(0.5);
  assert_non_null(strstr(cmd("status\n"), "- calibrated yes\r\n"));
  assert_int_equal(app.gyro.out.rate_valid, 1u);
  /* "ok drive.freq_hz VALUE Hz": the value as the command line prints it */
  char printed[32];
  assert_int_equal(sscanf(cmd("get drive.freq_hz\n"), "ok drive.freq_hz %31s", printed), 1);
  char line[64];
  (void)snprintf(line, sizeof line, "set drive.freq_hz %.9g\n", (double)v.drive_freq_hz + 0.01);
  assert_true(strncmp(cmd(line), "ok", 2) == 0);
  run_polled_s(0.05);
  assert_non_null(strstr(cmd("status\n"), "- calibrated stale\r\n"));
  assert_int_equal(app.gyro.out.rate_valid, 0u);
  assert_true((app.gyro.out.rate_invalid & RATE_INVALID_UNCALIBRATED) != 0u);
  assert_true((app.gyro.out.flags & GYRO_FLAG_UNCALIBRATED) != 0u);
  (void)snprintf(line, sizeof line, "set drive.freq_hz %s\n", printed);
  assert_true(strncmp(cmd(line), "ok", 2) == 0);
  run_polled_s(0.5);
  assert_non_null(strstr(cmd("status\n"), "- calibrated yes\r\n"));
  assert_int_equal(app.gyro.out.rate_valid, 1u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_default_plant),        cmocka_unit_test(test_tracking_kept),
      cmocka_unit_test(test_low_q_plant),          cmocka_unit_test(test_high_q_plant),
      cmocka_unit_test(test_fresh_part_not_valid), cmocka_unit_test(test_calibration_record),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
