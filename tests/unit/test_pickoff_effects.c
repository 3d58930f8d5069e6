/* The pickoff front end's imperfections (host_sim/plant/pickoff.h), each against its law:
 *  - capacitive nonlinearity: harmonics of x (1 + beta x/d + (x/d)^2) on a sine;
 *  - gain flicker: the relative gain's PSD K^2 / f, slope -1 over a decade, seen on the
 *    output;
 *  - phase flicker: a 1/f phase, applied as the delay n_p / w_ref;
 *  - a timing error (the ADC's aperture jitter, pickoff_step_at): noise of rms
 *    2 pi f A sigma / sqrt(2) on a sine;
 *  - off by default, bad values refused with nothing changed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/pickoff.h"
#include "plant/rng.h"
#include "psd_welch_ref.h"
#include "sine_fit_ref.h"

static const double kTwoPi = 6.28318530717958647692;

/* A drive pickoff whose filters pass DC to a few kHz with unit gain: no high-pass, the
 * low-pass at 10 fs, a lag of 2e-4 rad; no offset, noise, delay or feedthrough. */
static void clean_cfg(pickoff_cfg_t *c, double fs)
{
  pickoff_default_cfg(c, PICKOFF_DRIVE);
  c->fs_hz = fs;
  c->lag_ref_hz = fs / 50.0;
  c->gain_v_per_m = 1e5;
  c->phi0_rad = 2e-4;
  c->phi1_rad_per_k = 0.0;
  c->hp_hz = 0.0;
  c->lp_hz = 10.0 * fs;
  c->offset_v = 0.0;
  c->noise_v_rthz = 0.0;
  c->sample_delay_s = 0.0;
}

/* Runs p on x = a sin(w t) (t = (k+1) T at step k) for n samples, output into v. */
static void run_sine(pickoff_t *p, double a, double f, long n, double *v, const double *dt)
{
  const double T = 1.0 / p->cfg.fs_hz, w = kTwoPi * f;
  for (long k = 0; k < n; k++) {
    const double t = (double)(k + 1) * T;
    v[k] = pickoff_step_at(p, a * sin(w * t), a * w * cos(w * t), NULL, dt ? dt[k] : 0.0);
  }
}

/* Parallel plates of gap d = 40 um, imbalance beta = 0.3, a 4 um sine (u = 0.1): the
 * read displacement x (1 + beta u + u^2) has a DC and a second harmonic of beta A^2 /
 * (2 d), a third harmonic A^3 / (4 d^2), and a fundamental raised by 3 A^3 / (4 d^2).
 * The chain's gain is 1 to 1e-6 up to 4.5 kHz here; its cubic interpolation of the input
 * costs (3 w T)^4 / 384 = 2.6e-4 on the third harmonic: each within 1e-3 relative. */
static void test_gap_harmonics(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  clean_cfg(&c, 50000.0);
  c.gap_m = 40e-6;
  c.gap_asym = 0.3;
  static pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, c.temp_ref_k, 1u), 0);
  const double f = 1489.9, a = 4e-6, d = c.gap_m, g = c.gain_v_per_m, T = 1.0 / c.fs_hz;
  const long n = 20000, skip = 2000;
  double *v = malloc(sizeof(double) * (size_t)n);
  assert_non_null(v);
  run_sine(&p, a, f, n, v, NULL);
  const double fr[3] = {f, 2.0 * f, 3.0 * f};
  double coef[7];
  assert_true(ref_sine_fit(v + skip, (size_t)(n - skip), (double)(skip + 1) * T, T, fr, 3,
                           coef) >= 0.0);
  const double dc = coef[0] / g, h1 = hypot(coef[1], coef[2]) / g;
  const double h2 = hypot(coef[3], coef[4]) / g, h3 = hypot(coef[5], coef[6]) / g;
  const double want_dc = c.gap_asym * a * a / (2.0 * d), want_h3 = a * a * a / (4.0 * d * d);
  print_message("DC %.4e (%.4e), h1 %.6e (%.6e), h2 %.4e (%.4e), h3 %.4e (%.4e) m\n", dc,
                want_dc, h1, a + 3.0 * want_h3, h2, want_dc, h3, want_h3);
  assert_true(fabs(dc / want_dc - 1.0) < 1e-3);
  assert_true(fabs(h2 / want_dc - 1.0) < 1e-3);
  assert_true(fabs(h3 / want_h3 - 1.0) < 1e-3);
  assert_true(fabs(h1 / (a + 3.0 * want_h3) - 1.0) < 1e-5);
  assert_true(pickoff_gap_out(&p) == 0u);
  /* balanced pair: odd orders only */
  c.gap_asym = 0.0;
  assert_int_equal(pickoff_init(&p, &c, c.temp_ref_k, 1u), 0);
  run_sine(&p, a, f, n, v, NULL);
  assert_true(ref_sine_fit(v + skip, (size_t)(n - skip), (double)(skip + 1) * T, T, fr, 3,
                           coef) >= 0.0);
  assert_true(hypot(coef[3], coef[4]) / g < 1e-6 * want_dc);
  /* beyond |x| = 0.3 d the law is held at its edge and flagged until read */
  run_sine(&p, 0.5 * d, f, 200, v, NULL);
  assert_true(pickoff_gap_out(&p) == PICKOFF_OUT_GAP);
  assert_true(pickoff_gap_out(&p) == 0u);
  free(v);
}

/* Least-squares slope of log10 psd against log10 f over [f_lo, f_hi], and the mean of
 * f psd(f) there (K^2 for a 1/f spectrum K^2 / f). */
static double loglog_slope(const double *psd, double fs, size_t nseg, double f_lo, double f_hi,
                           double *k2)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0, sk = 0;
  int n = 0;
  for (size_t i = 1; i <= nseg / 2; i++) {
    const double f = (double)i * fs / (double)nseg;
    if (f < f_lo || f > f_hi) continue;
    const double x = log10(f), y = log10(psd[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    sk += f * psd[i];
    n++;
  }
  assert_true(n > 10);
  *k2 = sk / n;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/* Gain flicker K = 1e-3 /rtHz: the output of a constant displacement, relative to its
 * mean, has the one-sided PSD K^2 / f (+ the white floor K^2 / (fs/20) of flicker.h).
 * Over the decade 1-10 Hz the log-log slope is -0.99 by the target and the estimate's
 * scatter (about 40 bins, 18 segments averaged) is a few hundredths: within 0.1 of -1;
 * the level f psd within 1.5 dB of K^2 (design 0.3 dB). The phase flicker's generator the
 * same way, on n_p. fs = 20 kHz so that the decade fits in 26 s of samples. */
static void test_gain_phase_flicker_psd(void **state)
{
  (void)state;
  const double fs = 20000.0, K = 1e-3, x0 = 1e-6;
  const size_t nseg = 1u << 16, n = 1u << 19;
  pickoff_cfg_t c;
  clean_cfg(&c, fs);
  c.gain_flicker_1hz_rthz = K;
  c.phase_flicker_1hz_rad_rthz = K;
  static pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, c.temp_ref_k, 2u), 0);
  double *g = malloc(sizeof(double) * n), *ph = malloc(sizeof(double) * n);
  double *psd = malloc(sizeof(double) * (nseg / 2 + 1));
  assert_non_null(g);
  assert_non_null(ph);
  assert_non_null(psd);
  for (size_t k = 0; k < 200000; k++) (void)pickoff_step(&p, x0, 0.0, NULL); /* warm-up */
  for (size_t k = 0; k < n; k++) {
    g[k] = pickoff_step(&p, x0, 0.0, NULL) / (c.gain_v_per_m * x0) - 1.0;
    ph[k] = p.phase_noise_rad;
  }
  for (int which = 0; which < 2; which++) {
    assert_true(ref_psd_welch(which ? ph : g, n, fs, nseg, psd) > 10);
    double k2;
    const double slope = loglog_slope(psd, fs, nseg, 1.0, 10.0, &k2);
    print_message("%s flicker: slope %.3f over 1-10 Hz, f psd %.3e (K^2 %.3e)\n",
                  which ? "phase" : "gain", slope, k2, K * K);
    assert_true(fabs(slope + 1.0) < 0.1);
    assert_true(fabs(10.0 * log10(k2 / (K * K))) < 1.5);
  }
  free(g);
  free(ph);
  free(psd);
}

/* The phase flicker is the delay n_p / w_ref: on a sine at the reference frequency the
 * output differs from the noiseless chain's by -(n_p / w_ref) v' (first order; the
 * neglected n_p^2 / 2 is 1e-6 relative here). v' from the noiseless output's fitted sine. */
static void test_phase_flicker_is_a_delay(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  clean_cfg(&c, 50000.0);
  c.lag_ref_hz = 1489.9;
  static pickoff_t a, b;
  assert_int_equal(pickoff_init(&a, &c, c.temp_ref_k, 3u), 0);
  c.phase_flicker_1hz_rad_rthz = 1e-3;
  assert_int_equal(pickoff_init(&b, &c, c.temp_ref_k, 3u), 0);
  const double f = c.lag_ref_hz, w = kTwoPi * f, T = 1.0 / c.fs_hz, amp = 5e-6;
  const long n = 30000, skip = 5000;
  double *va = malloc(sizeof(double) * (size_t)n), *vb = malloc(sizeof(double) * (size_t)n);
  double *np = malloc(sizeof(double) * (size_t)n);
  assert_non_null(va);
  assert_non_null(vb);
  assert_non_null(np);
  for (long k = 0; k < n; k++) {
    const double t = (double)(k + 1) * T;
    va[k] = pickoff_step(&a, amp * sin(w * t), amp * w * cos(w * t), NULL);
    vb[k] = pickoff_step(&b, amp * sin(w * t), amp * w * cos(w * t), NULL);
    np[k] = b.phase_noise_rad;
  }
  double coef[3];
  assert_true(ref_sine_fit(va + skip, (size_t)(n - skip), (double)(skip + 1) * T, T, &f, 1,
                           coef) >= 0.0);
  double e2 = 0.0, d2 = 0.0;
  for (long k = skip; k < n; k++) {
    const double t = (double)(k + 1) * T;
    const double dv = w * (-coef[1] * sin(w * t) + coef[2] * cos(w * t));
    const double d = vb[k] - va[k], want = -np[k] / w * dv;
    e2 += (d - want) * (d - want);
    d2 += d * d;
  }
  print_message("phase flicker: difference %.3e V rms, residual against the delay %.3e V\n",
                sqrt(d2 / (n - skip)), sqrt(e2 / (n - skip)));
  assert_true(d2 > 0.0);
  assert_true(sqrt(e2 / d2) < 1e-3);
  free(va);
  free(vb);
  free(np);
}

/* A timing error dt (the ADC's aperture jitter) samples the output dt later: Gaussian
 * dt of rms sigma = 10 ns on a 1489.9 Hz sine of amplitude A at the output is noise of
 * rms 2 pi f A sigma / sqrt(2) (Kester §2.3). 50000 samples estimate an rms within
 * 1/sqrt(2 N) = 0.3 %: within 2 %. */
static void test_timing_error_noise(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  clean_cfg(&c, 50000.0);
  static pickoff_t a, b;
  assert_int_equal(pickoff_init(&a, &c, c.temp_ref_k, 4u), 0);
  assert_int_equal(pickoff_init(&b, &c, c.temp_ref_k, 4u), 0);
  const double f = 1489.9, amp = 20e-6, sigma = 10e-9, T = 1.0 / c.fs_hz;
  const long n = 60000, skip = 10000;
  double *va = malloc(sizeof(double) * (size_t)n), *vb = malloc(sizeof(double) * (size_t)n);
  double *dt = malloc(sizeof(double) * (size_t)n);
  assert_non_null(va);
  assert_non_null(vb);
  assert_non_null(dt);
  rng_t r;
  rng_seed(&r, 5u, 77u);
  for (long k = 0; k < n; k++) dt[k] = sigma * rng_gauss(&r);
  run_sine(&a, amp, f, n, va, NULL);
  run_sine(&b, amp, f, n, vb, dt);
  double coef[3];
  assert_true(ref_sine_fit(va + skip, (size_t)(n - skip), (double)(skip + 1) * T, T, &f, 1,
                           coef) >= 0.0);
  double s2 = 0.0;
  for (long k = skip; k < n; k++) s2 += (vb[k] - va[k]) * (vb[k] - va[k]);
  const double rms = sqrt(s2 / (double)(n - skip));
  const double want = kTwoPi * f * hypot(coef[1], coef[2]) * sigma / sqrt(2.0);
  print_message("timing error 10 ns rms: noise %.4e V rms, 2 pi f A sigma / sqrt 2 = %.4e V\n",
                rms, want);
  assert_true(fabs(rms / want - 1.0) < 0.02);
  free(va);
  free(vb);
  free(dt);
}

/* Off by default: the default configuration has every imperfection at zero, and a chain
 * with them explicitly zero (and a zero timing error) gives the same bits as the default.
 * Bad values are refused and leave the pickoff as it was. */
static void test_off_by_default_and_validation(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  pickoff_default_cfg(&c, PICKOFF_SENSE);
  assert_true(c.gap_m == 0.0 && c.gap_asym == 0.0 && c.gain_flicker_1hz_rthz == 0.0 &&
              c.phase_flicker_1hz_rad_rthz == 0.0);
  static pickoff_t a, b, before;
  assert_int_equal(pickoff_init(&a, &c, 300.0, 9u), 0);
  c.gap_asym = 0.7; /* shape parameters without their switch: nothing */
  c.flicker_fmin_hz = 0.2;
  assert_int_equal(pickoff_init(&b, &c, 300.0, 9u), 0);
  for (int k = 0; k < 5000; k++) {
    const double x = 1e-9 * sin(0.187 * k), v = 1e-9 * 9361.0 * cos(0.187 * k);
    const double va = pickoff_step(&a, x, v, NULL), vb = pickoff_step_at(&b, x, v, NULL, 0.0);
    assert_memory_equal(&va, &vb, sizeof va);
  }
  before = a;
  const struct {
    int field;
    double v;
  } bad[] = {{0, -1e-6}, {0, NAN}, {1, 1.5}, {2, -1e-3}, {3, 0.2}, {4, 0.0}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    pickoff_default_cfg(&c, PICKOFF_SENSE);
    c.gain_flicker_1hz_rthz = 1e-4; /* a flicker on: its fmin must be > 0 and <= fs/1000 */
    if (bad[i].field == 0) c.gap_m = bad[i].v;
    else if (bad[i].field == 1) c.gap_asym = bad[i].v;
    else if (bad[i].field == 2) c.gain_flicker_1hz_rthz = bad[i].v;
    else if (bad[i].field == 3) c.phase_flicker_1hz_rad_rthz = bad[i].v;
    else c.flicker_fmin_hz = bad[i].v;
    assert_int_equal(pickoff_init(&a, &c, 300.0, 9u), -1);
    assert_memory_equal(&a, &before, sizeof a);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gap_harmonics),
      cmocka_unit_test(test_gain_phase_flicker_psd),
      cmocka_unit_test(test_phase_flicker_is_a_delay),
      cmocka_unit_test(test_timing_error_noise),
      cmocka_unit_test(test_off_by_default_and_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
