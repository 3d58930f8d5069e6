/* biquad cascade (TDF-II, float) against scipy.signal.sosfilt vectors
 * (tools/gen_filter_vectors.py) and a long-double direct-form-I reference. */
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
#include "iir_ref.h"
#include "test_vectors.h"

typedef struct {
  size_t n_sections;
  double sos[6 * BIQUAD_MAX_SECTIONS];      /* scipy's coefficients, double */
  biquad_coeffs_t f32[BIQUAD_MAX_SECTIONS]; /* the same rounded to float */
  double sos32[6 * BIQUAD_MAX_SECTIONS];    /* the rounded ones back in double */
  size_t n;
  double *x, *y, *y32; /* input (float values), sosfilt(sos), sosfilt(rounded sos) */
} design_t;

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
  char name[64];
  size_t rows = 0, cols = 0;
  snprintf(name, sizeof name, "butter_%zu_sos.csv", idx);
  double *sos = tv_load_csv(name, &rows, &cols);
  assert_non_null(sos);
  assert_int_equal(cols, 6);
  assert_true(rows >= 1 && rows <= BIQUAD_MAX_SECTIONS);
  d->n_sections = rows;
  for (size_t s = 0; s < rows; s++) {
    const double *r = &sos[6 * s];
    assert_true(r[3] == 1.0);
    memcpy(&d->sos[6 * s], r, 6 * sizeof(double));
    const biquad_coeffs_t c = {(float)r[0], (float)r[1], (float)r[2], (float)r[4], (float)r[5]};
    d->f32[s] = c;
  }
  free(sos);
  /* A separate pass from the stored floats: GCC 12.2 at -O2 on x86-64 (SLP vectorizer)
   * drops the double -> float -> double rounding when the float struct is built and
   * widened again in one go. */
  for (size_t s = 0; s < rows; s++) {
    const biquad_coeffs_t *c = &d->f32[s];
    double *o = &d->sos32[6 * s];
    o[0] = c->b0;
    o[1] = c->b1;
    o[2] = c->b2;
    o[3] = 1.0;
    o[4] = c->a1;
    o[5] = c->a2;
  }
  for (size_t i = 0; i < 6 * rows; i++) assert_true(d->sos32[i] == (double)(float)d->sos32[i]);
  snprintf(name, sizeof name, "butter_%zu_time.csv", idx);
  double *t = tv_load_csv(name, &rows, &cols);
  assert_non_null(t);
  assert_int_equal(cols, 3);
  d->n = rows;
  d->x = malloc(rows * sizeof(double));
  d->y = malloc(rows * sizeof(double));
  d->y32 = malloc(rows * sizeof(double));
  assert_non_null(d->x);
  assert_non_null(d->y);
  assert_non_null(d->y32);
  for (size_t i = 0; i < rows; i++) {
    d->x[i] = (double)(float)t[3 * i]; /* the generator wrote float32 values */
    d->y[i] = t[3 * i + 1];
    d->y32[i] = t[3 * i + 2];
  }
  free(t);
}

static void free_design(design_t *d)
{
  free(d->x);
  free(d->y);
  free(d->y32);
}

static double max_abs(const double *v, size_t n)
{
  double m = 0.0;
  for (size_t i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* Largest error relative to the largest reference sample. */
static double rel_err(const float *got, const double *ref, size_t from, size_t to)
{
  double e = 0.0;
  for (size_t i = from; i < to; i++) e = fmax(e, fabs((double)got[i] - ref[i]));
  return e / max_abs(ref, to);
}

/* Error bound of the float recursion. Each TDF-II step rounds the state updates, whose
 * terms are about 2|y| (a1 is near -2), and 1/A(z) of the section carries those errors
 * to the output; their amplification is at most the l1 norm of the impulse response of
 * 1/A(z) (6400 for each section of the 100 Hz low-pass at 50 kHz, where
 * 1 + a1 + a2 = 1.6e-4). Bound relative to the largest output:
 *     4 * 2^-24 * sum over sections of ||1/A_s||_1. */
static double arith_tol(const biquad_coeffs_t *c, size_t n_sections)
{
  double k = 0.0;
  for (size_t s = 0; s < n_sections; s++) {
    double h1 = 0.0, h2 = 0.0, sum = 0.0;
    for (long i = 0; i < 4000000; i++) {
      const double h = (i == 0 ? 1.0 : 0.0) - (double)c[s].a1 * h1 - (double)c[s].a2 * h2;
      h2 = h1;
      h1 = h;
      sum += fabs(h);
      if (i > 100 && fabs(h) + fabs(h2) < 1e-13 * sum) break;
    }
    k += sum;
  }
  return 4.0 * ldexp(1.0, -24) * k;
}

static void test_matches_sosfilt_vectors(void **state)
{
  (void)state;
  const size_t nd = n_designs();
  for (size_t k = 0; k < nd; k++) {
    design_t d;
    load_design(k, &d);
    biquad_cascade_t bq;
    assert_int_equal(biquad_cascade_init(&bq, d.f32, (uint32_t)d.n_sections), 0);
    float *out = malloc(d.n * sizeof *out);
    assert_non_null(out);
    for (size_t i = 0; i < d.n; i++) out[i] = biquad_cascade_step(&bq, (float)d.x[i]);

    /* scipy's own double output of the rounded coefficients vs an independent
     * long-double DF-I of the same: the vectors are what they claim. */
    double *ref = malloc(d.n * sizeof *ref);
    assert_non_null(ref);
    iir_ref_sos_filter(d.sos32, d.n_sections, d.x, ref, d.n);
    double e_ref = 0.0;
    for (size_t i = 0; i < d.n; i++) e_ref = fmax(e_ref, fabs(ref[i] - d.y32[i]));
    if (!(e_ref <= 1e-12 * max_abs(d.y32, d.n)))
      fail_msg("design %zu: vectors off by %.3g", k, e_ref);

    const double e = rel_err(out, d.y32, 0, d.n);
    const double e_exact = rel_err(out, d.y, 0, d.n);
    const double tol = arith_tol(d.f32, d.n_sections);
    printf("design %zu: float cascade vs sosfilt(float coeffs) %.3g (bound %.3g), vs "
           "sosfilt(exact coeffs) %.3g (relative to max |y|)\n",
           k, e, tol, e_exact);
    assert_true(e <= tol);
    free(out);
    free(ref);
    free_design(&d);
  }
}

/* Filtering in two halves with the same cascade equals the reference: the state
 * carries over. Restarting the second half from a cleared state does not, which shows
 * the test would see lost state. */
static void test_state_carries_over_two_halves(void **state)
{
  (void)state;
  const size_t nd = n_designs();
  for (size_t k = 0; k < nd; k++) {
    design_t d;
    load_design(k, &d);
    const size_t half = d.n / 2;
    biquad_cascade_t bq, fresh;
    float *out = malloc(d.n * sizeof *out), *lost = malloc(d.n * sizeof *lost);
    assert_non_null(out);
    assert_non_null(lost);
    assert_int_equal(biquad_cascade_init(&bq, d.f32, (uint32_t)d.n_sections), 0);
    for (size_t i = 0; i < half; i++) out[i] = biquad_cascade_step(&bq, (float)d.x[i]);
    memcpy(lost, out, half * sizeof *out);
    assert_int_equal(biquad_cascade_init(&fresh, d.f32, (uint32_t)d.n_sections), 0);
    for (size_t i = half; i < d.n; i++) {
      out[i] = biquad_cascade_step(&bq, (float)d.x[i]);
      lost[i] = biquad_cascade_step(&fresh, (float)d.x[i]);
    }
    const double e_kept = rel_err(out, d.y32, half, d.n);
    const double e_lost = rel_err(lost, d.y32, half, half + 20);
    assert_true(e_kept <= arith_tol(d.f32, d.n_sections));
    assert_true(e_lost > 1e-2 && e_lost > 10.0 * e_kept);
    free(out);
    free(lost);
    free_design(&d);
  }
}

/* DC gain of float coefficients, evaluated exactly in double. */
static double dc_gain(const biquad_coeffs_t *c, size_t n)
{
  double g = 1.0;
  for (size_t s = 0; s < n; s++) {
    g *= ((double)c[s].b0 + (double)c[s].b1 + (double)c[s].b2) /
         (1.0 + (double)c[s].a1 + (double)c[s].a2);
  }
  return g;
}

/* After biquad_cascade_reset(x0), a constant input x0 gives the steady output H(1) x0
 * from the first sample: no start-up transient. Without the preset the output starts
 * at 0 (the test can tell the difference). */
static void test_steady_state_reset_has_no_transient(void **state)
{
  (void)state;
  const size_t nd = n_designs();
  const float levels[] = {1.0f, -0.37f, 2.5f};
  for (size_t k = 0; k < nd; k++) {
    design_t d;
    load_design(k, &d);
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
      const float x0 = levels[l];
      const double y0 = dc_gain(d.f32, d.n_sections) * (double)x0;
      biquad_cascade_t bq;
      assert_int_equal(biquad_cascade_init(&bq, d.f32, (uint32_t)d.n_sections), 0);
      biquad_cascade_reset(&bq, x0);
      double worst = 0.0;
      for (int i = 0; i < 20000; i++) {
        worst = fmax(worst, fabs((double)biquad_cascade_step(&bq, x0) - y0));
      }
      /* The float recursion settles on its own fixed point, which differs from the exact
       * steady state by the rounding errors of one step amplified by 1/A(1): up to 8e-4
       * for the 100 Hz low-pass at 50 kHz (a constant input does not dither the
       * rounding). Bound as in arith_tol, relative to the larger of input and output. */
      const double scale = fmax(fabs(y0), fabs((double)x0));
      if (worst > arith_tol(d.f32, d.n_sections) * scale) {
        fail_msg("design %zu, x0 %g: deviation %.3g from %.9g", k, (double)x0, worst, y0);
      }
      /* Clearing instead: the step response, a transient of the order of x0. */
      biquad_cascade_reset(&bq, 0.0f);
      double transient = 0.0;
      for (int i = 0; i < 20000; i++) {
        transient = fmax(transient, fabs((double)biquad_cascade_step(&bq, x0) - y0));
      }
      assert_true(transient > 0.1 * fabs((double)x0));
      assert_true(transient > 20.0 * worst);
    }
    free_design(&d);
  }
}

static void test_init_rejects_bad_arguments_and_changes_nothing(void **state)
{
  (void)state;
  const biquad_coeffs_t good[2] = {{0.1f, 0.2f, 0.1f, -0.5f, 0.2f},
                                   {1.0f, 0.0f, -1.0f, 0.1f, 0.3f}};
  biquad_cascade_t bq;
  memset(&bq, 0x5A, sizeof bq);
  const biquad_cascade_t before = bq;

  assert_int_equal(biquad_cascade_init(NULL, good, 2), -1);
  assert_int_equal(biquad_cascade_init(&bq, NULL, 2), -1);
  assert_int_equal(biquad_cascade_init(&bq, good, 0), -1);
  assert_int_equal(biquad_cascade_init(&bq, good, BIQUAD_MAX_SECTIONS + 1u), -1);
  assert_memory_equal(&bq, &before, sizeof bq);

  const float bad_values[] = {NAN, INFINITY, -INFINITY};
  for (size_t v = 0; v < 3; v++) {
    for (size_t s = 0; s < 2; s++) {
      for (size_t f = 0; f < 5; f++) {
        biquad_coeffs_t c[2] = {good[0], good[1]};
        float *fields[5] = {&c[s].b0, &c[s].b1, &c[s].b2, &c[s].a1, &c[s].a2};
        *fields[f] = bad_values[v];
        assert_int_equal(biquad_cascade_init(&bq, c, 2), -1);
        assert_memory_equal(&bq, &before, sizeof bq);
      }
    }
  }

  /* A good init takes the sections and clears the state left by earlier use. */
  assert_int_equal(biquad_cascade_init(&bq, good, 2), 0);
  assert_int_equal(bq.num_sections, 2);
  for (int i = 0; i < 10; i++) (void)biquad_cascade_step(&bq, 1.0f);
  assert_int_equal(biquad_cascade_init(&bq, good, 2), 0);
  assert_true(biquad_cascade_step(&bq, 0.0f) == 0.0f);
  assert_true(bq.state[0].s1 == 0.0f && bq.state[1].s2 == 0.0f);
}

/* reset ignores NULL, and a non-finite level clears the state instead of poisoning it. */
static void test_reset_survives_bad_arguments(void **state)
{
  (void)state;
  biquad_cascade_reset(NULL, 1.0f);
  const biquad_coeffs_t c = {0.25f, 0.5f, 0.25f, -1.5f, 0.6f};
  biquad_cascade_t bq;
  assert_int_equal(biquad_cascade_init(&bq, &c, 1), 0);
  const float bad[] = {NAN, INFINITY, -INFINITY};
  for (size_t i = 0; i < 3; i++) {
    biquad_cascade_reset(&bq, 2.0f);
    biquad_cascade_reset(&bq, bad[i]);
    assert_true(bq.state[0].s1 == 0.0f && bq.state[0].s2 == 0.0f);
    assert_true(biquad_cascade_step(&bq, 0.0f) == 0.0f);
  }
}

/* A section equation check that does not rely on scipy: the impulse response of one
 * section is b0, b1 - a1 b0, ... (long division of B(z)/A(z)). */
static void test_impulse_response_of_one_section(void **state)
{
  (void)state;
  const biquad_coeffs_t c = {0.5f, -0.25f, 0.125f, -0.75f, 0.5f};
  biquad_cascade_t bq;
  assert_int_equal(biquad_cascade_init(&bq, &c, 1), 0);
  double h[16] = {0};
  const double b[3] = {0.5, -0.25, 0.125};
  for (int n = 0; n < 16; n++) {
    double v = (n < 3) ? b[n] : 0.0;
    if (n >= 1) v -= -0.75 * h[n - 1];
    if (n >= 2) v -= 0.5 * h[n - 2];
    h[n] = v;
  }
  for (int n = 0; n < 16; n++) {
    assert_float_equal(biquad_cascade_step(&bq, n == 0 ? 1.0f : 0.0f), h[n], 1e-6);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_matches_sosfilt_vectors),
      cmocka_unit_test(test_state_carries_over_two_halves),
      cmocka_unit_test(test_steady_state_reset_has_no_transient),
      cmocka_unit_test(test_init_rejects_bad_arguments_and_changes_nothing),
      cmocka_unit_test(test_reset_survives_bad_arguments),
      cmocka_unit_test(test_impulse_response_of_one_section),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
