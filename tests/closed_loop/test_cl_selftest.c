/* Built-in self-test on the default plant through the command line: LOCKED, `selftest`
 * applies the known force through the sense feedback electrodes and the rate channel's
 * response matches the calibrated expectation (PASS); with the sense electrodes' force
 * gone (a broken electrode: the plant's feedback actuator switched off) the same test
 * FAILS; it is refused while not locked. The continuous self-test: on a healthy part
 * its response is in its band and the rate stays valid, its tone is not in the output;
 * with the electrode dead the rate is not valid (CONT_SELFTEST). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"


static double cont_avg_dps(void)
{
  return hypot((double)app.gyro.selftest.w_avg[0], (double)app.gyro.selftest.w_avg[1]) *
         fabs((double)app.gyro.design->rate.scale_dps);
}

/* The default part with its calibration, whose self-test expectations the calibration
 * flow measured (tools/calibrate, on its own noise seed). */
static void part_values(param_values_t *v)
{
  default_part_values(v);
  assert_true(v->selftest_expect_dps > 1.0f && v->selftest_cont_expect_dps > 1.0f);
}

static void start_part(const plant_cfg_t *pc)
{
  param_values_t v;
  part_values(&v);
  app_plant_start(pc, 31u, &v);
}

static void start(int fb_mode)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.fb_mode = fb_mode;
  start_part(&pc);
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
  printf("# self-test response %.4f deg/s (expected %.4f)\n",
         (double)app.gyro.selftest.result_dps,
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

/* Rate output's rms about its mean over s seconds, sampled every block. */
static double rate_rms(double s, double *mean_out)
{
  const int n = (int)(s * 5000.0);
  double s1 = 0.0, s2 = 0.0;
  for (int i = 0; i < n; i++) {
    hal_host_run(GYRO_BLOCK);
    const double r = app.gyro.out.rate_dps;
    s1 += r;
    s2 += r * r;
  }
  const double m = s1 / n;
  if (mean_out != NULL) *mean_out = m;
  return sqrt(s2 / n - m * m);
}

/* The continuous test's response on the rate axis (and on the quadrature axis). */
static double cont_response_dps(int axis)
{
  const float *w = app.gyro.selftest.w + 2 * axis;
  return sqrt((double)(w[0] * w[0] + w[1] * w[1])) *
         fabs((double)app.gyro.design->rate.scale_dps);
}

static void test_continuous_healthy(void **state)
{
  (void)state;
  /* The same part and noise without and with the continuous test. */
  start(2);
  run_s(1.0);
  double m_off;
  const double rms_off = rate_rms(2.0, &m_off);
  start(2);
  assert_true(strncmp(cmd("set selftest.continuous 1\n"), "ok", 2) == 0);
  run_s(1.0);
  double m_on;
  const double rms_on = rate_rms(2.0, &m_on);
  printf("# continuous self-test: response %.4f deg/s (expected %.4f; quadrature axis %.4f), "
         "rate rms %.4f off / %.4f on deg/s, mean %.4f / %.4f\n",
         cont_response_dps(0), (double)params_current(&app.params)->selftest_cont_expect_dps,
         cont_response_dps(1), rms_off, rms_on, m_off, m_on);
  assert_int_equal(app.gyro.cont_fail, 0u);
  assert_true((app.gyro.out.flags & GYRO_FLAG_RATE_VALID) != 0u);
  /* Its 5 deg/s tone is taken out: the output's rms moves by less than 10 % (a tone
   * left at the Butterworth's -32 dB would add 0.1 deg/s rms to about 0.1). */
  assert_true(fabs(rms_on / rms_off - 1.0) < 0.10);
  assert_true(fabs(m_on - m_off) < 0.05);
}

/* On from power-on (a stored selftest.continuous 1), a healthy part is never flagged: the
 * verdict's low-pass of the weights has caught up with the response by the time the
 * verdict starts (it runs through the LMS's settling, not from zero after it). */
static void test_continuous_from_power_on(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.fb_mode = 2;
  param_values_t v;
  part_values(&v);
  v.selftest_continuous = 1u;
  app_plant_start(&pc, 31u, &v);
  long flagged = 0, first = -1, valid = 0;
  const long n = (long)(2.0 * 50000.0 / GYRO_BLOCK);
  for (long b = 0; b < n; b++) {
    hal_host_run(GYRO_BLOCK);
    valid += app.gyro.out.rate_valid != 0u;
    if ((app.gyro.out.rate_invalid & RATE_INVALID_CONT_SELFTEST) != 0u) {
      if (first < 0) first = b;
      flagged++;
    }
  }
  printf("# continuous self-test on from power-on: CONT_SELFTEST in %ld blocks of 2 s (from "
         "%.3f s), rate valid in %ld\n",
         flagged, first < 0 ? -1.0 : (double)first * GYRO_BLOCK / 50000.0, valid);
  assert_int_equal(flagged, 0);
  assert_int_equal(app.gyro.cont_fail, 0u);
}

/* The notch takes the tone out and nothing else: with the test on, the output at a
 * constant 100 deg/s is the same (an LMS notch's pass band is 1 / (1 - mu/2), 0.2 %,
 * unless undone), and the judged response does not move with the rate. */
static void test_continuous_keeps_scale(void **state)
{
  (void)state;
  double m[2], resp[2];
  for (int on = 0; on < 2; on++) {
    plant_cfg_t pc;
    plant_default_cfg(&pc);
    pc.rate_dps = 100.0;
    start_part(&pc);
    if (on) assert_true(strncmp(cmd("set selftest.continuous 1\n"), "ok", 2) == 0);
    run_s(1.0);
    (void)rate_rms(2.0, &m[on]);
    resp[on] = cont_avg_dps();
  }
  printf("# at 100 deg/s: output %.5f off / %.5f on, judged response %.4f deg/s\n", m[0], m[1],
         resp[1]);
  assert_true(fabs(m[1] / m[0] - 1.0) < 1e-4);
  assert_true(fabs(resp[1] / (double)params_current(&app.params)->selftest_cont_expect_dps -
                   1.0) < 0.02);
  assert_int_equal(app.gyro.cont_fail, 0u);
}

static void test_continuous_dead_electrode(void **state)
{
  (void)state;
  start(0);
  assert_true(strncmp(cmd("set selftest.continuous 1\n"), "ok", 2) == 0);
  run_s(1.5);
  printf("# continuous self-test without the electrodes: response %.4f deg/s (quadrature "
         "axis %.4f)\n",
         cont_response_dps(0), cont_response_dps(1));
  assert_int_equal(app.gyro.cont_fail, 1u);
  assert_true((app.gyro.out.rate_invalid & RATE_INVALID_CONT_SELFTEST) != 0u);
  assert_true((app.gyro.out.flags & GYRO_FLAG_RATE_VALID) == 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_pass_on_healthy_part),
      cmocka_unit_test(test_fail_on_dead_electrode),
      cmocka_unit_test(test_continuous_healthy),
      cmocka_unit_test(test_continuous_from_power_on),
      cmocka_unit_test(test_continuous_keeps_scale),
      cmocka_unit_test(test_continuous_dead_electrode),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
