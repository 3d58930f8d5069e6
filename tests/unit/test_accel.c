#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <complex.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "plant/accel.h"
#include "plant/adc.h"
#include "plant/pickoff.h"
#include "sine_fit_ref.h"

static const double k_pi = 3.14159265358979323846;
#define T0_K 298.15
#define WN2 (2.0 * 3.14159265358979323846 * 2000.0) /* sense resonance (thesis §2.4.2) */
#define Q2 3.0

/* Forces are the coefficient-weighted sum of the three acceleration components. */
static void test_coefficients(void **state)
{
  (void)state;
  accel_cfg_t c;
  accel_default_cfg(&c);
  accel_t a;
  assert_int_equal(accel_init(&a, &c), 0);
  const double g[3] = {0.5, -2.0, 3.0};
  accel_out_t o;
  accel_step(&a, g, &o);
  assert_true(fabs(o.f_drive_mps2 + 0.5 * ACCEL_G0_MPS2) < 1e-12);
  assert_true(fabs(o.f_sense_mps2 - 2.0 * ACCEL_G0_MPS2) < 1e-12);
  const accel_cfg_t c2 = {{1.0, 2.0, 3.0}, {-4.0, 5.0, -6.0}};
  assert_int_equal(accel_init(&a, &c2), 0);
  accel_step(&a, g, &o);
  assert_true(fabs(o.f_drive_mps2 - (0.5 - 4.0 + 9.0)) < 1e-12);
  assert_true(fabs(o.f_sense_mps2 - (-2.0 - 10.0 - 18.0)) < 1e-12);
  const double bad_in[3] = {NAN, 0.0, 0.0};
  accel_step(&a, bad_in, &o);
  assert_true(o.f_drive_mps2 == 0.0 && o.f_sense_mps2 == 0.0);
  accel_t before = a;
  accel_cfg_t bad = c2;
  bad.sense_mps2_per_g[1] = INFINITY;
  assert_int_equal(accel_init(&a, &bad), -1);
  bad = c2;
  bad.drive_mps2_per_g[0] = 1e4;
  assert_int_equal(accel_init(&a, &bad), -1);
  assert_memory_equal(&a, &before, sizeof a);
}

typedef struct {
  uint64_t adc_clips, adc_clips_want, preamp_clips;
  double amp, amp_want;
} vib_result_t;

/* Sinusoidal vibration of ag g at f along the sense axis. The sense mode's steady
 * response to the accel force, x'' + (wn2/Q2) x' + wn2^2 x = f, is analytic; it goes
 * through the real sense pickoff (noise off) and ADC. Expected ADC input: gain x
 * filtered by the closed-form lag and band-pass, sampled 4 us after the tick. */
static vib_result_t vibrate(double ag, double f)
{
  accel_cfg_t acfg;
  accel_default_cfg(&acfg);
  accel_t acc;
  assert_int_equal(accel_init(&acc, &acfg), 0);
  pickoff_cfg_t pc;
  pickoff_default_cfg(&pc, PICKOFF_SENSE);
  pc.noise_v_rthz = 0.0;
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &pc, T0_K, 1u), 0);
  adc_cfg_t ac;
  adc_default_cfg(&ac);
  adc_t adc;
  assert_int_equal(adc_init(&adc, &ac), 0);

  const double T = 1.0 / pc.fs_hz, w = 2.0 * k_pi * f;
  /* force phasor for a(t) = ag sin(w t) along the sense axis: f = Re(F e^{jwt}) */
  const double g[3] = {0.0, ag, 0.0};
  accel_out_t fo;
  accel_step(&acc, g, &fo);
  const double complex F = fo.f_sense_mps2 * (-I);
  const double complex X = F / (WN2 * WN2 - w * w + I * w * WN2 / Q2);
  const double th = 1.0 / (2.0 * k_pi * pc.hp_hz), w0 = 2.0 * k_pi * pc.lp_hz;
  const double complex H = (1.0 /
                            (1.0 + I * w / (2.0 * k_pi * pc.lag_ref_hz) * tan(pc.phi0_rad))) *
                           (I * w * th / (1.0 + I * w * th)) *
                           (w0 * w0 / (w0 * w0 - w * w + I * w * w0 / pc.lp_q));
  const int warm = 2500, n = 25000;
  double *y = malloc((size_t)n * sizeof *y);
  assert_non_null(y);
  vib_result_t r = {0, 0, 0, 0.0, 0.0};
  for (int k = 0; k < warm + n; k++) {
    const double t = (double)(k + 1) * T;
    const double complex e = cexp(I * w * t);
    const double x = creal(X * e), v = creal(I * w * X * e);
    const double vin = pickoff_step(&p, x, v, NULL);
    const int16_t code = adc_convert(&adc, ADC_CH_SENSE, vin);
    if (k == warm - 1) {
      adc_clear_counts(&adc);
      p.preamp_clip_count = 0;
    }
    if (k >= warm) {
      y[k - warm] = adc_code_to_v(&adc, code);
      const double want = pc.gain_v_per_m * creal(X * H * cexp(I * w * (t + pc.sample_delay_s))) +
                          pc.offset_v;
      const double q = round(want * 32768.0 / 5.0);
      if (q > 32767.0 || q < -32768.0) r.adc_clips_want++;
    }
  }
  r.adc_clips = adc.clip_count[ADC_CH_SENSE];
  r.preamp_clips = p.preamp_clip_count;
  r.amp_want = pc.gain_v_per_m * cabs(X * H);
  double coef[3];
  ref_sine_fit(y, (size_t)n, (double)(warm + 1) * T, T, &f, 1, coef);
  r.amp = hypot(coef[1], coef[2]);
  free(y);
  return r;
}

/* §4.4.2: shaking can push the pickoff out of the ADC range. 0.2 g at 200 Hz fits (the
 * ADC sees the analytic amplitude); 2 g at 200 Hz drives the sense pickoff to ~6.9 V and
 * the ADC clips exactly where the analytic signal is beyond the last code; 5 g at 5 Hz
 * saturates the preamp (19 V unclipped) while the band-pass keeps the ADC in range. */
static void test_vibration_clips_adc(void **state)
{
  (void)state;
  vib_result_t r = vibrate(0.2, 200.0);
  print_message("0.2 g 200 Hz: ADC %.4f V (want %.4f), ADC clips %llu, preamp clips %llu\n",
                r.amp, r.amp_want, (unsigned long long)r.adc_clips,
                (unsigned long long)r.preamp_clips);
  assert_true(fabs(r.amp / r.amp_want - 1.0) < 1e-3);
  assert_int_equal(r.adc_clips, 0);
  assert_int_equal(r.preamp_clips, 0);

  r = vibrate(2.0, 200.0);
  print_message(
      "2 g 200 Hz: amplitude %.3f V wanted, ADC clips %llu (analytic %llu), preamp clips %llu\n",
      r.amp_want, (unsigned long long)r.adc_clips, (unsigned long long)r.adc_clips_want,
      (unsigned long long)r.preamp_clips);
  assert_true(r.amp_want > 5.0);
  assert_true(r.adc_clips > 1000);
  assert_true(llabs((long long)r.adc_clips - (long long)r.adc_clips_want) <= 2);
  assert_int_equal(r.preamp_clips, 0);

  r = vibrate(5.0, 5.0);
  print_message("5 g 5 Hz: ADC clips %llu, preamp clips %llu\n",
                (unsigned long long)r.adc_clips, (unsigned long long)r.preamp_clips);
  assert_true(r.preamp_clips > 1000);
  assert_int_equal(r.adc_clips, 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_coefficients),
      cmocka_unit_test(test_vibration_clips_adc),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
