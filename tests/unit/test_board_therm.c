/* board_therm (the board thermometer's fusion, board_therm.h): the lead-lag against its
 * continuous step response (long time constants included: no dead band in float), the
 * model, the crossover's low-pass and where it starts, the hand-over's weight, and the
 * verdicts (off, waiting, stale, out of span) with the correction held when untrusted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "gyro/board_therm.h"

#define STEPS_PER_S 10u

static board_therm_cfg_t cfg(const float tz[2], const float tp[2], float start_s, float fade_s)
{
  const float c[4] = {1.0f, 2.0f, 0.1f, 0.01f};
  board_therm_cfg_t k;
  board_therm_design(&k, 1u, tz, tp, 25.0f, c, -40.0f, 85.0f, 3.0f, start_s, fade_s, 3.0f, 10.0f);
  return k;
}

/* H = 1: the model's variable is the reading */
static board_therm_cfg_t identity(float start_s, float fade_s)
{
  const float t[2] = {100.0f, 100.0f};
  return cfg(t, t, start_s, fade_s);
}

static const board_therm_bias_t SETTLED0 = {0.0f, 0.0f, 1.0f, 1u};

/* n steps with a reading every second (the sensor's cycle) */
static void run_s(const board_therm_cfg_t *c, board_therm_t *s, float x_c, float seconds,
                  board_therm_bias_t b)
{
  const uint32_t n = (uint32_t)(seconds * (float)STEPS_PER_S + 0.5f);
  for (uint32_t k = 0u; k < n; k++) {
    if (k % STEPS_PER_S == 0u) board_therm_reading(c, s, x_c);
    board_therm_step(c, s, b);
  }
}

static void test_identity_model(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  run_s(&c, &s, 30.0f, 2.0f, SETTLED0);
  run_s(&c, &s, 35.0f, 1.0f, SETTLED0); /* H = 1: y is the reading at once */
  assert_float_equal(s.y_c, 35.0f, 1e-5f);
  const float u = 10.0f;
  assert_float_equal(s.model_dps, 1.0f + u * (2.0f + u * (0.1f + u * 0.01f)), 1e-4f);
}

/* One section (the other H = 1): y(t) = 1 - (1 - tz / tp) e^(-t / tp) after a unit step,
 * sampled on the steps; the first step takes the reading as held over it. */
static void check_section(float tz_s, float tp_s, float t_check_s)
{
  const float tz[2] = {tz_s, 50.0f}, tp[2] = {tp_s, 50.0f};
  const board_therm_cfg_t c = cfg(tz, tp, 0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  run_s(&c, &s, 20.0f, 1.0f, SETTLED0);
  run_s(&c, &s, 21.0f, t_check_s, SETTLED0);
  const double r = (double)tz_s / (double)tp_s;
  const double want = 20.0 + 1.0 - (1.0 - r) * exp(-(double)t_check_s / (double)tp_s);
  assert_float_equal(s.y_c, (float)want, 2e-4f);
}

static void test_section_step_response(void **state)
{
  (void)state;
  check_section(30.0f, 250.0f, 100.0f);   /* a lag */
  check_section(300.0f, 120.0f, 60.0f);   /* a lead */
  check_section(1.0f, 20000.0f, 1000.0f); /* the longest pole: 4.9 % of the step in 1000 s */
}

static void test_crossover_starts_at_the_disagreement(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  board_therm_reading(&c, &s, 25.0f); /* M = c0 = 1 deg/s */
  const board_therm_bias_t b = {4.0f, 4.0f, 1.0f, 1u};
  board_therm_step(&c, &s, b);
  assert_int_equal(s.state, BOARD_THERM_OK);
  assert_float_equal(s.w, 1.0f, 0.0f);
  /* the fused bias B_P + corr is the model's from the first settled step */
  assert_float_equal(b.dps + s.corr_dps, 1.0f, 1e-6f);
  /* B_P steps by 1 deg/s: the fused bias follows it by 1 - e^-1 in one crossover (3 s) */
  const board_therm_bias_t b2 = {5.0f, 5.0f, 1.0f, 1u};
  run_s(&c, &s, 25.0f, 3.0f, b2);
  assert_float_equal(b2.dps + s.corr_dps, 1.0f + expf(-1.0f), 2e-3f);
  run_s(&c, &s, 25.0f, 60.0f, b2);
  assert_float_equal(b2.dps + s.corr_dps, 1.0f, 1e-4f);
}

/* The fused bias is sf M below the crossover, whatever the sample path's gradient term
 * and fast path add to B_P (they are P's, above the crossover they would be its flicker):
 * B_P + corr = B_s - LP_T(B_s - sf M). */
static void test_fused_bias_leaves_the_gradient_term_out(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  board_therm_reading(&c, &s, 25.0f);                    /* M = 1 */
  const board_therm_bias_t b = {7.0f, 4.0f, 1.001f, 1u}; /* a gradient term of 3 */
  run_s(&c, &s, 25.0f, 60.0f, b);
  assert_float_equal(b.dps + s.corr_dps, 1.001f, 1e-5f);
  /* B_s steps by 1 deg/s: the fused bias takes it and lets it go over the crossover */
  const board_therm_bias_t b2 = {7.0f, 5.0f, 1.001f, 1u};
  board_therm_step(&c, &s, b2);
  assert_float_equal(b2.dps + s.corr_dps, 1.001f + 1.0f - c.lp_a, 1e-4f);
}

static void test_unsettled_restarts_hold_keeps(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  board_therm_reading(&c, &s, 25.0f);
  const board_therm_bias_t b = {4.0f, 4.0f, 1.0f, 1u};
  run_s(&c, &s, 25.0f, 1.0f, b);
  const float d = s.d_dps;
  const board_therm_bias_t hold = {100.0f, 100.0f, 1.0f, BOARD_THERM_BIAS_HOLD};
  board_therm_step(&c, &s, hold);
  assert_float_equal(s.d_dps, d, 0.0f);
  const board_therm_bias_t unsettled = {100.0f, 100.0f, 1.0f, 0u};
  board_therm_step(&c, &s, unsettled);
  const board_therm_bias_t b7 = {7.0f, 7.0f, 1.0f, 1u};
  board_therm_step(&c, &s, b7); /* starts again at 7 - 1 */
  assert_float_equal(s.d_dps, 6.0f, 1e-6f);
}

static void test_hand_over_weight(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(10.0f, 20.0f);
  board_therm_t s;
  board_therm_init(&s);
  const board_therm_bias_t b = {4.0f, 4.0f, 1.0f, 1u};
  run_s(&c, &s, 25.0f, 9.9f, b);
  assert_float_equal(s.w, 0.0f, 0.0f);
  assert_float_equal(s.corr_dps, 0.0f, 0.0f);
  run_s(&c, &s, 25.0f, 10.1f, b); /* 20 s: half way */
  assert_float_equal(s.w, 0.5f, 1e-6f);
  assert_float_equal(s.corr_dps, -0.5f * 3.0f, 1e-4f);
  run_s(&c, &s, 25.0f, 20.0f, b);
  assert_float_equal(s.w, 1.0f, 0.0f);
}

static void test_stale_sensor(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  const board_therm_bias_t b = {4.0f, 4.0f, 1.0f, 1u};
  board_therm_step(&c, &s, b);
  assert_int_equal(s.state, BOARD_THERM_WAIT); /* no reading yet: not trusted */
  assert_true(board_therm_invalid(&s));
  run_s(&c, &s, 25.0f, 5.0f, b);
  assert_false(board_therm_invalid(&s));
  const board_therm_bias_t b2 = {9.0f, 9.0f, 1.0f, 1u};
  board_therm_reading(&c, &s, 25.0f);                               /* the last one */
  for (uint32_t k = 0u; k < 30u; k++) board_therm_step(&c, &s, b2); /* 3 s, no reading */
  assert_int_equal(s.state, BOARD_THERM_OK);
  board_therm_step(&c, &s, b2); /* past board.stale_s */
  assert_int_equal(s.state, BOARD_THERM_STALE);
  assert_true(board_therm_invalid(&s));
  const float corr = s.corr_dps;
  const board_therm_bias_t b3 = {20.0f, 20.0f, 1.0f, 1u};
  for (uint32_t k = 0u; k < 10u; k++) board_therm_step(&c, &s, b3);
  assert_float_equal(s.corr_dps, corr, 0.0f); /* held while not trusted */
  run_s(&c, &s, 25.0f, 0.1f, b2);             /* a reading again */
  assert_int_equal(s.state, BOARD_THERM_OK);
}

static void test_stale_before_the_hand_over_is_valid(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(100.0f, 10.0f);
  board_therm_t s;
  board_therm_init(&s);
  for (uint32_t k = 0u; k < 50u; k++) board_therm_step(&c, &s, SETTLED0);
  assert_int_equal(s.state, BOARD_THERM_WAIT);
  assert_false(board_therm_invalid(&s)); /* P's compensation alone: nothing to trust */
}

static void test_out_of_span(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  run_s(&c, &s, 86.0f, 1.0f, SETTLED0);
  assert_int_equal(s.state, BOARD_THERM_RANGE);
  assert_true(board_therm_invalid(&s));
  board_therm_init(&s);
  run_s(&c, &s, -41.0f, 1.0f, SETTLED0);
  assert_int_equal(s.state, BOARD_THERM_RANGE);
}

/* A sensor stuck while the part warms: the bias in P moves away from the stuck model,
 * and past board.agree_dps (10 here) the fusion is not trusted. */
static void test_stuck_sensor_disagrees(void **state)
{
  (void)state;
  const board_therm_cfg_t c = identity(0.0f, 0.0f);
  board_therm_t s;
  board_therm_init(&s);
  const board_therm_bias_t b = {1.0f, 1.0f, 1.0f, 1u};
  run_s(&c, &s, 25.0f, 10.0f, b);
  assert_int_equal(s.state, BOARD_THERM_OK);
  const board_therm_bias_t warm = {12.0f, 12.0f, 1.0f, 1u}; /* 11 deg/s from the stuck model */
  run_s(&c, &s, 25.0f, 30.0f, warm);
  assert_int_equal(s.state, BOARD_THERM_DISAGREE);
  assert_true(board_therm_invalid(&s));
  assert_string_equal(board_therm_state_name(BOARD_THERM_DISAGREE), "disagree");
}

static void test_off_and_bad_readings(void **state)
{
  (void)state;
  const float t[2] = {100.0f, 100.0f}, c0[4] = {1.0f, 2.0f, 0.0f, 0.0f};
  board_therm_cfg_t c;
  board_therm_design(&c, 0u, t, t, 25.0f, c0, -40.0f, 85.0f, 3.0f, 0.0f, 0.0f, 3.0f, 10.0f);
  board_therm_t s;
  board_therm_init(&s);
  const board_therm_bias_t b = {4.0f, 4.0f, 1.0f, 1u};
  run_s(&c, &s, 25.0f, 5.0f, b);
  assert_int_equal(s.state, BOARD_THERM_OFF);
  assert_false(board_therm_invalid(&s));
  assert_float_equal(s.corr_dps, 0.0f, 0.0f);
  board_therm_reading(&c, &s, NAN); /* not a reading */
  assert_float_equal(s.x_c, 25.0f, 0.0f);
  assert_string_equal(board_therm_state_name(BOARD_THERM_STALE), "stale");
  assert_string_equal(board_therm_state_name((board_therm_state_t)99), "?");
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_identity_model),
      cmocka_unit_test(test_section_step_response),
      cmocka_unit_test(test_crossover_starts_at_the_disagreement),
      cmocka_unit_test(test_fused_bias_leaves_the_gradient_term_out),
      cmocka_unit_test(test_unsettled_restarts_hold_keeps),
      cmocka_unit_test(test_hand_over_weight),
      cmocka_unit_test(test_stale_sensor),
      cmocka_unit_test(test_stale_before_the_hand_over_is_valid),
      cmocka_unit_test(test_out_of_span),
      cmocka_unit_test(test_stuck_sensor_disagrees),
      cmocka_unit_test(test_off_and_bad_readings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
