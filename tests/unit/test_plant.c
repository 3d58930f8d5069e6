/* Top level of the plant (host_sim/plant/plant): configuration and parameter table,
 * validation, and open-loop steady states through the whole chain (DAC -> actuator ->
 * mechanics -> pickoffs -> ADC) against closed forms written out here, fitted with the
 * Eigen least-squares reference. Also the thesis relations the defaults are meant to
 * reproduce: table 7-1 (square law), §7.2.2 (-99.56 deg), table 7-4 (drive phase and
 * bias slopes versus temperature). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <complex.h>
#include <cmocka.h>

#include "plant/plant.h"
#include "sine_fit_ref.h"

static const double kPi = 3.14159265358979323846;
static const double kDeg = 3.14159265358979323846 / 180.0;

/* ------------------------------------------------------------- parameters ------- */

static size_t type_size(plant_param_type_t t)
{
  return t == PLANT_PARAM_DOUBLE ? sizeof(double)
         : t == PLANT_PARAM_INT  ? sizeof(int)
                                 : sizeof(bool);
}

/* Every byte of plant_cfg_t belongs to exactly one parameter, apart from the tail
 * padding; names are unique and found; defaults are in range. */
static void test_param_table_complete(void **state)
{
  (void)state;
  const size_t n = plant_param_count();
  assert_true(n > 90);
  unsigned char owner[sizeof(plant_cfg_t)];
  memset(owner, 0, sizeof owner);
  size_t covered = 0, end = 0;
  plant_cfg_t c;
  plant_default_cfg(&c);
  for (size_t i = 0; i < n; i++) {
    const plant_param_desc_t *d = plant_param_at(i);
    assert_non_null(d);
    assert_ptr_equal(plant_param_find(d->name), d);
    const size_t sz = type_size(d->type);
    assert_true(d->offset + sz <= sizeof(plant_cfg_t));
    for (size_t b = d->offset; b < d->offset + sz; b++) {
      assert_int_equal(owner[b], 0); /* no overlap */
      owner[b] = 1;
    }
    covered += sz;
    if (d->offset + sz > end) end = d->offset + sz;
    assert_true(d->min <= d->max);
    assert_non_null(d->unit);
    assert_true(strlen(d->doc) > 10);
    const double v = plant_param_get(&c, d);
    if (!(v >= d->min && v <= d->max)) fail_msg("default of %s out of its range", d->name);
  }
  assert_null(plant_param_at(n));
  /* contiguous from 0, only tail padding after the last field */
  for (size_t b = 0; b < end; b++)
    if (!owner[b]) fail_msg("byte %zu of plant_cfg_t is not a parameter", b);
  assert_true(sizeof(plant_cfg_t) - end < sizeof(double));
  assert_int_equal(covered, end);
  printf("%zu parameters cover %zu of %zu bytes\n", n, covered, sizeof(plant_cfg_t));
}

/* Setting by name: range, finiteness, integrality; errors name the key; nothing
 * changes on error. */
static void test_param_set(void **state)
{
  (void)state;
  plant_cfg_t c, before;
  plant_default_cfg(&c);
  char err[200];
  assert_int_equal(plant_param_set(&c, "q_drive", 50.0, err, sizeof err), 0);
  assert_true(c.q_drive == 50.0);
  assert_int_equal(plant_param_set(&c, "brownian", 0.0, err, sizeof err), 0);
  assert_false(c.brownian);
  assert_int_equal(plant_param_set(&c, "pick_sense_temp_node", 2.0, err, sizeof err), 0);
  assert_int_equal(c.pick_sense_temp_node, 2);
  for (size_t i = 0; i < plant_param_count(); i++) {
    const plant_param_desc_t *d = plant_param_at(i);
    before = c;
    const double bad[4] = {d->max + 1.0 + fabs(d->max), d->min - 1.0 - fabs(d->min), NAN,
                           INFINITY};
    for (int k = 0; k < 4; k++) {
      err[0] = '\0';
      assert_int_equal(plant_param_set(&c, d->name, bad[k], err, sizeof err), -1);
      if (strstr(err, d->name) == NULL) fail_msg("error '%s' does not name %s", err, d->name);
      assert_memory_equal(&c, &before, sizeof c);
    }
    if (d->type != PLANT_PARAM_DOUBLE) {
      assert_int_equal(plant_param_set(&c, d->name, d->min + 0.5, err, sizeof err), -1);
      assert_non_null(strstr(err, d->name));
    }
    /* both ends of the range are accepted and read back */
    assert_int_equal(plant_param_set(&c, d->name, d->min, err, sizeof err), 0);
    assert_true(plant_param_get(&c, d) == d->min);
    assert_int_equal(plant_param_set(&c, d->name, d->max, err, sizeof err), 0);
    assert_true(plant_param_get(&c, d) == d->max);
    c = before;
  }
  assert_int_equal(plant_param_set(&c, "no_such_param", 1.0, err, sizeof err), -1);
  assert_non_null(strstr(err, "no_such_param"));
  assert_null(plant_param_find("no_such_param"));
  assert_null(plant_param_find(NULL));
}

/* plant_init rejects every parameter pushed out of its range, naming it, and leaves
 * the plant as it was (apart from the error text). Cross-field limits too. */
static void test_init_validation(void **state)
{
  (void)state;
  static plant_t p, before;
  plant_cfg_t c;
  plant_default_cfg(&c);
  char err[200];
  assert_int_equal(plant_cfg_check(&c, err, sizeof err), 0);
  assert_int_equal(plant_init(&p, &c, 1u), 0);
  before = p;
  for (size_t i = 0; i < plant_param_count(); i++) {
    const plant_param_desc_t *d = plant_param_at(i);
    if (d->type == PLANT_PARAM_BOOL) continue; /* a bool cannot hold a bad value */
    plant_cfg_t b = c;
    unsigned char *base = (unsigned char *)&b + d->offset;
    if (d->type == PLANT_PARAM_INT) {
      const int v = (int)d->max + 1;
      memcpy(base, &v, sizeof v);
    } else {
      const double v = NAN;
      memcpy(base, &v, sizeof v);
    }
    assert_int_equal(plant_init(&p, &b, 1u), -1);
    if (strstr(plant_error(&p), d->name) == NULL)
      fail_msg("init error '%s' does not name %s", plant_error(&p), d->name);
    assert_memory_equal(&p, &before, offsetof(plant_t, err));
  }
  struct {
    const char *key;
    double value;
  } cross[] = {{"f_drive_hz", 30000.0},       {"f_sense_hz", 24000.0},
               {"pick_lag_ref_hz", 26000.0},  {"dac_recon_hz", 60000.0},
               {"pick_sense_delay_s", 15e-6}, {"pick_drive_jitter_s", 2e-6},
               {"thermal_dt_s", 1e-5},        {"dac_gain_u2", 0.0}};
  for (size_t i = 0; i < sizeof cross / sizeof cross[0]; i++) {
    plant_cfg_t b = c;
    assert_int_equal(plant_param_set(&b, cross[i].key, cross[i].value, err, sizeof err), 0);
    assert_int_equal(plant_cfg_check(&b, err, sizeof err), -1);
    assert_non_null(strstr(err, cross[i].key));
    assert_int_equal(plant_init(&p, &b, 1u), -1);
    assert_non_null(strstr(plant_error(&p), cross[i].key));
    assert_memory_equal(&p, &before, offsetof(plant_t, err));
  }
  assert_int_equal(plant_thermal_preset(&c, "loose"), 0);
  assert_true(c.couple_sc_per_s < 1e-3);
  assert_int_equal(plant_thermal_preset(&c, "tight"), 0);
  assert_true(c.couple_sc_per_s >= 0.1);
  assert_int_equal(plant_thermal_preset(&c, "nope"), -1);

  /* profiles: a bad one changes nothing */
  plant_profiles_t pr = p.prof;
  pr.rate_dps.kind = PROFILE_SINE;
  pr.rate_dps.freq_hz = -1.0;
  assert_int_equal(plant_set_profiles(&p, &pr), -1);
  assert_non_null(strstr(plant_error(&p), "freq_hz"));
  assert_memory_equal(&p.prof, &before.prof, sizeof p.prof);
}

/* ------------------------------------------------------- open-loop chain -------- */

static void quiet(plant_cfg_t *c)
{
  c->brownian = false;
  c->drive_noise_white_v_rthz = c->drive_noise_1hz_v_rthz = 0.0;
  c->pick_drive_noise_v_rthz = c->pick_sense_noise_v_rthz = 0.0;
}

typedef struct {
  double drive_amp_v, drive_lag_deg; /* drive ADC = amp sin(wc t - lag) */
  double sense_amp_v, sense_lag_deg;
  double drive_offset_v;
} fit_t;

/* Half-frequency drive of amplitude u_v at the force frequency f_hz (U1 = u cos(wc t/2),
 * U2 = u sin(wc t/2), so U1^2 - U2^2 = u^2 cos(wc t) at the ticks), the frame for tick k
 * held over [t_k, t_k+1). Settles, then fits the last n_fit ADC samples (volts). */
static void run_open_loop(plant_t *p, double u_v, double f_hz, long n_settle, long n_fit,
                          fit_t *out)
{
  const double T = p->T, wc = 2.0 * kPi * f_hz;
  double *yd = malloc(sizeof(double) * (size_t)n_fit),
         *ys = malloc(sizeof(double) * (size_t)n_fit);
  assert_non_null(yd);
  assert_non_null(ys);
  for (long k = 0; k < n_settle + n_fit; k++) {
    hal_dac_frame_t fr;
    hal_dac_frame_midscale(&fr);
    const double tk = (double)k * T;
    fr.code[HAL_DAC_DRIVE_U1] = dac_v_to_code(u_v * cos(0.5 * wc * tk));
    fr.code[HAL_DAC_DRIVE_U2] = dac_v_to_code(u_v * sin(0.5 * wc * tk));
    fr.code[HAL_DAC_RATE_OUT] = (uint16_t)HAL_DAC_CODE_MID;
    fr.code[HAL_DAC_SPARE] = (uint16_t)HAL_DAC_CODE_MID;
    hal_adc_frame_t a;
    plant_step(p, &fr, &a);
    if (k >= n_settle) {
      yd[k - n_settle] = a.drive * (double)HAL_ADC_V_PER_CODE;
      ys[k - n_settle] = a.sense * (double)HAL_ADC_V_PER_CODE;
    }
  }
  /* the ADC frame of step k is sampled at t_{k+1} */
  const double t0 = (double)(n_settle + 1) * T;
  double coef[3];
  assert_true(ref_sine_fit(yd, (size_t)n_fit, t0, T, &f_hz, 1, coef) >= 0.0);
  out->drive_offset_v = coef[0];
  /* a cos + b sin = R sin(wt - lag): b = R cos(lag), a = -R sin(lag) */
  out->drive_amp_v = hypot(coef[1], coef[2]);
  out->drive_lag_deg = atan2(-coef[1], coef[2]) / kDeg;
  assert_true(ref_sine_fit(ys, (size_t)n_fit, t0, T, &f_hz, 1, coef) >= 0.0);
  out->sense_amp_v = hypot(coef[1], coef[2]);
  out->sense_lag_deg = atan2(-coef[1], coef[2]) / kDeg;
  free(yd);
  free(ys);
}

static double wrap_deg(double d)
{
  while (d > 180.0) d -= 360.0;
  while (d <= -180.0) d += 360.0;
  return d;
}

static double complex lp2(double f, double f0, double q)
{
  const double complex s = I * f / f0;
  return 1.0 / (s * s + s / q + 1.0);
}
static double complex hp1(double f, double f0)
{
  const double complex s = I * f / f0;
  return s / (1.0 + s);
}

/* Drive at resonance with 8 V, rate 100 deg/s and 1500 deg/s of quadrature: amplitude
 * and phase of both ADC channels against the closed form of every stage; the truth's
 * phasors against the same. The closed form is the linear chain's, so the part is the
 * ideal preset (the default part's stroke-dependent drive damping lowers the drive
 * amplitude by 0.3 % at 10 um, beyond the 0.2 % tolerance). */
static void test_open_loop_chain(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  quiet(&c);
  c.full_kinematics = false; /* (2-22) exactly, so (2-25) below is exact */
  c.rate_dps = 100.0;
  c.truth_decim = 1;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 7u), 0);
  const double u = 8.0, f = c.f_drive_hz, T = 1.0 / c.fs_hz;
  fit_t fit;
  run_open_loop(&p, u, f, 20000, 10000, &fit);

  /* closed form, stage by stage, at the node temperatures the thermal network settled
   * to (the circuit's self-heating warms the structure by about 1.3 K) */
  const plant_truth_t *t = plant_truth(&p);
  const double sres = 1.0 - 0.5 * c.ket_per_k * (t->struct_k - c.temp_ref_k); /* (2-32) */
  const double dtc = t->circuit_k - c.temp_ref_k;
  const double wc = 2.0 * kPi * f, wn1 = wc * sres, wn2 = 2.0 * kPi * c.f_sense_hz * sres;
  const double x = 0.5 * wc * T, sinc_f = sin(x) / x, sinc_v = sin(0.5 * x) / (0.5 * x);
  const double complex hr = lp2(0.5 * f, c.dac_recon_hz, c.dac_recon_q);
  /* force phasor (relative to cos(wc t)): hold delay T/2, recon on the voltages (6-25),
   * per-sample mean + hold (dac.h) */
  const double complex force = c.ks_drive_mps2_per_v2 * u * u * hr * hr * sinc_v * sinc_v *
                               sinc_f * sinc_f * cexp(-I * x);
  const double complex d1 = wn1 * wn1 - wc * wc + I * wn1 * wc / c.q_drive;
  const double complex y = force / d1; /* (2-24) */
  const double kq = 2.0 * wc * c.quad_dps * kDeg * sres * sres, om = c.rate_dps * kDeg;
  const double complex d2 = wn2 * wn2 - wc * wc + I * wn2 * wc / c.q_sense;
  const double complex xs = (2.0 * om * I * wc - kq) * y / d2; /* (2-25) with -k_q y */
  const double phd = (c.pick_drive_phi0_deg + c.pick_drive_phi1_deg_per_k * dtc) * kDeg;
  const double phs = (c.pick_sense_phi0_deg + c.pick_sense_phi1_deg_per_k * dtc) * kDeg;
  const double complex gd = c.pick_drive_gain_v_per_m /
                            (1.0 + I * tan(phd) * f / c.pick_lag_ref_hz) *
                            hp1(f, c.pick_drive_hp_hz) *
                            lp2(f, c.pick_drive_lp_hz, c.pick_drive_lp_q);
  const double complex gs = c.pick_sense_gain_v_per_m /
                            (1.0 + I * tan(phs) * f / c.pick_lag_ref_hz) *
                            hp1(f, c.pick_sense_hp_hz) *
                            lp2(f, c.pick_sense_lp_hz, c.pick_sense_lp_q) *
                            cexp(I * wc * c.pick_sense_delay_s);
  const double complex vd = gd * y, vs = gs * xs;
  /* the ADC fit is relative to sin(wc t); the phasors are relative to cos(wc t) */
  const double lag_d = wrap_deg(-(carg(vd) + 0.5 * kPi) / kDeg);
  const double lag_s = wrap_deg(-(carg(vs) + 0.5 * kPi) / kDeg);
  printf("drive ADC: %.5f V lag %.4f deg (closed form %.5f V, %.4f deg)\n", fit.drive_amp_v,
         fit.drive_lag_deg, cabs(vd), lag_d);
  printf("sense ADC: %.5f V lag %.4f deg (closed form %.5f V, %.4f deg)\n", fit.sense_amp_v,
         fit.sense_lag_deg, cabs(vs), lag_s);
  assert_true(fabs(fit.drive_amp_v / cabs(vd) - 1.0) < 2e-3);
  assert_true(fabs(wrap_deg(fit.drive_lag_deg - lag_d)) < 0.05);
  assert_true(fabs(fit.sense_amp_v / cabs(vs) - 1.0) < 2e-3);
  assert_true(fabs(wrap_deg(fit.sense_lag_deg - lag_s)) < 0.05);
  assert_true(fabs(fit.drive_offset_v - c.pick_drive_offset_v) < 1e-3);

  /* §7.2.2: at resonance the drive signal lags the force by 90 deg plus the hold
   * (wc T / 2) plus 9.56 deg of analog circuit */
  plant_phase_budget_t b;
  plant_drive_phase_budget(&c, f, t->circuit_k, &b);
  printf("phase budget at %.1f Hz: recon %.3f + lag %.3f + aa %.3f = analog %.3f deg; hold %.3f; "
         "latency %.3f\n",
         f, b.recon_deg, b.pick_lag_deg, b.aa_deg, b.analog_deg, b.zoh_deg, b.latency_deg);
  plant_drive_phase_budget(&c, f, c.temp_ref_k, &b);
  assert_true(fabs(b.analog_deg - 9.56) < 0.005);
  plant_drive_phase_budget(&c, f, t->circuit_k, &b);
  const double mech_lag = carg(d1) / kDeg; /* 90 deg + the warm structure's detuning */
  assert_true(fabs(fit.drive_lag_deg - (mech_lag + b.zoh_deg + b.analog_deg - 90.0)) < 0.05);

  /* truth phasors: frequency, amplitude, phase (2-24), sense components */
  printf("truth: f %.6f Hz, |y| %.4e m (closed form %.4e), phase %.4f deg, sense vel %.4e "
         "disp %.4e m\n",
         t->drive_freq_hz, t->drive_amp_m, cabs(y), t->drive_phase_rad / kDeg, t->sense_vel_m,
         t->sense_disp_m);
  assert_true(fabs(t->drive_freq_hz / f - 1.0) < 1e-5); /* DAC quantisation */
  assert_true(fabs(t->drive_amp_m / cabs(y) - 1.0) < 2e-3);
  assert_true(fabs(t->drive_phase_rad / kDeg + mech_lag) < 0.02);
  /* relative to the drive motion: x/y = (2 Omega j wc - kq) / d2 */
  const double complex rel = (2.0 * om * I * wc - kq) / d2 * cabs(y);
  /* along y (disp) is Re, along y' (vel) is Im in this convention */
  assert_true(fabs(t->sense_disp_m - creal(rel)) < 2e-3 * cabs(rel));
  assert_true(fabs(t->sense_vel_m - cimag(rel)) < 2e-3 * cabs(rel));
  assert_true(fabs(t->drive_force_mps2 / cabs(force) - 1.0) < 1e-3);
  assert_true(t->adc_clip[0] == 0 && t->adc_clip[1] == 0);
  assert_true(fabs(t->rate_dps - 100.0) < 1e-12);
}

/* Table 7-1: demodulated drive amplitude against the half-frequency voltage amplitude,
 * at 1490 Hz: linear in U^2, 0.8754 V at 12.75 V, on the ideal preset (the linear law the
 * drive pickoff gain was derived from; the default part's compression, set to the
 * thesis's 0.25 %, is cl_square_law's). */
static void test_table_7_1_square_law(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  quiet(&c);
  static plant_t p;
  const double u[3] = {3.0, 7.5, 12.75}, thesis[3] = {0.04957, 0.3080, 0.8754};
  double amp[3];
  for (int i = 0; i < 3; i++) {
    assert_int_equal(plant_init(&p, &c, 3u), 0);
    fit_t fit;
    run_open_loop(&p, u[i], 1490.0, 20000, 5000, &fit);
    amp[i] = fit.drive_amp_v;
    printf("table 7-1: U %.2f V -> %.4f V (thesis %.4f)\n", u[i], amp[i], thesis[i]);
  }
  /* square law: amplitude / U^2 constant */
  for (int i = 1; i < 3; i++)
    assert_true(fabs((amp[i] / (u[i] * u[i])) / (amp[0] / (u[0] * u[0])) - 1.0) < 2e-3);
  /* and the thesis's scale, within its own 0.6 % scatter about a line plus the 0.7 %
   * of a line through the origin */
  for (int i = 0; i < 3; i++) assert_true(fabs(amp[i] / thesis[i] - 1.0) < 0.025);
}

/* Table 7-4 relations, open loop at the drive frequency: the drive signal's phase moves
 * by -kET Q1 per kelvin of structure temperature (the phase loop's P moves by the
 * opposite, +0.0769 deg/K measured), and the sense signal's phase relative to the
 * drive signal lags by 0.1018 deg/K (x 1500 deg/s of quadrature = 2.67 deg/s/K of
 * bias, measured 2.666). */
static void test_table_7_4_slopes(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  quiet(&c);
  static plant_t p;
  const double dt = 9.0;
  fit_t fit[2];
  for (int i = 0; i < 2; i++) {
    c.temp_k = c.temp_ref_k + i * dt; /* thermal nodes start settled at the ambient */
    assert_int_equal(plant_init(&p, &c, 5u), 0);
    run_open_loop(&p, 8.0, c.f_drive_hz, 20000, 5000, &fit[i]);
  }
  const double p_slope = -(fit[1].drive_lag_deg - fit[0].drive_lag_deg) / dt;
  const double rel_slope = ((fit[1].sense_lag_deg - fit[1].drive_lag_deg) -
                            (fit[0].sense_lag_deg - fit[0].drive_lag_deg)) /
                           dt;
  const double bias_slope = c.quad_dps * rel_slope * kDeg;
  printf("table 7-4: drive phase %+.4f deg/K (P slope %+.4f, measured +0.0769), sense-drive "
         "lag %+.4f deg/K -> bias %+.3f deg/s/K (measured +2.666)\n",
         p_slope, -p_slope, rel_slope, bias_slope);
  assert_true(fabs(-p_slope / 0.0769 - 1.0) < 0.03);
  assert_true(fabs(bias_slope / 2.666 - 1.0) < 0.03);
}

/* The range budget: the default design point fits the ADC, and a simulation of it
 * (quadrature, full-scale rate, the budget's vibration) stays under the computed
 * worst case without clipping. */
static void test_adc_budget(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  double frac[2];
  const double worst = plant_adc_fraction(&c, frac);
  printf("ADC range used at the design point: drive %.1f %%, sense %.1f %%\n", 100 * frac[0],
         100 * frac[1]);
  assert_true(worst < 1.0);
  c.rate_dps = c.rate_fs_dps;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 9u), 0);
  plant_profiles_t pr = p.prof;
  pr.accel_g.amp_g[ACCEL_AXIS_SENSE] = c.vib_g;
  pr.accel_g.freq_hz[ACCEL_AXIS_SENSE] = c.vib_hz;
  assert_int_equal(plant_set_profiles(&p, &pr), 0);
  /* drive voltage for 10 um at resonance */
  const double u = sqrt(c.drive_amp_m * pow(2 * kPi * c.f_drive_hz, 2) / c.q_drive /
                        c.ks_drive_mps2_per_v2);
  const double wc = 2.0 * kPi * c.f_drive_hz;
  double peak[2] = {0, 0};
  for (long k = 0; k < 40000; k++) {
    hal_dac_frame_t fr;
    hal_dac_frame_midscale(&fr);
    fr.code[0] = dac_v_to_code(u * cos(0.5 * wc * k * p.T));
    fr.code[1] = dac_v_to_code(u * sin(0.5 * wc * k * p.T));
    fr.code[2] = fr.code[3] = (uint16_t)HAL_DAC_CODE_MID;
    hal_adc_frame_t a;
    plant_step(&p, &fr, &a);
    if (k > 20000) {
      peak[0] = fmax(peak[0], fabs(plant_truth(&p)->adc_v[0]));
      peak[1] = fmax(peak[1], fabs(plant_truth(&p)->adc_v[1]));
    }
  }
  printf("simulated peaks: drive %.1f %%, sense %.1f %% of full scale\n", 100 * peak[0] / 5.0,
         100 * peak[1] / 5.0);
  assert_true(peak[0] / 5.0 <= frac[0] && peak[1] / 5.0 <= frac[1]);
  assert_true(peak[1] / 5.0 > 0.8 * frac[1]); /* the budget is not a loose bound */
  assert_true(plant_truth(&p)->adc_clip[0] == 0 && plant_truth(&p)->adc_clip[1] == 0);
}

/* Thermal plumbing: the ambient profile reaches the nodes, the structure node moves the
 * resonance (2-32), and the pickoffs follow their chosen node. */
static void test_temperature_plumbing(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  quiet(&c);
  assert_int_equal(plant_thermal_preset(&c, "tight"), 0);
  c.pick_sense_temp_node = THERMAL_BOARD;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 11u), 0);
  plant_profiles_t pr = p.prof;
  profile_const(&pr.ambient_k, c.temp_k + 20.0);
  assert_int_equal(plant_set_profiles(&p, &pr), 0);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  for (long k = 0; k < 500000; k++) plant_step(&p, &fr, NULL); /* 10 s */
  const plant_truth_t *t = plant_truth(&p);
  /* the closed form of thermal.h after 10 s from the settled start */
  thermal_cfg_t th;
  thermal_preset(&th, THERMAL_PRESET_TIGHT);
  static thermal_t ref;
  assert_int_equal(thermal_init(&ref, &th, c.temp_k), 0);
  for (int k = 0; k < 10000; k++) thermal_step(&ref, c.temp_k + 20.0);
  printf("after 10 s of +20 K: structure %.4f circuit %.4f board %.4f K\n", t->struct_k,
         t->circuit_k, t->board_k);
  assert_true(fabs(t->struct_k - thermal_temp(&ref, THERMAL_STRUCT)) < 1e-9);
  assert_true(fabs(t->board_k - thermal_temp(&ref, THERMAL_BOARD)) < 1e-9);
  const double wn = 2 * kPi * c.f_drive_hz *
                    (1.0 - 0.5 * c.ket_per_k * (t->struct_k - c.temp_ref_k));
  assert_true(fabs(t->wn_drive_rad_s / wn - 1.0) < 1e-12);
  assert_true(p.pick[1].temp_k == t->board_k);
  assert_true(p.pick[0].temp_k == t->circuit_k);
  /* the sense phase follows (2-40) to within the step */
  const double phi = (c.pick_sense_phi0_deg +
                      c.pick_sense_phi1_deg_per_k * (t->board_k - c.temp_ref_k)) *
                     kDeg;
  assert_true(fabs(p.pick[1].phi_rad - phi) <= c.pick_phase_step_rad);
  assert_true(t->ambient_k == c.temp_k + 20.0);
  assert_true(t->dac_rejects == 0);
  /* a bad frame is rejected and counted, the previous one held */
  hal_dac_frame_t bad = {{HAL_DAC_CODE_MAX + 1u, 0, 0, 0}};
  /* the mid-scale level itself: 0 V but for the default part's DAC INL at that code */
  const double held_v = plant_truth(&p)->dac_held_v[0];
  assert_true(fabs(held_v) < 4.0 * HAL_DAC_V_PER_CODE);
  plant_step_hal(&p, &bad, NULL);
  assert_true(plant_truth(&p)->dac_rejects == 1);
  assert_true(plant_truth(&p)->dac_held_v[0] == held_v);
}

/* plant.cold_start: power-on after a long power-off. The nodes, the resonance and the
 * pickoffs start at the ambient and warm as the thermal network alone does from there
 * (thermal_init_cold); off (the default), they start in the steady state as before. The
 * switch takes 0 or 1 only, and a refused value changes nothing. */
/* A table or chamber moved while the plant runs: a linear edge from the value at that
 * moment, then held; a bad move changes nothing. */
static void test_move_input(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  quiet(&c);
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 3u), 0);
  const hal_dac_frame_t dac = {0};
  hal_adc_frame_t adc;
  const uint64_t n_100ms = (uint64_t)llround(0.1 * c.fs_hz);
  for (uint64_t k = 0; k < n_100ms; k++) plant_step(&p, &dac, &adc);
  assert_int_equal(plant_move_input(&p, PLANT_INPUT_RATE, 50.0, 0.2), 0);
  for (uint64_t k = 0; k < n_100ms; k++) plant_step(&p, &dac, &adc); /* half the edge */
  assert_float_equal(plant_input_now(&p, PLANT_INPUT_RATE), 25.0, 1e-6);
  for (uint64_t k = 0; k < 2u * n_100ms; k++) plant_step(&p, &dac, &adc);
  assert_float_equal(plant_input_now(&p, PLANT_INPUT_RATE), 50.0, 0.0);
  /* back down from where it is, the ambient on its own */
  assert_int_equal(plant_move_input(&p, PLANT_INPUT_AMBIENT, c.temp_k + 10.0, 0.1), 0);
  for (uint64_t k = 0; k < n_100ms; k++) plant_step(&p, &dac, &adc);
  assert_float_equal(plant_input_now(&p, PLANT_INPUT_AMBIENT), c.temp_k + 10.0, 1e-9);
  assert_float_equal(plant_input_now(&p, PLANT_INPUT_RATE), 50.0, 0.0);
  const plant_profiles_t before = p.prof;
  const struct {
    plant_input_t which;
    double to, edge_s;
  } bad[] = {{PLANT_INPUT_RATE, 2e4, 0.1},      {PLANT_INPUT_RATE, NAN, 0.1},
             {PLANT_INPUT_RATE, 10.0, 0.0},     {PLANT_INPUT_RATE, 10.0, NAN},
             {PLANT_INPUT_AMBIENT, 100.0, 1.0}, {PLANT_INPUT_AMBIENT, 300.0, 2e5}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(plant_move_input(&p, bad[i].which, bad[i].to, bad[i].edge_s), -1);
    assert_non_null(strstr(plant_error(&p), "move to"));
    assert_memory_equal(&p.prof, &before, sizeof before);
  }
  /* a long power-off at the ambient now: every node there, warming again from it */
  assert_true(plant_truth(&p)->circuit_k > c.temp_k + 1.0); /* its own dissipation */
  assert_int_equal(plant_cold_soak(&p), 0);
  for (int i = 0; i < THERMAL_NODES; i++)
    assert_float_equal(thermal_temp(&p.thermal, i), c.temp_k + 10.0, 0.0);
}

static void test_cold_start(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  assert_false(c.cold_start);
  quiet(&c);
  thermal_cfg_t th;
  thermal_preset(&th, THERMAL_PRESET_DEFAULT);
  double tss[3];
  thermal_steady(&th, c.temp_k, tss);
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 3u), 0);
  assert_true(plant_truth(&p)->circuit_k == tss[THERMAL_CIRCUIT]);
  assert_true(plant_truth(&p)->board_k == tss[THERMAL_BOARD]);
  char err[200];
  plant_cfg_t before = c;
  const double bad[3] = {2.0, 0.5, -1.0};
  for (int i = 0; i < 3; i++) {
    assert_int_equal(plant_param_set(&c, "cold_start", bad[i], err, sizeof err), -1);
    assert_non_null(strstr(err, "cold_start: "));
    assert_memory_equal(&c, &before, sizeof c);
  }
  assert_int_equal(plant_param_set(&c, "cold_start", 1.0, err, sizeof err), 0);
  assert_true(c.cold_start);
  assert_int_equal(plant_init(&p, &c, 3u), 0);
  const plant_truth_t *t = plant_truth(&p);
  assert_true(t->struct_k == c.temp_k && t->circuit_k == c.temp_k && t->board_k == c.temp_k);
  assert_true(p.pick[0].temp_k == c.temp_k && p.pick[1].temp_k == c.temp_k);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  for (long k = 0; k < 500000; k++) plant_step(&p, &fr, NULL); /* 10 s */
  static thermal_t ref;
  assert_int_equal(thermal_init_cold(&ref, &th, c.temp_k), 0);
  for (int k = 0; k < 10000; k++) thermal_step(&ref, c.temp_k);
  printf("cold start, 10 s after power-on: structure %+.4f circuit %+.4f board %+.4f K\n",
         t->struct_k - c.temp_k, t->circuit_k - c.temp_k, t->board_k - c.temp_k);
  for (int i = 0; i < 3; i++) {
    const double tk = i == 0 ? t->struct_k : i == 1 ? t->circuit_k : t->board_k;
    assert_true(fabs(tk - thermal_temp(&ref, i)) < 1e-9);
  }
  /* warming: the circuit at its own heating rate rise/tau (1.5 K / 300 s) at first */
  assert_true(t->circuit_k - c.temp_k > 0.8 * 10.0 * 1.5 / 300.0);
  assert_true(t->circuit_k < tss[THERMAL_CIRCUIT] && t->board_k < tss[THERMAL_BOARD]);
  assert_true(p.pick[0].temp_k == t->circuit_k);
}

/* The converters' INL patterns belong to the board (plant.board_seed), not to the run:
 * two runs with other noise seeds on one board see the same ladders (a calibration and the
 * runs after it see one part), and another board_seed is another board. */
static void test_board_seed(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_default_cfg(&c);
  c.adc_inl_code_lsb = 2.0;
  static plant_t a, b;
  assert_int_equal(plant_init(&a, &c, 11u), 0);
  assert_int_equal(plant_init(&b, &c, 12u), 0);
  for (int ch = 0; ch < DAC_NCH; ch++)
    assert_memory_equal(a.dac.inl[ch].err_lsb, b.dac.inl[ch].err_lsb,
                        sizeof a.dac.inl[ch].err_lsb);
  assert_memory_equal(a.adc.inl.err_lsb, b.adc.inl.err_lsb, sizeof a.adc.inl.err_lsb);
  c.board_seed = 2;
  assert_int_equal(plant_init(&b, &c, 11u), 0);
  assert_true(memcmp(a.dac.inl[2].err_lsb, b.dac.inl[2].err_lsb, sizeof a.dac.inl[2].err_lsb) !=
              0);
  assert_true(memcmp(a.adc.inl.err_lsb, b.adc.inl.err_lsb, sizeof a.adc.inl.err_lsb) != 0);
}

/* The default part is built and runs at -40 and at 85 degC ambient (the sense circuit's
 * lag of (2-40) has passed through zero into a 3.4 deg lead at -40 degC) with no law
 * outside its range; an off-nominal part whose laws leave their ranges is not refused
 * either: each evaluation there is counted, with the time of the first. */
static void test_law_warnings(void **state)
{
  (void)state;
  static plant_t p;
  plant_cfg_t c;
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  const double ambients[2] = {233.15, 358.15};
  for (int i = 0; i < 2; i++) {
    plant_default_cfg(&c);
    quiet(&c);
    c.temp_k = ambients[i];
    assert_int_equal(plant_init(&p, &c, 5u), 0);
    for (long k = 0; k < 5000; k++) plant_step(&p, &fr, NULL);
    assert_true(plant_warning_total(&p) == 0);
    const double tc = plant_truth(&p)->circuit_k;
    const double law = (c.pick_sense_phi0_deg +
                        c.pick_sense_phi1_deg_per_k * (tc - c.temp_ref_k)) *
                       kDeg;
    print_message("ambient %.2f K: circuit %.3f K, sense phase %+.4f deg\n", c.temp_k, tc,
                  p.pick[1].phi_rad / kDeg);
    assert_true(fabs(p.pick[1].phi_rad - law) <= c.pick_phase_step_rad);
  }
  assert_true(p.pick[1].phi_rad > 0.0);
  /* off-nominal: 40 deg + 1 deg/K of sense lag passes 80 deg at 85 degC; the drive gain
   * falls 9.9 %/K and is gone below -40 degC: both from the start */
  plant_default_cfg(&c);
  quiet(&c);
  c.temp_k = 358.15;
  c.pick_sense_phi0_deg = 40.0;
  c.pick_sense_phi1_deg_per_k = 1.0;
  assert_int_equal(plant_init(&p, &c, 5u), 0);
  const plant_warning_t *w = plant_warnings(&p);
  assert_true(w[PLANT_LAW_PICK_SENSE_PHASE].count == 1 &&
              w[PLANT_LAW_PICK_SENSE_PHASE].first_t_s == 0.0);
  for (long k = 0; k < 500; k++) plant_step(&p, &fr, NULL); /* 10 ms: 10 thermal updates */
  assert_true(w[PLANT_LAW_PICK_SENSE_PHASE].count == 11);
  assert_true(p.pick[1].phi_rad == PICKOFF_LAG_MAX_LOWPASS_RAD);
  assert_true(plant_warning_total(&p) == 11);
  assert_string_equal(plant_law_name(PLANT_LAW_PICK_SENSE_PHASE), "pick_sense_phase");
  assert_null(plant_law_name(PLANT_LAWS));
  /* a law that leaves its range during the run: first time after the start */
  plant_default_cfg(&c);
  quiet(&c);
  c.pick_drive_gain_tc_per_k = 0.099;
  c.tau_circuit_s = 0.01;
  assert_int_equal(plant_init(&p, &c, 5u), 0);
  assert_true(plant_warning_total(&p) == 0);
  plant_profiles_t pr = p.prof;
  profile_const(&pr.ambient_k, 233.15);
  assert_int_equal(plant_set_profiles(&p, &pr), 0);
  for (long k = 0; k < 50000; k++) plant_step(&p, &fr, NULL); /* 1 s */
  w = plant_warnings(&p);
  print_message("drive gain: %llu warnings from %.4f s\n",
                (unsigned long long)w[PLANT_LAW_PICK_DRIVE_GAIN].count,
                w[PLANT_LAW_PICK_DRIVE_GAIN].first_t_s);
  assert_true(w[PLANT_LAW_PICK_DRIVE_GAIN].count > 900);
  assert_true(w[PLANT_LAW_PICK_DRIVE_GAIN].first_t_s > 0.0 &&
              w[PLANT_LAW_PICK_DRIVE_GAIN].first_t_s < 0.1);
  assert_true(p.pick[0].gain_now == c.pick_drive_gain_v_per_m * PICKOFF_GAIN_MIN_FACTOR);
  /* an ambient the thermal network cannot take: held, counted */
  profile_const(&pr.ambient_k, 2500.0);
  if (plant_set_profiles(&p, &pr) == 0) {
    for (long k = 0; k < 100; k++) plant_step(&p, &fr, NULL);
    assert_true(plant_warnings(&p)[PLANT_LAW_AMBIENT].count == 2);
    assert_true(plant_truth(&p)->ambient_k == 233.15);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_param_table_complete), cmocka_unit_test(test_param_set),
      cmocka_unit_test(test_init_validation),      cmocka_unit_test(test_open_loop_chain),
      cmocka_unit_test(test_table_7_1_square_law), cmocka_unit_test(test_table_7_4_slopes),
      cmocka_unit_test(test_adc_budget),           cmocka_unit_test(test_temperature_plumbing),
      cmocka_unit_test(test_cold_start),           cmocka_unit_test(test_law_warnings),
      cmocka_unit_test(test_board_seed),           cmocka_unit_test(test_move_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
