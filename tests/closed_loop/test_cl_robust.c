/* Lock robustness on the default plant (issue figures): a +-1 Hz step of the drive
 * resonance (27 K of structure temperature by (2-32)) and an ambient ramp over the
 * industrial range -40..85 degC must not lose lock. The step is made by setting the
 * plant's thermal nodes directly (a real part cannot jump, so this is harsher than
 * life); the ramp runs with the plant's thermal time constants shortened so that the
 * whole range passes in simulated seconds. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app_plant.h"


static void start(const plant_cfg_t *pc) { app_plant_start(pc, 21u, NULL); }

static void step_structure(double dk)
{
  double t[THERMAL_NODES];
  for (int i = 0; i < THERMAL_NODES; i++) t[i] = thermal_temp(&plant.thermal, i) + dk;
  thermal_set(&plant.thermal, t);
}

static void check_step(double dk)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  start(&pc);
  run_s(0.3);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  const double f0 = plant_truth(&plant)->wn_drive_rad_s / (2.0 * M_PI);
  step_structure(dk);
  run_s(0.002);
  const double f1 = plant_truth(&plant)->wn_drive_rad_s / (2.0 * M_PI);
  /* (2-32): kET = 40 ppm/K, so 27 K moves 1489.9 Hz by about 0.8 Hz; 33 K by 1 Hz. */
  assert_true(fabs(fabs(f1 - f0) - 1.0) < 0.05);
  run_s(0.5);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_true(fabs(plant_truth(&plant)->drive_amp_m / 10.0e-6 - 1.0) < 0.01);
}

static void test_resonance_step_up(void **state)
{
  (void)state;
  check_step(-1.0 / (0.5 * 40e-6 * 1489.9)); /* colder: stiffer, resonance up 1 Hz */
}

static void test_resonance_step_down(void **state)
{
  (void)state;
  check_step(+1.0 / (0.5 * 40e-6 * 1489.9));
}

static void test_ambient_ramp(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.temp_k = 233.15;    /* start settled at -40 degC */
  pc.tau_struct_s = 0.5; /* thermal nodes follow in a fraction of a second */
  pc.tau_circuit_s = 0.5;
  pc.tau_board_s = 0.5;
  /* The default part: its sense circuit lag (3 deg at 25 degC, 0.1 deg/K, table 7-4)
   * passes through zero into a 3.4 deg lead at -40 degC, (2-40) continued (pickoff.h). */
  start(&pc);
  assert_true(plant.pick[1].phi_rad < 0.0);
  plant_profiles_t prof;
  memset(&prof, 0, sizeof prof);
  profile_const(&prof.rate_dps, 0.0);
  profile_ramp(&prof.ambient_k, 233.15, 125.0 / 20.0, 1.0, 21.0); /* -40 -> 85 degC in 20 s */
  accel_profile_zero(&prof.accel_g);
  assert_int_equal(plant_set_profiles(&plant, &prof), 0);
  run_s(1.0);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  double worst = 0.0;
  for (int i = 0; i < 220; i++) {
    run_s(0.1);
    assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
    const double e = fabs(plant_truth(&plant)->drive_amp_m / 10.0e-6 - 1.0);
    if (e > worst) worst = e;
  }
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_true(plant_truth(&plant)->struct_k > 273.15 + 80.0);
  for (int i = 0; i < PLANT_LAWS; i++) assert_true(plant_warnings(&plant)[i].count == 0);
  /* The resonance moved by about 125 K * 0.5 * 40 ppm/K * 1490 Hz = 3.7 Hz. */
  assert_true(worst < 0.01);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_resonance_step_up),
      cmocka_unit_test(test_resonance_step_down),
      cmocka_unit_test(test_ambient_ramp),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
