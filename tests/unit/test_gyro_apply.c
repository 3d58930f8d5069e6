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
#include "gyro/gyro_block.h"

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

static void later_p_init(param_values_t *v) { v->drive_p_init_deg += 1.0f; }

/* THERMO_SLEW seen over s_s of blocks with P held at p_deg (LOCKED: P not held). */
static uint32_t slew_over(double s_s, double p_deg)
{
  uint32_t slew = 0u;
  g.drive.p_eq_rad = (float)(p_deg * 0.017453292519943295);
  for (long n = 0; n < (long)(s_s * 50000.0 / RATE_DECIM); n++) {
    gyro_block_p(&g);
    slew |= g.valid.thermo & RATE_INVALID_THERMO_SLEW;
  }
  return slew;
}

/* A new drive.p_init_deg (live) moves the reference P_f's low-pass works around
 * (rate_channel_rebase): P_f is kept and re-expressed around it, and so are the fast
 * start's held value and the thermometer checks' slew window and trend (in the same
 * coordinates). Before, they stayed where they were, and the next window read the change
 * of reference as a move of P_f of 1 deg with the temperature unchanged (THERMO_SLEW,
 * the fast path held out for 180 s on the default design). */
static void test_new_reference_moves_the_checks_with_p_f(void **state)
{
  (void)state;
  design(&d1, NULL);
  design(&d2, later_p_init);
  assert_int_equal(gyro_init_from_design(&g, &d1), 0);
  g.sup.mode = GYRO_MODE_LOCKED;
  const double p_deg = (double)d1.rate.p_ref_deg + 0.2;
  (void)slew_over(2.0, p_deg); /* P_f's fast start, then at rest */
  assert_int_equal(slew_over(1.0, p_deg), 0u);
  const float f_before = g.rate.p_f_deg;
  /* Each where it was from P_f, before and after. */
  const float held_gap_deg = g.rate.p_held_dev_deg - g.rate.p_dev_deg;
  const float window_gap_deg = g.valid.p_dev_window_deg - g.rate.p_dev_deg;
  const float trend_gap_deg = g.valid.trend_p_deg - g.rate.p_dev_deg;
  gyro_apply(&g, &d2);
  assert_true(g.rate.p_f_deg == f_before);
  assert_float_equal(g.rate.p_held_dev_deg - g.rate.p_dev_deg, held_gap_deg, 1e-4f);
  assert_float_equal(g.valid.p_dev_window_deg - g.rate.p_dev_deg, window_gap_deg, 1e-4f);
  assert_float_equal(g.valid.trend_p_deg - g.rate.p_dev_deg, trend_gap_deg, 1e-4f);
  assert_int_equal(slew_over(2.0, p_deg), 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sweep_step_kept),
      cmocka_unit_test(test_new_frequency_retunes),
      cmocka_unit_test(test_stop_restores_frequency),
      cmocka_unit_test(test_amplitude_step_reacquires),
      cmocka_unit_test(test_new_reference_moves_the_checks_with_p_f),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
