#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include <math.h>

#include "dsp/pi.h"

/* A controller under test: the configuration it was designed from, the coefficients
 * the step uses and its state. A change of gains or limits is a new design whose
 * coefficients take over from the state as it is (the sample path's design change). */
typedef struct {
  pi_cfg_t cfg;
  pi_coeffs_t c;
  pi_t s;
} tpi_t;

static int t_init(tpi_t *p, const pi_cfg_t *cfg)
{
  if (p == NULL) return pi_init(cfg, NULL, NULL);
  if (pi_init(cfg, &p->c, &p->s) != 0) return -1;
  p->cfg = *cfg;
  return 0;
}

static float t_step(tpi_t *p, float e) { return pi_step(&p->c, &p->s, e); }

static int t_reset(tpi_t *p, float u, float e_prev)
{
  return p == NULL ? pi_reset(NULL, NULL, u, e_prev) : pi_reset(&p->c, &p->s, u, e_prev);
}

/* A design with the new values (nothing changes when it is rejected), then its
 * coefficients take over. */
static int t_redesign(tpi_t *p, pi_cfg_t c)
{
  c.u_init = c.u_min;
  if (pi_design(&c, &p->c) != 0) return -1;
  p->cfg = c;
  pi_limit(&p->c, &p->s);
  return 0;
}

static int t_set_gains(tpi_t *p, float kp, float ki)
{
  if (p == NULL) return -1;
  pi_cfg_t c = p->cfg;
  c.kp = kp;
  c.ki = ki;
  return t_redesign(p, c);
}

static int t_set_limits(tpi_t *p, float u_min, float u_max)
{
  pi_cfg_t c = p->cfg;
  c.u_min = u_min;
  c.u_max = u_max;
  return t_redesign(p, c);
}

static pi_cfg_t cfg_default(void)
{
  return (pi_cfg_t){.kp = 0.5f,
                    .ki = 200.0f,
                    .dt_s = 1.0f / 50000.0f,
                    .u_min = -10.0f,
                    .u_max = 10.0f,
                    .u_init = 0.0f};
}

/* Step e = E from e(-1) = 0: u(k) = u0 + Kp E + Ki T E k, the inverse z-transform of
 * C(z) E / (1 - z^-1) with C from (6-26b). Float accumulation of u adds at most about
 * half an ulp of u per sample. */
static void test_step_response_analytic(void **state)
{
  (void)state;
  tpi_t pi;
  pi_cfg_t c = cfg_default();
  c.u_init = 0.25f;
  assert_int_equal(t_init(&pi, &c), 0);
  const double e = 0.01, kp = 0.5, kit = 200.0 / 50000.0;
  for (int k = 0; k < 2000; k++) {
    const double u = (double)t_step(&pi, (float)e);
    const double expect = 0.25 + kp * e + kit * e * k;
    assert_true(fabs(u - expect) < (1e-6 + 1e-7 * (k + 1)) * fabs(expect));
  }
}

/* Ramp e(k) = r k: u(k) = u0 + Kp r k + Ki T r k (k - 1) / 2. */
static void test_ramp_response_analytic(void **state)
{
  (void)state;
  tpi_t pi;
  pi_cfg_t c = cfg_default();
  c.u_min = -1000.0f;
  c.u_max = 1000.0f;
  assert_int_equal(t_init(&pi, &c), 0);
  const double r = 1e-4, kp = 0.5, kit = 200.0 / 50000.0;
  for (int k = 0; k < 3000; k++) {
    const double u = (double)t_step(&pi, (float)(r * k));
    const double expect = kp * r * k + kit * r * k * (k - 1) / 2.0;
    assert_true(fabs(u - expect) <= (1e-6 + 1e-7 * (k + 1)) * fabs(expect));
  }
}

/* Thesis worked example (6.4): C(s) = 2e-5 + 5.7e-3/s at 57 kHz is
 * C(z) = (2e-5 - 1.99e-5 z^-1) / (1 - z^-1): impulse response b0 = 2e-5, then
 * b0 + b1 = Ki T = 1e-7 per sample. */
static void test_thesis_example_coefficients(void **state)
{
  (void)state;
  tpi_t pi;
  const pi_cfg_t c = {.kp = 2e-5f,
                      .ki = 5.7e-3f,
                      .dt_s = 1.0f / 57000.0f,
                      .u_min = -1.0f,
                      .u_max = 1.0f,
                      .u_init = 0.0f};
  assert_int_equal(t_init(&pi, &c), 0);
  /* b0 = Kp, b1 = Ki T - Kp */
  assert_true(fabs((double)pi.c.kp - 2e-5) < 2e-5 * 1e-6);
  assert_true(fabs(((double)pi.c.ki_t - (double)pi.c.kp) + 1.99e-5) < 1.99e-5 * 1e-6);
  const double u0 = (double)t_step(&pi, 1.0f);
  assert_true(fabs(u0 - 2e-5) < 2e-5 * 1e-6);
  for (int k = 1; k < 10; k++) {
    const double u = (double)t_step(&pi, 0.0f);
    assert_true(fabs(u - 1e-7) < 1e-7 * 1e-5);
  }
}

/* First-order plant y(k+1) = a y(k) + (1 - a) K u(k) under PI. The setpoint first asks
 * for more than the actuator can give (u saturates at u_max) for n_sat samples, then
 * drops to a reachable value; returns the samples until y stays within 2 % of it. */
typedef struct {
  int positional; /* 1: a textbook positional PI with clamped output, for contrast */
} loop_opts_t;

static int recovery_samples(int n_sat, loop_opts_t o)
{
  const double a = 0.99, kplant = 1.0;
  tpi_t pi;
  const pi_cfg_t c = {
      .kp = 0.5f, .ki = 5.0f, .dt_s = 1e-3f, .u_min = -1.0f, .u_max = 1.0f, .u_init = 0.0f};
  assert_int_equal(t_init(&pi, &c), 0);
  double y = 0.0, integ = 0.0;
  int inside_since = -1;
  for (int k = 0; k < n_sat + 60000; k++) {
    const double sp = (k < n_sat) ? 2.0 : 0.5;
    const double e = sp - y;
    double u;
    if (o.positional) {
      u = fmin(1.0, fmax(-1.0, 0.5 * e + integ));
      integ += 5.0 * 1e-3 * e; /* (6-26b) integrator with no anti-windup */
    } else {
      u = (double)t_step(&pi, (float)e);
      assert_true(u <= 1.0 && u >= -1.0);
    }
    y = a * y + (1.0 - a) * kplant * u;
    if (k >= n_sat) {
      if (fabs(y - 0.5) <= 0.01) {
        if (inside_since < 0) {
          inside_since = k;
        }
      } else {
        inside_since = -1;
      }
    }
  }
  assert_true(inside_since >= 0);
  return inside_since - n_sat;
}

/* Anti-windup: the velocity form's recovery does not depend on how long it was
 * saturated; the positional form's recovery grows with it (showing the test can tell). */
static void test_anti_windup_recovery_independent_of_saturation_time(void **state)
{
  (void)state;
  const int r_short = recovery_samples(500, (loop_opts_t){0});
  const int r_long = recovery_samples(5000, (loop_opts_t){0});
  const int p_short = recovery_samples(500, (loop_opts_t){1});
  const int p_long = recovery_samples(5000, (loop_opts_t){1});
  print_message("recovery (samples): velocity form %d / %d, positional form %d / %d\n", r_short,
                r_long, p_short, p_long);
  assert_true(abs(r_short - r_long) <= 1);
  assert_true(p_long > 2 * p_short); /* the windup the clamped velocity form avoids */
  assert_true(r_long < p_long);
}

/* Position form on a limit: a zero-mean error alternating around an output held near
 * u_min = 0 leaves the integral where it was (its clamp is its own), where the velocity
 * form ratchets up (its clamp cuts the proportional kick's negative half away). */
static void test_position_form_does_not_ratchet(void **state)
{
  (void)state;
  const pi_cfg_t cfg = {1.0f, 1.0f, 1e-3f, 0.0f, 10.0f, 0.0f};
  pi_coeffs_t c;
  pi_t vel, pos;
  assert_int_equal(pi_init(&cfg, &c, &vel), 0);
  assert_int_equal(pi_init(&cfg, &c, &pos), 0);
  float integ = 0.01f;
  for (int k = 0; k < 1000; k++) {
    const float e = (k & 1) ? 0.5f : -0.5f;
    (void)pi_step(&c, &vel, e);
    (void)pi_step_position(&c, &pos, &integ, e);
  }
  print_message("after 1000 alternating errors: velocity form u %.4f, position integral %.4f\n",
                (double)vel.u, (double)integ);
  assert_true(vel.u > 0.2f);                      /* ratcheted */
  assert_float_equal(integ, 0.01f, 1e-3f);        /* Ki T sums +-0.5 to zero */
  assert_float_equal(pos.u, 0.01f + 0.5f, 1e-3f); /* last error +0.5: integral + Kp e */
}

/* Changing Kp and Ki mid-run makes no step: with a constant error the increment at the
 * change is the new integral term alone (Kp acts on e(k) - e(k-1) = 0). */
static void test_gain_change_is_bumpless(void **state)
{
  (void)state;
  tpi_t pi;
  assert_int_equal(
      t_init(&pi, &(pi_cfg_t){cfg_default().kp, 200.0f, 1.0f / 50000.0f, -10.0f, 10.0f, 0.0f}),
      0);
  const float e = 0.2f;
  float u = 0.0f;
  for (int k = 0; k < 100; k++) {
    u = t_step(&pi, e);
  }
  assert_int_equal(t_set_gains(&pi, 5.0f, 400.0f), 0);
  assert_true(pi_output(&pi.s) == u);
  const float u_next = t_step(&pi, e);
  const float expected_increment = 400.0f / 50000.0f * e; /* Ki T e(k-1), e(k-1) = e */
  assert_true(fabsf((u_next - u) - expected_increment) < 1e-6f);
  /* a positional PI would have jumped by (5 - 0.5) * 0.2 = 0.9 */
  assert_true(fabsf(u_next - u) < 0.01f);
}

/* Reset to a given output with the current error: no proportional kick. */
static void test_reset_to_output(void **state)
{
  (void)state;
  tpi_t pi;
  pi_cfg_t c = cfg_default();
  assert_int_equal(t_init(&pi, &c), 0);
  for (int k = 0; k < 50; k++) {
    (void)t_step(&pi, 0.3f);
  }
  assert_int_equal(t_reset(&pi, 2.5f, 0.1f), 0);
  assert_true(pi_output(&pi.s) == 2.5f);
  const float u = t_step(&pi, 0.1f);
  assert_true(fabsf(u - (2.5f + 200.0f / 50000.0f * 0.1f)) < 1e-6f); /* integral term only */
  /* a reset outside the limits is clamped into them */
  assert_int_equal(t_reset(&pi, 50.0f, 0.0f), 0);
  assert_true(pi_output(&pi.s) == 10.0f);
  const tpi_t before = pi;
  assert_int_equal(t_reset(&pi, NAN, 0.0f), -1);
  assert_int_equal(t_reset(&pi, 0.0f, INFINITY), -1);
  assert_int_equal(t_reset(NULL, 0.0f, 0.0f), -1);
  assert_memory_equal(&pi, &before, sizeof pi);
}

static void test_limits_hold_and_change(void **state)
{
  (void)state;
  tpi_t pi;
  assert_int_equal(t_init(&pi, &(pi_cfg_t){0.5f, 200.0f, 1e-3f, -1.0f, 2.0f, 0.0f}), 0);
  for (int k = 0; k < 1000; k++) {
    const float u = t_step(&pi, (k < 500) ? 100.0f : -100.0f);
    assert_true(u <= 2.0f && u >= -1.0f);
  }
  assert_true(pi_output(&pi.s) == -1.0f);
  assert_int_equal(t_set_limits(&pi, -0.5f, 0.5f), 0);
  assert_true(pi_output(&pi.s) == -0.5f);
  const tpi_t before = pi;
  assert_int_equal(t_set_limits(&pi, 1.0f, 1.0f), -1);
  assert_int_equal(t_set_limits(&pi, 1.0f, -1.0f), -1);
  assert_int_equal(t_set_limits(&pi, NAN, 1.0f), -1);
  assert_int_equal(t_set_limits(&pi, -INFINITY, 1.0f), -1);
  assert_memory_equal(&pi, &before, sizeof pi);
}

static void test_bad_config_rejected_unchanged(void **state)
{
  (void)state;
  tpi_t pi;
  memset(&pi, 0x77, sizeof pi);
  const tpi_t sentinel = pi;
  pi_cfg_t bad[12];
  for (size_t i = 0; i < 12; i++) {
    bad[i] = cfg_default();
  }
  bad[0].kp = NAN;
  bad[1].ki = INFINITY;
  bad[2].dt_s = 0.0f;
  bad[3].dt_s = -1e-5f;
  bad[4].dt_s = NAN;
  bad[5].u_min = 10.0f; /* u_min == u_max */
  bad[6].u_min = 11.0f; /* u_min > u_max */
  bad[7].u_max = NAN;
  bad[8].u_init = 11.0f;
  bad[9].u_init = NAN;
  bad[10].ki = 3e38f;
  bad[10].dt_s = 100.0f; /* Ki T overflows */
  bad[11].u_min = -INFINITY;
  for (size_t i = 0; i < 12; i++) {
    assert_int_equal(t_init(&pi, &bad[i]), -1);
    assert_memory_equal(&pi, &sentinel, sizeof pi);
  }
  assert_int_equal(t_init(&pi, NULL), -1);
  pi_cfg_t good_cfg = cfg_default();
  assert_int_equal(t_init(NULL, &good_cfg), -1);
  assert_memory_equal(&pi, &sentinel, sizeof pi);

  assert_int_equal(t_init(&pi, &good_cfg), 0);
  (void)t_step(&pi, 1.0f);
  const tpi_t good = pi;
  assert_int_equal(t_set_gains(&pi, NAN, 1.0f), -1);
  assert_int_equal(t_set_gains(&pi, 1.0f, -INFINITY), -1);
  assert_int_equal(t_set_gains(NULL, 1.0f, 1.0f), -1);
  assert_memory_equal(&pi, &good, sizeof pi);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_step_response_analytic),
      cmocka_unit_test(test_ramp_response_analytic),
      cmocka_unit_test(test_thesis_example_coefficients),
      cmocka_unit_test(test_anti_windup_recovery_independent_of_saturation_time),
      cmocka_unit_test(test_gain_change_is_bumpless),
      cmocka_unit_test(test_position_form_does_not_ratchet),
      cmocka_unit_test(test_reset_to_output),
      cmocka_unit_test(test_limits_hold_and_change),
      cmocka_unit_test(test_bad_config_rejected_unchanged),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
