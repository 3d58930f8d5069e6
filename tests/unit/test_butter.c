/* Butterworth designer against scipy.signal.butter vectors (tools/gen_filter_vectors.py),
 * a long-double reference filter and Eigen polynomial roots (tests/reference/iir_ref). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "dsp/biquad.h"
#include "dsp/butter.h"
#include "iir_ref.h"
#include "test_vectors.h"

#define TWO_PI 6.283185307179586476925
#define PI 3.141592653589793238463
#define MAXS BUTTER_MAX_SECTIONS

typedef struct {
  butter_type_t type;
  unsigned order;
  double f1_hz, f2_hz, fs_hz;
  size_t n_sections;
  double sos[6 * MAXS]; /* scipy */
  double poles_re[2 * MAXS], poles_im[2 * MAXS];
  size_t n_freq;
  double *freq; /* f_hz, re, im rows */
  size_t n;
  double *x, *y; /* input (float values), sosfilt(sos, x) */
} design_t;

/* tests/vectors/butter_<idx>_<what>.csv */
static double *load(const char *what, size_t idx, size_t *rows, size_t cols)
{
  char name[64];
  size_t c = 0;
  snprintf(name, sizeof name, "butter_%zu_%s.csv", idx, what);
  double *d = tv_load_csv(name, rows, &c);
  assert_non_null(d);
  assert_int_equal(c, cols);
  return d;
}

static size_t n_designs(void)
{
  size_t rows = 0, cols = 0;
  double *d = tv_load_csv("butter_designs.csv", &rows, &cols);
  assert_non_null(d);
  free(d);
  return rows;
}

static void load_design(size_t idx, design_t *d)
{
  size_t rows = 0, cols = 0;
  double *all = tv_load_csv("butter_designs.csv", &rows, &cols);
  assert_non_null(all);
  assert_int_equal(cols, 7);
  assert_true(idx < rows);
  const double *r = &all[7 * idx];
  d->type = (butter_type_t)(int)r[1];
  d->order = (unsigned)r[2];
  d->f1_hz = r[3];
  d->f2_hz = r[4];
  d->fs_hz = r[5];
  d->n_sections = (size_t)r[6];
  free(all);

  double *sos = load("sos", idx, &rows, 6);
  assert_int_equal(rows, d->n_sections);
  memcpy(d->sos, sos, rows * 6 * sizeof(double));
  free(sos);

  double *p = load("poles", idx, &rows, 2);
  assert_int_equal(rows, 2 * d->n_sections);
  for (size_t i = 0; i < rows; i++) {
    d->poles_re[i] = p[2 * i];
    d->poles_im[i] = p[2 * i + 1];
  }
  free(p);

  d->freq = load("freqresp", idx, &d->n_freq, 3);
  double *t = load("time", idx, &d->n, 3);
  d->x = malloc(d->n * sizeof(double));
  d->y = malloc(d->n * sizeof(double));
  assert_non_null(d->x);
  assert_non_null(d->y);
  for (size_t i = 0; i < d->n; i++) {
    d->x[i] = (double)(float)t[3 * i];
    d->y[i] = t[3 * i + 1];
  }
  free(t);
}

static void free_design(design_t *d)
{
  free(d->freq);
  free(d->x);
  free(d->y);
}

static void f64_to_sos(const butter_sos_f64_t *s, size_t n, double *sos)
{
  for (size_t i = 0; i < n; i++) {
    const double r[6] = {s[i].b0, s[i].b1, s[i].b2, 1.0, s[i].a1, s[i].a2};
    memcpy(&sos[6 * i], r, sizeof r);
  }
}

static void f32_to_sos(const biquad_coeffs_t *s, size_t n, double *sos)
{
  for (size_t i = 0; i < n; i++) {
    const double r[6] = {s[i].b0, s[i].b1, s[i].b2, 1.0, s[i].a1, s[i].a2};
    memcpy(&sos[6 * i], r, sizeof r);
  }
}

/* Roots of z^2 + a1 z + a2. */
static void quad_roots(double a1, double a2, double *re, double *im)
{
  const double disc = a1 * a1 - 4.0 * a2;
  if (disc < 0.0) {
    re[0] = re[1] = -0.5 * a1;
    im[0] = 0.5 * sqrt(-disc);
    im[1] = -im[0];
  } else {
    const double q = -0.5 * (a1 + (a1 < 0.0 ? -sqrt(disc) : sqrt(disc)));
    re[0] = q;
    re[1] = a2 / q;
    im[0] = im[1] = 0.0;
  }
}

/* Every pole of the sections matches a distinct scipy pole within tol[section]. */
static void check_poles(const design_t *d, const double *sos, const double *tol)
{
  int used[2 * MAXS] = {0};
  for (size_t s = 0; s < d->n_sections; s++) {
    double re[2], im[2];
    quad_roots(sos[6 * s + 4], sos[6 * s + 5], re, im);
    for (int k = 0; k < 2; k++) {
      size_t best = 0;
      double bd = INFINITY;
      for (size_t j = 0; j < 2 * d->n_sections; j++) {
        const double dist = hypot(re[k] - d->poles_re[j], im[k] - d->poles_im[j]);
        if (!used[j] && dist < bd) {
          bd = dist;
          best = j;
        }
      }
      if (bd > tol[s]) fail_msg("section %zu pole off by %.3g (tol %.3g)", s, bd, tol[s]);
      used[best] = 1;
    }
  }
}

/* Product of the numerators normalised to b0 = 1 (the zeros, whatever the pairing). */
static void numerator_product(const double *sos, size_t n, double *poly)
{
  size_t deg = 0;
  poly[0] = 1.0;
  for (size_t s = 0; s < n; s++) {
    const double c1 = sos[6 * s + 1] / sos[6 * s], c2 = sos[6 * s + 2] / sos[6 * s];
    poly[deg + 1] = 0.0;
    poly[deg + 2] = 0.0;
    for (size_t k = deg + 2; k >= 1; k--) {
      poly[k] += c1 * poly[k - 1] + (k >= 2 ? c2 * poly[k - 2] : 0.0);
      if (k == 1) break;
    }
    deg += 2;
  }
}

static double max_abs(const double *v, size_t n)
{
  double m = 0.0;
  for (size_t i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* ------------------------------------------------------- exact (double) design --- */

static void test_f64_design_matches_scipy(void **state)
{
  (void)state;
  const size_t nd = n_designs();
  for (size_t k = 0; k < nd; k++) {
    design_t d;
    load_design(k, &d);
    butter_sos_f64_t s[MAXS];
    const int n = butter_design_f64(d.type, d.order, d.f1_hz, d.f2_hz, d.fs_hz, s, MAXS);
    assert_int_equal(n, (int)d.n_sections);
    double sos[6 * MAXS];
    f64_to_sos(s, d.n_sections, sos);

    /* Denominators section by section: same poles, same order (nearest the unit circle
     * last, as scipy's zpk2sos). */
    for (size_t i = 0; i < d.n_sections; i++) {
      assert_float_equal(s[i].a1, d.sos[6 * i + 4], 1e-12);
      assert_float_equal(s[i].a2, d.sos[6 * i + 5], 1e-12);
    }
    double ptol[MAXS];
    for (size_t i = 0; i < MAXS; i++) ptol[i] = 1e-11;
    check_poles(&d, sos, ptol);

    /* Zeros: the product of the numerator shapes is scipy's (pairing may differ). */
    double mine[2 * MAXS + 1], ref[2 * MAXS + 1];
    numerator_product(sos, d.n_sections, mine);
    numerator_product(d.sos, d.n_sections, ref);
    for (size_t i = 0; i <= 2 * d.n_sections; i++) assert_float_equal(mine[i], ref[i], 1e-9);

    /* Overall response, complex, at every frequency scipy evaluated. */
    double worst = 0.0;
    for (size_t i = 0; i < d.n_freq; i++) {
      double re, im, sre, sim;
      iir_ref_sos_freqresp(sos, d.n_sections, d.freq[3 * i], d.fs_hz, &re, &im);
      iir_ref_sos_freqresp(d.sos, d.n_sections, d.freq[3 * i], d.fs_hz, &sre, &sim);
      /* scipy evaluates in double: near DC the 100 Hz filter's A(z) is 1.6e-4 per
       * section, which costs it a few digits. */
      assert_true(hypot(sre - d.freq[3 * i + 1], sim - d.freq[3 * i + 2]) < 1e-10);
      worst = fmax(worst, hypot(re - d.freq[3 * i + 1], im - d.freq[3 * i + 2]));
    }
    assert_true(worst < 1e-9);

    /* Time domain in long double against scipy's sosfilt. */
    double *y = malloc(d.n * sizeof *y);
    assert_non_null(y);
    iir_ref_sos_filter(sos, d.n_sections, d.x, y, d.n);
    double e = 0.0;
    for (size_t i = 0; i < d.n; i++) e = fmax(e, fabs(y[i] - d.y[i]));
    assert_true(e <= 1e-9 * max_abs(d.y, d.n));
    printf("design %zu (double): max |dH| %.3g, max |dy| %.3g\n", k, worst, e);
    free(y);
    free_design(&d);
  }
}

/* ------------------------------------------------------------- float design --- */

/* The reference point of the gain normalisation: z = 1, -1 or exp(j w0). */
static double ref_freq_hz(const design_t *d)
{
  if (d->type == BUTTER_LOWPASS) return 0.0;
  if (d->type == BUTTER_HIGHPASS) return 0.5 * d->fs_hz;
  const double t = sqrt(tan(PI * d->f1_hz / d->fs_hz) * tan(PI * d->f2_hz / d->fs_hz));
  return d->fs_hz / PI * atan(t);
}

/* |A(exp(j 2 pi f/fs))| of 1 + a1 z^-1 + a2 z^-2. */
static double den_mag(double a1, double a2, double f_hz, double fs_hz)
{
  const double w = TWO_PI * f_hz / fs_hz;
  return hypot(1.0 + a1 * cos(w) + a2 * cos(2.0 * w), a1 * sin(w) + a2 * sin(2.0 * w));
}

static void test_float_design_matches_scipy(void **state)
{
  (void)state;
  const size_t nd = n_designs();
  for (size_t k = 0; k < nd; k++) {
    design_t d;
    load_design(k, &d);
    biquad_coeffs_t c[MAXS];
    butter_sos_f64_t s[MAXS];
    const int n = butter_design(d.type, d.order, d.f1_hz, d.f2_hz, d.fs_hz, c, MAXS);
    assert_int_equal(n, (int)d.n_sections);
    assert_int_equal(butter_design_f64(d.type, d.order, d.f1_hz, d.f2_hz, d.fs_hz, s, MAXS), n);
    double sos[6 * MAXS];
    f32_to_sos(c, d.n_sections, sos);
    const double fref = ref_freq_hz(&d);

    /* Each float section: the denominator is the exact one rounded to nearest, and its
     * gain at the reference frequency is 1 up to the rounding of its numerator gain. */
    double delta[MAXS], ptol[MAXS];
    for (size_t i = 0; i < d.n_sections; i++) {
      assert_true(c[i].a1 == (float)s[i].a1 && c[i].a2 == (float)s[i].a2);
      double re, im;
      iir_ref_sos_freqresp(&sos[6 * i], 1, fref, d.fs_hz, &re, &im);
      assert_true(fabs(hypot(re, im) - 1.0) <= ldexp(1.0, -23));
      delta[i] = fabs((double)c[i].a1 - s[i].a1) + fabs((double)c[i].a2 - s[i].a2);
      /* Root sensitivity of the pair: |dp| <= (|da1||p| + |da2|) / |p - p'|. */
      double pr[2], pi[2];
      quad_roots(s[i].a1, s[i].a2, pr, pi);
      ptol[i] = 2.0 * delta[i] / hypot(pr[0] - pr[1], pi[0] - pi[1]) + 1e-12;
    }
    check_poles(&d, sos, ptol);

    /* Overall response vs scipy: the difference is the first-order effect of the rounded
     * denominators, at the frequency and at the renormalisation point, plus the
     * rounding of the numerator gains:
     *   |dH| <= |H| sum_s (delta_s (1/|A_s(f)| + 1/|A_s(fref)|) + 2^-24). */
    double worst = 0.0, worst_ratio = 0.0;
    for (size_t i = 0; i < d.n_freq; i++) {
      const double f = d.freq[3 * i];
      double re, im;
      iir_ref_sos_freqresp(sos, d.n_sections, f, d.fs_hz, &re, &im);
      const double href = hypot(d.freq[3 * i + 1], d.freq[3 * i + 2]);
      double bound = 0.0;
      for (size_t j = 0; j < d.n_sections; j++) {
        bound += delta[j] * (1.0 / den_mag(s[j].a1, s[j].a2, f, d.fs_hz) +
                             1.0 / den_mag(s[j].a1, s[j].a2, fref, d.fs_hz)) +
                 ldexp(1.0, -24);
      }
      bound = 1.5 * bound * href + 1e-12;
      const double dh = hypot(re - d.freq[3 * i + 1], im - d.freq[3 * i + 2]);
      if (dh > bound) fail_msg("design %zu, %.6g Hz: |dH| %.3g > %.3g", k, f, dh, bound);
      worst = fmax(worst, dh);
      worst_ratio = fmax(worst_ratio, dh / bound);
    }

    /* Time domain: the float cascade on scipy's input reproduces scipy's output. */
    biquad_cascade_t bq;
    assert_int_equal(biquad_cascade_init(&bq, c, (uint32_t)n), 0);
    double e = 0.0;
    for (size_t i = 0; i < d.n; i++) {
      const float v = biquad_cascade_step(&bq, (float)d.x[i]);
      e = fmax(e, fabs((double)v - d.y[i]));
    }
    e /= max_abs(d.y, d.n);
    printf("design %zu (float): max |dH| %.3g (%.2f of bound), time-domain error %.3g of max "
           "|y|\n",
           k, worst, worst_ratio, e);
    /* 0.1 % of full scale: far below anything the rate channel resolves at these levels,
     * far above what a wrong coefficient or section would give. */
    assert_true(e <= 1e-3);
    free_design(&d);
  }
}

/* The renormalisation makes the 100 Hz low-pass's float DC gain exactly 1; rounding
 * scipy's coefficients alone misses by about 2e-4 (why butter_design renormalises). */
static void test_float_dc_gain_is_exact(void **state)
{
  (void)state;
  biquad_coeffs_t c[2];
  assert_int_equal(butter_design(BUTTER_LOWPASS, 4, 100.0, 0.0, 50000.0, c, 2), 2);
  double g = 1.0;
  for (int i = 0; i < 2; i++) {
    g *= ((double)c[i].b0 + (double)c[i].b1 + (double)c[i].b2) /
         (1.0 + (double)c[i].a1 + (double)c[i].a2);
  }
  design_t d;
  load_design(0, &d);
  double gn = 1.0;
  for (int i = 0; i < 2; i++) {
    const double *r = &d.sos[6 * i];
    gn *= ((double)(float)r[0] + (double)(float)r[1] + (double)(float)r[2]) /
          (1.0 + (double)(float)r[4] + (double)(float)r[5]);
  }
  free_design(&d);
  printf("LP 100 Hz @ 50 kHz, float: DC gain - 1 = %.3g renormalised, %.3g naively rounded\n",
         g - 1.0, gn - 1.0);
  assert_true(g == 1.0);
  assert_true(fabs(gn - 1.0) > 1e-5);
}

/* ------------------------------------------------------------ bad arguments --- */

typedef struct {
  int type;
  unsigned order;
  double f1, f2, fs;
  uint32_t max;
  int expect;
} bad_case_t;

static void test_bad_arguments_are_rejected_and_change_nothing(void **state)
{
  (void)state;
  const double fs = 50000.0;
  const bad_case_t cases[] = {
      {BUTTER_LOWPASS, 0, 100.0, 0.0, fs, MAXS, BUTTER_ERR_ORDER},
      {BUTTER_LOWPASS, 3, 100.0, 0.0, fs, MAXS, BUTTER_ERR_ORDER},
      {BUTTER_HIGHPASS, 5, 100.0, 0.0, fs, MAXS, BUTTER_ERR_ORDER},
      {BUTTER_LOWPASS, 18, 100.0, 0.0, fs, MAXS, BUTTER_ERR_ORDER},
      {BUTTER_BANDPASS, 0, 100.0, 200.0, fs, MAXS, BUTTER_ERR_ORDER},
      {BUTTER_BANDPASS, 9, 100.0, 200.0, fs, MAXS, BUTTER_ERR_ORDER},
      {BUTTER_LOWPASS, 4, 0.0, 0.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, -10.0, 0.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 25000.0, 0.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 30000.0, 0.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, NAN, 0.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 100.0, 0.0, NAN, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 100.0, 0.0, INFINITY, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 100.0, 0.0, 0.0, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 100.0, 0.0, -fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_HIGHPASS, 4, INFINITY, 0.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_BANDPASS, 4, 1700.0, 1300.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_BANDPASS, 4, 1500.0, 1500.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_BANDPASS, 4, 1300.0, 25000.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_BANDPASS, 4, 1300.0, NAN, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_BANDPASS, 4, 0.0, 1700.0, fs, MAXS, BUTTER_ERR_FREQ},
      {BUTTER_LOWPASS, 4, 100.0, 0.0, fs, 1, BUTTER_ERR_SPACE},
      {BUTTER_BANDPASS, 4, 1300.0, 1700.0, fs, 3, BUTTER_ERR_SPACE},
      {BUTTER_LOWPASS, 4, 100.0, 0.0, fs, 0, BUTTER_ERR_SPACE},
      {7, 4, 100.0, 0.0, fs, MAXS, BUTTER_ERR_ARG},
      {-1, 4, 100.0, 0.0, fs, MAXS, BUTTER_ERR_ARG},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const bad_case_t *b = &cases[i];
    biquad_coeffs_t c[MAXS], c0[MAXS];
    butter_sos_f64_t s[MAXS], s0[MAXS];
    memset(c, 0x3C, sizeof c);
    memset(s, 0x3C, sizeof s);
    memcpy(c0, c, sizeof c);
    memcpy(s0, s, sizeof s);
    const int r1 = butter_design((butter_type_t)b->type, b->order, b->f1, b->f2, b->fs, c,
                                 b->max);
    const int r2 = butter_design_f64((butter_type_t)b->type, b->order, b->f1, b->f2, b->fs, s,
                                     b->max);
    if (r1 != b->expect || r2 != b->expect) fail_msg("case %zu: returned %d/%d", i, r1, r2);
    assert_memory_equal(c, c0, sizeof c);
    assert_memory_equal(s, s0, sizeof s);
  }
  assert_int_equal(butter_design(BUTTER_LOWPASS, 4, 100.0, 0.0, fs, NULL, MAXS), BUTTER_ERR_ARG);
  assert_int_equal(butter_design_f64(BUTTER_LOWPASS, 4, 100.0, 0.0, fs, NULL, MAXS),
                   BUTTER_ERR_ARG);
  /* Largest orders are accepted; f2 is ignored for low-/high-pass. */
  biquad_coeffs_t c[MAXS];
  assert_int_equal(butter_design(BUTTER_LOWPASS, 16, 2000.0, NAN, fs, c, MAXS), 8);
  assert_int_equal(butter_design(BUTTER_BANDPASS, 8, 5000.0, 9000.0, fs, c, MAXS), 8);
}

/* A cut-off so low that a float denominator rounds onto the unit circle is refused
 * by the float design (the double design still exists) and writes nothing. */
static void test_float_precision_limit(void **state)
{
  (void)state;
  biquad_coeffs_t c[MAXS], c0[MAXS];
  butter_sos_f64_t s[MAXS];
  memset(c, 0x3C, sizeof c);
  memcpy(c0, c, sizeof c);
  assert_int_equal(butter_design_f64(BUTTER_LOWPASS, 2, 1e-4, 0.0, 50000.0, s, MAXS), 1);
  assert_true(s[0].a2 < 1.0);
  assert_int_equal(butter_design(BUTTER_LOWPASS, 2, 1e-4, 0.0, 50000.0, c, MAXS),
                   BUTTER_ERR_PRECISION);
  assert_memory_equal(c, c0, sizeof c);
}

/* ----------------------------------------- why cascades (thesis 5.5.1, (5-12)) --- */

/* The 100 Hz 4th-order low-pass at 50 kHz as ONE transfer function (scipy's b, a): in
 * double its step response settles on 1; rounded to float, its denominator has a root
 * outside the unit circle (its coefficients need 1e-8 of 1 + sum(a) and float keeps
 * 5e-7 of a coefficient near 6), and the float direct form diverges. The float cascade
 * of the same filter settles on 1. */
static void test_direct_form_fails_in_float(void **state)
{
  (void)state;
  size_t rows = 0, cols = 0;
  double *ba = tv_load_csv("butter_0_ba.csv", &rows, &cols);
  assert_non_null(ba);
  assert_int_equal(rows, 5);
  assert_int_equal(cols, 2);
  double b[5], a[5];
  float bf[5], af[5];
  for (int i = 0; i < 5; i++) {
    b[i] = ba[2 * i];
    a[i] = ba[2 * i + 1];
    bf[i] = (float)b[i];
    af[i] = (float)a[i];
  }
  free(ba);

  double re[4], im[4], r_exact = 0.0, r_float = 0.0;
  assert_int_equal(iir_ref_poly_roots(a, 4, re, im), 4);
  for (int i = 0; i < 4; i++) r_exact = fmax(r_exact, hypot(re[i], im[i]));
  const double a32[5] = {af[0], af[1], af[2], af[3], af[4]};
  assert_int_equal(iir_ref_poly_roots(a32, 4, re, im), 4);
  for (int i = 0; i < 4; i++) r_float = fmax(r_float, hypot(re[i], im[i]));
  printf("direct form: largest pole radius %.6f exact, %.6f with float coefficients\n", r_exact,
         r_float);
  assert_true(r_exact < 1.0);
  assert_true(r_float > 1.0);

  /* Step responses, direct form II transposed, 4th order. */
  double sd[4] = {0}, yd = 0.0;
  float sf[4] = {0}, yf = 0.0f;
  biquad_coeffs_t c[2];
  assert_int_equal(butter_design(BUTTER_LOWPASS, 4, 100.0, 0.0, 50000.0, c, 2), 2);
  biquad_cascade_t bq;
  assert_int_equal(biquad_cascade_init(&bq, c, 2), 0);
  float yc = 0.0f;
  int diverged = 0;
  for (int n = 0; n < 100000; n++) {
    yd = b[0] + sd[0];
    for (int k = 0; k < 3; k++) sd[k] = b[k + 1] - a[k + 1] * yd + sd[k + 1];
    sd[3] = b[4] - a[4] * yd;
    yf = bf[0] + sf[0];
    for (int k = 0; k < 3; k++) sf[k] = bf[k + 1] - af[k + 1] * yf + sf[k + 1];
    sf[3] = bf[4] - af[4] * yf;
    if (!(fabsf(yf) < 1e6f)) diverged = 1;
    yc = biquad_cascade_step(&bq, 1.0f);
  }
  printf("step response after 2 s: direct form double %.9f, direct form float %g, float "
         "cascade %.9f\n",
         yd, (double)yf, (double)yc);
  assert_float_equal(yd, 1.0, 1e-6);
  assert_true(diverged);
  assert_float_equal(yc, 1.0, 2e-3);
}

/* ------------------------------------------------------- long run in float --- */

static uint64_t lcg = 0x9E3779B97F4A7C15ull;

/* Triangular dither (sum of two uniforms) with peak amplitude `peak`. */
static float dither(double peak)
{
  double u = 0.0;
  for (int k = 0; k < 2; k++) {
    lcg = lcg * 6364136223846793005ull + 1442695040888963407ull;
    u += (double)(lcg >> 11) / 9007199254740992.0 - 0.5;
  }
  return (float)(u * peak);
}

typedef struct {
  double err_all;     /* mean(y) / (G mean(x)) - 1 over the whole run */
  double worst_block; /* the same per block, largest magnitude */
  double first, last; /* first and last block */
  double excursion;   /* max |y - level| */
} long_run_t;

/* A DC level plus dither through the 4th-order 100 Hz low-pass at fs_hz, in float,
 * started in its steady state. G is the float filter's exact DC gain, in double. */
static long_run_t long_run(double fs_hz, float level, double peak, uint32_t blocks,
                           uint32_t per_block)
{
  biquad_coeffs_t c[2];
  assert_int_equal(butter_design(BUTTER_LOWPASS, 4, 100.0, 0.0, fs_hz, c, 2), 2);
  double g = 1.0;
  for (int i = 0; i < 2; i++) {
    g *= ((double)c[i].b0 + (double)c[i].b1 + (double)c[i].b2) /
         (1.0 + (double)c[i].a1 + (double)c[i].a2);
  }
  biquad_cascade_t bq;
  assert_int_equal(biquad_cascade_init(&bq, c, 2), 0);
  biquad_cascade_reset(&bq, level);
  long_run_t r = {0.0, 0.0, 0.0, 0.0, 0.0};
  double sx_all = 0.0, sy_all = 0.0;
  for (uint32_t blk = 0; blk < blocks; blk++) {
    double sx = 0.0, sy = 0.0;
    for (uint32_t i = 0; i < per_block; i++) {
      const float x = level + dither(peak);
      const float y = biquad_cascade_step(&bq, x);
      sx += (double)x;
      sy += (double)y;
      r.excursion = fmax(r.excursion, fabs((double)y - (double)level));
    }
    const double err = sy / (g * sx) - 1.0;
    r.worst_block = fmax(r.worst_block, fabs(err));
    if (blk == 0) r.first = err;
    r.last = err;
    sx_all += sx;
    sy_all += sy;
  }
  r.err_all = sy_all / (g * sx_all) - 1.0;
  return r;
}

/* The 100 Hz 4th-order low-pass at 50 kHz in float over 10^7 samples (200 s): a DC
 * level of 0.7 with triangular dither of +-0.1 peak. No drift, no divergence, and the
 * mean output equals the exact DC response (gain 1 times the mean input, in double)
 * within 1e-5 in every block of 10^6 samples and overall.
 * The dither must be this large at 50 kHz: each sample adds only b0 x = 4e-5 x to a
 * state of size x, so a dither much below ulp(x)/b0 = 1.5e-3 leaves the rounding of
 * that sum nearly constant, and 1/A(1) = 6400 turns it into a DC error (next test). */
static void test_long_run_dc_gain_and_no_drift(void **state)
{
  (void)state;
  const long_run_t r = long_run(50000.0, 0.7f, 0.1, 10u, 1000000u);
  printf("LP 100 Hz @ 50 kHz float, 1e7 samples, level 0.7 + dither 0.1 pk: DC gain error "
         "%.3g overall, worst block of 1e6 %.3g, first/last block %.3g/%.3g, max |y - level| "
         "%.3g\n",
         r.err_all, r.worst_block, r.first, r.last, r.excursion);
  assert_true(fabs(r.err_all) <= 1e-5);
  assert_true(r.worst_block <= 1e-5);
  assert_true(fabs(r.last - r.first) <= 1e-5);
  assert_true(r.excursion < 0.02);
}

/* With a nearly constant input (dither +-1e-3) the float cascade at 50 kHz has a
 * level-dependent DC error of order 1e-3: the rounding of the state updates no longer
 * averages out, and 1/A(1) amplifies it. It stays below the bound of the biquad test
 * (4 * 2^-24 * sum ||1/A_s||_1 = 4e-3). Run at 5 kHz (after decimation) the same
 * low-pass has A(1) 100 times larger and the error drops below 1e-5. */
static void test_dc_error_of_nearly_constant_input(void **state)
{
  (void)state;
  const float levels[] = {0.7f, 0.3f, 1.0f, -0.45f};
  double worst50 = 0.0, worst5 = 0.0;
  for (size_t i = 0; i < sizeof levels / sizeof levels[0]; i++) {
    const long_run_t a = long_run(50000.0, levels[i], 1e-3, 1u, 1000000u);
    const long_run_t b = long_run(5000.0, levels[i], 1e-3, 1u, 200000u);
    printf("LP 100 Hz, level %.2f + dither 1e-3 pk: DC gain error %.3g at 50 kHz, %.3g at 5 "
           "kHz\n",
           (double)levels[i], a.err_all, b.err_all);
    worst50 = fmax(worst50, fabs(a.err_all));
    worst5 = fmax(worst5, fabs(b.err_all));
  }
  assert_true(worst50 <= 4e-3);
  assert_true(worst5 <= 1e-5);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_f64_design_matches_scipy),
      cmocka_unit_test(test_float_design_matches_scipy),
      cmocka_unit_test(test_float_dc_gain_is_exact),
      cmocka_unit_test(test_bad_arguments_are_rejected_and_change_nothing),
      cmocka_unit_test(test_float_precision_limit),
      cmocka_unit_test(test_direct_form_fails_in_float),
      cmocka_unit_test(test_long_run_dc_gain_and_no_drift),
      cmocka_unit_test(test_dc_error_of_nearly_constant_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
