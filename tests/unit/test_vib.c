/* Random vibration bands (host_sim/plant/vib.h): the generated acceleration has the PSD
 * G (g^2/Hz) in its band and the variance of its design; bands add on their axes;
 * validation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/vib.h"
#include "psd_welch_ref.h"

/* Mean of the estimated PSD over [f_lo, f_hi] against G there. */
static double band_level(const double *psd, double fs, size_t nseg, double f_lo, double f_hi)
{
  double s = 0.0;
  int n = 0;
  for (size_t i = 1; i <= nseg / 2; i++) {
    const double f = (double)i * fs / (double)nseg;
    if (f >= f_lo && f <= f_hi) {
      s += psd[i];
      n++;
    }
  }
  assert_true(n > 0);
  return s / n;
}

/* G = 1e-3 g^2/Hz over 20-2000 Hz on the sense axis and 4e-4 g^2/Hz flat from DC to
 * 500 Hz on the drive axis, 50 kHz, 2^21 samples: the PSD within 0.5 dB of G between
 * sqrt(2) f_lo and f_hi / sqrt(2) (design 0.3 dB, estimate over ~1000 bins of 62
 * averaged segments well under 0.1 dB), 20 dB down an octave beyond f_hi (4th order:
 * 24 dB at 2 f_hi, 27 dB at 2.2 f_hi), and the variance within 2 % of G times the design's noise bandwidth (the
 * integral of vib_band_psd; the estimate's sd about 1 %); the normal axis untouched. */
static void test_band_psd_and_variance(void **state)
{
  (void)state;
  const double fs = 50000.0;
  accel_profile_t a;
  accel_profile_zero(&a);
  a.n_bands = 2;
  a.band_axis[0] = 1;
  a.band_psd_g2_per_hz[0] = 1e-3;
  a.band_f_lo_hz[0] = 20.0;
  a.band_f_hi_hz[0] = 2000.0;
  a.band_axis[1] = 0;
  a.band_psd_g2_per_hz[1] = 4e-4;
  a.band_f_lo_hz[1] = 0.0;
  a.band_f_hi_hz[1] = 500.0;
  assert_int_equal(accel_profile_check(&a, NULL), 0);
  static vib_t v;
  assert_int_equal(vib_init(&v, &a, fs, 3u), 0);
  const size_t n = 1u << 21, nseg = 1u << 16;
  double *x[2], *psd = malloc((nseg / 2 + 1) * sizeof *psd);
  x[0] = malloc(n * sizeof(double));
  x[1] = malloc(n * sizeof(double));
  assert_non_null(x[0]);
  assert_non_null(x[1]);
  assert_non_null(psd);
  for (size_t k = 0; k < 50000; k++) {
    double g[3] = {0.0, 0.0, 0.0};
    vib_step(&v, g);
  }
  for (size_t k = 0; k < n; k++) {
    double g[3] = {0.0, 0.0, 0.0};
    vib_step(&v, g);
    assert_true(g[2] == 0.0);
    x[0][k] = g[1]; /* band 0: sense */
    x[1][k] = g[0]; /* band 1: drive */
  }
  for (int j = 0; j < 2; j++) {
    assert_true(ref_psd_welch(x[j], n, fs, nseg, psd) > 10);
    const double lo = a.band_f_lo_hz[j] > 0.0 ? sqrt(2.0) * a.band_f_lo_hz[j] : 1.0;
    const double hi = a.band_f_hi_hz[j] / sqrt(2.0), G = a.band_psd_g2_per_hz[j];
    const double in_band = 10 * log10(band_level(psd, fs, nseg, lo, hi) / G);
    const double beyond = 10 * log10(band_level(psd, fs, nseg, 2.0 * a.band_f_hi_hz[j],
                                                2.2 * a.band_f_hi_hz[j]) /
                                     G);
    double var = 0.0, design = 0.0;
    for (size_t k = 0; k < n; k++) var += x[j][k] * x[j][k];
    var /= (double)n;
    const double df = 0.25;
    for (double f = 0.5 * df; f < 0.5 * fs; f += df) design += vib_band_psd(&v, j, fs, f) * df;
    print_message("band %d: in band %+.3f dB, an octave above %.1f dB, variance %.4e g^2 "
                  "(design %.4e, G (f_hi - f_lo) %.4e)\n",
                  j, in_band, beyond, var, design, G * (a.band_f_hi_hz[j] - a.band_f_lo_hz[j]));
    assert_true(fabs(in_band) < 0.5);
    assert_true(beyond < -20.0);
    assert_true(fabs(var / design - 1.0) < 0.02);
    assert_true(
        fabs(vib_band_psd(&v, j, fs, a.band_f_lo_hz[j] > 0 ? sqrt(20.0 * 2000.0) : 0.0) / G -
             1.0) < 1e-12);
  }
  free(x[0]);
  free(x[1]);
  free(psd);
}

/* A band must end below 0.45 fs; no band, nothing added and nothing drawn. */
static void test_check_and_off(void **state)
{
  (void)state;
  accel_profile_t a;
  accel_profile_zero(&a);
  static vib_t v, before;
  assert_int_equal(vib_init(&v, &a, 50000.0, 1u), 0);
  double g[3] = {0.5, -0.25, 1.0};
  vib_step(&v, g);
  assert_true(g[0] == 0.5 && g[1] == -0.25 && g[2] == 1.0);
  before = v;
  a.n_bands = 1;
  a.band_axis[0] = 2;
  a.band_psd_g2_per_hz[0] = 1e-4;
  a.band_f_hi_hz[0] = 22500.0;
  const char *key = NULL;
  assert_int_equal(vib_check(&a, 50000.0, &key), -1);
  assert_string_equal(key, "band_f_hi_hz[0]");
  assert_int_equal(vib_init(&v, &a, 50000.0, 1u), -1);
  assert_memory_equal(&v, &before, sizeof v);
  a.band_f_hi_hz[0] = 22499.0;
  assert_int_equal(vib_check(&a, 50000.0, &key), 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_band_psd_and_variance),
      cmocka_unit_test(test_check_and_off),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
