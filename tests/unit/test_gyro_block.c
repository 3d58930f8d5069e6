/* gyro_block_p: the thermometer's checks (rate_valid) and the compensation's filters
 * (rate_channel) together. Whenever the thermometer's checks pass, the compensation's
 * dynamic terms (the gradient term k (P_c - LP_tau(P_c)) and P_c's lag behind P_f) must
 * be within rate.valid_tol_dps of what the temperature alone would make them: a
 * disturbance of P that no temperature makes (a shock on the drive phase) may make the
 * rate invalid, never wrong and valid. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "gyro/gyro.h"
#include "gyro/gyro_block.h"

static gyro_t g;
static gyro_design_t d;

/* A part like the 1300 Hz / Q 200 one the calibration flow made (its ramp is the one
 * whose bias was 1 deg/s off while valid): bias slope 5 (deg/s)/deg, gradient term
 * 4 (deg/s)/deg over 20 s, P_c over 5 s. */
static const double K_GRAD = 4.0, TAU_G_S = 20.0, TAU_C_S = 5.0, C1 = 5.0;

static void make(void)
{
  param_values_t v;
  param_values_defaults(&v);
  v.rate_bias_grad_dps_per_deg = (float)K_GRAD;
  v.rate_grad_tau_s = (float)TAU_G_S;
  v.rate_comp_tau_s = (float)TAU_C_S;
  v.rate_bias_c1_dps_per_deg = (float)C1;
  v.rate_p_range_deg = 30.0f;
  assert_int_equal(gyro_design(&v, &d), 0);
  assert_int_equal(gyro_init_from_design(&g, &d), 0);
  g.sup.mode = GYRO_MODE_LOCKED; /* P not held: gyro_block_p holds it while not LOCKED */
}

/* The compensation's bias against the one the temperature alone makes, in deg/s: P_c
 * (P_f - lag) against the ramp's (P less r times P_f's and P_c's delays) at the bias
 * slope, the gradient term against k r tau. */
static double dynamic_error_dps(double r_deg_s, double t_s)
{
  const double hp = (double)g.rate.p_hp_deg;
  const double p_c = (double)g.rate.p_dev_deg - (double)g.rate.p_comp_lag_deg;
  /* P_f's delay: its low-pass's (alpha per update at 500 Hz) and its mean's half-window */
  const double a = (double)d.rate.p_lpf_alpha, t_upd_s = RATE_P_DECIM / 50000.0;
  const double delay_s = t_upd_s * (1.0 - a) / a + 0.5 * t_upd_s + TAU_C_S;
  return K_GRAD * (hp - r_deg_s * TAU_G_S) + C1 * (p_c - r_deg_s * (t_s - delay_s));
}

/* P ramps at r (2 K/min on that part) with a disturbance of dp for dur_s at t_dist_s:
 * the largest dynamic error seen while the thermometer's checks passed, after the
 * filters reached the ramp's steady state. */
/* Gaussian noise for P, deterministic (a xorshift and Box-Muller). */
static uint32_t s_rng = 12345u;
static double gauss(void)
{
  double u[2];
  for (int i = 0; i < 2; i++) {
    s_rng ^= s_rng << 13;
    s_rng ^= s_rng >> 17;
    s_rng ^= s_rng << 5;
    u[i] = ((double)s_rng + 1.0) / 4294967297.0;
  }
  return sqrt(-2.0 * log(u[0])) * cos(2.0 * M_PI * u[1]);
}

static double worst_valid_error_noisy(double r_deg_s, double dp_deg, double dur_s,
                                      double t_dist_s, double t_end_s, double sd_deg,
                                      uint32_t *slew_seen, double *valid_frac)
{
  long judged = 0, valid = 0;
  const double blocks_per_s = 50000.0 / RATE_DECIM;
  const double p0_deg = (double)d.rate.p_ref_deg;
  double worst = 0.0;
  *slew_seen = 0u;
  for (long n = 0; n < (long)(t_end_s * blocks_per_s); n++) {
    const double t = (double)n / blocks_per_s;
    const int in_dist = t >= t_dist_s && t < t_dist_s + dur_s;
    const double p_deg = p0_deg + r_deg_s * t + (in_dist ? dp_deg : 0.0) + sd_deg * gauss();
    g.drive.p_eq_rad = (float)(p_deg * M_PI / 180.0);
    gyro_block_p(&g);
    *slew_seen |= g.valid.thermo & RATE_INVALID_THERMO_SLEW;
    if (t > 10.0 * (TAU_G_S + TAU_C_S)) {
      judged++;
      if (g.valid.thermo == 0u) {
        valid++;
        worst = fmax(worst, fabs(dynamic_error_dps(r_deg_s, t)));
      }
    }
  }
  if (valid_frac != NULL) *valid_frac = judged > 0 ? (double)valid / (double)judged : 0.0;
  return worst;
}

static double worst_valid_error(double r_deg_s, double dp_deg, double dur_s, double t_dist_s,
                                double t_end_s, uint32_t *slew_seen)
{
  return worst_valid_error_noisy(r_deg_s, dp_deg, dur_s, t_dist_s, t_end_s, 0.0, slew_seen, NULL);
}


/* In a steady ramp the dynamic terms are the ramp's: no check trips. */
static void test_ramp_valid_and_right(void **state)
{
  (void)state;
  make();
  uint32_t slew = 0u;
  const double worst = worst_valid_error(0.014, 0.0, 0.0, 1e9, 400.0, &slew);
  assert_int_equal(slew, 0u);
  assert_true(worst < 0.1 * (double)d.valid.tol_dps);
}

/* A kick of dp_deg for dur_s on P at 300 s, the ramp at r: it trips the slew checks,
 * the rate is never valid and wrong, and valid again by 600 s. */
static void kick(double r_deg_s, double dp_deg, double dur_s)
{
  make();
  uint32_t slew = 0u;
  const double worst = worst_valid_error(r_deg_s, dp_deg, dur_s, 300.0, 600.0, &slew);
  print_message("worst valid dynamic error %.5f deg/s\n", worst);
  assert_int_not_equal(slew, 0u);
  assert_true(worst <= (double)d.valid.tol_dps);
  assert_int_equal(g.valid.thermo, 0u);
}

/* A 10 ms kick of 0.3 deg on P in the ramp: beyond the slew cap. Before, the cap
 * restarted the filters, which dropped the gradient term (1.1 deg/s here) and left the
 * rate valid and 0.90 deg/s wrong for the gradient term's time constant. */
static void test_kick_in_ramp_never_valid_and_wrong(void **state)
{
  (void)state;
  kick(0.014, 0.3, 0.01);
}

/* A larger kick (3 deg for 50 ms, beyond RATE_VALID_RESTART_CAPS) at rest: whatever it
 * leaves in the filters keeps the rate invalid until it is within the tolerance. */
static void test_large_kick_at_rest(void **state)
{
  (void)state;
  kick(0.0, 3.0, 0.05);
}

/* The same kick in the ramp: the filters restart once P_f is at rest again and drop the
 * ramp's gradient (1.1 deg/s of gradient term): invalid until what they dropped has
 * faded or come back, valid again after. */
static void test_large_kick_in_ramp(void **state)
{
  (void)state;
  kick(0.014, 3.0, 0.05);
}

/* A move of P that lasts (0.3 deg for 2 s, at rest and in the ramp): the filters restart
 * once P_f is at rest at the moved value, which is no temperature. Before, the
 * compensation then read the moved P_f as valid: 1.49 deg/s wrong until P returned. */
static void test_lasting_move_never_valid_and_wrong(void **state)
{
  (void)state;
  kick(0.0, 0.3, 2.0);
  kick(0.014, 0.3, 2.0);
  kick(0.014, -0.5, 20.0);
}

/* The 1300 Hz part's P_f is noisy enough (0.0017 deg rms over 0.1 s) that in its 2 K/min
 * ramp a window tips over the cap every few seconds: those trips are no move to keep the
 * rate invalid for, and the filters keep the ramp's gradient (before, each trip dropped
 * it). */
static void test_noisy_ramp(void **state)
{
  (void)state;
  make();
  uint32_t slew = 0u;
  double valid = 0.0;
  const double worst = worst_valid_error_noisy(0.014, 0.0, 0.0, 1e9, 600.0, 0.075, &slew, &valid);
  print_message("noisy ramp: worst valid error %.3f deg/s, valid %.4f\n", worst, valid);
  assert_int_not_equal(slew, 0u); /* the cap was tipped */
  assert_true(worst <= (double)d.valid.tol_dps);
  assert_true(valid > 0.95);
}

/* The compensation as the flow now sets it (three 15 s stages of P_c, the fast path of one
 * 5 s stage and the blend) on a part with the default part's bias slope, 35 (deg/s)/deg,
 * and gradient terms that take each path's ramp lag back (k = c1 x lag / tau_g): the
 * bias the firmware takes off (comp_bias_dps, whichever path carries it) against the one
 * the temperature alone makes, c1 (P - r P_f's delay). A kick on P moves the fast path
 * further and for a shorter time than the slow one, whose trace the validity's shadow
 * follows: the rate must still never be valid and wrong. */
static const double C1_FAST = 35.0, TAU_G_FAST_S = 10.0;

static void make_fast(void)
{
  param_values_t v;
  param_values_defaults(&v);
  v.rate_bias_c1_dps_per_deg = (float)C1_FAST;
  v.rate_grad_tau_s = (float)TAU_G_FAST_S;
  v.rate_comp_tau_s = 15.0f;
  v.rate_comp_stages = 3u;
  v.rate_bias_grad_dps_per_deg = (float)(C1_FAST * 45.0 / TAU_G_FAST_S);
  v.rate_comp_fast_tau_s = 5.0f;
  v.rate_grad_fast_dps_per_deg = (float)(C1_FAST * 5.0 / TAU_G_FAST_S);
  v.rate_comp_blend_dps = 0.1f;
  v.rate_p_range_deg = 30.0f;
  assert_int_equal(gyro_design(&v, &d), 0);
  assert_int_equal(gyro_init_from_design(&g, &d), 0);
  g.sup.mode = GYRO_MODE_LOCKED; /* P not held: gyro_block_p holds it while not LOCKED */
}

static double worst_valid_bias_error(double r_deg_s, double dp_deg, double dur_s, double t_dist_s,
                                     double t_end_s, uint32_t *slew_seen, double *fast_w_max)
{
  const double blocks_per_s = 50000.0 / RATE_DECIM;
  const double p0_deg = (double)d.rate.p_ref_deg;
  const double a = (double)d.rate.p_lpf_alpha, t_upd_s = RATE_P_DECIM / 50000.0;
  const double delay_s = t_upd_s * (1.0 - a) / a + 0.5 * t_upd_s;
  double worst = 0.0;
  *slew_seen = 0u;
  *fast_w_max = 0.0;
  for (long n = 0; n < (long)(t_end_s * blocks_per_s); n++) {
    const double t = (double)n / blocks_per_s;
    const int in_dist = t >= t_dist_s && t < t_dist_s + dur_s;
    const double p_deg = p0_deg + r_deg_s * t + (in_dist ? dp_deg : 0.0);
    g.drive.p_eq_rad = (float)(p_deg * M_PI / 180.0);
    gyro_block_p(&g);
    *slew_seen |= g.valid.thermo & RATE_INVALID_THERMO_SLEW;
    if (t >= t_dist_s) *fast_w_max = fmax(*fast_w_max, (double)g.rate.comp_fast_w);
    if (t > 300.0 && g.valid.thermo == 0u) {
      const double want = C1_FAST * (r_deg_s * (t - delay_s)) + (double)d.rate.bias_c_dps[0];
      worst = fmax(worst, fabs((double)g.rate.comp_bias_dps - want));
    }
  }
  return worst;
}

static void kick_fast(double r_deg_s, double dp_deg, double dur_s)
{
  make_fast();
  uint32_t slew = 0u;
  double w_max = 0.0;
  const double worst = worst_valid_bias_error(r_deg_s, dp_deg, dur_s, 400.0, 900.0, &slew,
                                              &w_max);
  print_message("fast path: kick %.2f deg for %.2f s in %.3f deg/s: worst valid error %.3f "
                "deg/s, fast weight up to %.2f\n",
                dp_deg, dur_s, r_deg_s, worst, w_max);
  assert_true(worst <= (double)d.valid.tol_dps);
  assert_int_equal(g.valid.thermo, 0u);
  if (dp_deg != 0.0) {
    assert_int_not_equal(slew, 0u);
    assert_true(w_max == 0.0); /* the fast path sat the move out (rate_channel_fast_hold) */
  }
}

static void test_fast_path_kicks_never_valid_and_wrong(void **state)
{
  (void)state;
  kick_fast(0.014, 0.0, 0.0); /* the ramp alone: both paths agree, valid and right */
  kick_fast(0.014, 0.3, 0.01);
  kick_fast(0.0, 3.0, 0.05);
  kick_fast(0.014, 3.0, 0.05);
  kick_fast(0.0, 0.3, 0.5); /* a drive-phase disturbance of half a second */
  kick_fast(0.014, -0.03, 5.0);
  kick_fast(0.014, -0.1, 5.0);
}

/* The loop state's clear after a fault (gyro_block_clear, then the rate slots): P_f starts
 * again from the reference, and so do the thermometer's checks (rate_valid_restart), as
 * at power-on. Before, they kept what they found about the P_f of before the fault (the
 * slew window's start, a THERMO_SLEW, the shadow, the trend), which the new P_f, started
 * elsewhere, does not have. */
static void test_fault_clear_restarts_the_thermometer_checks(void **state)
{
  (void)state;
  make();
  uint32_t slew = 0u;
  (void)worst_valid_error(0.0, 0.5, 0.05, 1.0, 1.1, &slew); /* ends in the kick's trace */
  assert_int_not_equal(slew, 0u);
  g.sup.clear_req = 1u;
  gyro_block_run(&g, GYRO_SLOT_PROJECT, 0.0f, 0.0f);
  for (int i = 0; i < 2 && g.rate_clear_due != 0u; i++) {
    gyro_block_run(&g, GYRO_SLOT_RATE, 0.0f, 0.0f);
  }
  assert_int_equal(g.rate_clear_due, 0u);
  assert_true(g.rate.p_dev_deg == 0.0f);
  /* A fresh start's checks, but for what the verdict keeps (its history, the settling
   * check, the phase error's low-pass: reset on entering LOCKED). */
  rate_valid_t fresh;
  assert_int_equal(rate_valid_init(&d.valid, &fresh), 0);
  const rate_valid_t *v = &g.valid;
  fresh.reasons = v->reasons;
  fresh.drive = v->drive;
  fresh.range = v->range;
  fresh.settled = v->settled;
  fresh.settle_run = v->settle_run;
  fresh.was_locked = v->was_locked;
  fresh.x_rate = v->x_rate;
  fresh.x_quad = v->x_quad;
  fresh.d_rate = v->d_rate;
  fresh.d_quad = v->d_quad;
  fresh.phase_err_lp_rad = v->phase_err_lp_rad;
  fresh.blocks = v->blocks;
  fresh.onsets_pending = v->onsets_pending;
  fresh.onset_block = v->onset_block;
  assert_memory_equal(&fresh, v, sizeof fresh);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_ramp_valid_and_right),
      cmocka_unit_test(test_kick_in_ramp_never_valid_and_wrong),
      cmocka_unit_test(test_large_kick_at_rest),
      cmocka_unit_test(test_large_kick_in_ramp),
      cmocka_unit_test(test_noisy_ramp),
      cmocka_unit_test(test_lasting_move_never_valid_and_wrong),
      cmocka_unit_test(test_fast_path_kicks_never_valid_and_wrong),
      cmocka_unit_test(test_fault_clear_restarts_the_thermometer_checks),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
