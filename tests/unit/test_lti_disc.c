#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "matexp_ref.h"
#include "plant/lti_disc.h"
#include "plant/rng.h"

static double max_abs_diff(int n, const double *a, const double *b)
{
  double m = 0.0;
  for (int i = 0; i < n * n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

/* exp([[0, w], [-w, 0]]) is the rotation [[cos w, sin w], [-sin w, cos w]], for
 * arguments that need no scaling, some and many squarings. */
static void test_rotation(void **state)
{
  (void)state;
  const double ws[] = {0.3, 5.0, 40.0};
  for (int k = 0; k < 3; k++) {
    const double w = ws[k];
    const double a[4] = {0.0, w, -w, 0.0};
    double e[4];
    assert_int_equal(lti_expm(2, a, e), 0);
    const double ref[4] = {cos(w), sin(w), -sin(w), cos(w)};
    assert_true(max_abs_diff(2, e, ref) < 1e-12 * (1.0 + w));
  }
}

/* The shift matrix is nilpotent: exp has 1/k! on the k-th superdiagonal. */
static void test_nilpotent(void **state)
{
  (void)state;
  double a[16] = {0}, e[16];
  for (int i = 0; i < 3; i++) a[i * 4 + i + 1] = 1.0;
  assert_int_equal(lti_expm(4, a, e), 0);
  const double fact[4] = {1.0, 1.0, 0.5, 1.0 / 6.0};
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      const double want = (j >= i) ? fact[j - i] : 0.0;
      assert_true(fabs(e[i * 4 + j] - want) < 1e-15);
    }
}

/* Random dense matrices up to the maximum size, against Eigen's Pade exponential. */
static void test_against_eigen(void **state)
{
  (void)state;
  rng_t r;
  rng_seed(&r, 2024u, 1u);
  for (int n = 1; n <= LTI_MAX_N; n++) {
    for (int rep = 0; rep < 3; rep++) {
      double a[LTI_MAX_N * LTI_MAX_N], e[LTI_MAX_N * LTI_MAX_N], ref[LTI_MAX_N * LTI_MAX_N];
      const double scale = (rep == 0) ? 0.1 : (rep == 1) ? 1.0 : 3.0;
      for (int i = 0; i < n * n; i++) a[i] = scale * rng_gauss(&r);
      assert_int_equal(lti_expm(n, a, e), 0);
      assert_int_equal(ref_matexp(n, a, ref), 0);
      double norm = 0.0;
      for (int i = 0; i < n * n; i++) norm = fmax(norm, fabs(ref[i]));
      assert_true(max_abs_diff(n, e, ref) < 1e-11 * norm);
    }
  }
}

/* A stiff block (the pickoff's lag pole at small phase: -T/tau ~ -2000) coupled to a slow
 * one, as in the plant's chains. */
static void test_stiff(void **state)
{
  (void)state;
  const double a[9] = {-2000.0, 0.0, 0.0, 2000.0, -0.01, 1.0, 0.0, -1.0, -1.4};
  double e[9], ref[9];
  assert_int_equal(lti_expm(3, a, e), 0);
  assert_int_equal(ref_matexp(3, a, ref), 0);
  assert_true(max_abs_diff(3, e, ref) < 1e-10);
}

/* Bad sizes and non-finite entries are refused and leave the output alone. */
static void test_bad_input(void **state)
{
  (void)state;
  double a[4] = {1.0, NAN, 0.0, 1.0};
  double e[4] = {7.0, 7.0, 7.0, 7.0};
  assert_int_equal(lti_expm(2, a, e), -1);
  for (int i = 0; i < 4; i++) assert_true(e[i] == 7.0);
  a[1] = INFINITY;
  assert_int_equal(lti_expm(2, a, e), -1);
  a[1] = 0.0;
  assert_int_equal(lti_expm(0, a, e), -1);
  assert_int_equal(lti_expm(LTI_MAX_N + 1, a, e), -1);
  for (int i = 0; i < 4; i++) assert_true(e[i] == 7.0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_rotation),      cmocka_unit_test(test_nilpotent),
      cmocka_unit_test(test_against_eigen), cmocka_unit_test(test_stiff),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
