/* Q against temperature (host_sim/plant/qlaw.h): the material laws against published
 * values, the factors' sizes, the ranges. The laws acting on the mechanics' ring-down:
 * test_mech_effects. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/qlaw.h"

/* Sutherland's air viscosity against the table of F. P. Incropera et al., Fundamentals
 * of Heat and Mass Transfer (table A.4, 1e-7 N s/m^2: 250 K 159.6, 300 K 184.6, 350 K
 * 208.2, 400 K 230.1), as ratios to 300 K: within 1 %. Silicon's expansion coefficient
 * 2.57e-6 /K at 300 K (Okada & Tokumaru), its conductivity ratio 200 K / 300 K 1.69
 * (Glassbrenner & Slack: 264 / 156 W/(m K)) within 3 %. */
static void test_material_laws(void **state)
{
  (void)state;
  const double t[4] = {250.0, 300.0, 350.0, 400.0}, mu[4] = {159.6, 184.6, 208.2, 230.1};
  for (int i = 0; i < 4; i++) {
    const double r = qlaw_air_viscosity_rel(t[i]) / qlaw_air_viscosity_rel(300.0);
    assert_true(fabs(r / (mu[i] / mu[1]) - 1.0) < 0.01);
  }
  assert_true(fabs(qlaw_air_viscosity_rel(298.15) - 1.0) < 1e-15);
  assert_true(fabs(qlaw_si_expansion_per_k(300.0) / 2.568e-6 - 1.0) < 1e-3);
  assert_true(
      fabs(qlaw_si_conductivity_rel(200.0) / qlaw_si_conductivity_rel(300.0) / (264.0 / 156.0) -
           1.0) < 0.03);
  /* d ln mu / d ln T = 3/2 - T / (T + S): 0.77 at 298 K, the T^0.7 of the power law */
  const double h = 0.01, t0 = 298.15;
  const double slope = (log(qlaw_air_viscosity_rel(t0 + h)) -
                        log(qlaw_air_viscosity_rel(t0 - h))) /
                       (log(t0 + h) - log(t0 - h));
  assert_true(fabs(slope - (1.5 - t0 / (t0 + QLAW_AIR_SUTHERLAND_K))) < 1e-6);
}

/* The factors: exactly 1 for the constant law (and at T0 for the others); the gas law
 * -0.26 %/K at 25 degC, the thermoelastic law -1.4 %/K, 0.48 at 85 degC and 3.2 at
 * -40 degC (qlaw.h); each times wn(T)/wn(T0) or its inverse cube. */
static void test_factors(void **state)
{
  (void)state;
  const double t0 = 298.15;
  int out = 7;
  assert_true(qlaw_factor(QLAW_CONST, 1e4, t0, 0.5, &out) == 1.0 && out == 0);
  assert_true(qlaw_factor(QLAW_GAS, t0, t0, 1.0, NULL) == 1.0);
  assert_true(fabs(qlaw_factor(QLAW_TED, t0, t0, 1.0, NULL) - 1.0) < 1e-15);
  const double g = qlaw_factor(QLAW_GAS, t0 + 1.0, t0, 1.0, NULL) - 1.0;
  const double e = qlaw_factor(QLAW_TED, t0 + 1.0, t0, 1.0, NULL) - 1.0;
  print_message("per kelvin at 25 degC: gas %+.4f %%, thermoelastic %+.4f %%\n", 100 * g,
                100 * e);
  assert_true(fabs(g + 0.0026) < 0.0001);
  assert_true(fabs(e + 0.0142) < 0.0005);
  assert_true(fabs(qlaw_factor(QLAW_TED, 358.15, t0, 1.0, NULL) - 0.480) < 0.001);
  assert_true(fabs(qlaw_factor(QLAW_TED, 233.15, t0, 1.0, NULL) - 3.199) < 0.001);
  const double r = 0.999;
  assert_true(fabs(qlaw_factor(QLAW_GAS, 300.0, t0, r, NULL) /
                       qlaw_factor(QLAW_GAS, 300.0, t0, 1.0, NULL) -
                   r) < 1e-15);
  assert_true(fabs(qlaw_factor(QLAW_TED, 300.0, t0, r, NULL) /
                       qlaw_factor(QLAW_TED, 300.0, t0, 1.0, NULL) -
                   1.0 / (r * r * r)) < 1e-14);
}

/* Each law holds over -40..85 degC; outside its range it is held at the edge, flagged. */
static void test_ranges(void **state)
{
  (void)state;
  const double t0 = 298.15;
  for (int law = QLAW_GAS; law <= QLAW_TED; law++) {
    const double lo = law == QLAW_GAS ? QLAW_GAS_T_MIN_K : QLAW_TED_T_MIN_K;
    const double hi = law == QLAW_GAS ? QLAW_GAS_T_MAX_K : QLAW_TED_T_MAX_K;
    int out = 1;
    (void)qlaw_factor(law, 233.15, t0, 1.0, &out);
    assert_int_equal(out, 0);
    (void)qlaw_factor(law, 358.15, t0, 1.0, &out);
    assert_int_equal(out, 0);
    const double edge = qlaw_factor(law, lo, t0, 1.0, NULL);
    assert_true(qlaw_factor(law, lo - 50.0, t0, 1.0, &out) == edge && out == 1);
    const double top = qlaw_factor(law, hi, t0, 1.0, NULL);
    assert_true(qlaw_factor(law, hi + 50.0, t0, 1.0, &out) == top && out == 1);
    (void)qlaw_factor(law, NAN, t0, 1.0, &out);
    assert_int_equal(out, 1);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_material_laws),
      cmocka_unit_test(test_factors),
      cmocka_unit_test(test_ranges),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
