#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include <math.h>

#include "dsp/multdemod.h"
#include "ref_signal.h"
#include "test_vectors.h"

#define FS_HZ 50000.0
#define FC_HZ 1750.0

/* The scipy-designed 4th-order 100 Hz Butterworth (tools/gen_demod_vectors.py). */
static uint32_t load_sections(biquad_coeffs_t *sec)
{
  size_t rows = 0, cols = 0;
  double *v = tv_load_csv("multdemod_lp_sos.csv", &rows, &cols);
  assert_non_null(v);
  assert_int_equal(cols, 5);
  assert_true(rows >= 1 && rows <= BIQUAD_MAX_SECTIONS);
  for (size_t i = 0; i < rows; i++) {
    sec[i] = (biquad_coeffs_t){(float)v[5 * i], (float)v[5 * i + 1], (float)v[5 * i + 2],
                               (float)v[5 * i + 3], (float)v[5 * i + 4]};
  }
  free(v);
  return (uint32_t)rows;
}

static void init_lp(multdemod_t *m)
{
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  const uint32_t n = load_sections(sec);
  assert_int_equal(multdemod_init(m, &(multdemod_cfg_t){sec, n}), 0);
}

/* Against scipy's sosfilt of 2 d sin and 2 d cos in double (amplitude steps + noise),
 * same float-rounded inputs and coefficients: relative RMS error below 3e-4 in both
 * channels. The residual (about 1e-4) is the float rounding noise of the cascade itself,
 * which a 100 Hz filter at 50 kHz amplifies (poles within 1e-2 of z = 1); a wrong
 * product, sign or channel would be off by order 1. */
static void test_matches_scipy_reference(void **state)
{
  (void)state;
  multdemod_t m;
  init_lp(&m);
  size_t rows = 0, cols = 0;
  double *v = tv_load_csv("multdemod_ref.csv", &rows, &cols);
  assert_non_null(v);
  assert_int_equal(cols, 5);
  assert_true(rows > 1000);
  double ei = 0.0, eq = 0.0, ri = 0.0, rq = 0.0;
  for (size_t k = 0; k < rows; k++) {
    const double *r = &v[5 * k];
    multdemod_step(&m, (float)r[0], (float)r[1], (float)r[2]);
    ei += pow(multdemod_in_phase(&m) - r[3], 2);
    eq += pow(multdemod_quadrature(&m) - r[4], 2);
    ri += r[3] * r[3];
    rq += r[4] * r[4];
  }
  print_message("relative RMS error vs scipy: in-phase %.2e, quadrature %.2e\n", sqrt(ei / ri),
                sqrt(eq / rq));
  assert_true(sqrt(ei / ri) < 3e-4);
  assert_true(sqrt(eq / rq) < 3e-4);
  free(v);
}

/* Noisy constant amplitudes: after the low-pass transient the outputs average to
 * [A1, A2]; the 2 wc ripple is below 1e-6 of the amplitude after this low-pass. */
static void test_converges_to_true_amplitudes(void **state)
{
  (void)state;
  const double a1 = 0.01, a2 = -0.004;
  multdemod_t m;
  init_lp(&m);
  ref_rng_t g;
  ref_rng_seed(&g, 41u);
  double sum_i = 0.0, sum_q = 0.0;
  const uint64_t n = 60000u, skip = 5000u;
  for (uint64_t k = 0; k < n; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    const double d = a1 * rs + a2 * rc + 0.002 * ref_rng_gauss(&g);
    multdemod_step(&m, (float)d, (float)rs, (float)rc);
    if (k >= skip) {
      sum_i += multdemod_in_phase(&m);
      sum_q += multdemod_quadrature(&m);
    }
  }
  assert_true(fabs(sum_i / (double)(n - skip) - a1) < 1e-4);
  assert_true(fabs(sum_q / (double)(n - skip) - a2) < 1e-4);
}

/* Without sections the outputs are the raw products 2 d sin, 2 d cos, which carry
 * the full amplitude at 2 wc. */
static void test_no_lowpass_gives_raw_products(void **state)
{
  (void)state;
  multdemod_t m;
  assert_int_equal(multdemod_init(&m, &(multdemod_cfg_t){NULL, 0u}), 0);
  double max_i = -1.0, min_i = 1.0;
  for (uint64_t k = 0; k < 2000u; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    const float d = (float)(0.01 * rs);
    multdemod_step(&m, d, (float)rs, (float)rc);
    assert_true(multdemod_in_phase(&m) == 2.0f * d * (float)rs);
    assert_true(multdemod_quadrature(&m) == 2.0f * d * (float)rc);
    max_i = fmax(max_i, multdemod_in_phase(&m));
    min_i = fmin(min_i, multdemod_in_phase(&m));
  }
  /* A1 (1 - cos 2wc k): swings between 0 and 2 A1 */
  assert_true(max_i > 0.0199 && min_i < 0.0001);
}

/* Reset to known amplitudes: no start-up transient of the amplitude on a constant
 * input. What remains is the low-pass's response to the 2 wc ripple switching on (about
 * 1 % of the ripple amplitude A1 = 0.01 for this 100 Hz filter), gone after 20 ms; a
 * cleared filter would instead start 100 % off. */
static void test_reset_presets_steady_state(void **state)
{
  (void)state;
  multdemod_t m;
  init_lp(&m);
  assert_int_equal(multdemod_reset(&m, 0.01f, 0.003f), 0);
  for (uint64_t k = 0; k < 5000u; k++) {
    double rs, rc;
    ref_carrier(k, FC_HZ, FS_HZ, &rs, &rc);
    multdemod_step(&m, (float)(0.01 * rs + 0.003 * rc), (float)rs, (float)rc);
    const float tol = (k < 1000u) ? 1.5e-4f : 5e-6f;
    assert_true(fabsf(multdemod_in_phase(&m) - 0.01f) < tol);
    assert_true(fabsf(multdemod_quadrature(&m) - 0.003f) < tol);
  }
  const multdemod_t before = m;
  assert_int_equal(multdemod_reset(&m, NAN, 0.0f), -1);
  assert_int_equal(multdemod_reset(NULL, 0.0f, 0.0f), -1);
  assert_memory_equal(&m, &before, sizeof m);
  assert_int_equal(multdemod_reset(&m, 0.0f, 0.0f), 0);
  assert_true(multdemod_in_phase(&m) == 0.0f && m.lp_i.state[0].s1 == 0.0f);
}

static void test_bad_config_rejected_unchanged(void **state)
{
  (void)state;
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS + 1];
  const uint32_t n = load_sections(sec);
  multdemod_t m;
  memset(&m, 0x3C, sizeof m);
  const multdemod_t sentinel = m;
  assert_int_equal(multdemod_init(&m, NULL), -1);
  assert_int_equal(multdemod_init(NULL, &(multdemod_cfg_t){sec, n}), -1);
  assert_int_equal(multdemod_init(&m, &(multdemod_cfg_t){NULL, 2u}), -1);
  for (uint32_t i = n; i <= BIQUAD_MAX_SECTIONS; i++) {
    sec[i] = sec[0];
  }
  assert_int_equal(multdemod_init(&m, &(multdemod_cfg_t){sec, BIQUAD_MAX_SECTIONS + 1u}), -1);
  sec[1].a1 = NAN;
  assert_int_equal(multdemod_init(&m, &(multdemod_cfg_t){sec, n}), -1);
  sec[1].a1 = 0.0f;
  sec[0].b0 = INFINITY;
  assert_int_equal(multdemod_init(&m, &(multdemod_cfg_t){sec, n}), -1);
  assert_memory_equal(&m, &sentinel, sizeof m);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_matches_scipy_reference),
      cmocka_unit_test(test_converges_to_true_amplitudes),
      cmocka_unit_test(test_no_lowpass_gives_raw_products),
      cmocka_unit_test(test_reset_presets_steady_state),
      cmocka_unit_test(test_bad_config_rejected_unchanged),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
