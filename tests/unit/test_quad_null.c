/* Quadrature nulling (firmware/gyro/quad_null): against a quasi-static model of the
 * nulling electrodes, q = q0 + c (V1^2 - V2^2), seen through a first-order lag of 2 ms
 * (the rate channel's output filter, about its 100 Hz Butterworth's delay), updated at
 * 500 Hz (the rate channel's thermometer block, RATE_P_DECIM). The voltages the module outputs are what the model gets, so
 * the root and the electrode choice are in the loop. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "gyro/quad_null.h"

#define DT_S 2e-3f
#define LAG_S 2e-3f

typedef struct {
  float q0_dps, c_dps_per_v2; /* the part */
  float q_meas_dps;           /* through the lag */
} model_t;

static float model_quad(const model_t *m, const quad_null_t *q)
{
  return m->q0_dps + m->c_dps_per_v2 * (q->v1_v * q->v1_v - q->v2_v * q->v2_v);
}

/* Runs n updates; returns the first time (s) from which |q| stayed <= 1 deg/s, or -1. */
static float run(const quad_null_design_t *d, quad_null_t *q, model_t *m, long n,
                 float ramp_dps_per_s)
{
  float t_in = -1.0f;
  for (long k = 0; k < n; k++) {
    m->q0_dps += ramp_dps_per_s * DT_S;
    const float truth = model_quad(m, q);
    m->q_meas_dps += (truth - m->q_meas_dps) * (DT_S / LAG_S);
    quad_null_update(d, q, m->q_meas_dps);
    if (fabsf(truth) <= 1.0f) {
      if (t_in < 0.0f) t_in = (float)k * DT_S;
    } else {
      t_in = -1.0f;
    }
  }
  return t_in;
}

static quad_null_cfg_t cfg_for(float c_dps_per_v2, float bw_hz)
{
  const quad_null_cfg_t c = {c_dps_per_v2, bw_hz, 12.0f, 1.0f, 0.1f, DT_S};
  return c;
}

/* 1500 deg/s under 1 deg/s within ln(1500) / (2 pi f_c) plus the lag: 0.58 s at 2 Hz
 * (bound 0.7 s); the voltage the model needs, sqrt(1500 / 20) = 8.660 V on V2. */
static void test_nulls_1500(void **state)
{
  (void)state;
  quad_null_design_t d;
  const quad_null_cfg_t cfg = cfg_for(20.0f, 2.0f);
  assert_int_equal(quad_null_design(&cfg, &d), 0);
  quad_null_t q;
  quad_null_reset(&d, &q, 0.0f);
  assert_true(q.v1_v == 0.0f && q.v2_v == 0.0f);
  model_t m = {1500.0f, 20.0f, 0.0f};
  const float t_in = run(&d, &q, &m, 1000, 0.0f); /* 2 s */
  print_message("1500 deg/s: within 1 deg/s from %.3f s; V1 %.4f V, V2 %.4f V, q %.2e\n", t_in,
                q.v1_v, q.v2_v, model_quad(&m, &q));
  /* the float integrator's dead band: half an ulp of u (75 V^2) over Ki T */
  assert_true(fabsf(model_quad(&m, &q)) < 0.01f);
  assert_true(t_in >= 0.0f && t_in < 0.7f);
  assert_true(q.v1_v == 0.0f);
  assert_true(fabsf(q.v2_v - sqrtf(1500.0f / 20.0f)) < 1e-3f);
  assert_true(q.settled && !q.at_limit);
}

/* Negative quadrature goes on the other electrode. */
static void test_sign_picks_electrode(void **state)
{
  (void)state;
  quad_null_design_t d;
  const quad_null_cfg_t cfg = cfg_for(20.0f, 2.0f);
  assert_int_equal(quad_null_design(&cfg, &d), 0);
  quad_null_t q;
  quad_null_reset(&d, &q, 0.0f);
  model_t m = {-800.0f, 20.0f, 0.0f};
  assert_true(run(&d, &q, &m, 1000, 0.0f) >= 0.0f);
  assert_true(q.v2_v == 0.0f && fabsf(q.v1_v - sqrtf(40.0f)) < 1e-3f);
}

/* The identified gain off by 2x either way: still first order (f_c scales with the
 * error), still nulled within 1.5 s; the rate of a ramp's residual r / (2 pi f_c). */
static void test_gain_error_and_ramp(void **state)
{
  (void)state;
  const float c_hat[] = {10.0f, 40.0f};
  for (int i = 0; i < 2; i++) {
    quad_null_design_t d;
    const quad_null_cfg_t cfg = cfg_for(c_hat[i], 2.0f);
    assert_int_equal(quad_null_design(&cfg, &d), 0);
    quad_null_t q;
    quad_null_reset(&d, &q, 0.0f);
    model_t m = {1500.0f, 20.0f, 0.0f};
    const float t_in = run(&d, &q, &m, 750, 0.0f);
    print_message("identified c %.0f of 20: within 1 deg/s from %.3f s\n", c_hat[i], t_in);
    assert_true(t_in >= 0.0f && t_in < 1.5f);
  }
  /* k_q follows the structure: 1500 deg/s at -0.03 /K (about 2x the silicon's
   * frequency tempco, thermoelastic) and 2 K/min is 1.5 deg/s per second; at 2 Hz the
   * residual is 1.5 / (2 pi 2) = 0.12 deg/s */
  quad_null_design_t d;
  const quad_null_cfg_t cfg = cfg_for(20.0f, 2.0f);
  assert_int_equal(quad_null_design(&cfg, &d), 0);
  quad_null_t q;
  quad_null_reset(&d, &q, 0.0f);
  model_t m = {1500.0f, 20.0f, 0.0f};
  (void)run(&d, &q, &m, 1000, 0.0f);
  (void)run(&d, &q, &m, 1000, 1.5f);
  const float resid = model_quad(&m, &q);
  const float law = 1.5f / (6.2831853f * 2.0f) + 1.5f * LAG_S;
  print_message("ramp 1.5 deg/s per s: residual %.4f deg/s (r / (2 pi f_c) + r lag: %.4f)\n",
                resid, law);
  assert_true(fabsf(resid - law) < 0.01f);
  assert_true(q.settled);
}

/* A quadrature beyond the electrodes' reach: held at the limit, flagged, never settled;
 * it comes off the limit at once when the quadrature falls within reach. */
static void test_limit(void **state)
{
  (void)state;
  quad_null_design_t d;
  const quad_null_cfg_t cfg = cfg_for(20.0f, 2.0f);
  assert_int_equal(quad_null_design(&cfg, &d), 0);
  quad_null_t q;
  quad_null_reset(&d, &q, 0.0f);
  model_t m = {5000.0f, 20.0f, 0.0f}; /* 12 V reaches 2880 deg/s */
  assert_true(run(&d, &q, &m, 1000, 0.0f) < 0.0f);
  assert_true(q.at_limit && !q.settled);
  assert_true(q.v2_v == 12.0f);
  m.q0_dps = 1500.0f;
  assert_true(run(&d, &q, &m, 1000, 0.0f) >= 0.0f);
  assert_true(!q.at_limit && q.settled);
}

/* No measurement holds the voltages and clears settled; a bad design changes nothing. */
static void test_bad_input(void **state)
{
  (void)state;
  quad_null_design_t d;
  const quad_null_cfg_t good = cfg_for(20.0f, 2.0f);
  assert_int_equal(quad_null_design(&good, &d), 0);
  quad_null_t q;
  quad_null_reset(&d, &q, 0.0f);
  model_t m = {1500.0f, 20.0f, 0.0f};
  (void)run(&d, &q, &m, 1000, 0.0f);
  const float v2 = q.v2_v;
  quad_null_update(&d, &q, NAN);
  quad_null_update(&d, &q, INFINITY);
  assert_true(q.v2_v == v2 && !q.settled);
  const quad_null_design_t before = d;
  const quad_null_cfg_t bad[] = {
      {0.0f, 2.0f, 12.0f, 1.0f, 0.1f, DT_S},     {NAN, 2.0f, 12.0f, 1.0f, 0.1f, DT_S},
      {20.0f, 0.0f, 12.0f, 1.0f, 0.1f, DT_S},    {20.0f, 600.0f, 12.0f, 1.0f, 0.1f, DT_S},
      {20.0f, 2.0f, -1.0f, 1.0f, 0.1f, DT_S},    {20.0f, 2.0f, 12.0f, 0.0f, 0.1f, DT_S},
      {20.0f, 2.0f, 12.0f, 1.0f, -1.0f, DT_S},   {20.0f, 2.0f, 12.0f, 1.0f, 0.1f, 0.0f},
      {20.0f, 2.0f, INFINITY, 1.0f, 0.1f, DT_S}, {20.0f, 2.0f, 12.0f, 1.0f, 1e9f, DT_S}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(quad_null_design(&bad[i], &d), -1);
    assert_memory_equal(&d, &before, sizeof d);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nulls_1500), cmocka_unit_test(test_sign_picks_electrode),
      cmocka_unit_test(test_gain_error_and_ramp), cmocka_unit_test(test_limit),
      cmocka_unit_test(test_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
