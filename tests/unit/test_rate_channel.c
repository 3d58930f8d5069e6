#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "dsp/butter.h"
#include "gyro/rate_channel.h"

static rate_channel_cfg_t base_cfg(biquad_coeffs_t *sec, float phi_dm)
{
  const int n = butter_design(BUTTER_LOWPASS, 4u, 100.0, 0.0, 50000.0 / RATE_DECIM, sec,
                              BIQUAD_MAX_SECTIONS);
  assert_int_equal(n, 2);
  rate_channel_cfg_t c = {.ref_re = cosf(phi_dm),
                          .ref_im = sinf(phi_dm),
                          .scale_dps = 250.0f,
                          .bias_c_dps = {0, 0, 0, 0},
                          .sf_c = {0, 0, 0, 0, 0},
                          .p_ref_deg = 0.0f,
                          .p_lpf_alpha = 0.5f,
                          .grad_a = 1.0f, /* no gradient term unless a test sets one */
                          .comp_a = 1.0f, /* the compensation reads P_f */
                          .comp_stages = 1u,
                          .comp_fast_a = 0.0f, /* no fast path unless a test sets one */
                          .blend_dps = 0.1f,
                          .blend_inv_per_dps = 10.0f,
                          .p_mode_k = 2.7658e-2f, /* 1 - (1 - 2.8e-3)^10 per block */
                          /* 1 Hz, zeta 0.707 per 0.2 ms block (gyro_design.c) */
                          .ref_lp_kp = 1.7772e-3f,
                          .ref_lp_ki = 1.5791e-6f,
                          .ref_wide_kp = 1.7772e-2f, /* 10 Hz */
                          .ref_wide_ki = 1.5791e-4f,
                          .ref_wide_blocks = 0u,
                          .ref_narrow_k = 0.5f, /* narrow within a few blocks */
                          .lpf_sections = (uint32_t)n,
                          .min_drive_v = 0.1f,
                          .turn_max_dps = 300.0f};
  memcpy(c.lpf, sec, (size_t)n * sizeof sec[0]);
  return c;
}

/* The configuration the channel under test runs with: the test's own, by pointer, as
 * the gyro runs with the published design. */
static const rate_channel_cfg_t *s_cfg;

static int rc_init(rate_channel_t *rc, const rate_channel_cfg_t *c)
{
  const int r = rate_channel_init(c, rc);
  if (r == 0) s_cfg = c;
  return r;
}

/* One block as gyro_tick feeds the channel: the same sense phasor on every tick. */
static void block(rate_channel_t *rc, float d_s, float d_c, float s_s, float s_c, float p_rad)
{
  for (uint32_t i = 0; i < RATE_DECIM; i++) rate_channel_accumulate(rc, s_s, s_c);
  rate_channel_update(s_cfg, rc, d_s, d_c, p_rad, 0.0f);
  rate_channel_update_p(s_cfg, rc, p_rad);
}

/* A sense phasor built as (r + j q) A_set e^{j psi} must come out as rate r and
 * quadrature q, for any reference phase and amplitude setpoint, whatever the measured
 * drive phasor (it only gates the output). */
static void test_phasor_separation(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  for (int i = 0; i < 200; i++) {
    const double psi = -3.0 + 0.03 * i, th = 0.7 * i, amp = 0.5 + 0.01 * i;
    const double r = 1e-3 * (i - 100), q = 0.02 - 1e-4 * i;
    rate_channel_cfg_t c = base_cfg(sec, 0.0f);
    c.ref_re = (float)(cos(psi) / amp);
    c.ref_im = (float)(sin(psi) / amp);
    rate_channel_t rc;
    assert_int_equal(rc_init(&rc, &c), 0);
    const double er = amp * (r * cos(psi) - q * sin(psi)),
                 ei = amp * (r * sin(psi) + q * cos(psi));
    block(&rc, (float)(0.3 * cos(th)), (float)(0.3 * sin(th)), (float)er, (float)ei, 0.0f);
    assert_true(fabs((double)rc.rate_raw - r) < 2e-6);
    assert_true(fabs((double)rc.quad_raw - q) < 2e-6);
  }
}

/* 1 % demodulation-phase error leaks sin(0.01 rad) of the quadrature into rate. */
static void test_phase_error_leakage(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.01f);
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  block(&rc, 1.0f, 0.0f, 0.0f, 1.0f, 0.0f); /* pure quadrature, phi_dm true = 0 */
  assert_true(fabs((double)rc.rate_raw - sin(0.01)) < 1e-6);
}

/* After the Butterworth settles: rate = L(scale * r) * sf(x) - bias(x), with L the
 * linearisation of the uncompensated rate, x = P_f - the calibration's reference
 * (cal.ref_p_deg) and P low-passed around another working point (drive.p_init_deg). */
static void test_compensation_polynomials(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  c.bias_c_dps[0] = 58.533f; /* the thesis's fit, 7.3.2 */
  c.bias_c_dps[1] = 34.59f;
  c.bias_c_dps[2] = 0.1f;
  c.sf_c[1] = 1e-3f;
  c.sf_c[3] = -2e-6f;
  c.sf_c[4] = 3e-7f;
  c.lin_c2_per_dps = 2e-5f;   /* 0.1 % at 50 deg/s */
  c.lin_c3_per_dps2 = -4e-8f; /* -0.01 % */
  c.p_ref_deg = -1.5f;
  const double ref_p_deg = -1.0;
  c.p_poly_off_deg = (float)(c.p_ref_deg - ref_p_deg);
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_reset(s_cfg, &rc, -1.5f);
  const double p_deg = -1.7, r = 0.2, q = -0.05;
  /* 5 s: P's step reaches the reference's correction through its 1 Hz low-pass as well
   * (the block passes no loop error), which must have settled to 1e-5 as well. */
  for (int n = 0; n < 25000; n++) {
    block(&rc, 1.0f, 0.0f, (float)r, (float)q, (float)(p_deg * M_PI / 180.0));
  }
  const double x = p_deg - ref_p_deg;
  const double sf = 1.0 + 1e-3 * x - 2e-6 * x * x * x + 3e-7 * x * x * x * x;
  const double bias = 58.533 + 34.59 * x + 0.1 * x * x;
  assert_true(fabs((double)rc.p_f_deg - p_deg) < 1e-5);
  assert_true(fabs((double)rc.rate_unc_dps - 250.0 * r) < 250.0 * r * 1e-5);
  assert_true(fabs((double)rc.quad_dps - 250.0 * q) < 250.0 * fabs(q) * 1e-5); /* not compensated */
  const double u = 250.0 * r, lin = u + 2e-5 * u * u - 4e-8 * u * u * u;
  assert_true(fabs((double)rc.rate_dps - (lin * sf - bias)) < 1e-3);
  assert_true(fabs((lin - u) * sf) > 0.04); /* the linearisation is seen */
}

/* The low-pass of P tracks a slow change without a dead band: a 1e-4 deg change of P
 * (0.003 deg/s of bias at the thesis's slope) is followed. */
static void test_p_lowpass_resolution(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  c.p_ref_deg = -100.0f;
  c.p_lpf_alpha = 1.25e-2f; /* 1 Hz at fs / RATE_P_DECIM */
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_reset(s_cfg, &rc, -100.0f);
  const double p_deg = -100.0 + 1e-4;
  for (int n = 0; n < 50000; n++) {
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  }
  assert_true(fabs((double)rc.p_f_deg - p_deg) < 2e-5);
}

/* The gradient term: on a steady ramp of P at r the high-pass P_f - LP_tau(P_f) settles
 * to r tau, and the bias it adds to k r tau; when P stops it decays to nothing. A jump
 * of P across a hold (the restart of a part that cooled meanwhile) is no gradient. */
static void test_gradient_term(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  const double tau_s = 2.0, k = 10.0, r_deg_s = 0.01, t_upd_s = RATE_P_DECIM / 50000.0;
  c.p_lpf_alpha = 1.25e-2f; /* 1 Hz at fs / RATE_P_DECIM */
  c.grad_k_dps_per_deg = (float)k;
  c.grad_a = (float)(1.0 - exp(-t_upd_s / tau_s));
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_reset(s_cfg, &rc, 0.0f);
  const long blocks_per_s = 50000 / RATE_DECIM;
  double p_deg = 0.0;
  for (long n = 0; n < 20 * blocks_per_s; n++) { /* 10 tau */
    p_deg += r_deg_s / (double)blocks_per_s;
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  }
  assert_true(fabs((double)rc.p_hp_deg - r_deg_s * tau_s) < 0.01 * r_deg_s * tau_s);
  assert_true(fabs((double)rc.rate_dps + k * r_deg_s * tau_s) < 0.01 * k * r_deg_s * tau_s);
  for (long n = 0; n < 20 * blocks_per_s; n++) {
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  }
  assert_true(fabs((double)rc.p_hp_deg) < 1e-4 * r_deg_s * tau_s);
  /* Held, P moves by 0.5 deg, released: the fast start carries P_f there, no gradient. */
  rate_channel_hold_p(&rc, 1);
  block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  rate_channel_hold_p(&rc, 0);
  p_deg += 0.5;
  double hp_max = 0.0;
  for (long n = 0; n < 2 * blocks_per_s; n++) {
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
    hp_max = fmax(hp_max, fabs((double)rc.p_hp_deg));
  }
  assert_true(fabs((double)rc.p_f_deg - p_deg) < 1e-3);
  assert_true(hp_max < 2e-4); /* 0.5 deg x COMP_FILTERS_HELD_W_MAX, and the lag of P_f */
}

/* The compensation's own thermometer P_c (rate.comp_tau_s): after a step of P it follows
 * P_f with its time constant, so the bias polynomial moves 1 - 1/e of the way in one. */
static void test_compensation_thermometer_lowpass(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  const double tau_s = 1.0, c1 = 10.0, dp_deg = 0.1;
  c.p_lpf_alpha = 1.25e-2f;
  c.bias_c_dps[1] = (float)c1;
  c.comp_a = (float)(1.0 - exp(-(RATE_P_DECIM / 50000.0) / tau_s));
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_reset(s_cfg, &rc, 0.0f);
  const long blocks_per_s = 50000 / RATE_DECIM;
  for (long n = 0; n < 2 * blocks_per_s; n++) block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  assert_true(fabs((double)rc.rate_dps) < 1e-6);
  const float p_rad = (float)(dp_deg * M_PI / 180.0);
  for (long n = 0; n < blocks_per_s; n++) block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, p_rad);
  /* P_f's own 1 Hz low-pass (0.16 s) delays P_c a little more: 0.55 .. 0.632 of the way */
  const double frac = -(double)rc.rate_dps / (c1 * dp_deg);
  assert_true(frac > 0.55 && frac < 0.64);
  for (long n = 0; n < 12 * blocks_per_s; n++) block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, p_rad);
  assert_true(fabs((double)rc.rate_dps + c1 * dp_deg) < 1e-4);
}

/* The compensation thermometer with n stages of tau = 2 s (c1 = 10 (deg/s)/deg): after
 * a step of P of 0.1 deg held step_s, the output has a fraction in (lo, hi) of its final
 * value (P_f's own 1 Hz low-pass, 0.16 s, delays it a little), all of it after settle_s
 * more; then a ramp of 0.01 deg/s for ramp_s leaves P_c behind P_f by n tau, to tol. */
static void check_stages(uint32_t n, double step_s, double lo, double hi, double settle_s,
                         double ramp_s, double tol)
{
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  const double tau_s = 2.0, c1 = 10.0, dp_deg = 0.1;
  c.p_lpf_alpha = 1.25e-2f;
  c.bias_c_dps[1] = (float)c1;
  c.comp_a = (float)(1.0 - exp(-(RATE_P_DECIM / 50000.0) / tau_s));
  c.comp_stages = n;
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_reset(s_cfg, &rc, 0.0f);
  const long blocks_per_s = 50000 / RATE_DECIM;
  for (long k = 0; k < 2 * blocks_per_s; k++) block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  assert_true(fabs((double)rc.rate_dps) < 1e-6);
  const float p_rad = (float)(dp_deg * M_PI / 180.0);
  for (long k = 0; k < (long)(step_s * blocks_per_s); k++)
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, p_rad);
  const double frac = -(double)rc.rate_dps / (c1 * dp_deg);
  print_message("%u stages: %.4f of the step at %.0f s\n", n, frac, step_s);
  assert_true(frac > lo && frac < hi);
  for (long k = 0; k < (long)(settle_s * blocks_per_s); k++)
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, p_rad);
  assert_true(fabs((double)rc.rate_dps + c1 * dp_deg) < 1e-4);
  const double slope_deg_s = 0.01;
  double p_deg = dp_deg;
  for (long k = 0; k < (long)(ramp_s * blocks_per_s); k++) {
    p_deg += slope_deg_s / (double)blocks_per_s;
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  }
  assert_true(fabs((double)rc.p_comp_lag_deg - (double)n * tau_s * slope_deg_s) < tol);
}

/* Two stages (rate.comp_stages 2): after a step of P, P_c has 1 - 2/e = 0.264 of it at
 * one rate.comp_tau_s (one stage would be past 0.55), all of it in the end; on a ramp
 * of P, P_c lags P_f by 2 tau (the gradient term's to take), to 1 %; a stage count
 * outside 1..3 is refused. */
static void test_compensation_thermometer_two_stages(void **state)
{
  (void)state;
  check_stages(2u, 2.0, 0.225, 0.265, 40.0, 60.0, 4e-4);
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  rate_channel_t rc;
  c.comp_stages = COMP_STAGES_MAX;
  assert_int_equal(rc_init(&rc, &c), 0);
  c.comp_stages = COMP_STAGES_MAX + 1u;
  assert_int_equal(rc_init(&rc, &c), -1);
  c.comp_stages = 0u;
  assert_int_equal(rc_init(&rc, &c), -1);
}

/* Three stages: at 3 tau after a step P_c has 1 - (1 + 3 + 9/2)/e^3 = 0.577 of it (two
 * stages: 0.80); on a ramp it lags P_f by 3 tau. */
static void test_compensation_thermometer_three_stages(void **state)
{
  (void)state;
  check_stages(3u, 6.0, 0.55, 0.58, 60.0, 80.0, 6e-4);
}

/* The fast path (rate.comp_fast_tau_s) and the blend: a slow thermometer of three 2 s
 * stages and a fast one of 0.5 s, bias slope c1 = 10 (deg/s)/deg, no gradient terms.
 * At rest both agree: the slow path's output, the fast one's weight 0. On a ramp of P at
 * r the slow one lags by 6 s r and the fast one by 0.5 s r, their biases differ by
 * d = c1 5.5 s r: at r = 0.01 deg/s (d = 0.55 > 2 x 0.1) the output is the fast path's
 * alone, as a channel of that one stage gives it; at r = 0.0025 (d = 0.1375, between
 * blend and twice it) the weight is (d - blend) / blend and the output within blend of the
 * fast path. A blend of 0 or a fast low-pass outside 0..1 is refused. */
static void run_ramp(rate_channel_t *rc, const rate_channel_cfg_t *c, double r_deg_s, double s)
{
  const long blocks_per_s = 50000 / RATE_DECIM;
  s_cfg = c;
  double p_deg = 0.0;
  for (long k = 0; k < 10 * blocks_per_s; k++) block(rc, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  assert_true(fabs((double)rc->rate_dps) < 1e-6);
  assert_true(rc->comp_fast_w == 0.0f);
  for (long k = 0; k < (long)(s * blocks_per_s); k++) {
    p_deg += r_deg_s / (double)blocks_per_s;
    block(rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  }
}

static void test_compensation_fast_path_blend(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  const double t_upd_s = RATE_P_DECIM / 50000.0, c1 = 10.0, blend = 0.1;
  rate_channel_cfg_t slow = base_cfg(sec, 0.0f);
  slow.p_lpf_alpha = 1.25e-2f;
  slow.bias_c_dps[1] = (float)c1;
  slow.comp_a = (float)(1.0 - exp(-t_upd_s / 2.0));
  slow.comp_stages = 3u;
  slow.comp_fast_a = (float)(1.0 - exp(-t_upd_s / 0.5));
  slow.blend_dps = (float)blend;
  slow.blend_inv_per_dps = (float)(1.0 / blend);
  rate_channel_cfg_t fast = slow; /* the fast path alone, as a channel of its own */
  fast.comp_a = slow.comp_fast_a;
  fast.comp_stages = 1u;
  fast.comp_fast_a = 0.0f;
  rate_channel_t rc, rf;
  assert_int_equal(rc_init(&rc, &slow), 0);
  assert_int_equal(rc_init(&rf, &fast), 0);
  run_ramp(&rc, &slow, 0.01, 30.0);
  run_ramp(&rf, &fast, 0.01, 30.0);
  print_message("r 0.01: w %.3f, out %.5f, fast alone %.5f\n", (double)rc.comp_fast_w,
                (double)rc.rate_dps, (double)rf.rate_dps);
  assert_true(rc.comp_fast_w == 1.0f);
  assert_true(fabs((double)rc.rate_dps - (double)rf.rate_dps) < 1e-5);
  assert_true(fabs((double)rc.rate_dps + c1 * 0.01 * (30.0 - 0.5 - 0.16)) < 0.01);
  assert_int_equal(rc_init(&rc, &slow), 0);
  assert_int_equal(rc_init(&rf, &fast), 0);
  run_ramp(&rc, &slow, 0.0025, 40.0);
  run_ramp(&rf, &fast, 0.0025, 40.0);
  const double d = c1 * 5.5 * 0.0025, w = (d - blend) / blend;
  print_message("r 0.0025: w %.3f (%.3f), out %.5f, fast alone %.5f\n", (double)rc.comp_fast_w,
                w, (double)rc.rate_dps, (double)rf.rate_dps);
  assert_true(fabs((double)rc.comp_fast_w - w) < 0.02);
  assert_true(fabs((double)rc.rate_dps - (double)rf.rate_dps) <= blend);
  assert_true(fabs((double)rc.rate_dps - (double)rf.rate_dps) > 0.5 * (1.0 - w) * d);
  slow.blend_dps = 0.0f;
  assert_int_equal(rc_init(&rc, &slow), -1);
  slow.blend_dps = (float)blend;
  slow.comp_fast_a = 1.5f;
  assert_int_equal(rc_init(&rc, &slow), -1);
}

/* The rate's own turn of P (the reciprocal Coriolis force on the drive mode) is no
 * temperature: with rate.p_rate_deg_per_dps set, P_f stays where it was while the rate
 * steps to 100 deg/s and P turns by 0.002 deg with it; without, it follows P. The turn
 * changes with temperature (rate.p_rate_c1_per_dps per degree of x): at x = 10.3 deg a
 * turn of 1e-5 + 1.03e-5 deg/(deg/s) is taken out as well; and one with the square of the
 * rate (rate.p_rate2_deg_per_dps2). */
static void test_rate_taken_out_of_p(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  const double p0_deg = 0.3, r = 0.4; /* 250 x 0.4 = 100 deg/s */
  const struct {
    double beta0, beta1, gamma, off_deg, beta_true;
    int taken;
  } cases[] = {{0.0, 0.0, 0.0, 0.0, 2e-5, 0},
               {2e-5, 0.0, 0.0, 0.0, 2e-5, 1},
               {1e-5, 1e-6, 0.0, 10.0, 2.03e-5, 1},
               {1e-5, 0.0, 1e-7, 0.0, 2e-5, 1}}; /* 1e-7 x 100 deg/s: another 1e-5 */
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    rate_channel_cfg_t c = base_cfg(sec, 0.0f);
    c.p_lpf_alpha = 1.25e-2f;
    c.p_rate_deg_per_dps = (float)cases[k].beta0;
    c.p_rate_c1_per_dps = (float)cases[k].beta1;
    c.p_rate2_deg_per_dps2 = (float)cases[k].gamma;
    c.p_poly_off_deg = (float)cases[k].off_deg; /* x = P_f + 10 */
    rate_channel_t rc;
    assert_int_equal(rc_init(&rc, &c), 0);
    rate_channel_reset(s_cfg, &rc, (float)p0_deg);
    const double p_deg = p0_deg + cases[k].beta_true * 250.0 * r;
    for (int n = 0; n < 25000; n++) { /* 5 s */
      block(&rc, 1.0f, 0.0f, (float)r, 0.0f, (float)(p_deg * M_PI / 180.0));
    }
    const double want = cases[k].taken ? p0_deg : p_deg;
    assert_true(fabs((double)rc.p_f_deg - want) < 2e-5);
  }
}

/* A rate far beyond full scale (a scale stale by orders: 1.9e6 deg/s after a sweep that
 * tuned the sense mode to the drive, test_cl_sense_tune.c) is no rate: P is taken as it
 * is, P_f stays at P. Failed before turn_max_dps: the square of that rate in the
 * correction ran P_f to -3.6e5 deg within a second, and the supervisor faulted. */
static void test_absurd_rate_leaves_p_alone(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  c.p_lpf_alpha = 1.25e-2f;
  c.p_rate_deg_per_dps = 1e-5f;
  c.p_rate2_deg_per_dps2 = 1e-7f;
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_reset(s_cfg, &rc, 0.3f);
  const float r = 1.9e6f / 250.0f;
  for (int n = 0; n < 25000; n++) block(&rc, 1.0f, 0.0f, r, 0.0f, (float)(0.3 * M_PI / 180.0));
  assert_true(fabs((double)rc.p_f_deg - 0.3) < 1e-4);
}

/* Scale-factor linearity through the decimated output filter: the mean output over a
 * long window equals scale * level to 2e-6 relative (plus the noise of the mean) at
 * every level from 1e-3 to 0.5, with noise on the input as the LMSD delivers it. Run at
 * 50 kHz this filter would be off by about 1e-3, differently at each level. */
static void test_dc_linearity(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  const double levels[] = {1e-3, 0.013, 0.1, 0.3, 0.5, -0.2};
  uint32_t lcg = 12345u;
  for (size_t i = 0; i < sizeof levels / sizeof levels[0]; i++) {
    rate_channel_cfg_t c = base_cfg(sec, 0.0f);
    rate_channel_t rc;
    assert_int_equal(rc_init(&rc, &c), 0);
    double sum = 0.0;
    long n_sum = 0;
    for (long n = 0; n < 400000; n++) {
      lcg = lcg * 1664525u + 1013904223u;
      const double noise = 1e-3 * ((double)(lcg >> 8) / 16777216.0 - 0.5);
      rate_channel_accumulate(&rc, (float)(levels[i] + noise), 0.0f);
      if (n % RATE_DECIM == RATE_DECIM - 1) {
        rate_channel_update(s_cfg, &rc, 1.0f, 0.0f, 0.0f, 0.0f);
        rate_channel_update_p(s_cfg, &rc, 0.0f);
      }
      if (n >= 50000 && n % RATE_DECIM == RATE_DECIM - 1) {
        sum += rc.rate_unc_dps;
        n_sum++;
      }
    }
    /* Tolerance: 2e-6 relative plus 3e-6 absolute, about 6 standard errors of the mean
     * of the input noise (2.9e-4 rms over 3.5e5 samples). */
    const double err = sum / n_sum / 250.0 - levels[i];
    assert_true(fabs(err) < 2e-6 * fabs(levels[i]) + 3e-6);
  }
}

/* The phase loop's jitter reaches the true drive phase through the mode's lag (6-17);
 * the sense quadrature turns with the true drive phase. A step of P, passed on through
 * that lag to the sense phasor, must leave the rate output unchanged (before P's own
 * 1 Hz low-pass follows), where an uncorrected reference would show q * dP. */
static void test_reference_follows_drive_jitter(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  c.p_lpf_alpha = 1.25e-2f; /* 1 Hz at fs / RATE_P_DECIM */
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  const double q = 0.5, dp = 1e-3, k = 2.8e-3;
  double lag = 0.0, worst = 0.0;
  for (int n = 0; n < 2500; n++) {                      /* 50 ms after the step */
    const double p = dp;                                /* P stepped at n = 0 */
    lag += k * (p - lag);                               /* the structure's response (6-17) */
    const double sr = -q * sin(lag), si = q * cos(lag); /* quadrature turned by the true phase */
    rate_channel_accumulate(&rc, (float)sr, (float)si);
    if (n % RATE_DECIM != RATE_DECIM - 1) continue;
    rate_channel_update(s_cfg, &rc, 1.0f, 0.0f, (float)p, (float)-lag);
    rate_channel_update_p(s_cfg, &rc, (float)p);
    if (n > 100 && fabs((double)rc.rate_raw) > worst) worst = fabs((double)rc.rate_raw);
  }
  /* Left: P's 1 Hz low-pass moving over 50 ms (2 pi 1 Hz 0.05 s ~ 0.3 of dp at most). */
  assert_true(worst < 0.35 * q * dp);
  assert_true(worst < q * dp); /* uncorrected it would be q * dp */
}

/* A part of Q = 5000 (tau = 2Q/wn = 1.07 s) in its phase loop (30 Hz, the PI zero on the
 * mode's pole, drive_loop.h), with the drive pickoff's white phase noise n on the
 * measurement (8e-6 rad/rtHz: 2 uV/rtHz on 0.35 V). Below the loop's bandwidth the loop
 * writes -n onto the true drive phase; to hold it there P moves by tens of times as much
 * (tau s at 30 Hz is 200), and the quadrature turns with the true phase. The reference's
 * correction must follow the true phase, not P's wander: what is left is the phase
 * noise its complementary low-pass passes, q * LP(n), LP of about 3.3 Hz of noise
 * bandwidth: 1.5e-5 rad rms, against 5.5e-5 rad rms of true phase (n over the loop's
 * 30 Hz, times pi/2 for its first-order roll-off) that an uncorrected reference leaves.
 * Asserted: below half the uncorrected error, and below twice the prediction. */
static void test_reference_high_q_loop(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  const double t_blk = RATE_DECIM / 50000.0, tau = 2.0 * 5000.0 / (2.0 * M_PI * 1489.9);
  const double k = 1.0 - exp(-t_blk / tau), kp = 2.0 * M_PI * 30.0 * tau, ki = kp / tau;
  c.p_mode_k = (float)k;
  c.p_lpf_alpha = 1.25e-2f; /* 1 Hz at fs / RATE_P_DECIM */
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  const double q = 0.5, sigma_n = 8e-6 * sqrt(0.5 / t_blk), p_static = 0.3;
  double theta = 0.0, integ = p_static, p = p_static;
  uint32_t seed = 12345u;
  double sum_res2 = 0.0, sum_th2 = 0.0;
  int count = 0;
  const int n_blocks = (int)(20.0 / t_blk);
  for (int b = 0; b < n_blocks; b++) {
    /* Gaussian by the sum of 12 uniforms (the test needs only its variance). */
    double u = 0.0;
    for (int i = 0; i < 12; i++) {
      seed = seed * 1664525u + 1013904223u;
      u += (double)(seed >> 8) / 16777216.0;
    }
    const double n = sigma_n * (u - 6.0);
    theta += k * ((p - p_static) - theta); /* the structure's phase (6-17) */
    const double e = -(theta + n);         /* the loop's measured error */
    for (uint32_t i = 0; i < RATE_DECIM; i++) {
      rate_channel_accumulate(&rc, (float)(-q * sin(theta)), (float)(q * cos(theta)));
    }
    rate_channel_update(s_cfg, &rc, 1.0f, 0.0f, (float)p, (float)e);
    rate_channel_update_p(s_cfg, &rc, (float)p);
    integ += ki * t_blk * e;
    p = integ + kp * e;
    if (b > n_blocks / 2) {
      sum_res2 += (double)rc.rate_raw * (double)rc.rate_raw;
      sum_th2 += q * q * theta * theta;
      count++;
    }
  }
  const double res = sqrt(sum_res2 / count), unc = sqrt(sum_th2 / count);
  printf("high-Q loop: residual %.3g, uncorrected %.3g (q rad)\n", res / q, unc / q);
  assert_true(res < 0.5 * unc);
  assert_true(res < 2.0 * q * 1.5e-5);
}

/* While held (acquisition), P's swings do not reach P_f; after the release P_f starts
 * as a running mean (the held value weighing as 4 means) and reaches a new level in a
 * few tens of ms, where the plain 1 Hz low-pass would still be 80 % short of it. */
static void test_p_hold_and_fast_start(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  c.p_ref_deg = 25.7f;
  c.p_lpf_alpha = 1.25e-2f; /* 1 Hz at fs / RATE_P_DECIM */
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  rate_channel_hold_p(&rc, 1);
  for (int n = 0; n < 500; n++) { /* 0.1 s of acquisition: P swings by +-5 deg */
    const double p_deg = 25.7 + 5.0 * sin(0.05 * n);
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_deg * M_PI / 180.0));
  }
  assert_true(rc.p_f_deg == 25.7f);
  rate_channel_hold_p(&rc, 0);
  const double p_locked = 25.75;
  for (int n = 0; n < 200; n++) { /* 40 ms = 20 means of P */
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_locked * M_PI / 180.0));
  }
  /* running mean with the prior as 4 of 24: 1/6 of the 0.05 deg step left */
  assert_true(fabs((double)rc.p_f_deg - p_locked) < 0.05 / 6.0 + 1e-4);
  assert_true(fabs((double)rc.p_f_deg - p_locked) > 0.05 / 6.0 - 1e-3);
  for (int n = 0; n < 20000; n++) {
    block(&rc, 1.0f, 0.0f, 0.0f, 0.0f, (float)(p_locked * M_PI / 180.0));
  }
  assert_true(fabs((double)rc.p_f_deg - p_locked) < 1e-4);
}

/* No drive: no ratio is formed and the outputs stay finite. */
static void test_no_drive(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  rate_channel_cfg_t c = base_cfg(sec, 0.0f);
  rate_channel_t rc;
  assert_int_equal(rc_init(&rc, &c), 0);
  block(&rc, 0.0f, 0.0f, 1.0f, 1.0f, 0.0f); /* drive below min_drive_v */
  assert_true(rc.rate_raw == 0.0f && rc.quad_raw == 0.0f);
  assert_true(isfinite(rc.rate_dps));
  c.p_lpf_alpha = 0.0f;
  assert_int_equal(rc_init(&rc, &c), -1);
  c = base_cfg(sec, 0.0f);
  c.ref_re = 0.0f;
  c.ref_im = 0.0f;
  assert_int_equal(rc_init(&rc, &c), -1);
  c = base_cfg(sec, NAN);
  assert_int_equal(rc_init(&rc, &c), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_phasor_separation),
      cmocka_unit_test(test_phase_error_leakage),
      cmocka_unit_test(test_compensation_polynomials),
      cmocka_unit_test(test_p_lowpass_resolution),
      cmocka_unit_test(test_gradient_term),
      cmocka_unit_test(test_rate_taken_out_of_p),
      cmocka_unit_test(test_absurd_rate_leaves_p_alone),
      cmocka_unit_test(test_compensation_thermometer_lowpass),
      cmocka_unit_test(test_compensation_thermometer_two_stages),
      cmocka_unit_test(test_compensation_thermometer_three_stages),
      cmocka_unit_test(test_compensation_fast_path_blend),
      cmocka_unit_test(test_dc_linearity),
      cmocka_unit_test(test_reference_follows_drive_jitter),
      cmocka_unit_test(test_reference_high_q_loop),
      cmocka_unit_test(test_p_hold_and_fast_start),
      cmocka_unit_test(test_no_drive),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
