/* gyro_apply: a new design takes over through one pointer, and what a design change
 * means beyond new coefficients happens there: the NCO's step is the drive's own (the
 * self-calibration sweep moves it every tick) and is set from a design only when the
 * drive frequency changes; an amplitude setpoint step re-acquires. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "gyro/gyro.h"

static gyro_t g;
static gyro_design_t d1, d2;

static void design(gyro_design_t *d, void (*edit)(param_values_t *))
{
  param_values_t v;
  param_values_defaults(&v);
  if (edit != NULL) edit(&v);
  assert_int_equal(gyro_design(&v, d), 0);
}

static void smaller_amp(param_values_t *v) { v->drive_amp_set_v *= 0.9f; }
static void other_freq(param_values_t *v) { v->drive_freq_hz += 3.0f; }

/* In SWEEP the executive sets the NCO's step; a parameter change that leaves the drive
 * frequency alone must not put the design's step back for a sample (it did). */
static void test_sweep_step_kept(void **state)
{
  (void)state;
  design(&d1, NULL);
  design(&d2, smaller_amp);
  assert_int_equal(gyro_init_from_design(&g, &d1), 0);
  gyro_sweep_begin(&g);
  const uint32_t swept = d1.nco_half_step + 12345u;
  g.nco.half_step = swept;
  gyro_apply(&g, &d2);
  assert_ptr_equal(g.design, &d2);
  assert_int_equal(g.nco.half_step, swept);
}

/* A new drive frequency retunes the NCO. */
static void test_new_frequency_retunes(void **state)
{
  (void)state;
  design(&d1, NULL);
  design(&d2, other_freq);
  assert_int_not_equal(d1.nco_half_step, d2.nco_half_step);
  assert_int_equal(gyro_init_from_design(&g, &d1), 0);
  gyro_apply(&g, &d2);
  assert_int_equal(g.nco.half_step, d2.nco_half_step);
}

/* A sweep that ends without a hand-over (failed, or stopped by `drive off`) left the NCO
 * at its last excitation step, so the next `drive on` drove there, off the resonance (it
 * did): stopping the drive puts the NCO back on the design's frequency. */
static void test_stop_restores_frequency(void **state)
{
  (void)state;
  design(&d1, NULL);
  assert_int_equal(gyro_init_from_design(&g, &d1), 0);
  gyro_sweep_begin(&g);
  g.nco.half_step = d1.nco_half_step + 54321u;
  gyro_stop(&g);
  assert_int_equal(g.nco.half_step, d1.nco_half_step);
}

/* LOCKED, a new amplitude setpoint beyond the lock tolerance: ACQUIRE again. */
static void test_amplitude_step_reacquires(void **state)
{
  (void)state;
  design(&d1, NULL);
  design(&d2, smaller_amp);
  assert_int_equal(gyro_init_from_design(&g, &d1), 0);
  g.sup.mode = GYRO_MODE_LOCKED;
  gyro_apply(&g, &d2);
  assert_int_equal(g.sup.mode, GYRO_MODE_ACQUIRE);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sweep_step_kept),
      cmocka_unit_test(test_new_frequency_retunes),
      cmocka_unit_test(test_stop_restores_frequency),
      cmocka_unit_test(test_amplitude_step_reacquires),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
