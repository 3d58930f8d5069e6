/* The plant's imperfections beyond the linear gyro, through the whole plant (host_sim/
 * plant/plant.h), on the ideal part (plant_ideal_cfg) so that each is seen alone: every
 * one off there (the ideal part runs bit for bit as with them explicitly off), each switched on by its parameter and reaching its module with
 * the expected size, the converters' shared reference and the ADC's common aperture
 * jitter, shocks and random vibration through the g-sensitivity, Q(T) in the truth, the
 * laws' warnings over -40..85 degC and beyond, and the cross-field refusals; the sense
 * electrodes beyond the DAC (plant_set_electrodes): nulling, tuning, the half-frequency
 * feedback pair, matching (plant_sense_match). The physics
 * of each effect is tested on its module (test_mech_effects, test_pickoff_effects,
 * test_qlaw, test_inl, test_vref, test_drift, test_vib, test_profile, test_adc,
 * test_dac, test_actuator). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/plant.h"
#include "plant/qlaw.h"
#include "sine_fit_ref.h"

static const double kTwoPi = 6.28318530717958647692;
static const double kDeg = 6.28318530717958647692 / 360.0;

/* Every switch of an imperfection: zero in the default part. */
static const char *const kSwitches[] = {"quad_drift_dps",
                                        "inphase_drift_dps",
                                        "k3_drive_per_m2",
                                        "k3_sense_per_m2",
                                        "nl_damp_drive_per_m2",
                                        "fb_gap_m",
                                        "dac_inl_bow_lsb",
                                        "dac_inl_code_lsb",
                                        "pick_drive_gap_m",
                                        "pick_drive_gain_flicker_1hz_rthz",
                                        "pick_drive_phase_flicker_1hz_deg_rthz",
                                        "pick_sense_gap_m",
                                        "pick_sense_gain_flicker_1hz_rthz",
                                        "pick_sense_phase_flicker_1hz_deg_rthz",
                                        "adc_inl_bow_lsb",
                                        "adc_inl_code_lsb",
                                        "adc_aperture_jitter_s",
                                        "vref_noise_white_rthz",
                                        "vref_noise_1hz_rthz",
                                        "q_temp_law"};
#define NSWITCH (sizeof kSwitches / sizeof kSwitches[0])

/* Half-frequency drive at the default resonance, 8 V (the square law's test point). */
static void drive_frame(long k, double fs, hal_dac_frame_t *fr)
{
  const double ph = 0.5 * kTwoPi * 1489.9 * (double)k / fs;
  hal_dac_frame_midscale(fr);
  fr->code[HAL_DAC_DRIVE_U1] = dac_v_to_code(8.0 * cos(ph));
  fr->code[HAL_DAC_DRIVE_U2] = dac_v_to_code(8.0 * sin(ph));
  fr->code[HAL_DAC_RATE_OUT] = (uint16_t)HAL_DAC_CODE_MID;
  fr->code[HAL_DAC_SPARE] = (uint16_t)HAL_DAC_CODE_MID;
}

/* n samples of p under the drive; ADC frames into out (may be NULL). */
static void run(plant_t *p, long n, hal_adc_frame_t *out)
{
  for (long k = 0; k < n; k++) {
    hal_dac_frame_t fr;
    drive_frame((long)p->k, p->cfg.fs_hz, &fr);
    hal_adc_frame_t a;
    plant_step(p, &fr, &a);
    if (out != NULL) out[k] = a;
  }
}

/* Off in the ideal part: every switch is 0 there, and a part whose shape
 * parameters (correlation times, 1/f floors, imbalances) are changed while the switches
 * stay 0, with empty shock and band lists in its profile, gives the same ADC frames and
 * truth bit for bit. */
static void test_off_by_default(void **state)
{
  (void)state;
  plant_cfg_t c, d;
  plant_ideal_cfg(&c);
  for (size_t i = 0; i < NSWITCH; i++) {
    const plant_param_desc_t *pd = plant_param_find(kSwitches[i]);
    assert_non_null(pd);
    if (plant_param_get(&c, pd) != 0.0) fail_msg("%s is on in the default part", pd->name);
  }
  d = c;
  d.quad_drift_tau_s = d.inphase_drift_tau_s = 5.0;
  d.pick_flicker_fmin_hz = d.vref_noise_fmin_hz = 0.01;
  d.pick_drive_gap_asym = d.pick_sense_gap_asym = 0.5;
  static plant_t a, b;
  assert_int_equal(plant_init(&a, &c, 3u), 0);
  assert_int_equal(plant_init(&b, &d, 3u), 0);
  plant_profiles_t pr = b.prof;
  pr.accel_g.n_shocks = 0;
  pr.accel_g.n_bands = 0;
  assert_int_equal(plant_set_profiles(&b, &pr), 0);
  const long n = 30000;
  hal_adc_frame_t *fa = malloc(sizeof *fa * (size_t)n), *fb = malloc(sizeof *fb * (size_t)n);
  assert_non_null(fa);
  assert_non_null(fb);
  run(&a, n, fa);
  run(&b, n, fb);
  assert_memory_equal(fa, fb, sizeof *fa * (size_t)n);
  assert_memory_equal(&a.truth, &b.truth, sizeof a.truth);
  free(fa);
  free(fb);
}

/* Each switch on alone changes what the ADC reads within 0.3 s of the same drive (its
 * size is its module's test); none of them leaves a law's range at these values. */
static void test_each_switch_acts(void **state)
{
  (void)state;
  static const struct {
    const char *key;
    double v;
  } on[] = {{"quad_drift_dps", 20.0},
            {"inphase_drift_dps", 20.0},
            {"k3_drive_per_m2", 1e8},
            {"k3_sense_per_m2", 1e12},
            {"nl_damp_drive_per_m2", 1e9},
            {"fb_gap_m", 2e-6},
            {"dac_inl_bow_lsb", 2.0},
            {"dac_inl_code_lsb", 1.0},
            {"pick_drive_gap_m", 100e-6},
            {"pick_drive_gain_flicker_1hz_rthz", 1e-4},
            {"pick_drive_phase_flicker_1hz_deg_rthz", 0.01},
            {"pick_sense_gap_m", 2e-6},
            {"pick_sense_gain_flicker_1hz_rthz", 1e-4},
            {"pick_sense_phase_flicker_1hz_deg_rthz", 0.01},
            {"adc_inl_bow_lsb", 2.0},
            {"adc_inl_code_lsb", 1.0},
            {"adc_aperture_jitter_s", 1e-8},
            {"vref_noise_white_rthz", 1e-6},
            {"vref_noise_1hz_rthz", 1e-5},
            {"q_temp_law", 2.0}};
  assert_int_equal(sizeof on / sizeof on[0], NSWITCH);
  const long n = 15000;
  hal_adc_frame_t *ref = malloc(sizeof *ref * (size_t)n), *x = malloc(sizeof *x * (size_t)n);
  assert_non_null(ref);
  assert_non_null(x);
  static plant_t p;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  assert_int_equal(plant_init(&p, &c, 4u), 0);
  run(&p, n, ref);
  for (size_t i = 0; i < NSWITCH; i++) {
    plant_ideal_cfg(&c);
    char err[200];
    assert_int_equal(plant_param_set(&c, on[i].key, on[i].v, err, sizeof err), 0);
    assert_int_equal(plant_init(&p, &c, 4u), 0);
    run(&p, n, x);
    long differ = 0;
    for (long k = 0; k < n; k++) differ += memcmp(&x[k], &ref[k], sizeof x[k]) != 0;
    uint64_t warnings = 0;
    for (int l = 0; l < PLANT_LAWS; l++) warnings += plant_warnings(&p)[l].count;
    print_message("%-40s %-8g: %ld of %ld frames differ\n", on[i].key, on[i].v, differ, n);
    assert_true(differ > 0);
    assert_true(warnings == 0);
  }
  free(ref);
  free(x);
}

/* The feedback electrodes' bias softens the sense spring by 4 ks Vb^2 / gap (6-3) in
 * differential mode, not at all in the others; the coupling drifts reach the mechanics
 * with the scales of quad_dps and inphase_bias_dps (k_q = 2 wc quad, d_q = 2 inphase),
 * their rms within 20 % of the configured one after many correlation times (tau 20 ms,
 * 3 s: the estimate's sd about sqrt(tau / t) = 8 %). */
static void test_softening_and_drift_wiring(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  c.fb_gap_m = 2e-6;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 5u), 0);
  const double ke = 4.0 * c.ks_fb_mps2_per_v2 * c.fb_bias_v * c.fb_bias_v / c.fb_gap_m;
  assert_true(fabs(p.mech.cfg.ke2_per_s2 / ke - 1.0) < 1e-15);
  assert_true(plant_fb_softening(&c) == p.mech.cfg.ke2_per_s2);
  c.fb_mode = 1;
  assert_true(plant_fb_softening(&c) == 0.0);
  plant_ideal_cfg(&c);
  c.quad_drift_dps = 10.0;
  c.inphase_drift_dps = 2.0;
  c.quad_drift_tau_s = c.inphase_drift_tau_s = 0.02;
  assert_int_equal(plant_init(&p, &c, 5u), 0);
  assert_true(p.mech.drift_kq_per_s2 == 0.0); /* starts at the configured values */
  double skq = 0.0, sdq = 0.0;
  int cnt = 0;
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  for (long k = 0; k < 150000; k++) {
    plant_step(&p, &fr, NULL);
    if (k % 50 == 0) {
      skq += p.mech.drift_kq_per_s2 * p.mech.drift_kq_per_s2;
      sdq += p.mech.drift_dq_per_s * p.mech.drift_dq_per_s;
      cnt++;
    }
  }
  const double kq = 2.0 * kTwoPi * c.f_drive_hz * c.quad_drift_dps * kDeg;
  const double dq = 2.0 * c.inphase_drift_dps * kDeg;
  print_message("drift: k_q rms %.4g (%.4g), d_q rms %.4g (%.4g)\n", sqrt(skq / cnt), kq,
                sqrt(sdq / cnt), dq);
  assert_true(fabs(sqrt(skq / cnt) / kq - 1.0) < 0.2);
  assert_true(fabs(sqrt(sdq / cnt) / dq - 1.0) < 0.2);
}

/* One reference for both converters: with white reference noise W the DAC's held levels
 * move by r = (held - ideal) / ideal of rms W sqrt(fs/2), the same r each sample for the
 * two drive channels; the ADC reads through the same r (test_adc: v / (1 + r)). */
static void test_shared_reference(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  c.vref_noise_white_rthz = 1e-6;
  static plant_t a, b;
  plant_cfg_t d;
  plant_ideal_cfg(&d);
  assert_int_equal(plant_init(&a, &d, 6u), 0);
  assert_int_equal(plant_init(&b, &c, 6u), 0);
  double s2 = 0.0;
  int cnt = 0;
  for (long k = 0; k < 20000; k++) {
    hal_dac_frame_t fr;
    drive_frame(k, c.fs_hz, &fr);
    plant_step(&a, &fr, NULL);
    plant_step(&b, &fr, NULL);
    const double *u0 = a.truth.dac_held_v, *u1 = b.truth.dac_held_v;
    if (fabs(u0[0]) > 1.0 && fabs(u0[1]) > 1.0) {
      const double r0 = u1[0] / u0[0] - 1.0, r1 = u1[1] / u0[1] - 1.0;
      assert_true(fabs(r0 - r1) < 1e-12 + 1e-9 * fabs(r0));
      assert_true(fabs(r0 - b.vref.rel) < 1e-12); /* the frame held this sample */
      s2 += r0 * r0;
      cnt++;
    }
  }
  const double want = 1e-6 * sqrt(c.fs_hz / 2.0);
  print_message("reference: r rms %.4e (W sqrt(fs/2) %.4e)\n", sqrt(s2 / cnt), want);
  assert_true(fabs(sqrt(s2 / cnt) / want - 1.0) < 0.05);
}

/* The ADC's aperture jitter is one timing error per frame for both channels: the
 * analog values at the ADC move by dt y' on each, so the ratio of the two channels'
 * differences to their slopes is the same dt; its rms on the drive channel is
 * 2 pi f A sigma / sqrt(2) (within 3 %). */
static void test_common_aperture_jitter(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  c.brownian = false;
  c.pick_drive_noise_v_rthz = c.pick_sense_noise_v_rthz = 0.0;
  c.drive_noise_white_v_rthz = c.drive_noise_1hz_v_rthz = 0.0;
  c.fb_noise_white_v_rthz = c.fb_noise_1hz_v_rthz = 0.0;
  static plant_t a, b;
  assert_int_equal(plant_init(&a, &c, 7u), 0);
  c.adc_aperture_jitter_s = 20e-9;
  assert_int_equal(plant_init(&b, &c, 7u), 0);
  const double T = 1.0 / c.fs_hz, w = kTwoPi * 1489.9;
  double s2 = 0.0, amp2 = 0.0, prev[2] = {0, 0};
  long cnt = 0, same = 0, both = 0;
  for (long k = 0; k < 60000; k++) {
    hal_dac_frame_t fr;
    drive_frame(k, c.fs_hz, &fr);
    plant_step(&a, &fr, NULL);
    plant_step(&b, &fr, NULL);
    const double d0 = b.truth.adc_v[0] - a.truth.adc_v[0];
    const double d1 = b.truth.adc_v[1] - a.truth.adc_v[1];
    /* slopes from the jitter-free run's samples (central difference one step late) */
    const double s0 = (a.truth.adc_v[0] - prev[0]) / T, s1 = (a.truth.adc_v[1] - prev[1]) / T;
    prev[0] = a.truth.adc_v[0];
    prev[1] = a.truth.adc_v[1];
    if (k < 20000) continue;
    s2 += d0 * d0;
    amp2 += 2.0 * a.truth.adc_v[0] * a.truth.adc_v[0];
    cnt++;
    if (fabs(s0) > 0.5 * w * 0.3 && fabs(s1) > 0.5 * w * 0.5) {
      both++;
      same += (d0 / s0 > 0.0) == (d1 / s1 > 0.0);
    }
  }
  const double want = w * sqrt(amp2 / cnt) * 20e-9 / sqrt(2.0);
  print_message("aperture jitter: drive %.4e V rms (%.4e), same sign on both channels %ld of %ld\n",
                sqrt(s2 / cnt), want, same, both);
  assert_true(fabs(sqrt(s2 / cnt) / want - 1.0) < 0.03);
  assert_true(both > 1000 && same > 0.95 * both);
}

/* A half-sine shock of 100 g, 0.1 ms along the drive axis (velocity change
 * 2 peak g0 dur / pi = 0.0624 m/s) leaves the free drive mode (Q 1e5, at rest, no drive)
 * ringing at (dv / wn) cos(wn dur / 2) / (1 - (wn dur / pi)^2) (the half-sine's spectrum
 * at wn, Harris & Piersol ch. 8) times the held means' sinc^2(wn T / 2) = 0.9971
 * (dac.h): within 0.3 %. The acceleration truth holds the pulse's per-sample means. */
static void test_shock_response(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  c.brownian = false;
  c.q_drive = 1e5;
  c.drive_noise_white_v_rthz = c.drive_noise_1hz_v_rthz = 0.0;
  c.fb_noise_white_v_rthz = c.fb_noise_1hz_v_rthz = 0.0;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 8u), 0);
  plant_profiles_t pr = p.prof;
  pr.accel_g.n_shocks = 1;
  pr.accel_g.shock_axis[0] = 0;
  pr.accel_g.shock_t_s[0] = 0.01;
  pr.accel_g.shock_peak_g[0] = 100.0;
  pr.accel_g.shock_dur_s[0] = 1e-4;
  assert_int_equal(plant_set_profiles(&p, &pr), 0);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  double sum_a = 0.0;
  for (long k = 0; k < 1000; k++) {
    plant_step(&p, &fr, NULL);
    sum_a += p.truth.accel_g[0] / c.fs_hz;
  }
  const double dv = 2.0 * 100.0 * ACCEL_G0_MPS2 * 1e-4 / (0.5 * kTwoPi);
  assert_true(fabs(sum_a * ACCEL_G0_MPS2 / dv - 1.0) < 1e-12);
  const double wn = p.truth.wn_drive_rad_s, x = 0.5 * wn / c.fs_hz;
  const double sinc = sin(x) / x;
  const double want = dv / wn * cos(0.5 * wn * 1e-4) /
                      (1.0 - pow(wn * 1e-4 / (0.5 * kTwoPi), 2)) * sinc * sinc;
  const double amp = hypot(p.truth.y_m, p.truth.vy_mps / wn);
  print_message("shock: drive rings at %.5e m (half-sine spectrum %.5e m)\n", amp, want);
  assert_true(fabs(amp / want - 1.0) < 3e-3);
}

/* Random vibration through the acceleration truth: rms sqrt of the band's design
 * variance (test_vib) on its axis; a band beyond 0.45 fs and a bad shock are refused by
 * plant_set_profiles with the profiles unchanged. */
static void test_random_vibration_and_refusals(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 9u), 0);
  plant_profiles_t pr = p.prof;
  pr.accel_g.n_bands = 1;
  pr.accel_g.band_axis[0] = 1;
  pr.accel_g.band_psd_g2_per_hz[0] = 1e-6;
  pr.accel_g.band_f_lo_hz[0] = 20.0;
  pr.accel_g.band_f_hi_hz[0] = 500.0;
  assert_int_equal(plant_set_profiles(&p, &pr), 0);
  assert_true(p.vib_on && p.accel_any && !p.accel_dynamic);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  double s2 = 0.0;
  const long n = 200000;
  for (long k = 0; k < n; k++) {
    plant_step(&p, &fr, NULL);
    assert_true(p.truth.accel_g[0] == 0.0 && p.truth.accel_g[2] == 0.0);
    if (k >= 10000) s2 += p.truth.accel_g[1] * p.truth.accel_g[1];
  }
  double design = 0.0;
  for (double f = 0.125; f < 25000.0; f += 0.25)
    design += vib_band_psd(&p.vib, 0, c.fs_hz, f) * 0.25;
  const double rms = sqrt(s2 / (double)(n - 10000));
  print_message("random vibration: %.4e g rms (design %.4e)\n", rms, sqrt(design));
  assert_true(fabs(rms / sqrt(design) - 1.0) < 0.05);
  const plant_profiles_t before = p.prof;
  plant_profiles_t bad = pr;
  bad.accel_g.band_f_hi_hz[0] = 0.45 * c.fs_hz;
  assert_int_equal(plant_set_profiles(&p, &bad), -1);
  assert_non_null(strstr(plant_error(&p), "band_f_hi_hz[0]"));
  bad = pr;
  bad.accel_g.n_shocks = 1;
  bad.accel_g.shock_dur_s[0] = -1.0;
  assert_int_equal(plant_set_profiles(&p, &bad), -1);
  assert_non_null(strstr(plant_error(&p), "shock_dur_s[0]"));
  assert_memory_equal(&p.prof, &before, sizeof before);
}

/* The truth's drive Q follows the law at the structure temperature (the figure
 * selfcal_true_q of gyro-sim is its mean over the sweep); the constant law keeps it. */
static void test_truth_q(void **state)
{
  (void)state;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 10u), 0);
  assert_true(plant_truth(&p)->q_drive == c.q_drive);
  c.q_temp_law = QLAW_GAS;
  c.temp_k = 358.15;
  assert_int_equal(plant_init(&p, &c, 10u), 0);
  run(&p, 100, NULL);
  const plant_truth_t *t = plant_truth(&p);
  const double r = 1.0 - 0.5 * c.ket_per_k * (t->struct_k - c.temp_ref_k);
  const double want = c.q_drive * qlaw_factor(QLAW_GAS, t->struct_k, c.temp_ref_k, r, NULL);
  print_message("gas damping at %.2f K: Q %.4f (33.33 at 25 degC)\n", t->struct_k, t->q_drive);
  assert_true(fabs(t->q_drive / want - 1.0) < 1e-14);
  assert_true(t->q_drive < 0.9 * c.q_drive);
}

/* Every law holds over -40..85 degC ambient with the effects on; outside its range a law
 * is counted (each thermal update), never refused: the thermoelastic law below 200 K, the
 * cubic spring beyond |k3/k| y^2 = 0.1, the capacitive pickoff beyond |x| = 0.3 gap. */
static void test_law_warnings(void **state)
{
  (void)state;
  static plant_t p;
  plant_cfg_t c;
  const double ambients[2] = {233.15, 358.15};
  for (int law = QLAW_GAS; law <= QLAW_TED; law++)
    for (int i = 0; i < 2; i++) {
      plant_ideal_cfg(&c);
      c.temp_k = ambients[i];
      c.q_temp_law = law;
      c.k3_drive_per_m2 = 1e8;
      c.pick_drive_gap_m = 100e-6;
      c.pick_sense_gap_m = 2e-6;
      assert_int_equal(plant_init(&p, &c, 11u), 0);
      run(&p, 5000, NULL);
      assert_true(plant_warning_total(&p) == 0);
    }
  plant_ideal_cfg(&c);
  c.temp_k = 150.0;
  c.q_temp_law = QLAW_TED;
  assert_int_equal(plant_init(&p, &c, 11u), 0);
  run(&p, 500, NULL); /* 10 ms: 10 thermal updates */
  assert_true(plant_warnings(&p)[PLANT_LAW_Q_TEMP].count == 11);
  assert_string_equal(plant_law_name(PLANT_LAW_Q_TEMP), "q_temp");
  /* a free 10 um drive oscillation (Q 1e5, no drive: a strong cubic term would detune a
   * driven one) past the edge of each amplitude law: counted once per thermal update
   * from the first one after the start */
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  for (int which = 0; which < 2; which++) {
    plant_ideal_cfg(&c);
    c.q_drive = 1e5;
    if (which == 0) c.k3_drive_per_m2 = 4e9; /* 0.1 / 4e9: the edge at 5 um */
    else c.pick_drive_gap_m = 20e-6;         /* 0.3 gap = 6 um */
    assert_int_equal(plant_init(&p, &c, 11u), 0);
    const mech_state_t s0 = {10e-6, 0.0, 0.0, 0.0};
    mech_set_state(&p.mech, &s0);
    for (long k = 0; k < 5000; k++) plant_step(&p, &fr, NULL); /* 100 thermal updates */
    const plant_law_t law = which == 0 ? PLANT_LAW_DUFFING_DRIVE : PLANT_LAW_PICK_DRIVE_GAP;
    const plant_warning_t *w = plant_warnings(&p);
    print_message("%s: %llu warnings from %.4f s\n", plant_law_name(law),
                  (unsigned long long)w[law].count, w[law].first_t_s);
    assert_true(w[law].count == 99 && fabs(w[law].first_t_s - 1e-3) < 1e-12);
    assert_true(plant_warning_total(&p) == w[law].count);
  }
  assert_string_equal(plant_law_name(PLANT_LAW_DUFFING_DRIVE), "duffing_drive");
  assert_string_equal(plant_law_name(PLANT_LAW_PICK_SENSE_GAP), "pick_sense_gap");
  assert_null(plant_law_name(PLANT_LAWS));
}

/* Cross-field limits of the imperfections: refused by plant_cfg_check and plant_init,
 * naming the parameter, the plant unchanged: the aperture jitter beyond T/20 (the first
 * order of pickoff_step_at), and the feedback bias's softening at half the sense
 * stiffness (pull-in). (The 1/f floors' fs/1000 limits cannot bind within their ranges.) */
static void test_cross_checks(void **state)
{
  (void)state;
  static plant_t p, before;
  plant_cfg_t c;
  plant_ideal_cfg(&c);
  assert_int_equal(plant_init(&p, &c, 12u), 0);
  before = p;
  struct {
    const char *key, *on;
    double v, on_v;
  } cases[] = {{"adc_aperture_jitter_s", NULL, 1.01e-6, 0.0}, /* T/20 = 1 us */
               {"fb_gap_m", "fb_bias_v", 1e-7, 100.0}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    plant_cfg_t b = c;
    char err[200];
    assert_int_equal(plant_param_set(&b, cases[i].key, cases[i].v, err, sizeof err), 0);
    if (cases[i].on != NULL) {
      assert_int_equal(plant_cfg_check(&b, err, sizeof err), 0); /* fine while off */
      assert_int_equal(plant_param_set(&b, cases[i].on, cases[i].on_v, err, sizeof err), 0);
    }
    assert_int_equal(plant_cfg_check(&b, err, sizeof err), -1);
    print_message("%s\n", err);
    assert_non_null(strstr(err, cases[i].key));
    assert_int_equal(plant_init(&p, &b, 12u), -1);
    assert_non_null(strstr(plant_error(&p), cases[i].key));
    assert_memory_equal(&p, &before, offsetof(plant_t, err));
  }
}


/* ------------------------------------------------------------ sense electrodes -- */

/* The ideal part without Brownian noise (the truth's motion is then the response alone),
 * sense Q q2; the electrodes' voltage noise stays at its default. */
static void electrode_part(plant_cfg_t *c, double q2)
{
  plant_ideal_cfg(c);
  c->brownian = false;
  c->q_sense = q2;
}

/* Standard deviation of one nulling electrode's voltage noise at a sample, stationary
 * bound (flicker.h): W^2 fs / 2 of the white floor plus K^2 ln(fc / fmin) of the 1/f
 * part up to its corner fc = (K / W)^2. */
static double electrode_noise_sd_v(const plant_cfg_t *c)
{
  const double w = c->quadnull_noise_white_v_rthz, k = c->quadnull_noise_1hz_v_rthz;
  const double fc = (k / w) * (k / w);
  return sqrt(w * w * c->fs_hz / 2.0 + k * k * log(fc / c->quadnull_noise_fmin_hz));
}

/* Quadrature nulling: on a part with nulling electrodes of c = 20 (deg/s)/V^2, the
 * voltage pair V1 = 0, V2 = sqrt(quad_dps / c) = 8.660 V cancels the 1500 deg/s of k_q
 * (exactly with the electrodes' voltage noise off; with it on, the noise w moves the
 * coupling by 2 w / V: held within 4 sd of w, electrode_noise_sd_v), and
 * the sense motion in phase with the drive displacement (the truth's sense_disp_m) falls
 * to within 1e-4 of its value without the voltages (0.15 deg/s), once
 * rebased (the second thermal update, mech.h); the Coriolis-direction motion is not
 * touched (no rate: both within 1e-4 of the quadrature's). Without voltages the truth
 * gives the configured quadrature at the structure's temperature and the drive frequency
 * (1500 s^2 f_drive_hz / drive_freq_hz, s = wn1(T) / wn1(T0): the part self-heats by about
 * 1 K). The voltage is computed at T0, so 1500 (1 - s^2) = 0.08 deg/s stays: quad_true_dps
 * within 0.1 deg/s of 0, the motion within 1e-4 of the open one.
 * The same electrodes with an overlap l0/d = 5 soften the sense spring by
 * 2 c (l0/d) (V1^2 + V2^2), which the truth's sense_freq_hz shows. */
static void test_quadrature_nulling(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c, 3.0);
  c.quadnull_dps_per_v2 = 20.0;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 21u), 0);
  run(&p, 15000, NULL);
  const plant_truth_t *t = plant_truth(&p);
  const double open_disp = t->sense_disp_m, open_quad = t->quad_true_dps;
  print_message("without voltages: quad_true_dps %.4f (drive at %.4f Hz), sense_disp %.4e m\n",
                open_quad, t->drive_freq_hz, open_disp);
  const double s = t->wn_drive_rad_s / (kTwoPi * c.f_drive_hz); /* (2-32) at the structure */
  assert_true(fabs(open_quad / (1500.0 * s * s * c.f_drive_hz / t->drive_freq_hz) - 1.0) < 1e-9);
  const double v2 = sqrt(c.quad_dps / c.quadnull_dps_per_v2);
  const plant_electrodes_t e = {0.0, 0.0, 0.0, v2, 0.0};
  const double law = 1500.0 * (s * s - 1.0) * c.f_drive_hz / t->drive_freq_hz;
  /* the law, with the voltage noise off */
  plant_cfg_t quiet = c;
  quiet.quadnull_noise_white_v_rthz = quiet.quadnull_noise_1hz_v_rthz = 0.0;
  assert_int_equal(plant_init(&p, &quiet, 21u), 0);
  assert_int_equal(plant_set_electrodes(&p, &e), 0);
  run(&p, 15000, NULL);
  print_message("V2 = %.4f V, no voltage noise: quad_true_dps %.5f (law %.5f)\n", v2,
                t->quad_true_dps, law);
  assert_true(fabs(t->quad_true_dps - law) < 1e-3);
  /* with it: 2 w / V of the 1500 deg/s */
  assert_int_equal(plant_init(&p, &c, 21u), 0);
  assert_int_equal(plant_set_electrodes(&p, &e), 0);
  run(&p, 15000, NULL);
  const double sd_dps = 1500.0 * 2.0 * electrode_noise_sd_v(&c) / v2;
  print_message("V2 = %.4f V: quad_true_dps %.5f (%.1f sd of the noise from the law), "
                "sense_disp %.4e m (%.2e of it), sense_vel %.4e m\n",
                v2, t->quad_true_dps, (t->quad_true_dps - law) / sd_dps, t->sense_disp_m,
                t->sense_disp_m / open_disp, t->sense_vel_m);
  assert_true(fabs(t->quad_true_dps - law) < 4.0 * sd_dps);
  assert_true(fabs(t->sense_disp_m) < 1e-4 * fabs(open_disp));
  assert_true(fabs(t->sense_vel_m) < 1e-4 * fabs(open_disp));
  assert_true(t->elec_v.quadnull_v2_v == v2);
  assert_true(t->sense_shift_hz == 0.0); /* no overlap given: no softening */
  /* their softening with an overlap */
  c.quadnull_overlap_per_gap = 5.0;
  assert_int_equal(plant_init(&p, &c, 21u), 0);
  assert_int_equal(plant_set_electrodes(&p, &e), 0);
  run(&p, 500, NULL);
  const double cq = 2.0 * kTwoPi * c.f_drive_hz * c.quadnull_dps_per_v2 * kDeg;
  const double w2 = kTwoPi * c.f_sense_hz * s, ke = 2.0 * cq * 5.0 * v2 * v2;
  const double want = sqrt(w2 * w2 - ke) / kTwoPi;
  print_message("overlap/gap 5: sense resonance %.4f Hz (law %.4f Hz, shift %.3f Hz)\n",
                t->sense_freq_hz, want, t->sense_shift_hz);
  /* k_e goes as V^2 and f as its root: the noise moves f by (ke / w2^2) w / V, 4 sd */
  const double f_sd = ke / (w2 * w2 - ke) * electrode_noise_sd_v(&c) / v2;
  assert_true(fabs(t->sense_freq_hz / want - 1.0) < 4.0 * f_sd + 1e-9);
  assert_true(fabs(t->sense_shift_hz / (want - w2 / kTwoPi) - 1.0) < 1e-3);
}

/* Upward zero crossings of the truth's sense displacement over n samples with the DAC at
 * mid-scale (no drive): the free sense oscillation's frequency. */
static double sense_ring_hz(plant_t *p, long n)
{
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  const mech_state_t s0 = {0.0, 0.0, 1e-7, 0.0};
  mech_set_state(&p->mech, &s0);
  double prev = 1e-7, t_first = -1.0, t_last = 0.0;
  long crossings = 0;
  for (long k = 0; k < n; k++) {
    plant_step(p, &fr, NULL);
    const double x = plant_truth(p)->x_m, tk = plant_truth(p)->t_s;
    if (prev < 0.0 && x >= 0.0) {
      const double tc = tk - p->T * x / (x - prev);
      if (t_first < 0.0) t_first = tc;
      t_last = tc;
      crossings++;
    }
    prev = x;
  }
  assert_true(crossings > 10);
  return (double)(crossings - 1) / (t_last - t_first);
}

/* Frequency tuning: Vt = 4 V on electrodes of k_e/m = 1e6 (1/s^2)/V^2 softens the sense
 * spring by 1.6e7 1/s^2, 10 % of it: the sense mode rings at sqrt(wn2^2 - k_e) (times
 * sqrt(1 - 1/(4 Q^2)) for Q = 1000) within 2e-5 (the crossings' timing over 90 cycles,
 * the voltage noise's 1e-6), and the truth's sense_freq_hz and sense_shift_hz give the
 * law within 1e-6; the resonances at the structure temperature (the part self-heats by about
 * 1 K: (2-32)). The drive resonance is not moved. */
static void test_tuning_moves_sense(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c, 1000.0);
  c.tune_ke_per_s2_per_v2 = 1e6;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 22u), 0);
  const double f0 = sense_ring_hz(&p, 2500);
  const plant_electrodes_t e = {0.0, 0.0, 0.0, 0.0, 4.0};
  assert_int_equal(plant_set_electrodes(&p, &e), 0);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  for (int k = 0; k < 150; k++) plant_step(&p, &fr, NULL); /* rebased at 2 ms */
  const double f1 = sense_ring_hz(&p, 2500);
  const plant_truth_t *t = plant_truth(&p);
  const double s = t->wn_drive_rad_s / (kTwoPi * c.f_drive_hz); /* (2-32) at the structure */
  const double w2 = kTwoPi * c.f_sense_hz * s, ke = 1e6 * 16.0, damp = sqrt(1.0 - 0.25e-6);
  const double want = sqrt(w2 * w2 - ke) / kTwoPi;
  print_message("Vt 0: rings at %.4f Hz (law %.4f); Vt 4 V: %.4f Hz (law %.4f), truth %.4f Hz, "
                "shift %.3f Hz\n",
                f0, w2 / kTwoPi * damp, f1, want * damp, t->sense_freq_hz, t->sense_shift_hz);
  assert_true(fabs(f0 / (w2 / kTwoPi * damp) - 1.0) < 2e-5);
  assert_true(fabs(f1 / (want * damp) - 1.0) < 2e-5);
  assert_true(fabs(t->sense_freq_hz / want - 1.0) < 1e-6);
  assert_true(fabs(t->sense_shift_hz / (want - w2 / kTwoPi) - 1.0) < 1e-4);
  assert_true(t->wn_drive_rad_s == kTwoPi * c.f_drive_hz * s); /* not moved by the tuning */
  assert_true(p.mech.refresh_count >= 1);                      /* rebased into the generator */
}

/* Half-frequency feedback through the plant (fb_mode 3): U3 = A cos(wc t/2 + p),
 * U4 = A sin(wc t/2 + p), written every sample at its middle (the held levels of the
 * electrode input), give the sense force ks_fb A^2 cos(wc t + 2p) at the drive frequency,
 * per sample exactly (noise off): fitted amplitude within 1e-9, phase 2p within 1e-9 rad,
 * no static part. The fb electrodes' noise on then moves it by its own size only. In
 * fb_mode 2 the pair's voltages reach nothing: bit for bit the run without them. */
static void test_half_frequency_feedback(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c, 3.0);
  c.fb_mode = 3;
  c.fb_noise_white_v_rthz = c.fb_noise_1hz_v_rthz = 0.0;
  static plant_t p;
  assert_int_equal(plant_init(&p, &c, 23u), 0);
  const double f = c.f_drive_hz, A = 6.0, ph = 0.4, T = p.T;
  enum { N = 5000 };
  double *fx = malloc(sizeof(double) * N);
  assert_non_null(fx);
  for (long k = 0; k < N; k++) {
    const double tm = ((double)k + 0.5) * T, th = 0.5 * kTwoPi * f * tm + ph;
    const plant_electrodes_t e = {A * cos(th), A * sin(th), 0.0, 0.0, 0.0};
    assert_int_equal(plant_set_electrodes(&p, &e), 0);
    run(&p, 1, NULL);
    fx[k] = plant_truth(&p)->f_sense_mps2;
  }
  double coef[3];
  ref_sine_fit(fx, N, 0.5 * T, T, &f, 1, coef);
  const double amp = hypot(coef[1], coef[2]), phase = atan2(-coef[2], coef[1]);
  const double want = c.ks_fb_mps2_per_v2 * A * A;
  print_message("half-frequency feedback, %.1f V: sense force %.9f m/s^2 at %.1f Hz (law "
                "%.9f), phase %.9f rad (2p = %.9f), static %.2e\n",
                A, amp, f, want, phase, 2.0 * ph, coef[0]);
  assert_true(fabs(amp / want - 1.0) < 1e-9);
  assert_true(fabs(phase - 2.0 * ph) < 1e-9);
  assert_true(fabs(coef[0]) < 1e-9 * want);
  free(fx);
  /* fb_mode 2: the pair's voltages are not connected */
  plant_ideal_cfg(&c);
  static plant_t a, b;
  assert_int_equal(plant_init(&a, &c, 24u), 0);
  assert_int_equal(plant_init(&b, &c, 24u), 0);
  const plant_electrodes_t e = {7.0, -7.0, 0.0, 0.0, 0.0};
  assert_int_equal(plant_set_electrodes(&b, &e), 0);
  run(&a, 2000, NULL);
  run(&b, 2000, NULL);
  assert_memory_equal(&a.mech.z, &b.mech.z, sizeof a.mech.z);
  assert_memory_equal(&a.truth.adc, &b.truth.adc, sizeof a.truth.adc);
}

/* Matching (plant_sense_match): on the default part with tuning electrodes of 1e6
 * (1/s^2)/V^2 the sense resonance (2000 Hz) is brought to the drive's (1489.9 Hz) by
 * sqrt((wn2^2 - wn1^2) / 1e6) = 8.385 V, which the plant confirms (the truth's
 * sense_freq_hz within 1e-6 of the drive resonance), also at 85 degC and for a 110 Hz
 * split; a part whose sense mode (1400 Hz) is below its drive is reported unmatched, and
 * so are a part without tuning electrodes, a move past the pull-in margin and a voltage
 * beyond 100 V; bad arguments are refused. */
static void test_sense_match(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c, 3.0);
  c.tune_ke_per_s2_per_v2 = 1e6;
  c.tune_noise_white_v_rthz = c.tune_noise_1hz_v_rthz = 0.0; /* the law alone */
  plant_match_t m;
  static plant_t p;
  const double temps[2] = {298.15, 358.15}, splits[2] = {0.0, 110.0};
  for (int i = 0; i < 2; i++) {
    c.temp_k = temps[i];
    assert_int_equal(plant_init(&p, &c, 25u), 0);
    /* at the structure's temperature (self-heated above the ambient) */
    assert_int_equal(plant_sense_match(&c, plant_truth(&p)->struct_k, splits[i], 0.0, &m), 0);
    print_message("%s\n", m.msg);
    assert_true(m.reachable == 1 && m.tune_v > 0.0);
    const plant_electrodes_t e = {0.0, 0.0, 0.0, 0.0, m.tune_v};
    assert_int_equal(plant_set_electrodes(&p, &e), 0);
    run(&p, 200, NULL);
    const double f_drive = plant_truth(&p)->wn_drive_rad_s / kTwoPi;
    print_message("  plant: sense %.6f Hz, drive resonance %.6f Hz + %.0f Hz\n",
                  plant_truth(&p)->sense_freq_hz, f_drive, splits[i]);
    assert_true(fabs(plant_truth(&p)->sense_freq_hz / (f_drive + splits[i]) - 1.0) < 1e-6);
  }
  const double w1 = kTwoPi * c.f_drive_hz, w2 = kTwoPi * c.f_sense_hz;
  assert_int_equal(plant_sense_match(&c, c.temp_ref_k, 0.0, 0.0, &m), 0);
  assert_true(fabs(m.tune_v / sqrt((w2 * w2 - w1 * w1) / 1e6) - 1.0) < 1e-12);
  /* sense below drive */
  c.f_sense_hz = 1400.0;
  assert_int_equal(plant_sense_match(&c, c.temp_ref_k, 0.0, 0.0, &m), 1);
  print_message("%s\n", m.msg);
  assert_true(m.reachable == 0 && m.tune_v == 0.0);
  assert_non_null(strstr(m.msg, "cannot be matched"));
  /* no tuning electrodes; past the pull-in margin; beyond 100 V */
  electrode_part(&c, 3.0);
  assert_int_equal(plant_sense_match(&c, c.temp_ref_k, 0.0, 0.0, &m), 1);
  assert_non_null(strstr(m.msg, "no tuning electrodes"));
  c.tune_ke_per_s2_per_v2 = 1e6;
  c.f_sense_hz = 3000.0;
  assert_int_equal(plant_sense_match(&c, c.temp_ref_k, 0.0, 0.0, &m), 1);
  assert_non_null(strstr(m.msg, "pull-in"));
  c.f_sense_hz = 2000.0;
  c.tune_ke_per_s2_per_v2 = 1.0;
  assert_int_equal(plant_sense_match(&c, c.temp_ref_k, 0.0, 0.0, &m), 1);
  assert_non_null(strstr(m.msg, "beyond 100 V"));
  print_message("%s\n", m.msg);
  assert_int_equal(plant_sense_match(&c, NAN, 0.0, 0.0, &m), -1);
  assert_int_equal(plant_sense_match(&c, 300.0, -2000.0, 0.0, &m), -1);
  assert_int_equal(plant_sense_match(&c, 300.0, 0.0, -1.0, &m), -1);
  c.fb_mode = 9;
  assert_int_equal(plant_sense_match(&c, 300.0, 0.0, 0.0, &m), -1);
  assert_non_null(strstr(m.msg, "fb_mode"));
}

/* Refusals: an electrode voltage not finite or beyond 100 V (the plant unchanged, the key
 * named); the new parameters out of range (cfg unchanged). A tuning voltage past the pull-in margin is held there and counted as
 * sense_pull_in once per thermal update. */
static void test_electrode_refusals(void **state)
{
  (void)state;
  plant_cfg_t c;
  electrode_part(&c, 3.0);
  c.tune_ke_per_s2_per_v2 = 1e6;
  static plant_t p, before;
  assert_int_equal(plant_init(&p, &c, 26u), 0);
  before = p;
  const plant_electrodes_t bad[2] = {{0.0, 0.0, NAN, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0, -100.5}};
  for (int i = 0; i < 2; i++) {
    assert_int_equal(plant_set_electrodes(&p, &bad[i]), -1);
    print_message("%s\n", plant_error(&p));
    assert_non_null(strstr(plant_error(&p), i == 0 ? "quadnull_v1_v" : "tune_v"));
    assert_memory_equal(&p, &before, offsetof(plant_t, err));
  }
  const struct {
    const char *key;
    double v;
  } params[] = {{"quadnull_dps_per_v2", -1.0},
                {"quadnull_overlap_per_gap", 2e3},
                {"tune_ke_per_s2_per_v2", NAN},
                {"tune_noise_white_v_rthz", 1.0},
                {"fb_mode", 4.0}};
  for (size_t i = 0; i < sizeof params / sizeof params[0]; i++) {
    plant_cfg_t b = c;
    char err[200];
    assert_int_equal(plant_param_set(&b, params[i].key, params[i].v, err, sizeof err), -1);
    assert_non_null(strstr(err, params[i].key));
    assert_memory_equal(&b, &c, sizeof b);
  }
  /* pull-in: 10 V gives 1e8 1/s^2, beyond half of the 1.58e8 stiffness */
  const plant_electrodes_t e = {0.0, 0.0, 0.0, 0.0, 10.0};
  assert_int_equal(plant_set_electrodes(&p, &e), 0);
  hal_dac_frame_t fr;
  hal_dac_frame_midscale(&fr);
  for (long k = 0; k < 500; k++) plant_step(&p, &fr, NULL);
  const plant_warning_t *w = plant_warnings(&p);
  print_message("sense_pull_in: %llu from %.4f s; sense resonance %.2f Hz (about 2000 / sqrt 2 "
                "= %.2f)\n",
                (unsigned long long)w[PLANT_LAW_SENSE_PULL_IN].count,
                w[PLANT_LAW_SENSE_PULL_IN].first_t_s, plant_truth(&p)->sense_freq_hz,
                2000.0 / sqrt(2.0));
  assert_true(w[PLANT_LAW_SENSE_PULL_IN].count == 9);
  /* held at half the stiffness at T0, wn2(T)^2 - wn2(T0)^2 / 2 (the structure self-heats) */
  const double s = plant_truth(&p)->wn_drive_rad_s / (kTwoPi * c.f_drive_hz);
  const double w2 = kTwoPi * c.f_sense_hz;
  const double want = sqrt(w2 * w2 * s * s - 0.5 * w2 * w2) / kTwoPi;
  assert_true(fabs(plant_truth(&p)->sense_freq_hz / want - 1.0) < 1e-12);
  assert_string_equal(plant_law_name(PLANT_LAW_SENSE_PULL_IN), "sense_pull_in");
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_off_by_default),
      cmocka_unit_test(test_each_switch_acts),
      cmocka_unit_test(test_softening_and_drift_wiring),
      cmocka_unit_test(test_shared_reference),
      cmocka_unit_test(test_common_aperture_jitter),
      cmocka_unit_test(test_shock_response),
      cmocka_unit_test(test_random_vibration_and_refusals),
      cmocka_unit_test(test_truth_q),
      cmocka_unit_test(test_law_warnings),
      cmocka_unit_test(test_cross_checks),
      cmocka_unit_test(test_quadrature_nulling),
      cmocka_unit_test(test_tuning_moves_sense),
      cmocka_unit_test(test_half_frequency_feedback),
      cmocka_unit_test(test_sense_match),
      cmocka_unit_test(test_electrode_refusals),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
