/* The rate-valid verdict (gyro/rate_valid.h) on constructed evidence: each reason sets
 * on its own evidence and clears when it goes, the settling is measured, the
 * thermometer's bounds follow the bias slope, onsets are counted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "gyro/comp_filters.h"
#include "gyro/rate_valid.h"

static rate_valid_cfg_t cfg(void)
{
  rate_valid_cfg_t c = {.tol_dps = 0.25f,
                        .full_scale_dps = 300.0f,
                        .p_range_deg = 8.0f,
                        .p_window_max_deg = 0.005f,     /* 0.05 deg/s over 0.1 s */
                        .p_lag_per_deg = 0.159f / 0.1f, /* 1 Hz low-pass, 0.1 s window */
                        .sense_max_v2 = 16.0f,
                        .phase_tol_rad = 0.01745f,
                        .bias_slope_dps_per_deg = 0.0f,
                        .grad_k_abs_dps_per_deg = 0.0f,
                        .spur_m = {0.0f},
                        .settle_k = RATE_VALID_INPUT_K,
                        .settle_diff_k = 1.0f};
  rate_valid_spur_matrix(4e-4f, 1e-4f, 1u, 0.0f,
                         c.spur_m); /* P_c over 5 s, the gradient over 20 s */
  return c;
}

static rate_valid_t rv;
static const rate_channel_t k_filters_at_rest; /* the compensation's filters all 0 */
/* The configuration the monitors under test run with. */
static rate_valid_cfg_t s_cfg;

/* A window that ended is judged, and its shadow run, as gyro_block_p does over up to
 * six blocks. */
static void judge_window(void)
{
  if (!rv.slew_due) return;
  (void)rate_valid_slew(&s_cfg, &rv);
  assert_int_equal(rv.shadow_phase, 1u);
  for (uint32_t k = 0u; k < 5u && rv.shadow_phase != 0u; k++)
    rate_valid_shadow(&s_cfg, &rv, &k_filters_at_rest);
  assert_int_equal(rv.shadow_phase, 0u);
}
static rate_valid_history_t hist;

static int rv_init(rate_valid_t *v, const rate_valid_cfg_t *c)
{
  const int r = rate_valid_init(c, v);
  if (r == 0) s_cfg = *c;
  return r;
}

/* LOCKED and settled on quiet evidence; returns the verdict. */
static uint32_t settle(void)
{
  const rate_valid_cfg_t c = cfg();
  assert_int_equal(rv_init(&rv, &c), 0);
  hist = (rate_valid_history_t){{0u}, {0u}};
  uint32_t r = 0u;
  /* The inputs' low-pass (0.2 per block) reaches 1500 deg/s within 0.25 after about 40
   * blocks; then RATE_VALID_SETTLE_BLOCKS inside. */
  for (int i = 0; i < 80; i++) {
    rate_valid_settling(&s_cfg, &rv, 0.0f, 10.0f, 0.0f, 1500.0f, 150.0f);
    rate_valid_drive(&s_cfg, &rv, 0.0f, 1500.0f, 1.0f);
    rate_valid_range(&s_cfg, &rv, 0.0f);
    r = rate_valid_verdict(&rv, 0u);
  }
  return r;
}

static void test_bad_cfg(void **state)
{
  (void)state;
  rate_valid_cfg_t c = cfg();
  c.tol_dps = 0.0f;
  assert_int_equal(rv_init(&rv, &c), -1);
  c = cfg();
  c.full_scale_dps = NAN;
  assert_int_equal(rv_init(&rv, &c), -1);
  c = cfg();
  c.spur_m[14] = 1.0f; /* a shadow that never fades (hp's diagonal) */
  assert_int_equal(rv_init(&rv, &c), -1);
}

/* The output filters' settling is measured: outputs far from their inputs' low-pass keep
 * the rate invalid; RATE_VALID_SETTLE_BLOCKS in a row inside make it valid. */
static void test_settling_measured(void **state)
{
  (void)state;
  const rate_valid_cfg_t c = cfg();
  assert_int_equal(rv_init(&rv, &c), 0);
  for (int i = 0; i < 100; i++) {
    rate_valid_settling(&s_cfg, &rv, 0.0f, 10.0f, 0.0f, 700.0f, 150.0f); /* quad output lags */
    assert_int_not_equal(rate_valid_verdict(&rv, 0u) & RATE_INVALID_SETTLING, 0u);
  }
  assert_int_equal(settle(), 0u);
  /* A rail code is a disturbance: settling starts again. */
  assert_int_not_equal(rate_valid_verdict(&rv, RATE_INVALID_CLIP) & RATE_INVALID_SETTLING, 0u);
}

/* Once settled: the quadrature's difference from its reference ringing at a 110 Hz split
 * (the sense mode's free response, rate_valid.h RATE_VALID_RING_TOLS) is a disturbance
 * once its rms is beyond 2 tol_dps (0.5 deg/s), and not under it; a lasting difference on
 * the rate axis (a filter's lag in a fast move of the rate) is none. */
static uint32_t ring(float amp_dps, float rate_diff_dps, int blocks)
{
  uint32_t r = 0u;
  for (int i = 0; i < blocks; i++) {
    const float beat = amp_dps * sinf(2.0f * 3.14159265f * 110.0f * 2e-4f * (float)i);
    rate_valid_settling(&s_cfg, &rv, 0.0f, 10.0f, rate_diff_dps, 1500.0f + beat, 150.0f);
    r |= rate_valid_verdict(&rv, 0u);
  }
  return r;
}

static void test_ringing_unsettles(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  assert_int_equal(ring(0.6f, 5.0f, 2000), 0u); /* rms 0.42: valid */
  assert_int_equal(settle(), 0u);
  assert_int_equal(ring(0.8f, 0.0f, 2000) & RATE_INVALID_SETTLING, RATE_INVALID_SETTLING);
  /* a step's ringing (100 deg/s) trips within two blocks */
  assert_int_equal(settle(), 0u);
  assert_int_equal(ring(100.0f, 0.0f, 2), RATE_INVALID_SETTLING);
  /* gone, settled again as at any disturbance */
  assert_int_equal(ring(0.0f, 0.0f, 20), RATE_INVALID_SETTLING);
  assert_int_equal(ring(0.0f, 0.0f, 1), 0u);
}

static void test_over_range_and_sense(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  rate_valid_range(&s_cfg, &rv, -300.5f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_OVER_RANGE);
  rate_valid_range(&s_cfg, &rv, 299.0f);
  rate_valid_drive(&s_cfg, &rv, 0.0f, 1500.0f, 16.5f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_SENSE_RANGE);
  rate_valid_range(&s_cfg, &rv, NAN);
  assert_int_not_equal(rate_valid_verdict(&rv, 0u) & RATE_INVALID_OVER_RANGE, 0u);
}

/* A lasting phase error of e rad rotates Q sin(e) of quadrature into the rate: 0.01 deg
 * at 1500 deg/s is 0.26 deg/s, just over the 0.25 tolerance; 0.008 deg is not. */
static void test_phase_leak(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  for (int i = 0; i < 20000; i++)
    rate_valid_drive(&s_cfg, &rv, 0.008f * 0.0174533f, 1500.0f, 1.0f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  for (int i = 0; i < 20000; i++)
    rate_valid_drive(&s_cfg, &rv, 0.0105f * 0.0174533f, 1500.0f, 1.0f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_PHASE);
  /* Without quadrature the same error leaks nothing. */
  for (int i = 0; i < 10; i++) rate_valid_drive(&s_cfg, &rv, 0.0105f * 0.0174533f, 0.0f, 1.0f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  /* Beyond the lock tolerance, at once. */
  rate_valid_drive(&s_cfg, &rv, 0.02f, 0.0f, 1.0f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_PHASE);
}

/* After a hold, P_f may still be w / (1 - w) |P_held - P_f| from P: at a bias slope of
 * 26 deg/s per degree a gap of 1 deg needs w below about 1 %. The quadrature does not
 * count: the rate reference follows P itself, not P_f (rate_channel.h); counting it, as
 * before, kept a Q 2e4 part's tracking thermometer (p_eq, 0.1 deg of noise) invalid. */
static void test_thermo_settle_bound(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  s_cfg.p_window_max_deg = 100.0f; /* the jumps below are no slew here (test_thermo_slew) */
  rate_valid_thermo(&s_cfg, &rv, 1.0f, 0.0f, 0.02f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u); /* no bias slope: no error */
  s_cfg.bias_slope_dps_per_deg = 26.18f;
  rate_valid_thermo(&s_cfg, &rv, 1.0f, 0.0f, 0.02f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_SETTLE);
  rate_valid_thermo(&s_cfg, &rv, 1.0f, 0.0f, 0.005f);
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  rate_valid_thermo(&s_cfg, &rv, 9.0f, 9.0f, 0.0f); /* out of the calibrated range */
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_RANGE);
}

/* The calibrated range is centred on the thermometer's reference (cal.ref_p_deg), not on
 * P_f's working point: with the reference 3 deg above it, p_dev from -5 to +11 is in. */
static void test_thermo_range_about_reference(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  s_cfg.p_range_off_deg = -3.0f;
  s_cfg.p_window_max_deg = 100.0f; /* the jumps below are no slew here (test_thermo_slew) */
  const float in_deg[] = {-4.9f, 3.0f, 10.9f}, out_deg[] = {-5.1f, 11.1f, -9.0f};
  for (int i = 0; i < 3; i++) {
    rate_valid_thermo(&s_cfg, &rv, in_deg[i], in_deg[i], 0.0f);
    assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
    rate_valid_thermo(&s_cfg, &rv, out_deg[i], out_deg[i], 0.0f);
    assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_RANGE);
  }
}

/* A slew of P_f is judged over RATE_VALID_SLEW_UPDATES updates, against the cap and the
 * lag it leaves in P_f's low-pass. */
static void test_thermo_slew(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  float p = 0.0f;
  for (uint32_t i = 0; i < 3u * RATE_VALID_SLEW_UPDATES; i++) {
    p += 0.004f / (float)RATE_VALID_SLEW_UPDATES; /* 0.04 deg/s, under the cap */
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  }
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  for (uint32_t i = 0; i < 2u * RATE_VALID_SLEW_UPDATES; i++) {
    p += 0.004f / (float)RATE_VALID_SLEW_UPDATES;
    /* 0.004 deg per 0.1 s leaves P_f 0.0064 deg behind: with no bias slope no error,
     * whatever the quadrature (the reference does not read P_f) ... */
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  }
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  s_cfg.bias_slope_dps_per_deg = 52.0f;
  for (uint32_t i = 0; i < 2u * RATE_VALID_SLEW_UPDATES; i++) {
    p += 0.004f / (float)RATE_VALID_SLEW_UPDATES;
    /* ... at 52 deg/s per degree of bias slope 0.33 deg/s: beyond the tolerance though
     * under the cap. */
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  }
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_SLEW);
  s_cfg.bias_slope_dps_per_deg = 0.0f;
  /* Under the cap: a temperature's move, none of it into the shadow of the compensation */
  assert_true(rv.spur_deg[0] == 0.0f && rv.spur_deg[1] == 0.0f && rv.spur_deg[2] == 0.0f &&
              rv.spur_deg[3] == 0.0f);
  for (uint32_t i = 0; i < 2u * RATE_VALID_SLEW_UPDATES; i++) {
    p += 0.006f / (float)RATE_VALID_SLEW_UPDATES; /* 0.06 deg/s: beyond the cap */
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  }
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_SLEW);
  /* Beyond it: into the shadow (P_f carries 0.006 deg per window of it) */
  assert_true(rv.spur_deg[0] > 0.005f);
}

/* A move beyond the cap is THERMO_SLEW on the update that makes it, not a window later;
 * and P_f is trusted again only back at its trend from before the move: a move that
 * lasts keeps the rate invalid for as long as it lasts, one that returns frees it. */
static void test_slew_at_once_and_until_back(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  s_cfg.bias_slope_dps_per_deg = 10.0f; /* half the tolerance: 0.0125 deg of P */
  float p = 0.0f;
  for (uint32_t i = 0; i < 2u * RATE_VALID_SLEW_UPDATES; i++) {
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  }
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  while (rv.p_updates != 1u) {
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  }
  p = 0.05f; /* ten caps in one update, at the start of a window */
  rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
  assert_false(rv.slew_due);
  assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_SLEW);
  for (uint32_t i = 0; i < 100u * RATE_VALID_SLEW_UPDATES; i++) { /* 10 s at the moved P */
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
    assert_int_equal(rate_valid_verdict(&rv, 0u), RATE_INVALID_THERMO_SLEW);
  }
  assert_true(rv.displaced != 0u);
  p = 0.005f; /* back, to 0.05 deg/s: within half the tolerance of its trend */
  uint32_t n = 0;
  do {
    rate_valid_thermo(&s_cfg, &rv, p, 0.0f, 0.0f);
    judge_window();
  } while (rate_valid_verdict(&rv, 0u) != 0u && ++n < 100u * RATE_VALID_SLEW_UPDATES);
  assert_int_equal(rv.displaced, 0u);
  assert_int_equal(rate_valid_verdict(&rv, 0u), 0u);
  s_cfg.bias_slope_dps_per_deg = 0.0f;
}

/* A start far from the reference (a cold part): P_f converges from its held value, its
 * first windows far over the cap while the compensation's filters wait for P_f (they
 * take none of its moves), so nothing of them is the shadow's and the rate is valid
 * once P_f has settled (the cold plateau of cl_tempcomp_out_of_sample never came valid:
 * the restart that ended the armed windows put a window's move into the shadow). */
static void test_start_far_from_reference_comes_valid(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  s_cfg.bias_slope_dps_per_deg = 35.0f;
  /* P_f's fast start covers 3.8 deg: held at the reference (the drive's p_init), the
   * part's P at -25 degC is there (the default part's). Its first windows move beyond
   * RATE_VALID_RESTART_CAPS caps while the filters wait for P_f. */
  const float p = -3.8f, p_held = 0.0f;
  const float decay = expf(-0.002f / 0.159f); /* the 1 Hz low-pass per update */
  float w = 1.0f;
  uint32_t first_valid = 0u;
  for (uint32_t i = 1u; i <= 1500u; i++) { /* 3 s at 500 Hz */
    w *= decay;
    rate_valid_thermo(&s_cfg, &rv, p + w * (p_held - p), p_held, w);
    judge_window();
    if (rate_valid_verdict(&rv, 0u) == 0u) {
      if (first_valid == 0u) first_valid = i;
    } else {
      first_valid = 0u;
    }
  }
  assert_int_equal(rv.displaced, 0u);
  assert_int_not_equal(first_valid, 0u);
  assert_true(first_valid <= 1000u); /* within 2 s of the hold's end */
  s_cfg.bias_slope_dps_per_deg = 0.0f;
}

static void test_onsets_counted(void **state)
{
  (void)state;
  assert_int_equal(settle(), 0u);
  for (int i = 0; i < 3; i++) {
    rate_valid_range(&s_cfg, &rv, 400.0f);
    (void)rate_valid_verdict(&rv, 0u);
    rate_valid_count_onsets(&rv, &hist);
    (void)rate_valid_verdict(&rv, 0u);
    rate_valid_range(&s_cfg, &rv, 0.0f);
    (void)rate_valid_verdict(&rv, 0u);
    rate_valid_count_onsets(&rv, &hist);
  }
  assert_int_equal(hist.count[5], 3u); /* OVER_RANGE: three onsets, not six blocks */
  assert_true(hist.last_block[5] > 80u);
  assert_string_equal(rate_valid_reason_name(5), "OVER_RANGE");
  assert_string_equal(rate_valid_reason_name(RATE_INVALID_KINDS), "?");
}

/* The shadow's transition (rate_valid_spur_matrix) is the compensation's filters
 * (comp_filters_step) run on a leaking move of P_f, for one, two and three stages, with
 * and without the fast path: from any state, RATE_VALID_SLEW_UPDATES updates of both
 * agree; without a fast path its rows are 0. */
static void check_spur_matrix(uint32_t stages, float fa)
{
  enum { N = RATE_VALID_SPUR_N };
  const float ca = 4e-3f, ga = 1e-3f;
  float m[RATE_VALID_SPUR_M];
  rate_valid_spur_matrix(ca, ga, stages, fa, m);
  double s = 1.0;
  float mid[2] = {stages >= 2u ? 0.3f : 0.0f, stages >= 3u ? 0.4f : 0.0f};
  float lag = 0.5f, hp = -0.2f, f_lag = 0.25f, f_hp = 0.1f, no_mid[2] = {0.0f, 0.0f};
  const double x0[N] = {s, mid[0], mid[1], lag, hp, f_lag, f_hp};
  for (uint32_t n = 0; n < RATE_VALID_SLEW_UPDATES; n++) {
    const double step = -(double)ca * s;
    s += step;
    comp_filters_step(&lag, mid, &hp, (float)step, ca, ga, stages);
    if (fa > 0.0f) comp_filters_step(&f_lag, no_mid, &f_hp, (float)step, fa, ga, 1u);
  }
  const double x1[N] = {s, mid[0], mid[1], lag, hp, f_lag, f_hp};
  int k = 0;
  for (uint32_t i = 0; i < N; i++) {
    double y = 0.0;
    for (uint32_t j = 0; j <= i; j++) y += (double)m[k++] * x0[j];
    if (i >= 1u && i < 3u && i >= stages) continue; /* a stage not in use */
    if (i >= RATE_VALID_SPUR_FAST_LAG && fa == 0.0f) {
      assert_true(y == 0.0); /* no fast path: its rows are 0 */
      continue;
    }
    assert_true(fabs(y - x1[i]) < 1e-5);
  }
}

static void test_spur_matrix_is_the_filters(void **state)
{
  (void)state;
  for (uint32_t stages = 1u; stages <= COMP_STAGES_MAX; stages++) {
    check_spur_matrix(stages, 0.0f);
    check_spur_matrix(stages, 1.2e-2f);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_cfg),
      cmocka_unit_test(test_settling_measured),
      cmocka_unit_test(test_ringing_unsettles),
      cmocka_unit_test(test_over_range_and_sense),
      cmocka_unit_test(test_phase_leak),
      cmocka_unit_test(test_thermo_settle_bound),
      cmocka_unit_test(test_thermo_range_about_reference),
      cmocka_unit_test(test_thermo_slew),
      cmocka_unit_test(test_slew_at_once_and_until_back),
      cmocka_unit_test(test_start_far_from_reference_comes_valid),
      cmocka_unit_test(test_onsets_counted),
      cmocka_unit_test(test_spur_matrix_is_the_filters),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
