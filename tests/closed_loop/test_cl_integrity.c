/* Output integrity on the plant: the fault battery. Every case is a part, a setting or a
 * command sequence on which the gyro could put out a wrong rate; on each, the whole
 * application runs on the host plant and every block's output is judged:
 *   - once the rate has first been valid, no block has rate_valid = 1 with
 *     |rate - true rate| > max(1 deg/s, 1 % of the input);
 *   - whenever the rate is not valid, the analog rate output is commanded to the fault
 *     level rate.fault_out_v in the same block (never the 0 V of "no rotation").
 * The healthy default part, as the positive control, is valid >= 95 % of the time after
 * 0.3 s and first valid within 0.25 s of power-on. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "integrity_judge.h"

static void default_part(plant_cfg_t *pc) { plant_default_cfg(pc); }

static void test_healthy_default_part(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  judge_t j;
  start_part(&pc, NULL);
  judge_reset(&j);
  judge_run(&j, 1.5);
  judge_print("healthy default part", &j);
  judge_assert(&j);
  assert_true(j.first_valid_s >= 0.0 && j.first_valid_s <= 0.25);
  assert_true(j.valid_after_0p3 >= 0.95 * j.blocks_after_0p3);
}


/* Parts other than the default, on the default firmware values: each plant setting
 * that differs (0: the default part's), and how long to judge it. */
typedef struct {
  const char *name;
  double f_drive_hz, q_drive, quad_dps, rate_dps, temp_k;
  double run_s;
} part_case_t;

static part_case_t k_parts[] = {
    /* not const: cmocka passes it as void * */
    {"f_drive 1550 Hz", 1550.0, 0.0, 0.0, 0.0, 0.0, 2.0},       /* 60 Hz from drive.freq_hz */
    {"f_drive 1530 Hz", 1530.0, 0.0, 0.0, 0.0, 0.0, 2.0},       /* locks with P 60 deg off */
    {"Q 10000, defaults", 0.0, 10000.0, 0.0, 0.0, 0.0, 3.0},    /* beyond the default design */
    {"quad 4000, rate 100", 0.0, 0.0, 4000.0, 100.0, 0.0, 1.5}, /* sense ADC clips at peaks */
    {"rate 3000", 0.0, 0.0, 0.0, 3000.0, 0.0, 1.5},             /* ten times full scale */
    /* uncompensated bias 67 / 93 deg/s away from where the shipped values were taken */
    {"0 degC ambient", 0.0, 0.0, 0.0, 0.0, 273.15, 1.5},
    {"60 degC ambient", 0.0, 0.0, 0.0, 0.0, 333.15, 1.5},
};

static void test_part(void **state)
{
  const part_case_t *c = *state;
  plant_cfg_t pc;
  default_part(&pc);
  if (c->f_drive_hz > 0.0) pc.f_drive_hz = c->f_drive_hz;
  if (c->q_drive > 0.0) pc.q_drive = c->q_drive;
  if (c->quad_dps > 0.0) pc.quad_dps = c->quad_dps;
  if (c->rate_dps > 0.0) pc.rate_dps = c->rate_dps;
  if (c->temp_k > 0.0) pc.temp_k = c->temp_k;
  run_case(c->name, &pc, NULL, c->run_s);
}

/* Two in-range phase setpoints over the command line: the loop must not pin P. */
static void test_phase_setpoint_walk(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  judge_t j;
  start_part(&pc, NULL);
  judge_reset(&j);
  judge_run(&j, 0.4);
  assert_true(strncmp(cmd("set drive.phase_set_deg -179\n"), "ok", 2) == 0);
  judge_run(&j, 1.0);
  assert_true(strncmp(cmd("set drive.phase_set_deg 2\n"), "ok", 2) == 0);
  judge_run(&j, 2.0);
  judge_print("phase set -179 then 2", &j);
  judge_assert(&j);
  /* Locked on the new setpoint; P, which moved with it, is 2 deg from the thermometer's
   * reference, and the demodulation phase was measured at the old one: the calibration
   * is stale, not valid (with a calibrated range of +-5 deg of P, the set point's 2 deg
   * were once read as temperature: a valid rate 68 deg/s wrong). */
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_false(rate_valid_now());
  assert_non_null(strstr(cmd("status\n"), "- calibrated stale\r\n"));
  /* Not a dead end: back on the setpoint the values were taken at, valid again. P's way
   * back to the old setpoint is a move of P_f no temperature makes; the compensation's
   * fast path (the default part's calibration has one) takes in more of it than the slow
   * path and sits it out, and the shadow keeps the rate invalid until what the fast path
   * took in has decayed under half the tolerance: 14.5 s here (2 s with the slow
   * path alone). Judged over the whole wait: never valid and wrong. */
  assert_true(strncmp(cmd("set drive.phase_set_deg 0\n"), "ok", 2) == 0);
  double waited_s = 0.0, valid_from_s = 0.0;
  while (waited_s < 20.0) {
    judge_run(&j, 0.5);
    waited_s += 0.5;
    if (!rate_valid_now()) valid_from_s = waited_s;
  }
  print_message("# valid for good from %.1f s after the setpoint's return\n", valid_from_s);
  judge_assert(&j);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_true(rate_valid_now());
}

/* A high-Q part with the calibration its own sweep identifies (tests/slow/
 * test_integrity_selfcal.c runs that sweep, 22.6 s of simulated time: f0 1489.8612 Hz,
 * Q 4999.7, gain 0.81028 V/V^2, P 25.66 deg), then the structure 22.5 K warmer than at its
 * sweep: beyond the fixed-frequency drive's reach (the drive phase slips towards 90 deg). */
static void test_q5000_calibrated_warm(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  pc.q_drive = 5000.0;
  param_values_t v;
  default_part_values(&v);
  v.drive_cal_f0_hz = 1489.8612f;
  v.drive_freq_hz = 1489.8612f;
  v.drive_cal_q = 4999.7f;
  v.drive_cal_gain_v_per_v2 = 0.81028f;
  v.drive_p_init_deg = 25.66f;
  v.cal_ref_freq_hz = v.drive_freq_hz;
  pc.temp_k += 22.5;
  run_case("Q 5000 calibrated, +22.5 K", &pc, &v, 3.0);
}


static void test_sense_vibration_10g(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  judge_t j;
  start_part(&pc, NULL);
  plant_profiles_t prof;
  memset(&prof, 0, sizeof prof);
  profile_const(&prof.rate_dps, 0.0);
  profile_const(&prof.ambient_k, pc.temp_k);
  prof.accel_g.amp_g[ACCEL_AXIS_SENSE] = 10.0;
  prof.accel_g.freq_hz[ACCEL_AXIS_SENSE] = 100.0;
  assert_int_equal(plant_set_profiles(&plant, &prof), 0);
  judge_reset(&j);
  judge_run(&j, 1.5);
  judge_print("10 g at 100 Hz, sense axis", &j);
  judge_assert(&j);
}

static void set_value(param_values_t *v, const char *name, float x)
{
  const param_idx_t i = param_lookup(name, strlen(name));
  assert_true(i < PARAM_COUNT);
  memcpy((char *)v + param_info(i)->offset, &x, sizeof x);
}

static void test_amplitude_setpoint_at_limit(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  param_values_t v;
  default_part_values(&v);
  set_value(&v, "drive.amp_set_v", 4.5f);
  run_case("drive.amp_set_v 4.5", &pc, &v, 2.0);
}

static void test_drive_frequency_5000(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  param_values_t v;
  default_part_values(&v);
  set_value(&v, "drive.freq_hz", 5000.0f);
  run_case("drive.freq_hz 5000", &pc, &v, 2.0);
}

/* A subnormal gain: either refused before it reaches the gyro, or the rate is never
 * valid with it. */
static void test_subnormal_gain(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  param_values_t v;
  default_part_values(&v);
  set_value(&v, "drive.amp_kp", 1e-45f);
  assert_int_equal(plant_init(&plant, &pc, 31u), 0);
  assert_int_equal(hal_flash_host_configure(NULL), 0);
  hal_uart_host_reset();
  hal_host_attach(plant_step_hal, &plant);
  if (app_init_with(&app, &v) != 0) {
    printf("# subnormal drive.amp_kp refused at design\n");
    return;
  }
  assert_int_equal(hal_sample_timer_start(50000u, app_sample_isr, &app), 0);
  judge_t j;
  judge_reset(&j);
  judge_run(&j, 1.0);
  judge_print("drive.amp_kp 1e-45", &j);
  judge_assert(&j);
}

/* The self-calibration excites the drive off its operating point: the rate is not valid
 * during the sweep, and `status` says so. */
static void test_status_during_sweep(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  judge_t j;
  start_part(&pc, NULL);
  judge_reset(&j);
  judge_run(&j, 0.3);
  assert_true(strncmp(cmd("sweep\n"), "ok", 2) == 0);
  judge_run(&j, 1.0);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_SWEEP);
  const char *status = cmd("status\n");
  assert_non_null(strstr(status, "- rate_valid 0"));
  assert_null(strstr(status, "- rate_valid 1"));
  judge_print("status during sweep", &j);
  judge_assert(&j);
}

/* A sample lost between the converters and the interrupt (an overrun the HAL counts):
 * the NCO runs a sample behind from then on, so the drive faults and re-acquires, and
 * the rate is invalid from the block that saw it. */
static void test_lost_sample(void **state)
{
  (void)state;
  plant_cfg_t pc;
  default_part(&pc);
  judge_t j;
  start_part(&pc, NULL);
  judge_reset(&j);
  judge_run(&j, 0.5);
  assert_true(rate_valid_now());
  hal_host_lose_sample();
  hal_host_run(2u * GYRO_BLOCK);
  assert_false(rate_valid_now());
  assert_int_equal(app.gyro.sup.fault, GYRO_FAULT_LOST_SAMPLE);
  judge_run(&j, 1.0);
  judge_print("lost sample", &j);
  judge_assert(&j);
  assert_true(rate_valid_now()); /* re-acquired */
  assert_non_null(strstr(cmd("status\n"), "fault_LOST_SAMPLE count 1"));
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_healthy_default_part),
      cmocka_unit_test_prestate(test_part, &k_parts[0]),
      cmocka_unit_test_prestate(test_part, &k_parts[1]),
      cmocka_unit_test(test_phase_setpoint_walk),
      cmocka_unit_test(test_q5000_calibrated_warm),
      cmocka_unit_test_prestate(test_part, &k_parts[2]),
      cmocka_unit_test_prestate(test_part, &k_parts[3]),
      cmocka_unit_test_prestate(test_part, &k_parts[4]),
      cmocka_unit_test_prestate(test_part, &k_parts[5]),
      cmocka_unit_test_prestate(test_part, &k_parts[6]),
      cmocka_unit_test(test_sense_vibration_10g),
      cmocka_unit_test(test_amplitude_setpoint_at_limit),
      cmocka_unit_test(test_drive_frequency_5000),
      cmocka_unit_test(test_subnormal_gain),
      cmocka_unit_test(test_status_during_sweep),
      cmocka_unit_test(test_lost_sample),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
