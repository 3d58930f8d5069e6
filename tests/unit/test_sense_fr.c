/* sense_fr (force rebalance, sense_fr.h): the design places every root of the model, a
 * bad configuration is refused and changes nothing, and the update's steps (limit,
 * anti-windup, settling, a measurement that is not finite) do what the header says. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "dsp/math_const.h"
#include "gyro/sense_fr.h"

static sense_fr_cfg_t cfg_q1e4(void)
{
  const sense_fr_cfg_t c = {120.0f,  0.85f,  1600.0f, 1.0e4f, 1489.9f, 1.3f,
                            4.6e-4f, 100.0f, 0.05f,   0.005f, 2.0e-4f};
  return c;
}

/* The closed loop's characteristic polynomial of the model at s (sense_fr.h). */
static void char_poly(const sense_fr_cfg_t *c, const sense_fr_design_t *d, double sr, double si,
                      double *re, double *im)
{
  const double pr = d->p_re, pi = d->p_im, a = 1.0 / (double)c->lag_s, g = c->gain_per_v2;
  const double kpr = d->kp_re, kpi = d->kp_im;
  const double kir = d->kit_re / (double)c->dt_s, kii = d->kit_im / (double)c->dt_s;
  /* s (s - p)(s + a) */
  const double ar = sr - pr, ai = si - pi;
  const double br = sr * ar - si * ai, bi = sr * ai + si * ar;
  const double t1r = br * (sr + a) - bi * si, t1i = br * si + bi * (sr + a);
  /* g (-p) a (Kp s + Ki) */
  const double ur = kpr * sr - kpi * si + kir, ui = kpr * si + kpi * sr + kii;
  const double mr = -pr * g * a, mi = -pi * g * a;
  *re = t1r + (mr * ur - mi * ui);
  *im = t1i + (mr * ui + mi * ur);
}

static void test_design_places_roots(void **state)
{
  (void)state;
  const sense_fr_cfg_t c = cfg_q1e4();
  sense_fr_design_t d;
  assert_int_equal(sense_fr_design(&c, &d), 0);
  /* the plant's pole: decaying at ws / 2Q, turning at the 110 Hz split */
  assert_float_equal(d.p_re, -(float)(FM_PI * 1600.0 / 1.0e4), 1e-3f);
  assert_float_equal(d.p_im / (float)(2.0 * FM_PI), 110.1f, 0.05f);
  const double w = 2.0 * FM_PI * 120.0, z = 0.85;
  const double roots[3][2] = {{-z * w, w * sqrt(1.0 - z * z)},
                              {-z * w, -w * sqrt(1.0 - z * z)},
                              {-(double)d.c_re, -(double)d.c_im}};
  assert_true(d.c_re > 0.0f);
  for (int k = 0; k < 3; k++) {
    double re, im;
    char_poly(&c, &d, roots[k][0], roots[k][1], &re, &im);
    const double scale = pow(hypot(roots[k][0], roots[k][1]), 3.0);
    assert_true(hypot(re, im) < 1e-5 * scale);
  }
}

static void test_refuses_bad_configuration(void **state)
{
  (void)state;
  sense_fr_design_t d, before;
  memset(&d, 0x5A, sizeof d);
  before = d;
  sense_fr_cfg_t c = cfg_q1e4();
  c.gain_per_v2 = 0.0f;
  assert_int_equal(sense_fr_design(&c, &d), -1);
  c = cfg_q1e4();
  c.bw_hz = 240.0f; /* 2 zeta w beyond the lag's pole: c in the right half plane */
  assert_int_equal(sense_fr_design(&c, &d), -1);
  c = cfg_q1e4();
  c.q_sense = NAN;
  assert_int_equal(sense_fr_design(&c, &d), -1);
  c = cfg_q1e4();
  c.bw_hz = 300.0f; /* w T beyond the Euler integrator's reach */
  c.lag_s = 1e-5f;
  assert_int_equal(sense_fr_design(&c, &d), -1);
  assert_int_equal(memcmp(&d, &before, sizeof d), 0);
  assert_int_equal(sense_fr_design(NULL, &d), -1);
}

/* A constant residual drives the force to its limit: scaled back along its direction,
 * the integral held, never settled; a NaN holds the force and clears the settling. */
static void test_limit_and_settle(void **state)
{
  (void)state;
  const sense_fr_cfg_t c = cfg_q1e4();
  sense_fr_design_t d;
  assert_int_equal(sense_fr_design(&c, &d), 0);
  sense_fr_t fr;
  sense_fr_reset(&fr);
  for (int i = 0; i < 2000; i++) sense_fr_update(&d, &fr, 3.0f, 4.0f);
  assert_int_equal(fr.at_limit, 1u);
  assert_int_equal(fr.settled, 0u);
  assert_float_equal(hypotf(fr.f_re, fr.f_im), 100.0f, 1e-3f);
  const float i_re = fr.i_re;
  sense_fr_update(&d, &fr, 3.0f, 4.0f);
  assert_float_equal(fr.i_re, i_re, 1e-3f); /* held, not winding up */
  /* a zero residual: the force holds its integral, the loop settles after settle_s */
  sense_fr_reset(&fr);
  for (int i = 0; i < 24; i++) sense_fr_update(&d, &fr, 0.0f, 0.0f);
  assert_int_equal(fr.settled, 0u);
  sense_fr_update(&d, &fr, 0.0f, 0.0f);
  assert_int_equal(fr.settled, 1u);
  const float f_before = fr.f_re;
  sense_fr_update(&d, &fr, NAN, 0.0f);
  assert_int_equal(fr.skip, 1u);
  assert_int_equal(fr.settled, 0u);
  assert_true(fr.f_re == f_before);
  /* the readout is g (I + Kr R): g I with no residual (the steady state's -g F) */
  fr.i_re = -2.0f;
  fr.i_im = 1.0f;
  sense_fr_take(&d, &fr, 0.0f, 0.0f);
  assert_float_equal(fr.out_re, -2.6f, 1e-6f);
  assert_float_equal(fr.out_im, 1.3f, 1e-6f);
  /* ... and with one, g Kr R on top; a residual that is not finite reads g I alone */
  sense_fr_take(&d, &fr, 1.0f, 0.0f);
  assert_float_equal(fr.out_re, -2.6f + d.krg_re, 1e-5f);
  assert_float_equal(fr.out_im, 1.3f + d.krg_im, 1e-5f);
  sense_fr_take(&d, &fr, NAN, 0.0f);
  assert_float_equal(fr.out_re, -2.6f, 1e-6f);
}

/* The readout's zero, Kr s + Ki, lies on the third root -c (sense_fr.h): Kr c = Ki, with
 * Kr = krg / g. The readout -g F had its zero at -Ki / Kp: a matched part's step
 * overshot by 25 % and took 12 ms (test_cl_sense_tune.c, which failed first). */
static void test_readout_zero_on_third_root(void **state)
{
  (void)state;
  sense_fr_cfg_t c = cfg_q1e4();
  for (int k = 0; k < 2; k++) {
    if (k == 1) c.f_sense_hz = c.f_drive_hz; /* matched */
    sense_fr_design_t d;
    assert_int_equal(sense_fr_design(&c, &d), 0);
    const double g = (double)c.gain_per_v2;
    const double kr_re = d.krg_re / g, kr_im = d.krg_im / g;
    const double ki_re = d.kit_re / (double)c.dt_s, ki_im = d.kit_im / (double)c.dt_s;
    const double zr = kr_re * d.c_re - kr_im * d.c_im, zi = kr_re * d.c_im + kr_im * d.c_re;
    assert_true(hypot(zr - ki_re, zi - ki_im) < 1e-5 * hypot(ki_re, ki_im));
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_design_places_roots),
      cmocka_unit_test(test_refuses_bad_configuration),
      cmocka_unit_test(test_limit_and_settle),
      cmocka_unit_test(test_readout_zero_on_third_root),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
