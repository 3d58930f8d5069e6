/* NCO: phase accumulator + sincos_lut (5-14), with the locked wc/2 oscillator for the
 * half-frequency drive (6-18), (6-19). References: libm in double, a double-precision
 * FFT written here, and analytic bounds. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "dsp/nco.h"
#include "dsp/sincos.h"

#define TWO_PI 6.283185307179586476925
#define PI 3.141592653589793238463
#define TWO_POW_32 4294967296.0
#define FS_HZ 50000.0

static double counts_to_rad(uint32_t c) { return TWO_PI * (double)c / TWO_POW_32; }

/* ------------------------------------------------------------------ validation --- */

static void test_init_rejects_bad_config(void **state)
{
  (void)state;
  nco_t nco;
  memset(&nco, 0xA5, sizeof nco);
  nco_t before = nco;
  const nco_cfg_t bad[] = {
      {NAN, FS_HZ, 0.0},       {1000.0, NAN, 0.0},        {1000.0, FS_HZ, NAN},
      {1000.0, 0.0, 0.0},      {1000.0, -FS_HZ, 0.0},     {-1.0, FS_HZ, 0.0},
      {25000.0, FS_HZ, 0.0},   {30000.0, FS_HZ, 0.0},     {INFINITY, FS_HZ, 0.0},
      {1000.0, INFINITY, 0.0}, {1000.0, FS_HZ, INFINITY},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(nco_init(&nco, &bad[i]), -1);
    assert_memory_equal(&nco, &before, sizeof nco);
  }
  const nco_cfg_t good = {1000.0, FS_HZ, 0.0};
  assert_int_equal(nco_init(NULL, &good), -1);
  assert_int_equal(nco_init(&nco, NULL), -1);
  assert_memory_equal(&nco, &before, sizeof nco);

  assert_int_equal(nco_init(&nco, &good), 0);
  before = nco;
  assert_int_equal(nco_set_freq(&nco, NAN, FS_HZ), -1);
  assert_int_equal(nco_set_freq(&nco, 1000.0, 0.0), -1);
  assert_int_equal(nco_set_freq(&nco, 25000.0, FS_HZ), -1);
  assert_int_equal(nco_set_freq(NULL, 1000.0, FS_HZ), -1);
  assert_int_equal(nco_set_phase(&nco, NAN), -1);
  assert_int_equal(nco_set_phase(&nco, INFINITY), -1);
  assert_int_equal(nco_shift_phase(&nco, -INFINITY), -1);
  assert_int_equal(nco_set_phase(NULL, 1.0f), -1);
  assert_int_equal(nco_shift_phase(NULL, 1.0f), -1);
  assert_memory_equal(&nco, &before, sizeof nco);
}

/* The first sample is the configured phase; both oscillators start together. */
static void test_initial_phase(void **state)
{
  (void)state;
  const double phases[] = {0.0, 1.0, -1.0, 3.0, -3.0, 7.5, -100.25};
  for (size_t i = 0; i < sizeof phases / sizeof phases[0]; i++) {
    nco_t nco;
    const nco_cfg_t cfg = {1489.9, FS_HZ, phases[i]};
    assert_int_equal(nco_init(&nco, &cfg), 0);
    nco_out_t o;
    nco_step(&nco, &o);
    assert_float_equal(o.sin_wc, sin(phases[i]), 1e-6);
    assert_float_equal(o.cos_wc, cos(phases[i]), 1e-6);
    assert_int_equal(o.half_phase * 2u, o.phase);
    /* The wc/2 oscillator starts at half the wrapped phase, in [0, pi). */
    const double wrapped = phases[i] - TWO_PI * floor(phases[i] / TWO_PI);
    assert_float_equal(counts_to_rad(o.half_phase), 0.5 * wrapped, 1e-8);
  }
}

/* ----------------------------------------------------------- frequency accuracy --- */

/* Frequency measured from the outputs alone: unwrap atan2(sin, cos) over n samples. */
static double measured_freq_hz(nco_t *nco, int use_half, size_t n)
{
  double total = 0.0, prev = 0.0;
  for (size_t i = 0; i < n; i++) {
    nco_out_t o;
    nco_step(nco, &o);
    float s = o.sin_wc, c = o.cos_wc;
    if (use_half) sincos_lut(o.half_phase, &s, &c);
    const double a = atan2((double)s, (double)c);
    if (i > 0) {
      double d = a - prev;
      if (d > PI) d -= TWO_PI;
      if (d < -PI) d += TWO_PI;
      total += d;
    }
    prev = a;
  }
  return total / (double)(n - 1) / TWO_PI * FS_HZ;
}

static void test_frequency_accuracy(void **state)
{
  (void)state;
  const double freqs[] = {1489.9, 1750.0, 0.37, 123.456789, 12345.678, 24999.0};
  for (size_t i = 0; i < sizeof freqs / sizeof freqs[0]; i++) {
    nco_t nco;
    const nco_cfg_t cfg = {freqs[i], FS_HZ, 0.25};
    assert_int_equal(nco_init(&nco, &cfg), 0);
    const double f = measured_freq_hz(&nco, 0, 200000);
    const double fh = measured_freq_hz(&nco, 1, 200000);
    /* Step resolution fs/2^31, rounded to nearest: within fs/2^32 = 1.2e-5 Hz; the
     * measurement itself (atan2 of float outputs over 2e5 samples) adds < 1e-7 Hz. */
    const double tol = FS_HZ / TWO_POW_32 + 1e-7;
    printf("nco %.6f Hz: measured %.9f Hz (err %.3g), half %.9f Hz (err %.3g)\n", freqs[i], f,
           f - freqs[i], fh, fh - 0.5 * freqs[i]);
    assert_true(fabs(f - freqs[i]) <= tol);
    assert_true(fabs(fh - 0.5 * freqs[i]) <= 0.5 * tol);
  }
}

/* ----------------------------------------------------- lock, wraps, continuity --- */

static uint64_t lcg_state = 12345u;
static uint32_t lcg_next(void)
{
  lcg_state = lcg_state * 6364136223846793005ull + 1442695040888963407ull;
  return (uint32_t)(lcg_state >> 33);
}

/* 10^7 samples with frequency changes (and wc phase shifts) in between: the wc/2 phase
 * doubles to the wc phase at every sample, every step of either phase is exactly the
 * advance of the frequency in force, and neither the wc pair nor the drive pair
 * (sincos_lut(half_phase + pc)) moves by more than one sample's phase advance, except
 * for the commanded shifts, which land exactly. */
static void test_lock_and_continuity_over_1e7_samples(void **state)
{
  (void)state;
  const double freqs[] = {1489.9, 1490.2, 1750.0, 3.7, 0.001, 20000.3, 24999.999, 744.95};
  const float pc_rad = 0.7f; /* drive phase offset (6-18) */
  const uint32_t pc = sincos_rad_to_phase(pc_rad);
  nco_t nco;
  const nco_cfg_t cfg = {freqs[0], FS_HZ, -2.0};
  assert_int_equal(nco_init(&nco, &cfg), 0);
  double f_now = freqs[0];  /* the frequency last set */
  double f_incr = freqs[0]; /* the one the accumulator advanced with into this sample */

  nco_out_t prev;
  float pu1 = 0.0f, pu2 = 0.0f;
  uint32_t wraps = 0u, half_wraps = 0u, changes = 0u, shifts = 0u;
  uint32_t expected_jump = 0u; /* commanded wc phase change since prev (0 = none) */
  int changed = 0;
  double worst_ratio = 0.0;
  const uint32_t n = 10000000u;
  for (uint32_t i = 0; i < n; i++) {
    nco_out_t o;
    nco_step(&nco, &o);
    float u1, u2; /* U1 ~ cos, U2 ~ sin of the half-frequency phase (6-18) */
    sincos_lut(o.half_phase + pc, &u2, &u1);
    if (o.half_phase * 2u != o.phase) fail_msg("lock lost at sample %u", i);
    if (i > 0) {
      const uint32_t dp = o.phase - prev.phase - expected_jump;
      const uint32_t dh = o.half_phase - prev.half_phase;
      if (o.phase < prev.phase) wraps++;
      if (o.half_phase < prev.half_phase) half_wraps++;
      /* The advance is the one of the frequency in force (within the step resolution). */
      if (fabs((double)dp * FS_HZ / TWO_POW_32 - f_incr) > FS_HZ / TWO_POW_32)
        fail_msg("sample %u: step %u is not %.6f Hz", i, dp, f_incr);
      if (expected_jump == 0u) {
        if (dh * 2u != dp || dh >= 0x80000000u) fail_msg("sample %u: half step %u", i, dh);
        /* |d sin| <= |d phase| for a sine; float rounding adds < 1e-6. */
        const double lim = counts_to_rad(dp) + 1e-6;
        const double limh = counts_to_rad(dh) + 1e-6;
        const double m = fmax(fabs((double)o.sin_wc - (double)prev.sin_wc),
                              fabs((double)o.cos_wc - (double)prev.cos_wc));
        const double mh = fmax(fabs((double)u1 - (double)pu1), fabs((double)u2 - (double)pu2));
        if (m > lim || mh > limh) fail_msg("sample %u: output step %.3g/%.3g", i, m, mh);
        if (changed) worst_ratio = fmax(worst_ratio, fmax(m / lim, mh / limh));
      }
    }
    changed = 0;
    expected_jump = 0u;
    prev = o;
    pu1 = u1;
    pu2 = u2;
    /* nco_step has already advanced to the next sample's phase: a new frequency shows in
     * the increment after it, a phase shift in the next sample itself. */
    f_incr = f_now;
    const uint32_t r = lcg_next();
    if (r % 400000u == 0u) {
      f_now = freqs[lcg_next() % (sizeof freqs / sizeof freqs[0])];
      assert_int_equal(nco_set_freq(&nco, f_now, FS_HZ), 0);
      changes++;
      changed = 1;
    } else if (r % 400000u == 1u) {
      /* A commanded wc phase shift of up to +-3 rad lands on the next sample. */
      const float d = (float)((double)(lcg_next() % 6000u) / 1000.0 - 3.0);
      assert_int_equal(nco_shift_phase(&nco, d), 0);
      expected_jump = sincos_rad_to_phase(d) & ~1u;
      shifts++;
    }
  }
  printf("nco: 1e7 samples, %u wc wraps, %u wc/2 wraps, %u frequency changes, %u phase "
         "shifts; worst output step after a change %.3f of the phase advance\n",
         wraps, half_wraps, changes, shifts, worst_ratio);
  assert_true(wraps > 1000u && half_wraps > 500u && changes >= 10u && shifts >= 10u);
}

/* A wc phase shift moves the wc/2 oscillator by half of it, taken as the smallest move
 * (a -0.2 rad shift must not become +pi - 0.1 rad on the drive: that would flip both
 * drive voltages). */
static void test_phase_shift_moves_half_by_half(void **state)
{
  (void)state;
  const float deltas[] = {-0.2f, 0.2f, 3.0f, -3.0f, 6.0f, -6.0f};
  for (size_t i = 0; i < sizeof deltas / sizeof deltas[0]; i++) {
    nco_t nco;
    const nco_cfg_t cfg = {1489.9, FS_HZ, 0.3};
    assert_int_equal(nco_init(&nco, &cfg), 0);
    nco_t ref = nco;
    assert_int_equal(nco_shift_phase(&nco, deltas[i]), 0);
    nco_out_t a, b;
    nco_step(&ref, &a);
    nco_step(&nco, &b);
    /* The shift reduced to [-pi, pi), halved. */
    double dwc = remainder((double)deltas[i], TWO_PI);
    const double dh = remainder(counts_to_rad(b.half_phase - a.half_phase), TWO_PI);
    assert_float_equal(dh, 0.5 * dwc, 1e-6);
    assert_int_equal(b.half_phase * 2u, b.phase);
  }
  /* Absolute: the wc phase lands on the target, the wc/2 phase moves the short way. */
  nco_t nco;
  const nco_cfg_t cfg = {1489.9, FS_HZ, 1.0};
  assert_int_equal(nco_init(&nco, &cfg), 0);
  nco_out_t a, b;
  nco_step(&nco, &a);
  assert_int_equal(nco_set_phase(&nco, 0.5f), 0);
  nco_step(&nco, &b);
  assert_float_equal(sin((double)0.5f), b.sin_wc, 1e-6);
  assert_float_equal(cos((double)0.5f), b.cos_wc, 1e-6);
  const double dh = remainder(counts_to_rad(b.half_phase - a.half_phase), TWO_PI);
  assert_float_equal(dh, -0.25, 1e-6);
}

/* --------------------------------------------------------------- SFDR via FFT --- */

/* In-place radix-2 FFT in double (n a power of two). */
static void fft(double *re, double *im, size_t n)
{
  for (size_t i = 1, j = 0; i < n; i++) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) {
      double t = re[i];
      re[i] = re[j];
      re[j] = t;
      t = im[i];
      im[i] = im[j];
      im[j] = t;
    }
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const double ang = -TWO_PI / (double)len;
    for (size_t i = 0; i < n; i += len) {
      for (size_t k = 0; k < len / 2; k++) {
        const double wr = cos(ang * (double)k), wi = sin(ang * (double)k);
        const size_t a = i + k, b = i + k + len / 2;
        const double xr = re[b] * wr - im[b] * wi, xi = re[b] * wi + im[b] * wr;
        re[b] = re[a] - xr;
        im[b] = im[a] - xi;
        re[a] += xr;
        im[a] += xi;
      }
    }
  }
}

/* Modified Bessel function I0 by its power series (converges for any x). */
static double bessel_i0(double x)
{
  double sum = 1.0, term = 1.0;
  for (int k = 1; k < 200; k++) {
    term *= (x / (2.0 * k)) * (x / (2.0 * k));
    sum += term;
    if (term < 1e-17 * sum) break;
  }
  return sum;
}

#define SFDR_N 65536u
#define KAISER_BETA 20.0  /* sidelobes near -190 dB: leakage cannot hide a spur */
#define MAIN_LOBE_BINS 10 /* half-width sqrt(1 + (beta/pi)^2) = 6.4 bins, plus margin */

/* Spurious-free dynamic range (dB) of a real signal: carrier peak over the largest bin
 * outside the carrier's main lobe, DC to Nyquist. */
static double sfdr_db(const double *x, size_t n)
{
  double *re = malloc(n * sizeof *re), *im = malloc(n * sizeof *im);
  assert_non_null(re);
  assert_non_null(im);
  const double i0b = bessel_i0(KAISER_BETA);
  for (size_t i = 0; i < n; i++) {
    const double r = 2.0 * (double)i / (double)(n - 1) - 1.0;
    re[i] = x[i] * bessel_i0(KAISER_BETA * sqrt(fmax(0.0, 1.0 - r * r))) / i0b;
    im[i] = 0.0;
  }
  fft(re, im, n);
  size_t peak = 0;
  double pmax = -1.0;
  for (size_t k = 0; k <= n / 2; k++) {
    const double p = re[k] * re[k] + im[k] * im[k];
    if (p > pmax) {
      pmax = p;
      peak = k;
    }
  }
  double spur = 0.0;
  for (size_t k = 0; k <= n / 2; k++) {
    if (k + MAIN_LOBE_BINS >= peak && k <= peak + MAIN_LOBE_BINS) continue;
    const double p = re[k] * re[k] + im[k] * im[k];
    if (p > spur) spur = p;
  }
  free(re);
  free(im);
  return 10.0 * log10(pmax / spur);
}

static void test_sfdr(void **state)
{
  (void)state;
  /* Not bin-aligned for the FFT (bins are 0.763 Hz) nor for the table. */
  const double freqs[] = {1489.9, 744.95, 12345.678, 101.3};
  double worst = 1e9;
  double *s = malloc(SFDR_N * sizeof *s), *c = malloc(SFDR_N * sizeof *c);
  double *u = malloc(SFDR_N * sizeof *u);
  assert_non_null(s);
  assert_non_null(c);
  assert_non_null(u);
  for (size_t f = 0; f < sizeof freqs / sizeof freqs[0]; f++) {
    nco_t nco;
    const nco_cfg_t cfg = {freqs[f], FS_HZ, 0.1};
    assert_int_equal(nco_init(&nco, &cfg), 0);
    /* Skip ahead so the run starts at an arbitrary accumulator state. */
    for (uint32_t i = 0; i < 12345u; i++) {
      nco_out_t o;
      nco_step(&nco, &o);
    }
    const uint32_t pc = sincos_rad_to_phase(0.4f);
    for (size_t i = 0; i < SFDR_N; i++) {
      nco_out_t o;
      nco_step(&nco, &o);
      float u1, u2;
      sincos_lut(o.half_phase + pc, &u2, &u1);
      s[i] = o.sin_wc;
      c[i] = o.cos_wc;
      u[i] = u1;
    }
    const double ds = sfdr_db(s, SFDR_N), dc = sfdr_db(c, SFDR_N), du = sfdr_db(u, SFDR_N);
    printf("nco %.3f Hz: SFDR sin %.1f dB, cos %.1f dB, drive U1 at wc/2 %.1f dB\n", freqs[f],
           ds, dc, du);
    worst = fmin(worst, fmin(ds, fmin(dc, du)));
  }
  free(s);
  free(c);
  free(u);
  assert_true(worst >= 120.0);
}

/* The SFDR measurement must see a spur that is there: a -110 dBc tone added at an
 * unrelated frequency has to pull the figure below 120 dB. */
static void test_sfdr_detects_a_spur(void **state)
{
  (void)state;
  double *x = malloc(SFDR_N * sizeof *x);
  assert_non_null(x);
  for (size_t i = 0; i < SFDR_N; i++) {
    const double t = (double)i / FS_HZ;
    x[i] = sin(TWO_PI * 1489.9 * t) + pow(10.0, -110.0 / 20.0) * sin(TWO_PI * 4321.1 * t);
  }
  const double d = sfdr_db(x, SFDR_N);
  free(x);
  assert_true(d > 108.0 && d < 112.0);
}

/* One conversion of a frequency to a step (the NCO's and the self-calibration's sweep
 * plans): round to nearest with halves away from zero, negative frequencies wrapping
 * modulo 2^32, and nco_freq_of its inverse within fs/2^32. */
static void test_half_step_of(void **state)
{
  (void)state;
  const double fs_unit = 2147483648.0; /* fs = 2^31 Hz: the step is the frequency in Hz */
  assert_int_equal(nco_half_step_of(1000.5, fs_unit), 1001u);
  assert_int_equal(nco_half_step_of(1000.4999, fs_unit), 1000u);
  assert_int_equal(nco_half_step_of(0.0, fs_unit), 0u);
  assert_int_equal(nco_half_step_of(-3.0, fs_unit), 0xFFFFFFFDu);
  assert_int_equal(nco_half_step_of(-2.5, fs_unit), 0xFFFFFFFDu);
  nco_t n;
  const nco_cfg_t c = {1489.9, 50000.0, 0.0};
  assert_int_equal(nco_init(&n, &c), 0);
  assert_int_equal(n.half_step, nco_half_step_of(1489.9, 50000.0));
  assert_true(fabs(nco_freq_of(n.half_step, 50000.0) - 1489.9) <= 50000.0 / 4294967296.0);
  /* Over the frequencies the firmware asks for (sweeps from 100 Hz, up to fs/4) the step
   * is the one the NCO computed before the two conversions became one, floor(x + 0.5). */
  for (double f = 100.0; f < 12500.0; f += 0.0123) {
    const double x = f / 50000.0 * 2147483648.0;
    if (nco_half_step_of(f, 50000.0) != (uint32_t)floor(x + 0.5)) {
      print_message("# %.17g Hz\n", f);
      fail();
    }
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_init_rejects_bad_config),
      cmocka_unit_test(test_initial_phase),
      cmocka_unit_test(test_frequency_accuracy),
      cmocka_unit_test(test_lock_and_continuity_over_1e7_samples),
      cmocka_unit_test(test_phase_shift_moves_half_by_half),
      cmocka_unit_test(test_sfdr),
      cmocka_unit_test(test_sfdr_detects_a_spur),
      cmocka_unit_test(test_half_step_of),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
