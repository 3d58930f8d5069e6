/* The tracking drive's PLL (gyro/drive_track.h): its design from the identified model at
 * any Q, and the loop closed around the drive resonance's envelope model,
 *     dZ/dt = (-1/tau + j 2 pi (f0 - f)) Z + (1/tau) e^{j (P - pi/2)}      (6-12), (6-17)
 * in the NCO's frame (unit gain; a force of 1 holds |Z| = 1 at the resonance), stepped once
 * per block as the gyro runs it, with a proportional amplitude control whose force is
 * limited to ring the resonance up in about 3 ms whatever Q (as 12.75 V does on this comb):
 * pull-in from a resonance far off the calibrated frequency, a temperature ramp of the
 * resonance followed without a phase error, the NCO's integer step as the only
 * frequency, the window and its edge flag, the hold while the amplitude is tiny, and the
 * bumpless change of gains at lock. */
#include <complex.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "dsp/math_const.h"
#include "gyro/drive_track.h"

#define FS_HZ 50000.0
#define DECIM 10.0
#define F_CAL_HZ 1489.9
#define STEP_HZ (FS_HZ / 2147483648.0)

static drive_track_design_in_t design_in(double q)
{
  const drive_track_design_in_t in = {q,     F_CAL_HZ, 30.0,  3.0,         300.0, FS_HZ,
                                      DECIM, 2.0,      0.005, FM_PI / 2.0, 0.1};
  return in;
}

static void design(double q, drive_track_cfg_t *c, drive_track_design_out_t *o)
{
  const drive_track_design_in_t in = design_in(q);
  assert_int_equal(drive_track_design(&in, c, o), 0);
}

/* At every Q the crossover is near the one asked for and the margin at least 60 deg;
 * the thermometer's slope is 2Q/f0 rad per Hz. */
static void test_design_any_q(void **state)
{
  (void)state;
  const double qs[] = {20.0, 33.33, 1.0e3, 1.0e4, 1.0e5};
  for (size_t i = 0; i < sizeof qs / sizeof qs[0]; i++) {
    drive_track_cfg_t c;
    drive_track_design_out_t o;
    design(qs[i], &c, &o);
    print_message("# Q %g: bw %.2f Hz (acq %.2f), PM %.1f deg, kp %.3g Hz/rad\n", qs[i],
                  o.bw_hz, o.acq_bw_hz, o.phase_margin_deg, o.kp_hz_per_rad);
    assert_true(o.phase_margin_deg >= 60.0);
    assert_true(o.bw_hz > 20.0 && o.bw_hz <= 30.0);
    assert_true(o.acq_bw_hz > o.bw_hz);
    assert_true(c.kp_acq > c.kp_lock && c.kp_lock > 0.0f && c.ki_dt_lock > 0.0f);
    assert_float_equal(c.p_eq_per_step_rad, 2.0 * qs[i] / F_CAL_HZ * STEP_HZ,
                       1e-6 * c.p_eq_per_step_rad);
    assert_int_equal(c.win_steps, (int32_t)(0.005 * F_CAL_HZ / STEP_HZ));
  }
}

static void test_design_refuses(void **state)
{
  (void)state;
  drive_track_cfg_t c, keep;
  drive_track_design_out_t o;
  design(1000.0, &c, &o);
  keep = c;
  drive_track_design_in_t bad[8];
  for (int i = 0; i < 8; i++) bad[i] = design_in(1000.0);
  bad[0].q = 0.0;
  bad[1].q = NAN;
  bad[2].f0_hz = -1.0;
  bad[3].bw_hz = 0.0;
  bad[4].window_rel = 0.0;
  bad[5].acq_bw_factor = 0.5;
  bad[6].min_amp_rel = 1.0;
  bad[7].fs_hz = 0.0;
  for (int i = 0; i < 8; i++) {
    assert_int_equal(drive_track_design(&bad[i], &c, &o), -1);
    assert_memory_equal(&c, &keep, sizeof c);
  }
  assert_int_equal(drive_track_design(NULL, &c, &o), -1);
}

/* The envelope model with the PLL in the loop, once per block. */
typedef struct {
  double q, tau_s, f0_hz;
  double complex z;
  drive_track_cfg_t c;
  drive_track_t t;
  int32_t off;
} loop_t;

static void loop_init(loop_t *l, double q, double f0_hz)
{
  design(q, &l->c, &(drive_track_design_out_t){0});
  drive_track_reset(&l->t);
  l->q = q;
  l->tau_s = 2.0 * q / (2.0 * FM_PI * F_CAL_HZ);
  l->f0_hz = f0_hz;
  l->z = 0.0;
  l->off = 0;
}

/* One block: the plant over DECIM samples (exact for a constant frequency), then the PLL
 * on the phase it measured. Returns the phase error (rad). */
static double loop_block(loop_t *l, int locked)
{
  const double f_hz = F_CAL_HZ + l->off * STEP_HZ; /* the NCO's frequency: whole steps */
  const double dt = DECIM / FS_HZ;
  const double complex a = -1.0 / l->tau_s + I * 2.0 * FM_PI * (l->f0_hz - f_hz);
  const double f_max = l->tau_s / 0.003 > 1.0 ? l->tau_s / 0.003 : 1.0;
  double force = 1.0 + f_max * (1.0 - cabs(l->z));
  force = force < 0.0 ? 0.0 : (force > f_max ? f_max : force);
  const double complex u = force * cexp(I * (l->c.p_init_rad - FM_PI / 2.0)) / l->tau_s;
  const double complex e = cexp(a * dt);
  l->z = l->z * e + u * (e - 1.0) / a;
  const double err = remainder(0.0 - carg(l->z), 2.0 * FM_PI); /* phase set point 0 */
  l->off = drive_track_update(&l->c, &l->t, (float)err, (float)cabs(l->z), locked);
  return err;
}

/* The resonance 2 Hz off the calibrated frequency (130 bandwidths at Q = 10^5, about
 * 50 K of structure temperature): the PLL pulls in within 0.1 s and settles on it to
 * the NCO's resolution. */
static void test_pull_in(void **state)
{
  (void)state;
  const double qs[] = {33.33, 1.0e3, 1.0e5};
  const double df[] = {+2.0, -2.0};
  for (size_t i = 0; i < 3; i++) {
    for (size_t k = 0; k < 2; k++) {
      loop_t l;
      loop_init(&l, qs[i], F_CAL_HZ + df[k]);
      double t_in = -1.0;
      for (int n = 0; n < 5000; n++) { /* 1 s */
        const double err = loop_block(&l, n > 1000);
        const double f_hz = F_CAL_HZ + l.off * STEP_HZ;
        if (t_in < 0.0 && fabs(err) < 0.01 && fabs(f_hz - l.f0_hz) < 0.05) t_in = n * 2e-4;
      }
      const double f_hz = F_CAL_HZ + l.off * STEP_HZ;
      print_message("# Q %g, f0 %+g Hz: in at %.3f s, final error %.2e Hz\n", qs[i], df[k],
                    t_in, f_hz - l.f0_hz);
      assert_true(t_in >= 0.0 && t_in < 0.1);
      /* Settled: within a few steps (the model's steady state sits on a step). */
      assert_true(fabs(f_hz - l.f0_hz) < 4.0 * STEP_HZ + l.f0_hz / (2.0 * l.q) * 1e-3);
      assert_int_equal(l.t.at_limit, 0u);
    }
  }
}

/* The resonance ramping at 10 K/min x 20 ppm/K (5e-3 Hz/s) at Q = 10^5: followed with a
 * phase error below 0.5 deg (the loop is type 2 at high Q). */
static void test_ramp_followed(void **state)
{
  (void)state;
  loop_t l;
  loop_init(&l, 1.0e5, F_CAL_HZ);
  double worst = 0.0;
  for (int n = 0; n < 100000; n++) { /* 20 s */
    l.f0_hz = F_CAL_HZ - 5e-3 * n * 2e-4;
    const double err = loop_block(&l, n > 2500);
    if (n > 5000 && fabs(err) > worst) worst = fabs(err);
  }
  print_message("# ramp 5 mHz/s, Q 1e5: worst phase error %.3f deg\n", worst * 180.0 / FM_PI);
  assert_true(worst < 0.5 * FM_PI / 180.0);
  assert_true(fabs(F_CAL_HZ + l.off * STEP_HZ - l.f0_hz) < 1e-3);
}

/* A resonance outside the window: the frequency stops at the edge and says so. */
static void test_window_edge(void **state)
{
  (void)state;
  loop_t l;
  loop_init(&l, 1.0e3, F_CAL_HZ * 1.01);
  for (int n = 0; n < 20000; n++) (void)loop_block(&l, 0);
  assert_int_equal(l.off, l.c.win_steps);
  assert_int_equal(l.t.at_limit, 1u);
  assert_true(l.t.int_steps <= l.c.win_steps); /* no wind-up beyond it */
}

/* Tiny amplitude: the phase is noise, nothing moves. */
static void test_hold_while_small(void **state)
{
  (void)state;
  drive_track_cfg_t c;
  drive_track_t t;
  design(1.0e3, &c, &(drive_track_design_out_t){0});
  drive_track_reset(&t);
  for (int n = 0; n < 100; n++) assert_int_equal(drive_track_update(&c, &t, 1.0f, 0.05f, 0), 0);
  assert_float_equal(drive_track_p_eq_rad(&c, &t), c.p_init_rad, 0.0f);
}

/* The gains change at lock without a jump of the frequency, and p_eq follows the offset
 * by the thermometer's slope. */
static void test_bumpless_and_p_eq(void **state)
{
  (void)state;
  drive_track_cfg_t c;
  drive_track_t t;
  design(1.0e3, &c, &(drive_track_design_out_t){0});
  drive_track_reset(&t);
  int32_t off = 0;
  for (int n = 0; n < 50; n++) off = drive_track_update(&c, &t, 0.02f, 1.0f, 0);
  const int32_t before = off;
  const int32_t after = drive_track_update(&c, &t, 0.02f, 1.0f, 1);
  /* One more integral step (the locked one) and nothing of the proportional change. */
  assert_true(labs((long)(after - before)) <= (long)(c.ki_dt_lock * 0.02f) + 2L);
  assert_true(before < 0); /* e > 0: more lag than at the resonance, the frequency goes down */
  assert_float_equal(drive_track_p_eq_rad(&c, &t),
                     c.p_init_rad - c.p_eq_per_step_rad * (float)after, 1e-6f);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_design_any_q),      cmocka_unit_test(test_design_refuses),
      cmocka_unit_test(test_pull_in),           cmocka_unit_test(test_ramp_followed),
      cmocka_unit_test(test_window_edge),       cmocka_unit_test(test_hold_while_small),
      cmocka_unit_test(test_bumpless_and_p_eq),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
