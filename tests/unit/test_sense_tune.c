/* sense_tune (mode tuning's voltage and its temperature hold, sense_tune.h) against the
 * plant's own physics (plant_sense_match: (2-32) moves both resonances by the same
 * factor, the electrostatic softening does not): calibrated at 25 degC, the voltage the
 * hold gives for the drive's resonance at another temperature is the plant's own for
 * the target, across -40..85 degC, matched and at a 20 Hz split; the states' edges. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <cmocka.h>

#include "gyro/sense_tune.h"
#include "plant/plant.h"

#define KE 2.4e5 /* (1/s^2)/V^2 */

static plant_cfg_t part(void)
{
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.f_sense_hz = 1600.0;
  pc.q_sense = 1.0e4;
  pc.tune_ke_per_s2_per_v2 = KE;
  return pc;
}

/* The calibration a sweep at the reference temperature stages: the untuned resonance,
 * the drive's, the slope (here exact: the hold is under test, not the identification). */
static sense_tune_cfg_t calibrated(const plant_cfg_t *pc, uint32_t mode, double split_hz)
{
  plant_match_t m;
  assert_int_equal(plant_sense_match(pc, pc->temp_ref_k, 0.0, 0.0, &m), 0);
  const sense_tune_cfg_t c = {mode, split_hz, 10.0, m.f_sense_hz, m.f_drive_hz, KE};
  return c;
}

static void check_hold(uint32_t mode, double split_hz)
{
  const plant_cfg_t pc = part();
  const sense_tune_cfg_t c = calibrated(&pc, mode, split_hz);
  double worst_hz = 0.0;
  for (double t_c = -40.0; t_c <= 85.0; t_c += 5.0) {
    plant_match_t m;
    const double t_k = 273.15 + t_c;
    assert_int_equal(plant_sense_match(&pc, t_k, split_hz, 0.0, &m), 0);
    sense_tune_out_t o;
    sense_tune_at(&c, m.f_drive_hz, &o);
    assert_int_equal(o.state, SENSE_TUNE_OK);
    /* where the plant's sense resonance lands at the hold's voltage */
    const double ws = 2.0 * M_PI * m.f_sense_hz;
    const double f = sqrt(ws * ws - KE * o.v_v * o.v_v) / (2.0 * M_PI);
    if (fabs(f - m.f_target_hz) > worst_hz) worst_hz = fabs(f - m.f_target_hz);
    assert_true(fabs(o.v_v - m.tune_v) < 1e-6 * m.tune_v);
  }
  /* and without the hold (the voltage of 25 degC kept): off by tenths of a Hz */
  plant_match_t hot;
  assert_int_equal(plant_sense_match(&pc, 273.15 + 85.0, split_hz, 0.0, &hot), 0);
  sense_tune_out_t o25;
  sense_tune_at(&c, c.ref_hz, &o25);
  const double ws = 2.0 * M_PI * hot.f_sense_hz;
  const double f_kept = sqrt(ws * ws - KE * o25.v_v * o25.v_v) / (2.0 * M_PI);
  printf("# mode %u, split %.0f Hz: the hold within %.2g Hz of the target over -40..85 degC; "
         "the 25 degC voltage kept at 85 degC: %+.3f Hz\n",
         mode, split_hz, worst_hz, f_kept - hot.f_target_hz);
  assert_true(worst_hz < 1e-6);
  assert_true(fabs(f_kept - hot.f_target_hz) > 0.05); /* the hold matters */
}

static void test_hold_matched(void **state)
{
  (void)state;
  check_hold(SENSE_TUNE_MATCHED, 0.0);
}

static void test_hold_split(void **state)
{
  (void)state;
  check_hold(SENSE_TUNE_SPLIT, 20.0);
}

static void test_states(void **state)
{
  (void)state;
  sense_tune_cfg_t c = {SENSE_TUNE_OFF, 0.0, 10.0, 1600.0, 1490.0, KE};
  sense_tune_out_t o;
  sense_tune_at(&c, 1490.0, &o);
  assert_int_equal(o.state, SENSE_TUNE_IS_OFF);
  assert_true(o.v_v == 0.0);
  c.mode = SENSE_TUNE_MATCHED;
  c.ke_per_s2_per_v2 = 0.0; /* no electrodes, or no sweep */
  sense_tune_at(&c, 1490.0, &o);
  assert_int_equal(o.state, SENSE_TUNE_UNCALIBRATED);
  c.ke_per_s2_per_v2 = KE;
  c.s0_hz = 1480.0; /* below the drive's: tuning only lowers it */
  sense_tune_at(&c, 1490.0, &o);
  assert_int_equal(o.state, SENSE_TUNE_BELOW);
  assert_true(o.v_v == 0.0);
  c.s0_hz = 1600.0;
  c.v_max_v = 5.0; /* 7.5 V needed */
  sense_tune_at(&c, 1490.0, &o);
  assert_int_equal(o.state, SENSE_TUNE_LIMIT);
  assert_true(o.v_v == 5.0);
  c.v_max_v = 10.0;
  sense_tune_at(&c, NAN, &o); /* no drive frequency: the reference's */
  assert_int_equal(o.state, SENSE_TUNE_OK);
  assert_true(fabs(o.target_hz - 1490.0) < 1e-9);
  assert_true(sense_tune_volts(1600.0, 1600.0, KE) < 0.0);
  assert_true(sense_tune_volts(1600.0, 1490.0, -KE) < 0.0);
  assert_string_equal(sense_tune_state_name(SENSE_TUNE_LIMIT), "limit");
  assert_string_equal(sense_tune_state_name((sense_tune_state_t)99), "?");
}

/* The lost-match monitor's arithmetic (sense_tune.h): weights whose quadrature tone is
 * the rate tone times c0 + u d, with the ripple a DC of each axis puts on the notch's
 * weights (mu x / (1 - e^(j w_m T)) e^(-j theta), far larger than the quadrature tone),
 * sampled at irregular moments as a background would: the window's fit of tone and
 * ripple takes the ripple out, and the estimate is d. */
static void feed_tone(const sense_tune_disc_cfg_t *c, sense_tune_disc_t *s, double d_hz,
                      double windows)
{
  const double rr = 2.5, ri = -1.0; /* the rate axis's tone a - j b */
  const double kr = c->c0_re + c->u_re * d_hz, ki = c->c0_im + c->u_im * d_hz;
  const double qr = rr * kr - ri * ki, qi = rr * ki + ri * kr;
  const double step = 2.0 * M_PI / 20.0, mu = 0.004; /* 250 Hz at 5 kHz */
  const double dc[2] = {30.0, 1500.0};               /* rate, quadrature (raw units) */
  uint32_t tick = s->t0, lcg = 12345u;
  const uint32_t end = s->t0 + (uint32_t)(windows * (double)c->window_ticks);
  while (tick - s->t0 < end - s->t0 || tick < end) {
    lcg = lcg * 1664525u + 1013904223u;
    tick += 10u + (lcg >> 26); /* 10..73 ticks apart */
    if ((int32_t)(tick - end) > 0) break;
    const uint32_t blocks = tick / 10u;
    const double th = fmod((double)blocks * step, 2.0 * M_PI);
    /* the ripple's factor mu / (1 - e^(j w_m T)), times e^(-j theta) */
    const double dr = 1.0 - cos(step), di = -sin(step), dm = dr * dr + di * di;
    const double ar = mu * dr / dm, ai = -mu * di / dm;
    const double er = ar * cos(th) + ai * sin(th), ei = ai * cos(th) - ar * sin(th);
    const double tone[2][2] = {{rr, ri}, {qr, qi}};
    float w[4];
    for (int ax = 0; ax < 2; ax++) {
      const double pr = tone[ax][0] + dc[ax] * er, pi = tone[ax][1] + dc[ax] * ei;
      w[2 * ax] = (float)pr;        /* a */
      w[2 * ax + 1] = (float)(-pi); /* b: the phasor is a - j b */
    }
    const uint32_t phase = (uint32_t)(th / (2.0 * M_PI) * 4294967296.0);
    sense_tune_disc_feed(c, s, w, phase, tick);
  }
}

static void test_disc(void **state)
{
  (void)state;
  const sense_tune_disc_cfg_t c = {1u,  -0.095, 0.2325,          0.00263, -0.00528,
                                   3.7, 5000u,  1.0 - exp(-0.2), 0.0};
  sense_tune_disc_t s;
  const double d_hz[] = {0.0, 1.0, -2.0, 5.0};
  for (size_t i = 0; i < sizeof d_hz / sizeof d_hz[0]; i++) {
    sense_tune_disc_reset(&s, 1000u);
    assert_false(sense_tune_disc_settled(&s));
    feed_tone(&c, &s, d_hz[i], 40.0);
    printf("# detuned %+.1f Hz: the monitor reads %+.4f Hz after %u windows, lost %u\n",
           d_hz[i], s.det_hz, (unsigned)s.windows, (unsigned)s.lost);
    assert_true(sense_tune_disc_settled(&s));
    assert_true(fabs(s.det_hz - d_hz[i]) < 0.02);
    assert_int_equal(s.lost, fabs(d_hz[i]) > c.tol_hz ? 1u : 0u);
  }
}

/* The part's own zero (sense.tune_disc_zero_hz, measured by the flow on the tuned part):
 * a matched part whose reading the model puts at -1.35 Hz reads 0, and the tolerance is
 * symmetric about its match: 3.7 Hz of true detuning either way, not -2.3 and +5. */
static void test_disc_zero(void **state)
{
  (void)state;
  const double zero = -1.35;
  const sense_tune_disc_cfg_t c = {1u,  -0.095, 0.2325,          0.00263, -0.00528,
                                   3.7, 5000u,  1.0 - exp(-0.2), zero};
  sense_tune_disc_t s;
  const double d_hz[] = {0.0, -3.0, 3.0, -4.0, 4.0};
  for (size_t i = 0; i < sizeof d_hz / sizeof d_hz[0]; i++) {
    sense_tune_disc_reset(&s, 1000u);
    feed_tone(&c, &s, zero + d_hz[i], 40.0);
    printf("# zero %+.2f Hz, detuned %+.1f Hz: reads %+.4f Hz, lost %u\n", zero, d_hz[i],
           s.det_hz, (unsigned)s.lost);
    assert_true(fabs(s.det_hz - d_hz[i]) < 0.02);
    assert_int_equal(s.lost, fabs(d_hz[i]) > c.tol_hz ? 1u : 0u);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_hold_matched), cmocka_unit_test(test_hold_split),
      cmocka_unit_test(test_states),       cmocka_unit_test(test_disc),
      cmocka_unit_test(test_disc_zero),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
