/* The lost-match monitor's study (gyro/sense_tune.h, issue 19 item 5): on the matched
 * part of test_cl_sense_tune.c (sense Q 1e4, tuned by the sweep, calibrated as the flow
 * would), the plant's sense resonance moved by known amounts after tuning (the tuning
 * electrodes' gain, one of the law's unknowns, changed in the plant: the law's voltage
 * stays), and for each
 *   - the continuous test's two tones' ratio (quadrature over rate, from the LMS weights
 *     sampled every millisecond over 3 s) and its spread over 0.1 s means: the raw signal
 *     per Hz of detuning and its noise;
 *   - the monitor's reading (status tune_detune_hz) and its verdict;
 *   - the 0 -> 100 deg/s step's settling to 1 % (what the detuning does to the loop);
 * then the same on a part with the default part's noise sources (Brownian, pickoff and
 * electrode noise, feedthrough): the reading, and the rate's mean and noise at rest; and
 * the matched part's reading with the continuous test's tone at 150 and 500 Hz.
 * Figures, not goals: printed, with a loose check of the reading's slope. Label slow
 * (opt-in): ctest --test-dir build/host -L slow -R tune_disc_study (about 3 min). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "sense_tune_harness.h"

/* The electrodes' gain relative to the part's: the resonance moves by about -115 Hz per
 * unit (7.5 V on 2.4e5 (1/s^2)/V^2 at 1.49 kHz). */
static const double k_gains[] = {1.0, 1.002, 0.998, 1.005, 0.995, 1.01, 0.99, 1.02, 0.98, 1.1};
#define N_GAINS (sizeof k_gains / sizeof k_gains[0])

/* The two tones as phasors a - j b of the LMS weights (selftest.h) and their ratio. */
static void tone_ratio(const double w[4], double *re, double *im)
{
  const double rr = w[0], ri = -w[1], qr = w[2], qi = -w[3];
  const double m2 = rr * rr + ri * ri;
  *re = (qr * rr + qi * ri) / m2;
  *im = (qi * rr - qr * ri) / m2;
}

/* 3 s of the weights, every millisecond: the ratio of their mean, and the spread of the
 * ratio of 0.1 s means. Every millisecond is every fifth block, four phases of the 250 Hz
 * modulation evenly: the ripple the axes' DC puts on the weights (sense_tune.h) averages
 * out of these means (the monitor fits it out instead, whatever its sampling). */
static void ratio_over(double *re, double *im, double *sd_re, double *sd_im)
{
  double all[4] = {0.0, 0.0, 0.0, 0.0}, blk[4] = {0.0, 0.0, 0.0, 0.0};
  double s1[2] = {0.0, 0.0}, s2[2] = {0.0, 0.0};
  int nb = 0;
  for (int ms = 1; ms <= 3000; ms++) {
    hal_host_run(50u);
    app_poll(&app);
    for (int i = 0; i < 4; i++) {
      all[i] += (double)app.gyro.selftest.w[i] / 3000.0;
      blk[i] += (double)app.gyro.selftest.w[i] / 100.0;
    }
    if (ms % 100 == 0) {
      double x, y;
      tone_ratio(blk, &x, &y);
      s1[0] += x;
      s1[1] += y;
      s2[0] += x * x;
      s2[1] += y * y;
      nb++;
      memset(blk, 0, sizeof blk);
    }
  }
  tone_ratio(all, re, im);
  *sd_re = sqrt(fmax(s2[0] / nb - (s1[0] / nb) * (s1[0] / nb), 0.0));
  *sd_im = sqrt(fmax(s2[1] / nb - (s1[1] / nb) * (s1[1] / nb), 0.0));
}

static double detune_now(const plant_cfg_t *pc, double gain)
{
  plant_cfg_t p = *pc;
  p.tune_ke_per_s2_per_v2 = TUNE_KE * gain;
  plant.act.cfg.tune_ke_per_s2_per_v2 = p.tune_ke_per_s2_per_v2;
  return true_tuned_f(&p) - (double)app.gyro.out.f_drive_hz;
}

static void test_quiet_part(void **state)
{
  (void)state;
  const plant_cfg_t pc = part(SENSE_TEST_F_HZ, 1.0e4);
  matched_running(&pc);
  double det[N_GAINS], reading[N_GAINS], cr[N_GAINS], ci[N_GAINS];
  for (size_t i = 0; i < N_GAINS; i++) {
    (void)detune_now(&pc, k_gains[i]);
    app_plant_hold_rate(0.0);
    run_polled_s(1.5);
    det[i] = detune_now(&pc, k_gains[i]);
    double sr, si;
    ratio_over(&cr[i], &ci[i], &sr, &si);
    reading[i] = status_detune_hz();
    const uint32_t tune = app.gyro.out.rate_invalid & RATE_INVALID_TUNE;
    double fin = 0.0, rest = 0.0;
    const double settle_ms = sense_step_settle_ms(100.0, &fin, &rest);
    printf("# quiet: gain x%.3f: detuned %+.4f Hz; ratio %+.5f %+.5fj (0.1 s spread %.5f "
           "%.5f); the monitor reads %+.3f Hz, TUNE %s; 0 -> 100 deg/s to 1 %% in %.1f ms "
           "(step %.2f deg/s)\n",
           k_gains[i], det[i], cr[i], ci[i], sr, si, reading[i], tune != 0u ? "set" : "clear",
           settle_ms, fin - rest);
  }
  /* the raw ratio's and the reading's slopes over +-1 % (about +-1.1 Hz) */
  const double dd = det[5] - det[6];
  printf("# quiet: over %+.3f .. %+.3f Hz the ratio moves %+.5f %+.5fj per Hz, the reading "
         "%.3f Hz per Hz\n",
         det[6], det[5], (cr[5] - cr[6]) / dd, (ci[5] - ci[6]) / dd,
         (reading[5] - reading[6]) / dd);
  assert_true(fabs((reading[5] - reading[6]) / dd - 1.0) < 0.15);
}

static void test_noisy_part(void **state)
{
  (void)state;
  plant_cfg_t pc;
  sense_test_noisy_part(&pc, 1.0e4);
  pc.tune_ke_per_s2_per_v2 = TUNE_KE;
  matched_running(&pc);
  for (size_t i = 0; i < N_GAINS - 1u; i++) {
    (void)detune_now(&pc, k_gains[i]);
    app_plant_hold_rate(0.0);
    run_polled_s(1.5);
    const double det = detune_now(&pc, k_gains[i]);
    /* 4 s at rest: the rate's mean and the rms of its 10 ms means */
    double s1 = 0.0, s2 = 0.0;
    for (int b = 0; b < 400; b++) {
      double m = 0.0;
      for (int k = 0; k < 10; k++) {
        hal_host_run(50u);
        app_poll(&app);
        m += (double)app.gyro.out.rate_dps / 10.0;
      }
      s1 += m;
      s2 += m * m;
    }
    const double mean = s1 / 400.0;
    printf("# noisy: gain x%.3f: detuned %+.4f Hz; the monitor reads %+.3f Hz, TUNE %s; rate "
           "at rest %+.4f deg/s, rms of 10 ms means %.4f deg/s\n",
           k_gains[i], det, status_detune_hz(),
           (app.gyro.out.rate_invalid & RATE_INVALID_TUNE) != 0u ? "set" : "clear", mean,
           sqrt(fmax(s2 / 400.0 - mean * mean, 0.0)));
  }
}

/* The model behind c0 and u is the loop's above its band: how well it holds depends on
 * the tone's frequency (selftest.cont_freq_hz). The matched part at 150 and 500 Hz: the
 * monitor's reading, the continuous test's response against its expectation (the
 * simpler tone model, sense_fr_tone_gain), and the reasons the rate is not valid for. */
static void test_tone_frequency(void **state)
{
  (void)state;
  const plant_cfg_t pc = part(SENSE_TEST_F_HZ, 1.0e4);
  const double fm[2] = {150.0, 500.0};
  for (int i = 0; i < 2; i++) {
    matched_tuned(&pc, fm[i]);
    run_polled_s(2.0);
    const float *w = app.gyro.selftest.w_avg;
    printf("# tone %.0f Hz: detuned %+.4f Hz, the monitor reads %+.3f Hz; the test's "
           "response %.4g against %.4g expected; rate_invalid 0x%x\n",
           fm[i], true_tuned_f(&pc) - (double)app.gyro.out.f_drive_hz, status_detune_hz(),
           hypot((double)w[0], (double)w[1]), (double)app.gyro.design->selftest.cont_expect,
           app.gyro.out.rate_invalid);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_quiet_part),
      cmocka_unit_test(test_noisy_part),
      cmocka_unit_test(test_tone_frequency),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
