#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "plant/flicker.h"
#include "psd_welch_ref.h"

/* Generate n samples after a warm-up and return their Welch PSD (caller frees both). */
static double *run_psd(const flicker_spec_t *spec, double fs, size_t warm, size_t n,
                       size_t nseg, uint64_t seed)
{
  flicker_t f;
  assert_int_equal(flicker_init(&f, spec, fs, seed, 1u), 0);
  for (size_t i = 0; i < warm; i++) (void)flicker_step(&f);
  double *x = malloc(n * sizeof *x);
  double *psd = malloc((nseg / 2 + 1) * sizeof *psd);
  assert_non_null(x);
  assert_non_null(psd);
  for (size_t i = 0; i < n; i++) x[i] = flicker_step(&f);
  assert_true(ref_psd_welch(x, n, fs, nseg, psd) > 0);
  free(x);
  return psd;
}

/* Measured / target PSD, each averaged over the bins in [f_lo, f_hi], in dB. */
static double band_error_db(const double *psd, const flicker_spec_t *spec, double fs,
                            size_t nseg, double f_lo, double f_hi)
{
  double m = 0.0, t = 0.0;
  int cnt = 0;
  for (size_t i = 1; i <= nseg / 2; i++) {
    const double f = (double)i * fs / (double)nseg;
    if (f < f_lo || f > f_hi) continue;
    m += psd[i];
    t += flicker_target_psd(spec, fs, f);
    cnt++;
  }
  assert_true(cnt > 0);
  return 10.0 * log10(m / t);
}

/* White only: variance W^2 fs / 2 and a flat one-sided density W^2. */
static void test_white(void **state)
{
  (void)state;
  const flicker_spec_t spec = {3e-6, 0.0, 1e-3};
  const double fs = 50000.0;
  flicker_t f;
  assert_int_equal(flicker_init(&f, &spec, fs, 11u, 1u), 0);
  const int n = 200000;
  double s2 = 0.0;
  for (int i = 0; i < n; i++) {
    const double v = flicker_step(&f);
    s2 += v * v;
  }
  const double var = s2 / n, want = spec.white_rthz * spec.white_rthz * fs / 2.0;
  assert_true(fabs(var / want - 1.0) < 5.0 * sqrt(2.0 / n));
  double *psd = run_psd(&spec, fs, 0, 1u << 18, 1u << 10, 12u);
  const double bands[4][2] = {{50, 200}, {500, 2000}, {5000, 10000}, {15000, 24000}};
  for (int b = 0; b < 4; b++)
    assert_true(fabs(band_error_db(psd, &spec, fs, 1u << 10, bands[b][0], bands[b][1])) < 0.3);
  free(psd);
}

/* 1/f below the corner, white above, at a low sample rate so that the 1/f decades fit
 * in a short run (the design is relative to fc and fs): fs 1 kHz, corner 50 Hz, fmin
 * 1 mHz, 2^21 samples. Levels in octave bands within 0.75 dB of W^2 + K^2/f (design
 * +-0.28 dB, estimate ~4 % rms), and the log-log slope over 0.3..3 Hz within 0.05 of the
 * target's. */
static void test_flicker_slope_and_level(void **state)
{
  (void)state;
  const double fs = 1000.0;
  const flicker_spec_t spec = {1e-6, 1e-6 * sqrt(50.0), 1e-3};
  const size_t nseg = 1u << 13, n = 1u << 21;
  flicker_t f;
  assert_int_equal(flicker_init(&f, &spec, fs, 1u, 1u), 0);
  assert_true(fabs(f.corner_hz - 50.0) < 1e-9);
  double *psd = run_psd(&spec, fs, 1u << 18, n, nseg, 13u);
  const double centres[] = {0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0};
  for (size_t b = 0; b < sizeof centres / sizeof centres[0]; b++) {
    const double e = band_error_db(psd, &spec, fs, nseg, centres[b] / sqrt(2.0),
                                   centres[b] * sqrt(2.0));
    print_message("band %6.2f Hz: %+.3f dB\n", centres[b], e);
    assert_true(fabs(e) < 0.75);
  }
  /* least-squares slope of log10 PSD against log10 f, measured and target */
  double sx = 0, sy = 0, sxx = 0, sxy = 0, ty = 0, sxt = 0;
  int cnt = 0;
  for (size_t i = 1; i <= nseg / 2; i++) {
    const double fr = (double)i * fs / (double)nseg;
    if (fr < 0.3 || fr > 3.0) continue;
    const double lx = log10(fr), ly = log10(psd[i]),
                 lt = log10(flicker_target_psd(&spec, fs, fr));
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ty += lt;
    sxt += lx * lt;
    cnt++;
  }
  const double den = cnt * sxx - sx * sx;
  const double slope = (cnt * sxy - sx * sy) / den, tslope = (cnt * sxt - sx * ty) / den;
  print_message("slope %.4f (target %.4f)\n", slope, tslope);
  assert_true(fabs(slope - tslope) < 0.05);
  assert_true(slope < -0.9 && slope > -1.05);
  free(psd);
}

/* The drive-voltage default at the plant rate (fs 50 kHz, W 200 nV, K 2 uV -> corner
 * 100 Hz, fmin 1 mHz): levels in the 1/f part, at the corner, at the drive frequencies
 * and up to Nyquist. */
static void test_plant_rate(void **state)
{
  (void)state;
  const double fs = 50000.0;
  const flicker_spec_t spec = {200e-9, 2e-6, 1e-3};
  const size_t nseg = 1u << 12, n = 1u << 20;
  double *psd = run_psd(&spec, fs, 1u << 16, n, nseg, 14u);
  const double bands[5][2] = {
      {20.0, 50.0}, {70.0, 140.0}, {600.0, 900.0}, {1300.0, 1700.0}, {15000.0, 24000.0}};
  for (int b = 0; b < 5; b++) {
    const double e = band_error_db(psd, &spec, fs, nseg, bands[b][0], bands[b][1]);
    print_message("band %.0f-%.0f Hz: %+.3f dB\n", bands[b][0], bands[b][1], e);
    assert_true(fabs(e) < 0.6);
  }
  free(psd);
}

/* Reproducible per (seed, stream); streams independent. */
static void test_seeding(void **state)
{
  (void)state;
  const flicker_spec_t spec = {1e-6, 1e-5, 0.01};
  flicker_t a, b, c;
  assert_int_equal(flicker_init(&a, &spec, 50000.0, 3u, 1u), 0);
  assert_int_equal(flicker_init(&b, &spec, 50000.0, 3u, 1u), 0);
  assert_int_equal(flicker_init(&c, &spec, 50000.0, 3u, 2u), 0);
  double sab = 0, sac = 0, saa = 0, scc = 0;
  for (int i = 0; i < 20000; i++) {
    const double va = flicker_step(&a), vb = flicker_step(&b), vc = flicker_step(&c);
    assert_true(va == vb);
    sab += va * vb;
    sac += va * vc;
    saa += va * va;
    scc += vc * vc;
  }
  assert_true(fabs(sac) / sqrt(saa * scc) < 0.2);
}

/* The generator realises its designed cascade (flicker_design), one block late: run
 * the cascade itself in series form on the same Gaussian draws and compare sample by
 * sample. The slow branches' block update and linear interpolation are the only
 * approximation: in every octave band from 10 fmin up, the two spectra of the same
 * draws agree within 0.25 dB (no sampling scatter: the randomness is shared), and the
 * difference stays under the target by 15 dB. */
static void check_realises_cascade(const flicker_spec_t *spec, double fs, size_t n)
{
  flicker_t f;
  flicker_cascade_t c;
  assert_int_equal(flicker_init(&f, spec, fs, 7u, 3u), 0);
  assert_int_equal(flicker_design(spec, fs, &c), 0);
  assert_true(f.nslow > 0);
  rng_t r;
  rng_seed(&r, 7u, 3u);
  double xp[FLICKER_MAX_SECTIONS] = {0}, yp[FLICKER_MAX_SECTIONS] = {0};
  double *ref = malloc(n * sizeof *ref), *err = malloc(n * sizeof *err);
  double *gen = malloc(n * sizeof *gen);
  assert_non_null(ref);
  assert_non_null(err);
  assert_non_null(gen);
  const size_t m = FLICKER_BLOCK;
  double se = 0.0, sr = 0.0;
  for (size_t k = 0; k < n; k++) {
    double x = c.in_sd * gauss_zig(&r);
    for (int i = 0; i < c.n; i++) {
      const double y = c.b0[i] * x + c.b1[i] * xp[i] - c.a1[i] * yp[i];
      xp[i] = x;
      yp[i] = y;
      x = y;
    }
    ref[k] = x;
    const double g = flicker_step(&f);
    gen[k] = g;
    err[k] = k >= m ? g - ref[k - m] : g;
    se += err[k] * err[k];
    sr += x * x;
  }
  print_message("fs %.0f W %g K %g: %d fast + %d slow branches, rms difference %.2e of rms\n",
                fs, spec->white_rthz, spec->flicker_1hz_rthz, f.nfast, f.nslow, sqrt(se / sr));
  const size_t nseg = 1u << 14;
  double *pe = malloc((nseg / 2 + 1) * sizeof *pe), *pg = malloc((nseg / 2 + 1) * sizeof *pg);
  double *pr = malloc((nseg / 2 + 1) * sizeof *pr);
  assert_non_null(pe);
  assert_non_null(pg);
  assert_non_null(pr);
  assert_true(ref_psd_welch(err + m, n - m, fs, nseg, pe) > 0);
  assert_true(ref_psd_welch(gen + m, n - m, fs, nseg, pg) > 0);
  assert_true(ref_psd_welch(ref, n - m, fs, nseg, pr) > 0);
  for (double lo = 10.0 * spec->fmin_hz > 2.0 * fs / (double)nseg ? 10.0 * spec->fmin_hz
                                                                  : 2.0 * fs / (double)nseg;
       lo < 0.4 * fs; lo *= 2.0) {
    const double e = band_error_db(pe, spec, fs, nseg, lo, 2.0 * lo);
    const double d = band_error_db(pg, spec, fs, nseg, lo, 2.0 * lo) -
                     band_error_db(pr, spec, fs, nseg, lo, 2.0 * lo);
    print_message("  %8.3g-%-8.3g Hz: level %+.3f dB, difference %+.1f dB of the target\n", lo,
                  2 * lo, d, e);
    if (fabs(d) > 0.25 || e > -15.0) fail_msg("band %.3g-%.3g Hz off", lo, 2 * lo);
  }
  free(pe);
  free(pg);
  free(pr);
  free(gen);
  free(ref);
  free(err);
}

static void test_realises_cascade(void **state)
{
  (void)state;
  const flicker_spec_t drive = {200e-9, 2e-6, 1e-3}; /* electrode default: corner 100 Hz */
  const flicker_spec_t phase = {0.0, 1e-5, 1e-3};    /* pure 1/f: corner fs/20 */
  const flicker_spec_t slow = {1e-6, 1e-6 * sqrt(50.0), 1e-3};
  check_realises_cascade(&drive, 50000.0, 1u << 21);
  check_realises_cascade(&phase, 50000.0, 1u << 21);
  check_realises_cascade(&slow, 1000.0, 1u << 20);
}

/* Bad specs are refused, the instance untouched; an all-zero spec gives silence. */
static void test_bad_and_zero(void **state)
{
  (void)state;
  flicker_t f, before;
  memset(&f, 0x33, sizeof f);
  before = f;
  const flicker_spec_t bad[] = {{-1e-6, 0.0, 1e-3},  {1e-6, -1.0, 1e-3}, {1e-6, 1e-5, 0.0},
                                {1e-6, 1e-5, 100.0}, {NAN, 1e-5, 1e-3},  {1e-6, INFINITY, 1e-3},
                                {1e-18, 1.0, 1e-12}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
    assert_int_equal(flicker_init(&f, &bad[i], 50000.0, 1u, 1u), -1);
  const flicker_spec_t ok = {1e-6, 1e-5, 1e-3};
  assert_int_equal(flicker_init(&f, &ok, 0.0, 1u, 1u), -1);
  assert_int_equal(flicker_init(&f, &ok, NAN, 1u, 1u), -1);
  assert_memory_equal(&f, &before, sizeof f);
  const flicker_spec_t zero = {0.0, 0.0, 0.0};
  assert_int_equal(flicker_init(&f, &zero, 50000.0, 1u, 1u), 0);
  for (int i = 0; i < 100; i++) assert_true(flicker_step(&f) == 0.0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_white),        cmocka_unit_test(test_flicker_slope_and_level),
      cmocka_unit_test(test_plant_rate),   cmocka_unit_test(test_seeding),
      cmocka_unit_test(test_bad_and_zero), cmocka_unit_test(test_realises_cascade),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
