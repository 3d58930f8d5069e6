/* The mechanics' imperfections beyond the linear gyro (host_sim/plant/mech.h), each
 * against its physical law, measured on free oscillations and steady states of the
 * discretised model:
 *  - cubic suspension stiffness (Duffing): frequency shift 3 (k3/k) A^2 / 8;
 *  - electrostatic spring softening: df = -f0 k_e / (2 k) (exactly sqrt(1 - k_e/k));
 *  - Q against temperature (qlaw.h) at two temperatures, from the ring-down;
 *  - the coupling drifts act as the configured couplings do;
 *  - the electrodes' stiffness (mech_set_elec): a coupling acts as the configured k_q and
 *    nulls it, a softening moves the sense resonance by the sqrt law, held before the
 *    rebase, exact after it; the pull-in margin;
 *  - all off by default, bad values refused with nothing changed, the cubic law's range
 *    flagged. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/mech.h"
#include "plant/qlaw.h"
#include "sine_fit_ref.h"

static const double kTwoPi = 6.28318530717958647692;

static void quiet_cfg(mech_cfg_t *c)
{
  mech_default_cfg(c);
  c->brownian = 0;
  c->full_kinematics = 0;
}

/* Frequency of a free oscillation of axis (0 drive, 1 sense) from its upward zero
 * crossings (linear interpolation) over n samples after a start at x0, at rest. Also the
 * mean amplitude^2 over the run, x^2 + (v/w)^2 at the sample after each crossing (for
 * the Duffing oscillator that is A^2 (1 - (k3/k) A^2 / 4), 0.07 % of the shift here). */
static double free_frequency(mech_t *m, int axis, double x0, long n, double *amp2)
{
  mech_state_t s = {0.0, 0.0, 0.0, 0.0};
  if (axis == 0) s.y_m = x0;
  else s.x_m = x0;
  mech_set_state(m, &s);
  const double T = 1.0 / m->cfg.fs_hz;
  double prev = x0, t_first = -1.0, t_last = 0.0, a2 = 0.0, w = 0.0;
  long crossings = 0;
  for (long k = 1; k <= n; k++) {
    mech_step(m, 0.0, 0.0, 0.0, 0.0);
    const mech_state_t st = mech_state(m);
    const double x = axis == 0 ? st.y_m : st.x_m, v = axis == 0 ? st.vy_mps : st.vx_mps;
    if (prev < 0.0 && x >= 0.0) {
      const double t = (double)(k - 1) * T + T * (-prev) / (x - prev);
      if (t_first < 0.0) t_first = t;
      else w = kTwoPi * (double)crossings / (t - t_first);
      t_last = t;
      crossings++;
      if (w > 0.0) a2 += x * x + (v / w) * (v / w);
    }
    prev = x;
  }
  assert_true(crossings > 10);
  if (amp2 != NULL) *amp2 = a2 / (double)(crossings - 1);
  return (double)(crossings - 1) / (t_last - t_first);
}

/* Duffing: x'' + wn^2 (x + kappa x^3) = 0 from x = A at rest oscillates at
 * f0 (1 + 3 kappa A^2 / 8 - 21 (kappa A^2)^2 / 256 ...) (Lindstedt-Poincare). Here
 * kappa A^2 = 8/3 1e-3, a shift of 1e-3 f0 = 1.49 Hz. Tolerance of the measured shift
 * against 3 kappa A^2 / 8, derived: the cubic force is held at its mid-sample value,
 * gain sinc(w T / 2) = 0.99855 on its fundamental (mech.h): -0.15 %; Q = 1e6 lets A^2
 * fall 0.19 % over the 0.2 s run, the crossings' mean A^2 is used; second order
 * 21/256 (kappa A^2)^2 / (3/8 kappa A^2) = 0.06 %; the crossings' timing over 298
 * cycles, < 1e-6. So within 0.5 %. Hardening and softening alike. */
static void test_duffing_shift(void **state)
{
  (void)state;
  mech_cfg_t c;
  quiet_cfg(&c);
  c.q1 = 1e6;
  static mech_t m;
  const double A = 10e-6;
  const long n = 10000;
  assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 1u), 0);
  const double f0 = free_frequency(&m, 0, A, n, NULL);
  assert_true(fabs(f0 / c.f1_hz - 1.0) < 1e-6); /* linear: exact */
  for (int sign = -1; sign <= 1; sign += 2) {
    c.k3_drive_per_m2 = sign * (8.0 / 3.0) * 1e-3 / (A * A);
    assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 1u), 0);
    double a2;
    const double f = free_frequency(&m, 0, A, n, &a2);
    const double want = f0 * 3.0 * c.k3_drive_per_m2 * a2 / 8.0;
    print_message("k3/k %+.4g 1/m^2: f - f0 = %+.5f Hz, 3 k3 A^2 f0 / 8 = %+.5f Hz (A %.4g um)\n",
                  c.k3_drive_per_m2, f - f0, want, 1e6 * sqrt(a2));
    assert_true(fabs((f - f0) / want - 1.0) < 5e-3);
    assert_true(mech_laws_out(&m) == 0u); /* kappa A^2 = 2.7e-3: in range */
  }
  /* the sense suspension the same way (its own k3) */
  mech_cfg_t s;
  quiet_cfg(&s);
  s.q2 = 1e6;
  const double X = 1e-6;
  assert_int_equal(mech_init(&m, &s, s.temp_ref_k, 2u), 0);
  const double fs0 = free_frequency(&m, 1, X, n, NULL);
  s.k3_sense_per_m2 = (8.0 / 3.0) * 1e-3 / (X * X);
  assert_int_equal(mech_init(&m, &s, s.temp_ref_k, 2u), 0);
  double a2;
  const double fs1 = free_frequency(&m, 1, X, n, &a2);
  const double want = fs0 * 3.0 * s.k3_sense_per_m2 * a2 / 8.0;
  print_message("sense: f - f0 = %+.5f Hz, 3 k3 A^2 f0 / 8 = %+.5f Hz\n", fs1 - fs0, want);
  /* at 2 kHz the hold's gain is sinc = 0.99737: tolerance 0.6 % */
  assert_true(fabs((fs1 - fs0) / want - 1.0) < 6e-3);
}

/* The cubic expansion's range: beyond |k3/k| y^2 = MECH_DUFFING_MAX the term is held at
 * its edge (a softening spring then cannot run away) and flagged until read. */
static void test_duffing_range(void **state)
{
  (void)state;
  mech_cfg_t c;
  quiet_cfg(&c);
  c.k3_drive_per_m2 = -2.0 * MECH_DUFFING_MAX / (10e-6 * 10e-6); /* edge at 7.1 um */
  static mech_t m;
  assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 1u), 0);
  assert_true(mech_laws_out(&m) == 0u);
  (void)free_frequency(&m, 0, 10e-6, 2000, NULL);
  assert_true(mech_laws_out(&m) == MECH_OUT_DUFFING_DRIVE);
  assert_true(mech_laws_out(&m) == 0u); /* cleared when read */
  const mech_state_t st = mech_state(&m);
  assert_true(isfinite(st.y_m) && fabs(st.y_m) < 20e-6);
}

/* A biased parallel-plate pair softens the sense spring: f = f2 sqrt(1 - k_e/k), to first
 * order df = -f2 k_e / (2 k) (thesis (6-3); Senturia §6.4.3). k_e/k = 1 %: the exact law
 * within 1e-6 (the softening is in the generator, exact), the first-order law within
 * (k_e/k) / 4 = 0.25 % (its next term is -(k_e/k)^2 / 8 against k_e/(2k)). The drive is
 * untouched. */
static void test_spring_softening(void **state)
{
  (void)state;
  mech_cfg_t c;
  quiet_cfg(&c);
  c.q1 = c.q2 = 1e6;
  static mech_t m;
  assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 3u), 0);
  const double f0 = free_frequency(&m, 1, 1e-7, 10000, NULL);
  const double fd0 = free_frequency(&m, 0, 1e-6, 10000, NULL);
  const double k = (kTwoPi * c.f2_hz) * (kTwoPi * c.f2_hz);
  c.ke2_per_s2 = 0.01 * k;
  assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 3u), 0);
  const double f1 = free_frequency(&m, 1, 1e-7, 10000, NULL);
  const double df_first = -f0 * c.ke2_per_s2 / (2.0 * k);
  print_message("k_e/k = 1 %%: df = %.4f Hz; first order %.4f Hz, exact %.4f Hz\n", f1 - f0,
                df_first, f0 * (sqrt(0.99) - 1.0));
  assert_true(fabs(f1 / f0 - sqrt(0.99)) < 1e-6);
  assert_true(fabs((f1 - f0) / df_first - 1.0) < 2.5e-3 + 1e-4);
  assert_true(fabs(free_frequency(&m, 0, 1e-6, 10000, NULL) / fd0 - 1.0) < 1e-9);
  /* pull-in margin: at least half the stiffness is refused */
  c.ke2_per_s2 = 0.5 * k * 1.0001;
  const char *key = NULL;
  assert_true(mech_cfg_check(&c, &key) < 0);
  assert_string_equal(key, "ke2_per_s2");
}

/* Decay rate of a free drive oscillation: Q = wn / (2 sigma), sigma from a least-squares
 * line through ln of the amplitude sqrt(y^2 + (y'/wn)^2) at every sample (its ripple at
 * 2 w, of relative size 1/(2Q), averages out over the run's cycles). */
static double ringdown_q(mech_t *m, long n)
{
  mech_state_t s = {1e-6, 0.0, 0.0, 0.0};
  mech_set_state(m, &s);
  const double T = 1.0 / m->cfg.fs_hz, wn = mech_wn1(m);
  double st = 0, sv = 0, stt = 0, stv = 0;
  long cnt = 0;
  for (long k = 1; k <= n; k++) {
    mech_step(m, 0.0, 0.0, 0.0, 0.0);
    const mech_state_t x = mech_state(m);
    const double t = (double)k * T;
    const double l = 0.5 * log(x.y_m * x.y_m + (x.vy_mps / wn) * (x.vy_mps / wn));
    st += t;
    sv += l;
    stt += t * t;
    stv += t * l;
    cnt++;
  }
  const double slope = ((double)cnt * stv - st * sv) / ((double)cnt * stt - st * st);
  return wn / (-2.0 * slope);
}

/* Q(T) by its law at two temperatures, -40 and 85 degC, measured on the ring-down of a
 * Q = 1000 drive mode (tau = 0.21 s, 0.5 s of decay), against the law written out here
 * independently of qlaw.c: gas damping Q ~ wn / mu(T) with Sutherland's mu ~ T^1.5 /
 * (T + 110.4 K); thermoelastic Q ~ kappa / (alpha^2 T wn^3) with Okada & Tokumaru's
 * alpha(T) and kappa ~ T^-1.3. The blocks are made with the law's Q when the temperature
 * moves (mech_set_temp), so the measured Q matches to the fit's precision (1e-4 asked). */
static void test_q_law_two_temperatures(void **state)
{
  (void)state;
  const double temps[2] = {233.15, 358.15};
  for (int law = QLAW_GAS; law <= QLAW_TED; law++) {
    for (int i = 0; i < 2; i++) {
      mech_cfg_t c;
      quiet_cfg(&c);
      c.q1 = 1000.0;
      c.q_law = law;
      static mech_t m;
      assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 4u), 0);
      assert_true(mech_q1(&m) == 1000.0);
      assert_int_equal(mech_set_temp(&m, temps[i]), 0);
      const double t = temps[i], t0 = c.temp_ref_k;
      const double r = 1.0 - 0.5 * c.ket_per_k * (t - t0); /* wn(T) / wn(T0) (2-32) */
      double want;
      if (law == QLAW_GAS) {
        const double mu = pow(t, 1.5) / (t + 110.4), mu0 = pow(t0, 1.5) / (t0 + 110.4);
        want = 1000.0 * r * mu0 / mu;
      } else {
        const double a = (3.725 * (1 - exp(-5.88e-3 * (t - 124))) + 5.548e-4 * t);
        const double a0 = (3.725 * (1 - exp(-5.88e-3 * (t0 - 124))) + 5.548e-4 * t0);
        want = 1000.0 * pow(t / t0, -1.3) * (a0 / a) * (a0 / a) * (t0 / t) / (r * r * r);
      }
      const double q = ringdown_q(&m, 25000);
      print_message("law %d at %.2f K: Q %.3f measured, %.3f by the law (mech %.3f)\n", law, t,
                    q, want, mech_q1(&m));
      assert_true(fabs(mech_q1(&m) / want - 1.0) < 1e-12);
      assert_true(fabs(q / want - 1.0) < 1e-4);
      assert_true(fabs(mech_q2(&m) / c.q2 - mech_q1(&m) / c.q1) < 1e-14); /* one law */
      assert_true(mech_laws_out(&m) == 0u);
    }
  }
}

/* Outside its temperature range a Q law is held at the edge and flagged; the constant
 * law never is. */
static void test_q_law_range(void **state)
{
  (void)state;
  mech_cfg_t c;
  quiet_cfg(&c);
  c.q_law = QLAW_TED;
  static mech_t m;
  assert_int_equal(mech_init(&m, &c, 190.0, 5u), 0); /* below the law's 200 K */
  assert_true(mech_laws_out(&m) == MECH_OUT_Q);
  const double q_edge = mech_q1(&m);
  assert_int_equal(mech_set_temp(&m, 180.0), 0);
  assert_true(mech_laws_out(&m) == MECH_OUT_Q);
  /* held at 200 K: only the (2-32) factor wn(T0)^3 / wn(T)^3 still moves */
  const double r190 = 1.0 - 0.5 * c.ket_per_k * (190.0 - c.temp_ref_k);
  const double r180 = 1.0 - 0.5 * c.ket_per_k * (180.0 - c.temp_ref_k);
  assert_true(fabs(mech_q1(&m) / q_edge - pow(r190 / r180, 3.0)) < 1e-12);
  assert_int_equal(mech_set_temp(&m, 300.0), 0);
  assert_true(mech_laws_out(&m) == 0u);
  c.q_law = QLAW_CONST;
  assert_int_equal(mech_init(&m, &c, 100.0, 5u), 0);
  assert_true(mech_laws_out(&m) == 0u && mech_q1(&m) == c.q1);
}

/* Sense response to a drive held at resonance (force per sample), fitted at the drive
 * frequency: amplitude and phase of x. */
static void sense_phasor(mech_t *m, double *amp, double *ph)
{
  const double T = 1.0 / m->cfg.fs_hz, f = m->cfg.f1_hz, w = kTwoPi * f;
  const long n_settle = 20000, n_fit = 5000;
  double *x = malloc(sizeof(double) * (size_t)n_fit);
  assert_non_null(x);
  for (long k = 0; k < n_settle + n_fit; k++) {
    const double fy = 26.3 * (sin(w * ((double)k + 1.0) * T) - sin(w * (double)k * T)) / (w * T);
    mech_step(m, fy, 0.0, 0.0, 0.0);
    if (k >= n_settle) x[k - n_settle] = mech_state(m).x_m;
  }
  double coef[3];
  assert_true(ref_sine_fit(x, (size_t)n_fit, (double)(n_settle + 1) * T, T, &f, 1, coef) >= 0.0);
  *amp = hypot(coef[1], coef[2]);
  *ph = atan2(coef[1], coef[2]);
  free(x);
}

/* A drift of k_q or d_q (mech_set_coupling_drift, held at mid-sample) moves the sense
 * response as the same coupling configured in the generator does: amplitude within
 * 0.3 % (the hold's sinc(w T/2) = 0.99855 on the drifted part), phase within 0.05 deg. */
static void test_coupling_drift(void **state)
{
  (void)state;
  const double kq = 2.0 * (kTwoPi * 1489.9) * 100.0 * (kTwoPi / 360.0); /* 100 deg/s */
  const double dq = 2.0 * 100.0 * (kTwoPi / 360.0);
  for (int which = 0; which < 2; which++) {
    mech_cfg_t c;
    quiet_cfg(&c);
    static mech_t ref, dr;
    if (which == 0) c.kq_per_s2 = kq;
    else c.dq_per_s = dq;
    assert_int_equal(mech_init(&ref, &c, c.temp_ref_k, 6u), 0);
    quiet_cfg(&c);
    assert_int_equal(mech_init(&dr, &c, c.temp_ref_k, 6u), 0);
    double a0, p0, a1, p1;
    sense_phasor(&dr, &a0, &p0);
    assert_true(a0 < 1e-20); /* no coupling, no drift: no sense motion */
    assert_int_equal(mech_init(&dr, &c, c.temp_ref_k, 6u), 0);
    assert_int_equal(mech_set_coupling_drift(&dr, which == 0 ? kq : 0.0, which == 1 ? dq : 0.0),
                     0);
    sense_phasor(&ref, &a0, &p0);
    sense_phasor(&dr, &a1, &p1);
    print_message("%s: configured %.5e m at %.4f deg, drift %.5e m at %.4f deg\n",
                  which == 0 ? "k_q" : "d_q", a0, p0 * 360.0 / kTwoPi, a1, p1 * 360.0 / kTwoPi);
    assert_true(fabs(a1 / a0 - 1.0) < 3e-3);
    assert_true(fabs(p1 - p0) * 360.0 / kTwoPi < 0.05);
  }
  static mech_t m;
  mech_cfg_t c;
  quiet_cfg(&c);
  assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 6u), 0);
  assert_int_equal(mech_set_coupling_drift(&m, NAN, 0.0), -1);
  assert_true(m.drift_kq_per_s2 == 0.0 && m.held == 0);
}

/* The nulling electrodes' coupling k_yx (mech_set_elec) adds to k_q: before the rebase (a
 * held force) the sense response equals the configured coupling's within the hold's
 * sinc(wn1 T/2) = 0.99855 (0.3 %, as the drift); after mech_elec_rebase it is in the
 * generator, the same response within 1e-9; k_yx = -k_q nulls the quadrature motion to
 * 1e-9 of it. A small change after that stays held (no re-discretisation). */
static void test_elec_coupling(void **state)
{
  (void)state;
  const double kq = 2.0 * (kTwoPi * 1489.9) * 1500.0 * (kTwoPi / 360.0); /* 1500 deg/s */
  mech_cfg_t c;
  quiet_cfg(&c);
  c.kq_per_s2 = kq;
  static mech_t ref, el;
  assert_int_equal(mech_init(&ref, &c, c.temp_ref_k, 6u), 0);
  double a0, p0, a1, p1;
  sense_phasor(&ref, &a0, &p0);
  quiet_cfg(&c);
  assert_int_equal(mech_init(&el, &c, c.temp_ref_k, 6u), 0);
  assert_int_equal(mech_set_elec(&el, kq, 0.0), 0);
  assert_int_equal(el.held, 1);
  sense_phasor(&el, &a1, &p1);
  print_message("k_yx held: %.6e m at %.4f deg (configured k_q %.6e m at %.4f deg)\n", a1,
                p1 * 360.0 / kTwoPi, a0, p0 * 360.0 / kTwoPi);
  assert_true(fabs(a1 / a0 - 1.0) < 3e-3 && fabs(a1 / a0 - 1.0) > 1e-4);
  assert_true(fabs(p1 - p0) * 360.0 / kTwoPi < 0.05);
  const uint64_t r0 = el.refresh_count;
  assert_int_equal(mech_elec_rebase(&el), 1);
  assert_true(el.refresh_count == r0 + 1 && fabs(el.elec_disc[0] / kq - 1.0) < 1e-12);
  assert_int_equal(mech_init(&ref, &ref.cfg, c.temp_ref_k, 6u), 0);
  mech_set_state(&el, &(mech_state_t){0.0, 0.0, 0.0, 0.0});
  sense_phasor(&ref, &a0, &p0);
  sense_phasor(&el, &a1, &p1);
  print_message("k_yx rebased: %.9e m (configured %.9e m)\n", a1, a0);
  assert_true(fabs(a1 / a0 - 1.0) < 1e-9 && fabs(p1 - p0) < 1e-9);
  /* 0.5 deg/s more: below the 10 deg/s threshold, stays held */
  assert_int_equal(mech_set_elec(&el, kq * (1.0 + 0.5 / 1500.0), 0.0), 0);
  sense_phasor(&el, &a1, &p1);
  assert_int_equal(mech_elec_rebase(&el), 0);
  assert_true(fabs(el.elec_disc[0] / kq - 1.0) < 1e-12);
  /* nulling: the configured k_q against k_yx = -k_q, rebased */
  quiet_cfg(&c);
  c.kq_per_s2 = kq;
  assert_int_equal(mech_init(&el, &c, c.temp_ref_k, 6u), 0);
  assert_int_equal(mech_set_elec(&el, -kq, 0.0), 0);
  for (int k = 0; k < 50; k++) mech_step(&el, 0.0, 0.0, 0.0, 0.0);
  assert_int_equal(mech_elec_rebase(&el), 1);
  assert_true(fabs(mech_kyx_total(&el)) < 1e-9 * kq);
  sense_phasor(&el, &a1, &p1);
  print_message("k_q nulled by k_yx: %.3e m (%.3e of the quadrature motion)\n", a1, a1 / a0);
  assert_true(a1 < 1e-9 * a0);
}

/* The electrodes' softening k_e (mech_set_elec) moves the sense resonance to
 * sqrt(wn2^2 - k_e) (mech_wn2_eff): 1 % of the stiffness, held before the rebase (within
 * the hold's error on the shift, (1 - sinc(wn2 T/2)) k_e / (2 k) = 1.3e-5 of f) and
 * exact after it (1e-6, as test_spring_softening); held at the pull-in margin beyond half
 * the stiffness and flagged; bad values refused with nothing changed. */
static void test_elec_softening(void **state)
{
  (void)state;
  mech_cfg_t c;
  quiet_cfg(&c);
  c.q1 = c.q2 = 1e6;
  static mech_t m, before;
  assert_int_equal(mech_init(&m, &c, c.temp_ref_k, 3u), 0);
  const double f0 = free_frequency(&m, 1, 1e-7, 10000, NULL);
  const double k = (kTwoPi * c.f2_hz) * (kTwoPi * c.f2_hz), ke = 0.01 * k;
  assert_int_equal(mech_set_elec(&m, 0.0, ke), 0);
  const double f_held = free_frequency(&m, 1, 1e-7, 10000, NULL);
  assert_int_equal(mech_elec_rebase(&m), 1);
  const double f_exact = free_frequency(&m, 1, 1e-7, 10000, NULL);
  print_message("k_e/k = 1 %%: held %.5f Hz, rebased %.5f Hz, law %.5f Hz (truth %.5f Hz)\n",
                f_held, f_exact, f0 * sqrt(0.99), mech_wn2_eff(&m) / kTwoPi);
  assert_true(fabs(f_held / (f0 * sqrt(0.99)) - 1.0) < 2e-5);
  assert_true(fabs(f_exact / (f0 * sqrt(0.99)) - 1.0) < 1e-6);
  assert_true(fabs(mech_wn2_eff(&m) / (kTwoPi * c.f2_hz * sqrt(0.99)) - 1.0) < 1e-12);
  assert_true(mech_laws_out(&m) == 0u);
  /* pull-in margin: held at half the stiffness, flagged until read */
  assert_int_equal(mech_set_elec(&m, 0.0, 0.6 * k), 1);
  assert_true(m.elec_ke_per_s2 == 0.5 * k);
  assert_true(mech_laws_out(&m) == MECH_OUT_PULL_IN);
  assert_true(mech_laws_out(&m) == 0u);
  before = m;
  const double bad[][2] = {{NAN, 0.0}, {0.0, INFINITY}, {0.0, -1.0}, {2e9, 0.0}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(mech_set_elec(&m, bad[i][0], bad[i][1]), -1);
    assert_memory_equal(&m, &before, sizeof m);
  }
}

/* Off by default: the default configuration has every imperfection at zero, and a
 * mechanics with them explicitly zero runs bit for bit as the default. Bad values are
 * refused with the field named and nothing changed. */
static void test_off_by_default_and_validation(void **state)
{
  (void)state;
  mech_cfg_t c;
  mech_default_cfg(&c);
  assert_true(c.k3_drive_per_m2 == 0.0 && c.k3_sense_per_m2 == 0.0 && c.ke2_per_s2 == 0.0);
  assert_int_equal(c.q_law, QLAW_CONST);
  static mech_t a, b;
  assert_int_equal(mech_init(&a, &c, 310.0, 7u), 0);
  assert_int_equal(mech_init(&b, &c, 310.0, 7u), 0);
  assert_int_equal(mech_set_coupling_drift(&b, 0.0, 0.0), 0);
  assert_int_equal(mech_set_elec(&b, 0.0, 0.0), 0);
  assert_int_equal(b.held, 0);
  for (int k = 0; k < 2000; k++) {
    const double f = 20.0 * sin(0.187 * k);
    mech_step(&a, f, 0.0, 0.5, 0.0);
    mech_step(&b, f, 0.0, 0.5, 0.0);
  }
  assert_memory_equal(a.z, b.z, sizeof a.z);
  assert_int_equal(mech_elec_rebase(&b), 0);
  assert_true(b.refresh_count == a.refresh_count);
  const struct {
    const char *key;
    int field;
    double v;
  } bad[] = {{"k3_drive_per_m2", 0, NAN},
             {"k3_sense_per_m2", 1, 2e12},
             {"ke2_per_s2", 2, -1.0},
             {"q_law", 3, 3.0}};
  static mech_t before;
  before = a;
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    mech_default_cfg(&c);
    if (bad[i].field == 0) c.k3_drive_per_m2 = bad[i].v;
    else if (bad[i].field == 1) c.k3_sense_per_m2 = bad[i].v;
    else if (bad[i].field == 2) c.ke2_per_s2 = bad[i].v;
    else c.q_law = (int)bad[i].v;
    const char *key = NULL;
    assert_true(mech_cfg_check(&c, &key) < 0);
    assert_string_equal(key, bad[i].key);
    assert_true(mech_init(&a, &c, 300.0, 1u) < 0);
    assert_memory_equal(&a, &before, sizeof a);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_duffing_shift),
      cmocka_unit_test(test_duffing_range),
      cmocka_unit_test(test_spring_softening),
      cmocka_unit_test(test_q_law_two_temperatures),
      cmocka_unit_test(test_q_law_range),
      cmocka_unit_test(test_coupling_drift),
      cmocka_unit_test(test_elec_coupling),
      cmocka_unit_test(test_elec_softening),
      cmocka_unit_test(test_off_by_default_and_validation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
