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

/* f_c 2 Hz, 12 V, settled within 1 deg/s for 0.1 s; probe 3 V, 30 ms + 50 ms means */
static quad_null_design_t design(void)
{
  const quad_null_cfg_t c = {2.0f, 12.0f, 1.0f, 0.1f, 3.0f, 0.03f, 0.05f, 1.0f, DT_S};
  quad_null_design_t d;
  assert_int_equal(quad_null_design(&c, &d), 0);
  return d;
}

/* From power-on of the loop: the probe (two 80 ms phases) identifies c within 1 %
 * through the lag, then 1500 deg/s falls under 1 deg/s within ln(1500) / (2 pi f_c)
 * (0.58 s at 2 Hz): in all under 0.85 s. The voltage the model needs,
 * sqrt(1500 / 20) = 8.660 V, on V2. */
static void test_identifies_and_nulls(void **state)
{
  (void)state;
  const quad_null_design_t d = design();
  quad_null_t q;
  quad_null_start(&d, &q);
  assert_int_equal(q.mode, QUAD_NULL_PROBE_BASE);
  assert_true(q.v1_v == 0.0f && q.v2_v == 0.0f);
  model_t m = {1500.0f, 20.0f, 0.0f};
  const float t_in = run(&d, &q, &m, 1000, 0.0f); /* 2 s */
  print_message("1500 deg/s: c identified %.4f (20), within 1 deg/s from %.3f s; V1 %.4f V, "
                "V2 %.4f V, q %.2e\n",
                q.gain_dps_per_v2, t_in, q.v1_v, q.v2_v, model_quad(&m, &q));
  assert_int_equal(q.mode, QUAD_NULL_RUN);
  assert_true(fabsf(q.gain_dps_per_v2 / 20.0f - 1.0f) < 0.01f);
  assert_true(t_in >= 0.0f && t_in < 0.85f);
  assert_true(q.v1_v == 0.0f);
  assert_true(fabsf(q.v2_v - sqrtf(1500.0f / 20.0f)) < 1e-3f);
  /* the float integrator's dead band: half an ulp of u (75 V^2) over Ki T */
  assert_true(fabsf(model_quad(&m, &q)) < 0.01f);
  assert_true(q.settled && !q.at_limit);
}

/* Negative quadrature goes on the other electrode; a reversed wiring (c < 0) is
 * identified as such and nulled all the same. */
static void test_sign_and_wiring(void **state)
{
  (void)state;
  const quad_null_design_t d = design();
  quad_null_t q;
  quad_null_start(&d, &q);
  model_t m = {-800.0f, 20.0f, 0.0f};
  assert_true(run(&d, &q, &m, 1000, 0.0f) >= 0.0f);
  assert_true(q.v2_v == 0.0f && fabsf(q.v1_v - sqrtf(40.0f)) < 1e-3f);
  quad_null_start(&d, &q);
  model_t r = {1500.0f, -20.0f, 0.0f};
  assert_true(run(&d, &q, &r, 1000, 0.0f) >= 0.0f);
  assert_true(q.gain_dps_per_v2 < 0.0f && q.v2_v == 0.0f && q.v1_v > 8.6f);
}

/* A calibrated gain off by 2x either way: still first order (f_c scales with the
 * error), nulled within 1.2 s; a ramp of k_q leaves r / (2 pi f_c). */
static void test_gain_error_and_ramp(void **state)
{
  (void)state;
  const quad_null_design_t d = design();
  const float c_hat[] = {10.0f, 40.0f};
  for (int i = 0; i < 2; i++) {
    quad_null_t q;
    assert_int_equal(quad_null_start_with_gain(&d, &q, c_hat[i]), 0);
    model_t m = {1500.0f, 20.0f, 0.0f};
    const float t_in = run(&d, &q, &m, 750, 0.0f);
    print_message("gain %.0f given, 20 true: within 1 deg/s from %.3f s\n", c_hat[i], t_in);
    assert_true(t_in >= 0.0f && t_in < 1.2f);
  }
  /* k_q follows the structure: 1500 deg/s at -0.03 /K (about 2x the silicon's
   * frequency tempco, thermoelastic) and 2 K/min is 1.5 deg/s per second; at 2 Hz the
   * residual is 1.5 / (2 pi 2) = 0.12 deg/s, plus the lag's r T_lag */
  quad_null_t q;
  quad_null_start(&d, &q);
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
  const quad_null_design_t d = design();
  quad_null_t q;
  quad_null_start(&d, &q);
  model_t m = {5000.0f, 20.0f, 0.0f}; /* 12 V reaches 2880 deg/s */
  assert_true(run(&d, &q, &m, 1000, 0.0f) < 0.0f);
  assert_true(q.at_limit && !q.settled);
  assert_true(q.v2_v == 12.0f);
  m.q0_dps = 1500.0f;
  assert_true(run(&d, &q, &m, 1000, 0.0f) >= 0.0f);
  assert_true(!q.at_limit && q.settled);
}

/* Electrodes that do nothing (not fitted, a dead driver): the probe sees no step, the
 * loop fails with both at 0 V and never settles. */
static void test_no_electrodes(void **state)
{
  (void)state;
  const quad_null_design_t d = design();
  quad_null_t q;
  quad_null_start(&d, &q);
  model_t m = {1500.0f, 0.05f, 0.0f}; /* 9 V^2 moves it 0.45 deg/s: under 1 */
  (void)run(&d, &q, &m, 500, 0.0f);
  assert_int_equal(q.mode, QUAD_NULL_FAILED);
  assert_true(q.v1_v == 0.0f && q.v2_v == 0.0f && !q.settled);
}

/* No measurement holds the voltages and clears settled; a bad design or gain changes
 * nothing it should not. */
static void test_bad_input(void **state)
{
  (void)state;
  quad_null_design_t d = design();
  quad_null_t q;
  quad_null_start(&d, &q);
  model_t m = {1500.0f, 20.0f, 0.0f};
  (void)run(&d, &q, &m, 1000, 0.0f);
  const float v2 = q.v2_v;
  quad_null_update(&d, &q, NAN);
  quad_null_update(&d, &q, INFINITY);
  assert_true(q.v2_v == v2 && !q.settled);
  assert_int_equal(quad_null_start_with_gain(&d, &q, 0.0f), -1);
  assert_int_equal(q.mode, QUAD_NULL_OFF);
  assert_int_equal(quad_null_start_with_gain(&d, &q, NAN), -1);
  const quad_null_design_t before = d;
  const quad_null_cfg_t ok = {2.0f, 12.0f, 1.0f, 0.1f, 3.0f, 0.03f, 0.05f, 1.0f, DT_S};
  for (int i = 0; i < 9; i++) {
    const float bad_vals[] = {0.0f, NAN, -1.0f, INFINITY};
    for (int j = 0; j < 4; j++) {
      quad_null_cfg_t b = ok;
      float *f = &b.bw_hz + i;        /* the fields are floats, in order */
      if (i == 3 && j == 0) continue; /* settle_s 0 is valid */
      if (i == 5 && j == 0) continue; /* probe_wait_s 0 is valid */
      *f = bad_vals[j];
      assert_int_equal(quad_null_design(&b, &d), -1);
      assert_memory_equal(&d, &before, sizeof d);
    }
  }
  quad_null_cfg_t b = ok;
  b.bw_hz = 60.0f; /* f_c T = 0.12: not first order */
  assert_int_equal(quad_null_design(&b, &d), -1);
  b = ok;
  b.probe_v = 13.0f; /* beyond the limit */
  assert_int_equal(quad_null_design(&b, &d), -1);
  b = ok;
  b.settle_s = 1e9f;
  assert_int_equal(quad_null_design(&b, &d), -1);
  assert_memory_equal(&d, &before, sizeof d);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_identifies_and_nulls), cmocka_unit_test(test_sign_and_wiring),
      cmocka_unit_test(test_gain_error_and_ramp),  cmocka_unit_test(test_limit),
      cmocka_unit_test(test_no_electrodes),        cmocka_unit_test(test_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
