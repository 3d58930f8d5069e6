/* Three-node thermal network (host_sim/plant/thermal) against analytic step responses
 * and, for the general coupled case and the power-on warm-up of a cold start, the closed
 * form T(t) = Tss + exp(-L t)(T0 - Tss) evaluated with Eigen at each time (not stepped). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/thermal.h"
#include "expm_ref.h"

/* Uncoupled nodes, ambient step at t = 0: T_i(t) = Ta + r_i + (T_i(0) - Ta - r_i)
 * exp(-t / tau_i). */
static void test_uncoupled_step(void **state)
{
  (void)state;
  thermal_cfg_t c;
  thermal_default_cfg(&c);
  c.couple_per_s[0] = c.couple_per_s[1] = c.couple_per_s[2] = 0.0;
  c.dt_s = 0.01;
  static thermal_t th;
  assert_int_equal(thermal_init(&th, &c, 300.0), 0);
  for (int i = 0; i < 3; i++)
    assert_true(fabs(thermal_temp(&th, i) - (300.0 + c.rise_k[i])) < 1e-9);
  const double ta = 330.0;
  double worst = 0.0;
  for (int k = 1; k <= 100000; k++) { /* 1000 s */
    thermal_step(&th, ta);
    const double t = k * c.dt_s;
    for (int i = 0; i < 3; i++) {
      const double want = ta + c.rise_k[i] + (300.0 - ta) * exp(-t / c.tau_s[i]);
      worst = fmax(worst, fabs(thermal_temp(&th, i) - want));
    }
  }
  printf("uncoupled step: worst error %.2e K\n", worst);
  assert_true(worst < 1e-9);
}

/* Two equal nodes coupled at rate g, the third far away: the mean follows the ambient
 * with tau, the difference decays with 1/tau + 2 g. */
static void test_two_node_modes(void **state)
{
  (void)state;
  thermal_cfg_t c;
  thermal_default_cfg(&c);
  const double tau = 200.0, g = 0.02;
  c.tau_s[0] = c.tau_s[1] = tau;
  c.rise_k[0] = c.rise_k[1] = c.rise_k[2] = 0.0;
  c.couple_per_s[THERMAL_PAIR_SC] = g;
  c.couple_per_s[THERMAL_PAIR_SB] = 0.0;
  c.couple_per_s[THERMAL_PAIR_CB] = 0.0;
  c.dt_s = 1e-3;
  static thermal_t th;
  assert_int_equal(thermal_init(&th, &c, 290.0), 0);
  const double t0[3] = {310.0, 290.0, 290.0};
  thermal_set(&th, t0);
  const double ta = 300.0;
  double worst = 0.0;
  for (int k = 1; k <= 200000; k++) { /* 200 s */
    thermal_step(&th, ta);
    const double t = k * c.dt_s;
    const double mean = ta + (300.0 - ta) * exp(-t / tau); /* initial mean 300 */
    const double diff = 20.0 * exp(-t * (1.0 / tau + 2.0 * g));
    worst = fmax(worst, fabs(thermal_temp(&th, 0) - (mean + 0.5 * diff)));
    worst = fmax(worst, fabs(thermal_temp(&th, 1) - (mean - 0.5 * diff)));
  }
  printf("two-node modes: worst error %.2e K\n", worst);
  assert_true(worst < 1e-9);
}

/* General coupled network with self-heating: closed form against the stepped state,
 * and the steady state solves L T = b Ta + h. */
static void test_general_network(void **state)
{
  (void)state;
  const thermal_preset_t presets[3] = {THERMAL_PRESET_DEFAULT, THERMAL_PRESET_TIGHT,
                                       THERMAL_PRESET_LOOSE};
  for (int p = 0; p < 3; p++) {
    thermal_cfg_t c;
    thermal_preset(&c, presets[p]);
    static thermal_t th;
    assert_int_equal(thermal_init(&th, &c, 296.0), 0);
    /* build L, b, h here from the equations in thermal.h */
    const double *g = c.couple_per_s;
    const double gm[3][3] = {{0, g[0], g[1]}, {g[0], 0, g[2]}, {g[1], g[2], 0}};
    double l[9], rhs[3];
    const double ta = 340.0;
    for (int i = 0; i < 3; i++) {
      double s = 0;
      for (int j = 0; j < 3; j++) {
        l[i * 3 + j] = -gm[i][j];
        s += gm[i][j];
      }
      l[i * 3 + i] = 1.0 / c.tau_s[i] + s;
      rhs[i] = (ta + c.rise_k[i]) / c.tau_s[i];
    }
    double tss[3];
    thermal_steady(&c, ta, tss);
    for (int i = 0; i < 3; i++) {
      const double r = l[i * 3 + 0] * tss[0] + l[i * 3 + 1] * tss[1] + l[i * 3 + 2] * tss[2];
      assert_true(fabs(r - rhs[i]) < 1e-12);
    }
    double t0[3];
    for (int i = 0; i < 3; i++) t0[i] = thermal_temp(&th, i);
    double worst = 0.0;
    const int stride = 50000; /* compare every 50 s over 2000 s */
    for (int k = 1; k <= 2000000; k++) {
      thermal_step(&th, ta);
      if (k % stride) continue;
      const double t = k * c.dt_s;
      double a[9], e[9];
      for (int i = 0; i < 9; i++) a[i] = -l[i] * t;
      assert_int_equal(expm_ref(3, a, e), 0);
      for (int i = 0; i < 3; i++) {
        double want = tss[i];
        for (int j = 0; j < 3; j++) want += e[i * 3 + j] * (t0[j] - tss[j]);
        worst = fmax(worst, fabs(thermal_temp(&th, i) - want));
      }
    }
    printf("preset %d: worst error %.2e K over 2000 s in 1 ms steps\n", p, worst);
    assert_true(worst < 1e-8);
  }
}

/* A mid-interval ambient makes a ramp exact to second order: for a single node the
 * ramp response is Ta(t) - k tau (1 - exp(-t/tau)) (+ start transient). */
static void test_ramp_midpoint(void **state)
{
  (void)state;
  thermal_cfg_t c;
  thermal_default_cfg(&c);
  c.couple_per_s[0] = c.couple_per_s[1] = c.couple_per_s[2] = 0.0;
  c.rise_k[0] = c.rise_k[1] = c.rise_k[2] = 0.0;
  static thermal_t th;
  assert_int_equal(thermal_init(&th, &c, 300.0), 0);
  const double slope = 0.05, tau = c.tau_s[0]; /* K/s */
  double worst = 0.0;
  for (int k = 0; k < 600000; k++) {
    thermal_step(&th, 300.0 + slope * (k + 0.5) * c.dt_s);
    const double t = (k + 1) * c.dt_s;
    const double want = 300.0 + slope * t - slope * tau * (1.0 - exp(-t / tau));
    worst = fmax(worst, fabs(thermal_temp(&th, 0) - want));
  }
  printf("ramp, midpoint ambient: worst error %.2e K\n", worst);
  assert_true(worst < 1e-9);
}

/* During a chamber ramp, tight coupling keeps the nodes together, loose does not. */
static void test_presets_differ(void **state)
{
  (void)state;
  double spread[2];
  const thermal_preset_t pr[2] = {THERMAL_PRESET_TIGHT, THERMAL_PRESET_LOOSE};
  for (int p = 0; p < 2; p++) {
    thermal_cfg_t c;
    thermal_preset(&c, pr[p]);
    c.rise_k[0] = c.rise_k[1] = c.rise_k[2] = 0.0;
    c.dt_s = 0.1;
    static thermal_t th;
    assert_int_equal(thermal_init(&th, &c, 300.0), 0);
    spread[p] = 0.0;
    for (int k = 0; k < 6000; k++) { /* 10 min at 2 K/min */
      thermal_step(&th, 300.0 + 2.0 / 60.0 * (k + 0.5) * c.dt_s);
      const double a = thermal_temp(&th, 0), b = thermal_temp(&th, 1), d = thermal_temp(&th, 2);
      spread[p] = fmax(spread[p], fmax(fabs(a - b), fmax(fabs(a - d), fabs(b - d))));
    }
  }
  printf("node spread during a 2 K/min ramp: tight %.3f K, loose %.3f K\n", spread[0], spread[1]);
  assert_true(spread[0] < 0.2);
  assert_true(spread[1] > 3.0);
}

/* Power-on after a long power-off (thermal_init_cold): every node starts at the ambient
 * and the self-heating warms it through the network's own modes, the closed form
 * T(t) = Tss + exp(-L t)(Ta - Tss) (evaluated with Eigen, not stepped), towards the
 * steady state that thermal_init starts in. thermal_init keeps that steady state. */
static void test_cold_start(void **state)
{
  (void)state;
  const thermal_preset_t presets[3] = {THERMAL_PRESET_DEFAULT, THERMAL_PRESET_TIGHT,
                                       THERMAL_PRESET_LOOSE};
  const double ta = 298.15;
  for (int p = 0; p < 3; p++) {
    thermal_cfg_t c;
    thermal_preset(&c, presets[p]);
    c.dt_s = 0.01;
    static thermal_t cold, warm;
    assert_int_equal(thermal_init_cold(&cold, &c, ta), 0);
    assert_int_equal(thermal_init(&warm, &c, ta), 0);
    double tss[3];
    thermal_steady(&c, ta, tss);
    for (int i = 0; i < 3; i++) {
      assert_true(thermal_temp(&cold, i) == ta);
      assert_true(thermal_temp(&warm, i) == tss[i]);
    }
    /* -L from the equations of thermal.h */
    const double *g = c.couple_per_s;
    const double gm[3][3] = {{0, g[0], g[1]}, {g[0], 0, g[2]}, {g[1], g[2], 0}};
    double ml[9];
    for (int i = 0; i < 3; i++) {
      double s = 0.0;
      for (int j = 0; j < 3; j++) {
        ml[i * 3 + j] = gm[i][j];
        s += gm[i][j];
      }
      ml[i * 3 + i] = -1.0 / c.tau_s[i] - s;
    }
    double worst = 0.0, settled = 0.0;
    const int stride = 10000; /* every 100 s over 2 h */
    for (int k = 1; k <= 720000; k++) {
      thermal_step(&cold, ta);
      thermal_step(&warm, ta);
      if (k % stride) continue;
      const double t = k * c.dt_s;
      double a[9], e[9];
      for (int i = 0; i < 9; i++) a[i] = ml[i] * t;
      assert_int_equal(expm_ref(3, a, e), 0);
      for (int i = 0; i < 3; i++) {
        double want = tss[i];
        for (int j = 0; j < 3; j++) want += e[i * 3 + j] * (ta - tss[j]);
        worst = fmax(worst, fabs(thermal_temp(&cold, i) - want));
        settled = fmax(settled, fabs(thermal_temp(&warm, i) - tss[i]));
      }
    }
    printf("preset %d cold start: circuit %.4f K above ambient after 2 h (steady %.4f), "
           "worst error %.2e K; steady start stays within %.1e K\n",
           p, thermal_temp(&cold, THERMAL_CIRCUIT) - ta, tss[THERMAL_CIRCUIT] - ta, worst,
           settled);
    assert_true(worst < 1e-8);
    assert_true(settled < 1e-9);
    /* warmed: two hours are many times the slowest mode of every preset */
    for (int i = 0; i < 3; i++) assert_true(fabs(thermal_temp(&cold, i) - tss[i]) < 1e-3);
  }
  /* a bad configuration is refused, the network left as it was */
  thermal_cfg_t c;
  thermal_default_cfg(&c);
  static thermal_t th;
  assert_int_equal(thermal_init(&th, &c, ta), 0);
  const thermal_t before = th;
  c.tau_s[2] = -1.0;
  assert_true(thermal_init_cold(&th, &c, ta) < 0);
  thermal_default_cfg(&c);
  assert_true(thermal_init_cold(&th, &c, NAN) < 0);
  assert_memory_equal(&th, &before, sizeof th);
}

static void test_validation(void **state)
{
  (void)state;
  thermal_cfg_t c;
  thermal_default_cfg(&c);
  const char *key = NULL;
  assert_int_equal(thermal_cfg_check(&c, &key), 0);
  static thermal_t th;
  assert_int_equal(thermal_init(&th, &c, 300.0), 0);
  const thermal_t before = th;
  c.tau_s[1] = 0.0;
  assert_true(thermal_cfg_check(&c, &key) < 0);
  assert_string_equal(key, "tau_s[1]");
  assert_true(thermal_init(&th, &c, 300.0) < 0);
  assert_memory_equal(&th, &before, sizeof th);
  thermal_default_cfg(&c);
  c.couple_per_s[2] = -1.0;
  assert_true(thermal_cfg_check(&c, &key) < 0);
  assert_string_equal(key, "couple_per_s[2]");
  thermal_default_cfg(&c);
  c.rise_k[0] = NAN;
  assert_true(thermal_cfg_check(&c, &key) < 0);
  assert_string_equal(key, "rise_k[0]");
  thermal_default_cfg(&c);
  c.dt_s = 0.0;
  assert_true(thermal_cfg_check(&c, &key) < 0);
  assert_string_equal(key, "dt_s");
  thermal_default_cfg(&c);
  assert_true(thermal_init(&th, &c, NAN) < 0);
  assert_true(thermal_step(&th, INFINITY) < 0);
  assert_memory_equal(&th, &before, sizeof th);
  assert_true(isnan(thermal_temp(&th, 3)));
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_uncoupled_step),  cmocka_unit_test(test_two_node_modes),
      cmocka_unit_test(test_general_network), cmocka_unit_test(test_ramp_midpoint),
      cmocka_unit_test(test_presets_differ),  cmocka_unit_test(test_cold_start),
      cmocka_unit_test(test_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
