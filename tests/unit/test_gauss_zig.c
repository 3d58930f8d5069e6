/* Ziggurat normal deviates (host_sim/plant/gauss_zig) against the normal law: the
 * committed table is the recursion's, bit for bit; it closes (equal layer areas); moments, the CDF at nine points against erf, both tails
 * (the tail path and the wedge path), lag-1 correlation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <math.h>
#include <cmocka.h>

#include "plant/gauss_zig.h"

/* The recursion of gauss_zig.h in C, as the generator (tools/gen_zig_table.py) runs it
 * in Python: the committed literals must be exactly these doubles. */
static void test_table_is_the_recursion(void **state)
{
  (void)state;
  const double r = 3.442619855899, v = 9.91256303526217e-3;
  const gauss_zig_t *t = &gauss_zig_table;
  double x = r, f = exp(-0.5 * r * r);
  assert_true(t->x[0] == v / f);
  assert_true(t->f[0] == f);
  assert_true(t->x[1] == x && t->f[1] == f);
  for (int i = 1; i < GAUSS_ZIG_LAYERS - 1; i++) {
    x = sqrt(-2.0 * log(v / x + f));
    f = exp(-0.5 * x * x);
    if (t->x[i + 1] != x || t->f[i + 1] != f)
      fail_msg("layer %d: table %a %a, recursion %a %a", i + 1, t->x[i + 1], t->f[i + 1], x, f);
  }
  assert_true(t->x[GAUSS_ZIG_LAYERS] == 0.0 && t->f[GAUSS_ZIG_LAYERS] == 1.0);
}

static void test_table(void **state)
{
  (void)state;
  const gauss_zig_t z = gauss_zig_table;
  const double v = 9.91256303526217e-3;
  /* every layer i >= 1 has area x[i] (f[i+1] - f[i]) = V; layer 0 (rectangle + tail)
   * too: x[0] f(R) = V by construction */
  for (int i = 1; i < GAUSS_ZIG_LAYERS; i++) {
    const double a = z.x[i] * (z.f[i + 1] - z.f[i]);
    /* R and V carry 13 digits; the recursion grows their error to ~1e-9 at the top */
    if (fabs(a / v - 1.0) > 1e-8) fail_msg("layer %d area %.12g", i, a);
    assert_true(z.x[i + 1] < z.x[i]);
  }
  /* base: rectangle up to R plus the tail integral beyond R */
  const double tail = sqrt(M_PI / 2.0) * erfc(z.x[1] / sqrt(2.0));
  assert_true(fabs((z.x[1] * z.f[1] + tail) / v - 1.0) < 1e-9);
}

static void test_distribution(void **state)
{
  (void)state;
  rng_t r;
  rng_seed(&r, 2024u, 5u);
  const long n = 4000000;
  const double pts[9] = {-3, -2, -1, -0.5, 0, 0.5, 1, 2, 3};
  long below[9] = {0}, t35 = 0, t40 = 0;
  double s1 = 0, s2 = 0, s4 = 0, sxy = 0, prev = 0;
  for (long k = 0; k < n; k++) {
    const double g = gauss_zig(&r);
    s1 += g;
    s2 += g * g;
    s4 += g * g * g * g;
    sxy += g * prev;
    prev = g;
    for (int j = 0; j < 9; j++) below[j] += g < pts[j];
    t35 += fabs(g) > 3.5;
    t40 += fabs(g) > 4.0;
  }
  const double mean = s1 / n, var = s2 / n - mean * mean, kurt = s4 / n / (var * var);
  printf("zig: mean %.2e var %.5f kurt %.4f lag1 %.2e, |x|>3.5 %ld, |x|>4 %ld\n", mean, var,
         kurt, sxy / n, t35, t40);
  assert_true(fabs(mean) < 5.0 / sqrt(n));
  assert_true(fabs(var - 1.0) < 5.0 * sqrt(2.0 / n));
  assert_true(fabs(kurt - 3.0) < 5.0 * sqrt(24.0 / n));
  assert_true(fabs(sxy / n) < 5.0 / sqrt(n));
  for (int j = 0; j < 9; j++) {
    const double p = 0.5 * erfc(-pts[j] / sqrt(2.0));
    const double sd = sqrt(n * p * (1 - p));
    if (fabs(below[j] - n * p) > 5.0 * sd)
      fail_msg("CDF at %g: %ld, expected %.0f", pts[j], below[j], n * p);
  }
  const double p35 = erfc(3.5 / sqrt(2.0)), p40 = erfc(4.0 / sqrt(2.0));
  assert_true(fabs(t35 - n * p35) < 5.0 * sqrt(n * p35));
  assert_true(fabs(t40 - n * p40) < 5.0 * sqrt(n * p40));
}

int main(void)
{
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_table_is_the_recursion),
                                     cmocka_unit_test(test_table),
                                     cmocka_unit_test(test_distribution)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
