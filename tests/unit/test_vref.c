/* The converters' shared reference (host_sim/plant/vref.h): its relative noise has the
 * white level and the 1/f slope asked for; off at zero; bad specs refused. How the ADC
 * and DAC take it: test_adc, test_dac, test_plant. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/vref.h"
#include "psd_welch_ref.h"

/* White W = 1e-6 /rtHz and 1/f K = 1e-5 /rtHz at 1 Hz (corner 100 Hz), at fs = 5 kHz
 * (the generator's design is relative to fs and the corner; a low rate fits the decades
 * into a short run): the PSD's log-log slope over 0.5-5 Hz within 0.1 of the target's
 * (-0.98: the white floor is 1/20 of the 1/f part at 5 Hz), the level over 1-5 Hz and
 * the white level over 500-2000 Hz within 1 dB of W^2 + K^2 / f. */
static void test_white_and_flicker(void **state)
{
  (void)state;
  const double fs = 5000.0;
  const vref_cfg_t c = {{1e-6, 1e-5, 1e-3}};
  vref_t v;
  assert_int_equal(vref_init(&v, &c, fs, 3u), 0);
  assert_true(v.active);
  const size_t n = 1u << 20, nseg = 1u << 15;
  double *x = malloc(n * sizeof *x), *psd = malloc((nseg / 2 + 1) * sizeof *psd);
  assert_non_null(x);
  assert_non_null(psd);
  for (size_t k = 0; k < 100000; k++) (void)vref_step(&v);
  for (size_t k = 0; k < n; k++) {
    x[k] = vref_step(&v);
    assert_true(v.rel == x[k]);
  }
  assert_true(ref_psd_welch(x, n, fs, nseg, psd) > 10);
  double sx = 0, sy = 0, sxx = 0, sxy = 0, m_lo = 0, t_lo = 0, m_hi = 0, t_hi = 0;
  int cnt = 0;
  for (size_t i = 1; i <= nseg / 2; i++) {
    const double f = (double)i * fs / (double)nseg, target = flicker_target_psd(&c.noise, fs, f);
    if (f >= 0.5 && f <= 5.0) {
      sx += log10(f);
      sy += log10(psd[i]);
      sxx += log10(f) * log10(f);
      sxy += log10(f) * log10(psd[i]);
      cnt++;
    }
    if (f >= 1.0 && f <= 5.0) {
      m_lo += psd[i];
      t_lo += target;
    }
    if (f >= 500.0 && f <= 2000.0) {
      m_hi += psd[i];
      t_hi += target;
    }
  }
  const double slope = (cnt * sxy - sx * sy) / (cnt * sxx - sx * sx);
  const double t1 = flicker_target_psd(&c.noise, fs, 0.5),
               t2 = flicker_target_psd(&c.noise, fs, 5.0);
  const double target_slope = log10(t2 / t1); /* over one decade */
  print_message(
      "reference noise: slope %.3f (target %.3f), 1-5 Hz %+.2f dB, 500-2000 Hz %+.2f dB\n",
      slope, target_slope, 10 * log10(m_lo / t_lo), 10 * log10(m_hi / t_hi));
  assert_true(fabs(slope - target_slope) < 0.1);
  assert_true(fabs(10 * log10(m_lo / t_lo)) < 1.0);
  assert_true(fabs(10 * log10(m_hi / t_hi)) < 1.0);
  free(x);
  free(psd);
}

/* Off at zero: r = 0 every sample, nothing drawn. Bad specs refused, v unchanged. */
static void test_off_and_validation(void **state)
{
  (void)state;
  const vref_cfg_t off = {{0.0, 0.0, 1e-3}};
  static vref_t v, before;
  assert_int_equal(vref_init(&v, &off, 50000.0, 1u), 0);
  assert_false(v.active);
  const rng_t r0 = v.gen.rng;
  for (int k = 0; k < 100; k++) assert_true(vref_step(&v) == 0.0);
  assert_memory_equal(&v.gen.rng, &r0, sizeof r0);
  before = v;
  const vref_cfg_t bad[] = {{{-1e-6, 0.0, 1e-3}}, {{0.0, 1e-6, 100.0}}, {{NAN, 0.0, 1e-3}}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(vref_check(&bad[i], 50000.0), -1);
    assert_int_equal(vref_init(&v, &bad[i], 50000.0, 1u), -1);
    assert_memory_equal(&v, &before, sizeof v);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_white_and_flicker),
      cmocka_unit_test(test_off_and_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
