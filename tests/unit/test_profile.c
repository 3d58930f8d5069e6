/* Input profiles (host_sim/plant/profile): values against the closed forms written out
 * here, slopes against central differences, step tables (edges, hold, repeat), the
 * exact sample mean of the acceleration against numerical quadrature, validation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/profile.h"

static const double kTwoPi = 6.28318530717958647692;

/* dv/dt from profile_eval against a central difference, away from kinks */
static void check_slope(const profile_t *p, double t)
{
  const double h = 1e-6;
  double s;
  (void)profile_eval(p, t, &s);
  const double fd = (profile_eval(p, t + h, NULL) - profile_eval(p, t - h, NULL)) / (2 * h);
  assert_true(fabs(s - fd) <= 1e-6 * (1.0 + fabs(s)));
}

static void test_const_sine_ramp(void **state)
{
  (void)state;
  profile_t p;
  profile_const(&p, 12.5);
  assert_int_equal(profile_check(&p, NULL), 0);
  double s = 1.0;
  assert_true(profile_eval(&p, 3.0, &s) == 12.5 && s == 0.0);

  profile_sine(&p, 10.0, 100.0, 7.0, 0.3);
  assert_int_equal(profile_check(&p, NULL), 0);
  for (double t = -0.1; t < 1.0; t += 0.0137) {
    assert_true(fabs(profile_eval(&p, t, NULL) - (10.0 + 100.0 * sin(kTwoPi * 7.0 * t + 0.3))) <
                1e-12);
    check_slope(&p, t);
  }

  profile_ramp(&p, -20.0, 4.0, 1.0, 6.0);
  assert_int_equal(profile_check(&p, NULL), 0);
  assert_true(profile_eval(&p, 0.5, &s) == -20.0 && s == 0.0);
  assert_true(fabs(profile_eval(&p, 3.5, &s) - (-20.0 + 4.0 * 2.5)) < 1e-12 && s == 4.0);
  assert_true(fabs(profile_eval(&p, 9.0, &s) - 0.0) < 1e-12 && s == 0.0);
  check_slope(&p, 2.0);
}

static void test_heat_cool(void **state)
{
  (void)state;
  profile_t p;
  /* 22.5 degC room, heat gun towards 80 degC (tau 60 s) for 120 s from t = 30 s, then
   * cool with tau 900 s (§7.3.2 shape) */
  const double base = 295.65, hot = 353.15;
  profile_heat_cool(&p, base, hot, 30.0, 120.0, 60.0, 900.0);
  assert_int_equal(profile_check(&p, NULL), 0);
  assert_true(profile_eval(&p, 10.0, NULL) == base);
  const double v150 = hot + (base - hot) * exp(-120.0 / 60.0);
  assert_true(fabs(profile_eval(&p, 90.0, NULL) - (hot + (base - hot) * exp(-1.0))) < 1e-9);
  assert_true(fabs(profile_eval(&p, 150.0, NULL) - v150) < 1e-9); /* continuous at the switch */
  assert_true(fabs(profile_eval(&p, 150.0 - 1e-9, NULL) - v150) < 1e-6);
  const double t = 1050.0;
  assert_true(fabs(profile_eval(&p, t, NULL) - (base + (v150 - base) * exp(-900.0 / 900.0))) <
              1e-9);
  check_slope(&p, 100.0);
  check_slope(&p, 700.0);
  double s;
  (void)profile_eval(&p, 500.0, &s);
  assert_true(s < 0.0); /* cooling */
}

static void test_steps(void **state)
{
  (void)state;
  profile_t p;
  /* rate table: +20, +40, -40 deg/s, 10 s each, 0.5 s transitions */
  const double dur[3] = {10.0, 10.0, 10.0}, val[3] = {20.0, 40.0, -40.0};
  assert_int_equal(profile_steps(&p, 3, dur, val, 0.5, 0), 0);
  double s;
  assert_true(profile_eval(&p, -1.0, &s) == 20.0 && s == 0.0);
  assert_true(profile_eval(&p, 0.1, &s) == 20.0 && s == 0.0); /* no edge into the first */
  assert_true(profile_eval(&p, 5.0, &s) == 20.0 && s == 0.0);
  assert_true(fabs(profile_eval(&p, 10.25, &s) - 30.0) < 1e-9 && fabs(s - 40.0) < 1e-9);
  assert_true(profile_eval(&p, 15.0, &s) == 40.0 && s == 0.0);
  assert_true(fabs(profile_eval(&p, 20.25, &s) - 0.0) < 1e-9 && fabs(s + 160.0) < 1e-9);
  assert_true(profile_eval(&p, 29.0, NULL) == -40.0);
  assert_true(profile_eval(&p, 100.0, &s) == -40.0 && s == 0.0); /* hold */
  check_slope(&p, 10.3);
  /* repeating: the first step now has an edge from the last value */
  assert_int_equal(profile_steps(&p, 3, dur, val, 0.5, 1), 0);
  assert_true(fabs(profile_eval(&p, 30.25, &s) - (-10.0)) < 1e-9 && fabs(s - 120.0) < 1e-9);
  assert_true(profile_eval(&p, 35.0, NULL) == 20.0);
  assert_true(fabs(profile_eval(&p, 90.0 + 15.0, NULL) - 40.0) < 1e-9);
  /* instantaneous steps */
  assert_int_equal(profile_steps(&p, 3, dur, val, 0.0, 0), 0);
  assert_true(profile_eval(&p, 10.0, &s) == 40.0 && s == 0.0);
  assert_true(profile_eval(&p, 9.999999, NULL) == 20.0);
  /* the full 64-entry table */
  double d64[PROFILE_MAX_STEPS], v64[PROFILE_MAX_STEPS];
  for (int i = 0; i < PROFILE_MAX_STEPS; i++) {
    d64[i] = 1.0;
    v64[i] = i;
  }
  assert_int_equal(profile_steps(&p, PROFILE_MAX_STEPS, d64, v64, 0.0, 0), 0);
  assert_true(profile_eval(&p, 63.5, NULL) == 63.0);
  assert_true(profile_eval(&p, 17.2, NULL) == 17.0);
}

static void test_validation(void **state)
{
  (void)state;
  profile_t p, before;
  const char *key = NULL;
  const double dur[2] = {1.0, 2.0}, val[2] = {0.0, 1.0};
  assert_int_equal(profile_steps(&p, 2, dur, val, 0.1, 0), 0);
  before = p;
  assert_true(profile_steps(&p, 0, dur, val, 0.1, 0) < 0);
  assert_true(profile_steps(&p, PROFILE_MAX_STEPS + 1, dur, val, 0.1, 0) < 0);
  assert_true(profile_steps(&p, 2, dur, val, 1.5, 0) < 0); /* edge longer than a step */
  const double bad_dur[2] = {1.0, -2.0}, bad_val[2] = {0.0, NAN};
  assert_true(profile_steps(&p, 2, bad_dur, val, 0.0, 0) < 0);
  assert_true(profile_steps(&p, 2, dur, bad_val, 0.0, 0) < 0);
  assert_memory_equal(&p, &before, sizeof p); /* nothing changed */

  p.step_s[1] = 0.0;
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "step_s[1]");
  p = before;
  p.step_value[1] = INFINITY;
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "step_value[1]");
  p = before;
  p.n_steps = 65;
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "n_steps");
  p = before;
  p.kind = (profile_kind_t)9;
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "kind");
  profile_sine(&p, 0.0, 1.0, -5.0, 0.0);
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "freq_hz");
  profile_ramp(&p, 0.0, 1.0, 5.0, 4.0);
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "t_end_s");
  profile_heat_cool(&p, 300.0, 350.0, 0.0, 10.0, 0.0, 100.0);
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "tau_heat_s");
  profile_const(&p, NAN);
  assert_true(profile_check(&p, &key) < 0);
  assert_string_equal(key, "value");

  assert_int_equal(profile_kind_from_name("heat_cool"), PROFILE_HEAT_COOL);
  assert_int_equal(profile_kind_from_name("steps"), PROFILE_STEPS);
  assert_int_equal(profile_kind_from_name("bogus"), -1);
  assert_int_equal(profile_kind_from_name(NULL), -1);
  assert_string_equal(profile_kind_name(PROFILE_SINE), "sine");
}

/* The sample mean against Simpson's rule on 2000 panels, for slow and fast vibration. */
static void test_accel(void **state)
{
  (void)state;
  accel_profile_t a;
  accel_profile_zero(&a);
  assert_int_equal(accel_profile_check(&a, NULL), 0);
  a.const_g[2] = -1.0; /* gravity along the rate axis */
  a.amp_g[1] = 0.5;
  a.freq_hz[1] = 120.0;
  a.phase_rad[1] = 0.7;
  a.amp_g[0] = 0.2;
  a.freq_hz[0] = 3000.0;
  assert_int_equal(accel_profile_check(&a, NULL), 0);
  const double fs = 50e3;
  for (int k = 0; k < 200; k += 7) {
    const double t0 = k / fs, t1 = (k + 1) / fs;
    double m[3], v[3], sum[3] = {0, 0, 0};
    accel_profile_mean(&a, t0, t1, m);
    const int np = 2000;
    for (int j = 0; j <= np; j++) {
      const double w = (j == 0 || j == np) ? 1.0 : ((j & 1) ? 4.0 : 2.0);
      accel_profile_eval(&a, t0 + (t1 - t0) * j / np, v);
      for (int i = 0; i < 3; i++) sum[i] += w * v[i];
    }
    for (int i = 0; i < 3; i++) assert_true(fabs(m[i] - sum[i] / (3.0 * np)) < 1e-12);
  }
  double pk[3];
  accel_profile_peak(&a, pk);
  assert_true(pk[0] == 0.2 && pk[1] == 0.5 && pk[2] == 1.0);
  const char *key = NULL;
  a.freq_hz[2] = -1.0;
  assert_true(accel_profile_check(&a, &key) < 0);
  assert_string_equal(key, "freq_hz[2]");
  a.freq_hz[2] = 0.0;
  a.amp_g[0] = NAN;
  assert_true(accel_profile_check(&a, &key) < 0);
  assert_string_equal(key, "amp_g[0]");
}

/* Half-sine shocks (IEC 60068-2-27): the per-sample means over a run sum to the pulse's
 * velocity change 2 peak dur / pi (g s) exactly (to rounding), for pulses of many
 * samples and of less than one; each mean against Simpson's rule; nothing outside the
 * pulse; the shocks add to the other parts of their axis. */
static void test_half_sine_shocks(void **state)
{
  (void)state;
  accel_profile_t a;
  accel_profile_zero(&a);
  assert_false(accel_profile_dynamic(&a));
  a.n_shocks = 3;
  const double t_s[3] = {0.01003, 0.02, 0.03}, peak[3] = {50.0, -200.0, 1000.0};
  const double dur[3] = {0.5e-3, 7e-6, 1e-4};
  const int axis[3] = {0, 1, 0};
  for (int j = 0; j < 3; j++) {
    a.shock_t_s[j] = t_s[j];
    a.shock_peak_g[j] = peak[j];
    a.shock_dur_s[j] = dur[j];
    a.shock_axis[j] = axis[j];
  }
  a.const_g[1] = 0.25;
  assert_int_equal(accel_profile_check(&a, NULL), 0);
  assert_true(accel_profile_dynamic(&a));
  const double fs = 50e3;
  double dv[3] = {0, 0, 0};
  for (int k = 0; k < 2000; k++) {
    const double t0 = k / fs, t1 = (k + 1) / fs;
    double m[3];
    accel_profile_mean(&a, t0, t1, m);
    for (int i = 0; i < 3; i++) dv[i] += m[i] / fs;
    if (k % 13 == 0 || (t1 > 0.01 && t0 < 0.0106) || (t1 > 0.02 && t0 < 0.0201)) {
      double v[3], sum[3] = {0, 0, 0};
      const int np = 20000;
      for (int j = 0; j <= np; j++) {
        const double w = (j == 0 || j == np) ? 1.0 : ((j & 1) ? 4.0 : 2.0);
        accel_profile_eval(&a, t0 + (t1 - t0) * j / np, v);
        for (int i = 0; i < 3; i++) sum[i] += w * v[i];
      }
      /* Simpson on the kinks at a pulse's ends: 1e-6 of the peak */
      for (int i = 0; i < 3; i++) assert_true(fabs(m[i] - sum[i] / (3.0 * np)) < 1e-3);
    }
  }
  const double want0 = 2.0 * (peak[0] * dur[0] + peak[2] * dur[2]) / (0.5 * kTwoPi);
  const double want1 = 2.0 * peak[1] * dur[1] / (0.5 * kTwoPi) + 0.25 * 2000 / fs;
  print_message("shock velocity change: %.9e g s (2 peak dur / pi: %.9e)\n", dv[0], want0);
  assert_true(fabs(dv[0] / want0 - 1.0) < 1e-12);
  assert_true(fabs(dv[1] / want1 - 1.0) < 1e-12);
  assert_true(dv[2] == 0.0);
  double v[3];
  accel_profile_eval(&a, t_s[0] + 0.5 * dur[0], v);
  assert_true(fabs(v[0] - peak[0]) < 1e-12);
  accel_profile_eval(&a, t_s[0] - 1e-9, v);
  assert_true(v[0] == 0.0);
  double pk[3];
  accel_profile_peak(&a, pk);
  assert_true(pk[0] == 1050.0 && pk[1] == 200.25 && pk[2] == 0.0);
}

/* Every field of the shocks and the random bands is checked and named. */
static void test_shock_band_validation(void **state)
{
  (void)state;
  accel_profile_t good;
  accel_profile_zero(&good);
  good.n_shocks = 1;
  good.shock_dur_s[0] = 1e-3;
  good.shock_peak_g[0] = 10.0;
  good.n_bands = 1;
  good.band_psd_g2_per_hz[0] = 1e-3;
  good.band_f_lo_hz[0] = 20.0;
  good.band_f_hi_hz[0] = 40.0;
  assert_int_equal(accel_profile_check(&good, NULL), 0);
  assert_true(accel_profile_dynamic(&good));
  struct {
    const char *key;
    accel_profile_t a;
  } cases[11];
  for (int i = 0; i < 11; i++) cases[i].a = good;
  cases[0].key = "n_shocks", cases[0].a.n_shocks = PROFILE_MAX_SHOCKS + 1;
  cases[1].key = "shock_axis[0]", cases[1].a.shock_axis[0] = 3;
  cases[2].key = "shock_t_s[0]", cases[2].a.shock_t_s[0] = -1.0;
  cases[3].key = "shock_peak_g[0]", cases[3].a.shock_peak_g[0] = NAN;
  cases[4].key = "shock_dur_s[0]", cases[4].a.shock_dur_s[0] = 0.0;
  cases[5].key = "n_bands", cases[5].a.n_bands = -1;
  cases[6].key = "band_axis[0]", cases[6].a.band_axis[0] = -1;
  cases[7].key = "band_psd_g2_per_hz[0]", cases[7].a.band_psd_g2_per_hz[0] = 0.0;
  cases[8].key = "band_f_lo_hz[0]", cases[8].a.band_f_lo_hz[0] = 0.05;
  cases[9].key = "band_f_hi_hz[0]", cases[9].a.band_f_hi_hz[0] = 39.0; /* < an octave */
  cases[10].key = "band_f_hi_hz[0]", cases[10].a.band_f_hi_hz[0] = INFINITY;
  for (int i = 0; i < 11; i++) {
    const char *key = NULL;
    assert_true(accel_profile_check(&cases[i].a, &key) < 0);
    assert_string_equal(key, cases[i].key);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_const_sine_ramp),
      cmocka_unit_test(test_heat_cool),
      cmocka_unit_test(test_steps),
      cmocka_unit_test(test_validation),
      cmocka_unit_test(test_accel),
      cmocka_unit_test(test_half_sine_shocks),
      cmocka_unit_test(test_shock_band_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
