/* The plant's matrix exponential (host_sim/plant/expm, [13/13] Pade with scaling and
 * squaring) against Eigen's MatrixFunctions (tests/reference/matexp_ref) and closed
 * forms, over the sizes and argument norms the plant uses (thermal network, DAC
 * reconstruction filter, pickoff chains: n <= EXPM_MAX_N, stiff). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "matexp_ref.h"
#include "plant/expm.h"
#include "plant/rng.h"

enum { NMAX = EXPM_MAX_N * EXPM_MAX_N };

static double max_abs_diff(int n, const double *a, const double *b)
{
  double m = 0.0;
  for (int i = 0; i < n * n; i++) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

static double max_abs(int n, const double *a)
{
  double m = 0.0;
  for (int i = 0; i < n * n; i++) m = fmax(m, fabs(a[i]));
  return m;
}

/* Random dense matrices of every size, norms from no scaling to many squarings. */
static void test_against_eigen(void **state)
{
  (void)state;
  rng_t g;
  rng_seed(&g, 42u, 7u);
  const double norms[] = {1e-3, 0.1, 0.5, 3.0, 40.0, 400.0};
  for (int n = 1; n <= EXPM_MAX_N; n++) {
    for (size_t ni = 0; ni < sizeof norms / sizeof norms[0]; ni++) {
      for (int rep = 0; rep < 3; rep++) {
        double a[NMAX], e[NMAX], r[NMAX];
        for (int i = 0; i < n * n; i++) a[i] = rng_gauss(&g) * norms[ni] / n;
        /* keep the spectrum in the left half plane for the large norms, as in the
         * plant (exp of a matrix with large positive eigenvalues is ill-conditioned
         * for both implementations) */
        if (norms[ni] > 10.0)
          for (int i = 0; i < n; i++) a[i * n + i] -= norms[ni];
        assert_int_equal(expm(n, a, e), 0);
        assert_int_equal(ref_matexp(n, a, r), 0);
        /* exp is conditioned like its argument: allow eps * ||A|| growth */
        /* (a 1x1 at -800 underflows to 0 in both: judged absolutely there) */
        const double err = max_abs_diff(n, e, r) / fmax(max_abs(n, r), 1e-200);
        const double tol = 1e-13 * (1.0 + norms[ni]);
        if (!(err < tol)) {
          printf("expm n=%d norm=%g rel err %.3e\n", n, norms[ni], err);
          fflush(stdout);
        }
        assert_true(err < tol);
      }
    }
  }
}

/* exp([[0, w], [-w, 0]]) is the rotation by w, for arguments that need no scaling, some
 * and many squarings. */
static void test_rotation(void **state)
{
  (void)state;
  const double ws[] = {0.3, 5.0, 37.3};
  for (int k = 0; k < 3; k++) {
    const double w = ws[k];
    const double a[4] = {0.0, w, -w, 0.0};
    double e[4];
    assert_int_equal(expm(2, a, e), 0);
    const double ref[4] = {cos(w), sin(w), -sin(w), cos(w)};
    assert_true(max_abs_diff(2, e, ref) < 1e-13 * (1.0 + w));
  }
}

/* The shift matrix is nilpotent: exp has 1/k! on the k-th superdiagonal. */
static void test_nilpotent(void **state)
{
  (void)state;
  double a[16] = {0}, e[16];
  for (int i = 0; i < 3; i++) a[i * 4 + i + 1] = 1.0;
  assert_int_equal(expm(4, a, e), 0);
  const double fact[4] = {1.0, 1.0, 0.5, 1.0 / 6.0};
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      const double want = (j >= i) ? fact[j - i] : 0.0;
      assert_true(fabs(e[i * 4 + j] - want) < 1e-15);
    }
}

/* A stiff block (the pickoff's lag pole at small phase: -T/tau ~ -2000) coupled to a slow
 * one, as in the plant's chains. */
static void test_stiff(void **state)
{
  (void)state;
  const double a[9] = {-2000.0, 0.0, 0.0, 2000.0, -0.01, 1.0, 0.0, -1.0, -1.4};
  double e[9], ref[9];
  assert_int_equal(expm(3, a, e), 0);
  assert_int_equal(ref_matexp(3, a, ref), 0);
  assert_true(max_abs_diff(3, e, ref) < 1e-12 * max_abs(3, ref));
}

/* Bad sizes, NULL pointers and non-finite entries are refused and leave the output
 * alone. */
static void test_bad_input(void **state)
{
  (void)state;
  double a[4] = {1.0, NAN, 0.0, 1.0};
  double e[4] = {7.0, 7.0, 7.0, 7.0};
  assert_int_equal(expm(2, a, e), -1);
  a[1] = INFINITY;
  assert_int_equal(expm(2, a, e), -1);
  a[1] = 0.0;
  a[0] = a[2] = 1e308; /* finite, but the column sum overflows */
  assert_int_equal(expm(2, a, e), -1);
  a[0] = a[2] = 0.0;
  assert_int_equal(expm(0, a, e), -1);
  assert_int_equal(expm(EXPM_MAX_N + 1, a, e), -1);
  assert_int_equal(expm(2, NULL, e), -1);
  for (int i = 0; i < 4; i++) assert_true(e[i] == 7.0);
  assert_int_equal(expm(2, a, NULL), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_against_eigen), cmocka_unit_test(test_rotation),
      cmocka_unit_test(test_nilpotent),     cmocka_unit_test(test_stiff),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
