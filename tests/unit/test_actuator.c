#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <complex.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "plant/actuator.h"
#include "plant/dac.h"
#include "psd_welch_ref.h"
#include "sine_fit_ref.h"

static const double k_pi = 3.14159265358979323846;

static double sinc(double x) { return (x == 0.0) ? 1.0 : sin(x) / x; }

/* Reconstruction low-pass w0^2 / (s^2 + (w0/Q) s + w0^2) at w: gain and phase. */
static void recon(const dac_cfg_t *c, double w, double *mag, double *ph)
{
  const double w0 = 2.0 * k_pi * c->recon_cutoff_hz;
  const double re = w0 * w0 - w * w, im = w * w0 / c->recon_q;
  *mag = w0 * w0 / hypot(re, im);
  *ph = -atan2(im, re);
}

static void quiet_cfg(actuator_cfg_t *a)
{
  actuator_default_cfg(a);
  const flicker_spec_t off = {0.0, 0.0, 0.0};
  a->drive_noise = off;
  a->fb_noise = off;
  a->quadnull_noise = off;
  a->tune_noise = off;
}

typedef enum { HALF_FREQ, DC_AC } scheme_t;

/* Codes the firmware would write at tick k for either drive scheme (force frequency f). */
static hal_dac_frame_t drive_frame(scheme_t s, double t, double f, double amp, double dc, double p)
{
  hal_dac_frame_t fr;
  for (int c = 0; c < DAC_NCH; c++) fr.code[c] = (uint16_t)HAL_DAC_CODE_MID;
  if (s == HALF_FREQ) { /* (6-18), phase p on the voltages (6-25) */
    fr.code[0] = dac_v_to_code(amp * cos(k_pi * f * t + p));
    fr.code[1] = dac_v_to_code(amp * sin(k_pi * f * t + p));
  } else { /* (6-20) */
    fr.code[0] = dac_v_to_code(dc + amp * cos(2.0 * k_pi * f * t + p));
    fr.code[1] = dac_v_to_code(dc - amp * cos(2.0 * k_pi * f * t + p));
  }
  return fr;
}

/* Complex amplitude, at the tick instants, of the per-sample mean force of either
 * scheme, from the exact spectrum of the DAC output: the staircase of the samples of
 * A e^{j(wv t + p)} (wv = w/2 for half-frequency, w for DC+AC), held from the next tick,
 * is sum_m c_m e^{j v_m t}, v_m = wv + m ws,
 *   c_m = A e^{jp} sinc(v_m T/2) e^{-j v_m T/2} e^{-j v_m T} Hr(j v_m)   (ZOH, latency,
 *                                                                        filter)
 * Half-frequency: U1 = Re z, U2 = Im z, so U1^2 - U2^2 = Re z^2: components at
 * 2 wv + (m + m') ws. DC+AC: U1^2 - U2^2 = 4 D Re z. The mean over [t_k, t_k + T] of
 * e^{j v t} is e^{j v t_k} e^{j v T/2} sinc(v T/2), and at the ticks every v aliases to
 * w. Truncated at |m| <= 200 (terms fall as 1/m^3). */
static double complex mean_force_phasor(int half, const dac_cfg_t *dc, double ks, double w,
                                        double amp, double dcv, double p)
{
  const double T = 1.0 / dc->fs_hz, ws = 2.0 * k_pi * dc->fs_hz;
  const double w0 = 2.0 * k_pi * dc->recon_cutoff_hz, wv = half ? w / 2.0 : w;
  enum { M = 200 };
  static double complex c[2 * M + 1];
  for (int m = -M; m <= M; m++) {
    const double v = wv + m * ws;
    const double complex hr = w0 * w0 / (w0 * w0 - v * v + I * v * w0 / dc->recon_q);
    c[m + M] = amp * cexp(I * p) * sinc(v * T / 2.0) * cexp(-I * 1.5 * v * T) * hr;
  }
  double complex acc = 0.0;
  if (half) {
    for (int m = 0; m <= 2 * M; m++)
      for (int n = 0; n <= 2 * M; n++) {
        const double v = 2.0 * wv + (m + n - 2 * M) * ws;
        acc += c[m] * c[n] * cexp(I * v * T / 2.0) * sinc(v * T / 2.0);
      }
    return ks * acc;
  }
  for (int m = 0; m <= 2 * M; m++) {
    const double v = wv + (m - M) * ws;
    acc += c[m] * cexp(I * v * T / 2.0) * sinc(v * T / 2.0);
  }
  return 4.0 * ks * dcv * acc;
}

/* Both schemes through DAC (latency, ZOH, reconstruction filter) and actuator, against
 * the exact spectrum above: amplitude and phase of the held force to 1e-5 (14-bit codes).
 * Also printed: the simple estimate that keeps only the fundamentals,
 *   half-frequency: ks (A s_h |Hr(w/2)|)^2 sinc(wT/2), s_h = sinc(wT/4)
 *   DC+AC:          4 ks D A sinc(wT/2)^2 |Hr(w)|
 * which the per-sample mean misses by the aliases of the force's images near k fs +- w
 * (about 3e-4 of the force with the default 20 kHz filter). */
static void test_schemes_through_dac(void **state)
{
  (void)state;
  const double fs = 50000.0, T = 1.0 / fs, f = 1489.9, w = 2.0 * k_pi * f;
  dac_cfg_t dc;
  dac_default_cfg(&dc);
  actuator_cfg_t ac;
  quiet_cfg(&ac);
  const double ks = ac.ks_drive_mps2_per_v2;
  const int warm = 200, n = 20000;
  double *fy = malloc((size_t)n * sizeof *fy);
  assert_non_null(fy);
  for (int s = 0; s < 2; s++) {
    const scheme_t sch = (s == 0) ? HALF_FREQ : DC_AC;
    const double amp = (sch == HALF_FREQ) ? 10.0 : 5.0, dcv = 5.0, p = 0.3;
    dac_t d;
    actuator_t a;
    assert_int_equal(dac_init(&d, &dc), 0);
    assert_int_equal(actuator_init(&a, &ac, 1u), 0);
    for (int k = 0; k < warm + n; k++) {
      const hal_dac_frame_t fr = drive_frame(sch, (double)k * T, f, amp, dcv, p);
      dac_write(&d, &fr);
      dac_out_t o;
      dac_step(&d, &o);
      actuator_out_t out;
      actuator_step(&a, &o, &out);
      assert_true(out.f_sense_mps2 == 0.0);
      if (k >= warm) fy[k - warm] = out.f_drive_mps2;
    }
    double coef[5];
    const double fr2[2] = {f, 2.0 * f};
    ref_sine_fit(fy, (size_t)n, (double)warm * T, T, fr2, 2, coef);
    const double complex got = coef[1] - I * coef[2]; /* a cos + b sin = Re((a - jb) e^{jwt}) */
    const double complex want = mean_force_phasor(sch == HALF_FREQ, &dc, ks, w, amp, dcv, p);
    double simple, m, th;
    if (sch == HALF_FREQ) {
      recon(&dc, w / 2.0, &m, &th);
      const double v = amp * sinc(w * T / 4.0) * m;
      simple = ks * v * v * sinc(w * T / 2.0);
    } else {
      recon(&dc, w, &m, &th);
      simple = 4.0 * ks * dcv * amp * sinc(w * T / 2.0) * sinc(w * T / 2.0) * m;
    }
    const double rel = cabs(got - want) / cabs(want);
    print_message("%s: force %.6f m/s^2 (exact spectrum %.6f, fundamentals only %.6f), "
                  "error %.2e, phase %.6f rad (want %.6f)\n",
                  sch == HALF_FREQ ? "half-freq" : "DC+AC", cabs(got), cabs(want), simple, rel,
                  carg(got), carg(want));
    assert_true(rel < 1e-5);
    /* no static force and no second harmonic in either scheme */
    assert_true(fabs(coef[0]) < 1e-4 * cabs(want));
    assert_true(hypot(coef[3], coef[4]) < 1e-4 * cabs(want));
  }
  free(fy);
}

/* The sense feedback pair (FB_PAIR) is the drive's actuator on the sense axis: its two
 * voltages made by the DAC's drive channels (latency, hold, reconstruction filter) as
 * the half-frequency (6-18) and DC+AC (6-20) frames above, given to the pair through
 * the electrode input, give the sense force the exact spectrum predicts, to 1e-5 as the
 * drive's (test_schemes_through_dac), at the drive frequency (the force's frequency):
 * ks_fb A^2 for half-frequency, 4 ks_fb D A for DC+AC, each times the chain's gain; and
 * with ks_fb = ks_drive, bit for bit the drive force of the same voltages. The drive
 * comb (ks_drive 0 in the second actuator) then carries none. */
static void test_feedback_pair_schemes(void **state)
{
  (void)state;
  const double fs = 50000.0, T = 1.0 / fs, f = 1489.9, w = 2.0 * k_pi * f;
  dac_cfg_t dc;
  dac_default_cfg(&dc);
  actuator_cfg_t drv, fbp;
  quiet_cfg(&drv);
  quiet_cfg(&fbp);
  fbp.fb = ACTUATOR_FB_PAIR;
  fbp.ks_fb_mps2_per_v2 = drv.ks_drive_mps2_per_v2;
  fbp.ks_drive_mps2_per_v2 = 0.0;
  const int warm = 200, n = 20000;
  double *fx = malloc((size_t)n * sizeof *fx);
  assert_non_null(fx);
  for (int s = 0; s < 2; s++) {
    const scheme_t sch = (s == 0) ? HALF_FREQ : DC_AC;
    const double amp = (sch == HALF_FREQ) ? 8.0 : 4.0, dcv = 4.0, p = -0.7;
    dac_t d;
    actuator_t ad, af;
    assert_int_equal(dac_init(&d, &dc), 0);
    assert_int_equal(actuator_init(&ad, &drv, 1u), 0);
    assert_int_equal(actuator_init(&af, &fbp, 1u), 0);
    for (int k = 0; k < warm + n; k++) {
      const hal_dac_frame_t fr = drive_frame(sch, (double)k * T, f, amp, dcv, p);
      dac_write(&d, &fr);
      dac_out_t o;
      dac_step(&d, &o);
      actuator_elec_in_t e;
      memset(&e, 0, sizeof e);
      e.fb[0] = o.ch[HAL_DAC_DRIVE_U1];
      e.fb[1] = o.ch[HAL_DAC_DRIVE_U2];
      dac_out_t none = o; /* the pair's voltages are not on the drive comb */
      none.ch[HAL_DAC_DRIVE_U1].mean_v = none.ch[HAL_DAC_DRIVE_U1].mean_sq_v2 = 0.0;
      none.ch[HAL_DAC_DRIVE_U2].mean_v = none.ch[HAL_DAC_DRIVE_U2].mean_sq_v2 = 0.0;
      actuator_out_t od, of;
      actuator_step(&ad, &o, &od);
      actuator_step_elec(&af, &none, &e, &of);
      assert_true(of.f_sense_mps2 == od.f_drive_mps2); /* the drive's code path */
      assert_true(of.f_drive_mps2 == 0.0 && of.kyx_per_s2 == 0.0 && of.ke_per_s2 == 0.0);
      if (k >= warm) fx[k - warm] = of.f_sense_mps2;
    }
    double coef[5];
    const double fr2[2] = {f, 2.0 * f};
    ref_sine_fit(fx, (size_t)n, (double)warm * T, T, fr2, 2, coef);
    const double complex got = coef[1] - I * coef[2];
    const double complex want = mean_force_phasor(sch == HALF_FREQ, &dc, fbp.ks_fb_mps2_per_v2,
                                                  w, amp, dcv, p);
    const double nominal = sch == HALF_FREQ ? fbp.ks_fb_mps2_per_v2 * amp * amp
                                            : 4.0 * fbp.ks_fb_mps2_per_v2 * dcv * amp;
    const double rel = cabs(got - want) / cabs(want);
    print_message("pair, %s: sense force %.6f m/s^2 at %.1f Hz (exact spectrum %.6f, law %.6f "
                  "before the chain), error %.2e\n",
                  sch == HALF_FREQ ? "half-freq" : "DC+AC", cabs(got), f, cabs(want), nominal,
                  rel);
    assert_true(rel < 1e-5);
    assert_true(fabs(cabs(got) / nominal - 1.0) < 0.05); /* the chain's gain, a few % */
    assert_true(fabs(coef[0]) < 1e-4 * cabs(want));
    assert_true(hypot(coef[3], coef[4]) < 1e-4 * cabs(want));
  }
  free(fx);
}

/* The force law with noise, and the feedback electrodes, on hand-made constant
 * voltages (a constant v has mean v and mean square v^2 over the sample):
 *   f_drv = ks ((v1 + w1)^2 - (v2 + w2)^2)
 *   FB_SINGLE:       f_sen = ks_fb (u + w3)^2
 *   FB_DIFFERENTIAL: f_sen = ks_fb ((Vb + u + w3)^2 - (Vb - u + w4)^2) */
static void test_force_law(void **state)
{
  (void)state;
  const actuator_fb_t modes[4] = {ACTUATOR_FB_OFF, ACTUATOR_FB_SINGLE, ACTUATOR_FB_DIFFERENTIAL,
                                  ACTUATOR_FB_PAIR};
  for (int mi = 0; mi < 4; mi++) {
    actuator_cfg_t cfg;
    actuator_default_cfg(&cfg);
    cfg.drive_noise.white_rthz = 1e-3; /* large, to see it */
    cfg.fb_noise.white_rthz = 2e-3;
    cfg.fb = modes[mi];
    actuator_t a;
    assert_int_equal(actuator_init(&a, &cfg, 77u), 0);
    for (int k = 0; k < 100; k++) {
      const double v1 = 7.0 * sin(0.1 * k), v2 = -3.0 + 0.01 * k, u = 2.0 * cos(0.2 * k);
      const double e3 = 5.0 * cos(0.05 * k), e4 = 5.0 * sin(0.05 * k);
      dac_out_t o;
      memset(&o, 0, sizeof o);
      o.ch[0].mean_v = v1;
      o.ch[0].mean_sq_v2 = v1 * v1;
      o.ch[1].mean_v = v2;
      o.ch[1].mean_sq_v2 = v2 * v2;
      o.ch[3].mean_v = u;
      o.ch[3].mean_sq_v2 = u * u;
      actuator_elec_in_t e;
      memset(&e, 0, sizeof e);
      e.fb[0].mean_v = e3;
      e.fb[0].mean_sq_v2 = e3 * e3;
      e.fb[1].mean_v = e4;
      e.fb[1].mean_sq_v2 = e4 * e4;
      actuator_out_t out;
      actuator_step_elec(&a, &o, &e, &out);
      const double *w = out.noise_v;
      assert_true(w[4] == 0.0 && w[5] == 0.0 && w[6] == 0.0); /* no such electrodes */
      assert_true(out.kyx_per_s2 == 0.0 && out.ke_per_s2 == 0.0);
      assert_true(w[0] != 0.0 && w[1] != 0.0 && w[0] != w[1]);
      const double fd = cfg.ks_drive_mps2_per_v2 *
                        ((v1 + w[0]) * (v1 + w[0]) - (v2 + w[1]) * (v2 + w[1]));
      assert_true(fabs(out.f_drive_mps2 - fd) < 1e-12 * (1.0 + fabs(fd)));
      double fsn = 0.0;
      const double vb = cfg.fb_bias_v;
      if (modes[mi] == ACTUATOR_FB_SINGLE) {
        fsn = cfg.ks_fb_mps2_per_v2 * (u + w[2]) * (u + w[2]);
        assert_true(w[3] == 0.0);
      } else if (modes[mi] == ACTUATOR_FB_DIFFERENTIAL) {
        fsn = cfg.ks_fb_mps2_per_v2 *
              ((vb + u + w[2]) * (vb + u + w[2]) - (vb - u + w[3]) * (vb - u + w[3]));
      } else if (modes[mi] == ACTUATOR_FB_PAIR) { /* the electrode input, not the spare DAC */
        fsn = cfg.ks_fb_mps2_per_v2 * ((e3 + w[2]) * (e3 + w[2]) - (e4 + w[3]) * (e4 + w[3]));
      } else {
        assert_true(w[2] == 0.0 && w[3] == 0.0);
      }
      assert_true(fabs(out.f_sense_mps2 - fsn) < 1e-12 * (1.0 + fabs(fsn)));
    }
  }
}

/* The electrodes' stiffness with noise on hand-made voltages (the header):
 *   k_yx = c_q ((V1 + w5)^2 - (V2 + w6)^2)
 *   k_e  = ke_q ((V1 + w5)^2 + (V2 + w6)^2) + ke_t (Vt + w7)^2 + ke_fb ((U3 + w3)^2 + (U4 + w4)^2)
 * the last only in FB_PAIR; a per-sample mean square that is not the square of the mean
 * (a varying voltage) enters as such. */
static void test_electrode_stiffness(void **state)
{
  (void)state;
  for (int pair = 0; pair < 2; pair++) {
    actuator_cfg_t cfg;
    actuator_default_cfg(&cfg);
    cfg.fb = pair ? ACTUATOR_FB_PAIR : ACTUATOR_FB_DIFFERENTIAL;
    cfg.fb_ke_per_s2_per_v2 = 1e4;
    cfg.quadnull_kyx_per_s2_per_v2 = 2e4;
    cfg.quadnull_ke_per_s2_per_v2 = 3e5;
    cfg.tune_ke_per_s2_per_v2 = 5e5;
    cfg.quadnull_noise.white_rthz = 1e-3;
    cfg.tune_noise.white_rthz = 3e-3;
    actuator_t a;
    assert_int_equal(actuator_init(&a, &cfg, 78u), 0);
    for (int k = 0; k < 100; k++) {
      actuator_elec_in_t e;
      memset(&e, 0, sizeof e);
      const double v1 = 2.0 + 0.01 * k, v2 = 6.0 * sin(0.3 * k), vt = 9.0 - 0.02 * k;
      const double u3 = 4.0 * cos(0.4 * k), u4 = 4.0 * sin(0.4 * k);
      e.quadnull[0].mean_v = v1;
      e.quadnull[0].mean_sq_v2 = v1 * v1 + 0.25; /* a ripple within the sample */
      e.quadnull[1].mean_v = v2;
      e.quadnull[1].mean_sq_v2 = v2 * v2;
      e.tune.mean_v = vt;
      e.tune.mean_sq_v2 = vt * vt;
      e.fb[0].mean_v = u3;
      e.fb[0].mean_sq_v2 = u3 * u3;
      e.fb[1].mean_v = u4;
      e.fb[1].mean_sq_v2 = u4 * u4;
      dac_out_t o;
      memset(&o, 0, sizeof o);
      actuator_out_t out;
      actuator_step_elec(&a, &o, &e, &out);
      const double *w = out.noise_v;
      assert_true(w[4] != 0.0 && w[5] != 0.0 && w[6] != 0.0 && w[4] != w[5]);
      const double m1 = v1 * v1 + 0.25 + w[4] * (2.0 * v1 + w[4]);
      const double m2 = (v2 + w[5]) * (v2 + w[5]), mt = (vt + w[6]) * (vt + w[6]);
      const double kyx = cfg.quadnull_kyx_per_s2_per_v2 * (m1 - m2);
      double ke = cfg.quadnull_ke_per_s2_per_v2 * (m1 + m2) + cfg.tune_ke_per_s2_per_v2 * mt;
      if (pair)
        ke += cfg.fb_ke_per_s2_per_v2 * ((u3 + w[2]) * (u3 + w[2]) + (u4 + w[3]) * (u4 + w[3]));
      assert_true(fabs(out.kyx_per_s2 - kyx) < 1e-12 * fabs(kyx) + 1e-9);
      assert_true(fabs(out.ke_per_s2 - ke) < 1e-12 * ke);
    }
  }
}

/* Invalid configurations are refused, the instance untouched. */
static void test_bad_cfg(void **state)
{
  (void)state;
  actuator_t a, before;
  memset(&a, 0x21, sizeof a);
  before = a;
  actuator_cfg_t good, c;
  actuator_default_cfg(&good);
  c = good;
  c.ks_drive_mps2_per_v2 = -1.0;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.fs_hz = 0.0;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.fb = (actuator_fb_t)7;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.drive_noise.fmin_hz = -1.0;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.fb = ACTUATOR_FB_DIFFERENTIAL;
  c.fb_noise.white_rthz = NAN;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.fb_bias_v = INFINITY;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.quadnull_kyx_per_s2_per_v2 = -1.0;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.tune_ke_per_s2_per_v2 = NAN;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.fb_ke_per_s2_per_v2 = -2.0;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.quadnull_kyx_per_s2_per_v2 = 1.0;
  c.quadnull_noise.fmin_hz = 0.0;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  c = good;
  c.fb = (actuator_fb_t)4;
  assert_int_equal(actuator_init(&a, &c, 1u), -1);
  assert_memory_equal(&a, &before, sizeof a);
}

#define NSEG (1u << 14)

/* Band average of a PSD over |f - fc| in [d_lo, d_hi], both sides. */
static double band(const double *psd, double fs, double fc, double d_lo, double d_hi)
{
  double s = 0.0;
  int n = 0;
  for (size_t i = 1; i < NSEG / 2; i++) {
    const double f = (double)i * fs / NSEG, d = fabs(f - fc);
    if (d >= d_lo && d <= d_hi) {
      s += psd[i];
      n++;
    }
  }
  return s / n;
}

/* The thesis's point about 1/f drive-voltage noise (6-21, 6-23), with the same noise on
 * U1 and U2 and the same force amplitude (ks A_h^2 = 4 ks D A): measured force-noise PSD
 * (noisy minus noise-free actuator on the same DAC output) against
 *   half-frequency: 2 ks^2 Ah^2 [Sw(|f - wc/2|) + Sw(f + wc/2)]
 *   DC+AC:          2 ks^2 A^2  [Sw(|f - wc|)   + Sw(f + wc)] + 8 ks^2 D^2 Sw(f)
 * (Ah, A, D: carrier amplitudes and level of the DAC's per-sample means, fitted). Near
 * wc the DC+AC noise is the 1/f noise of the voltages shifted to wc, in the drive
 * mode's band; half-frequency drive moves it to wc/2 and leaves only the voltage noise
 * at wc/2 near wc. */
static void test_low_frequency_noise_placement(void **state)
{
  (void)state;
  const double fs = 50000.0, T = 1.0 / fs, fd = fs / 32.0; /* 1562.5 Hz, bin 512 */
  const flicker_spec_t noise = {1e-6, 2e-5, 0.5};          /* corner 400 Hz */
  const size_t warm = 50000, n = NSEG * 16;
  dac_cfg_t dc;
  dac_default_cfg(&dc);
  actuator_cfg_t quiet, noisy;
  quiet_cfg(&quiet);
  noisy = quiet;
  noisy.drive_noise = noise;
  const double ks = quiet.ks_drive_mps2_per_v2;
  double *fn = malloc(n * sizeof *fn), *m1 = malloc(n * sizeof *m1), *m2 = malloc(n * sizeof *m2);
  double *psd = malloc((NSEG / 2 + 1) * sizeof *psd);
  assert_true(fn && m1 && m2 && psd);
  double near_wc[2], want_wc[2];
  for (int s = 0; s < 2; s++) {
    const scheme_t sch = (s == 0) ? HALF_FREQ : DC_AC;
    const double amp = (sch == HALF_FREQ) ? 10.0 : 5.0, dcv = 5.0; /* same force, 25 m/s^2 */
    dac_t d;
    actuator_t aq, an;
    assert_int_equal(dac_init(&d, &dc), 0);
    assert_int_equal(actuator_init(&aq, &quiet, 5u), 0);
    assert_int_equal(actuator_init(&an, &noisy, 5u), 0);
    for (size_t k = 0; k < warm + n; k++) {
      const hal_dac_frame_t fr = drive_frame(sch, (double)k * T, fd, amp, dcv, 0.0);
      dac_write(&d, &fr);
      dac_out_t o;
      dac_step(&d, &o);
      actuator_out_t oq, on;
      actuator_step(&aq, &o, &oq);
      actuator_step(&an, &o, &on);
      if (k >= warm) {
        fn[k - warm] = on.f_drive_mps2 - oq.f_drive_mps2;
        m1[k - warm] = o.ch[0].mean_v;
        m2[k - warm] = o.ch[1].mean_v;
      }
    }
    /* carrier of the per-sample mean voltages */
    const double fcar = (sch == HALF_FREQ) ? fd / 2.0 : fd;
    double c1[3], c2[3];
    ref_sine_fit(m1, n, 0.0, T, &fcar, 1, c1);
    ref_sine_fit(m2, n, 0.0, T, &fcar, 1, c2);
    const double car = 0.5 * (hypot(c1[1], c1[2]) + hypot(c2[1], c2[2]));
    const double lev = 0.5 * (c1[0] + c2[0]);
    assert_true(ref_psd_welch(fn, n, fs, NSEG, psd) > 0);
    /* analytic, averaged over the same bins */
    double want = 0.0, want_h = 0.0;
    int cnt = 0, cnt_h = 0;
    for (size_t i = 1; i < NSEG / 2; i++) {
      const double f = (double)i * fs / NSEG;
      double sw;
      if (fabs(f - fd) >= 6.0 && fabs(f - fd) <= 40.0) {
        if (sch == HALF_FREQ)
          sw = 2.0 * ks * ks * car * car *
               (flicker_target_psd(&noise, fs, fabs(f - fd / 2.0)) +
                flicker_target_psd(&noise, fs, f + fd / 2.0));
        else
          sw = 2.0 * ks * ks * car * car *
                   (flicker_target_psd(&noise, fs, fabs(f - fd)) +
                    flicker_target_psd(&noise, fs, f + fd)) +
               8.0 * ks * ks * lev * lev * flicker_target_psd(&noise, fs, f);
        want += sw;
        cnt++;
      }
      if (sch == HALF_FREQ && fabs(f - fd / 2.0) >= 6.0 && fabs(f - fd / 2.0) <= 40.0) {
        want_h += 2.0 * ks * ks * car * car *
                  (flicker_target_psd(&noise, fs, fabs(f - fd / 2.0)) +
                   flicker_target_psd(&noise, fs, f + fd / 2.0));
        cnt_h++;
      }
    }
    want /= cnt;
    near_wc[s] = band(psd, fs, fd, 6.0, 40.0);
    want_wc[s] = want;
    print_message(
        "%s: carrier %.4f V level %.4f V; force noise 6-40 Hz from wc %.3e (want %.3e) (m/s^2)^2/Hz\n",
        sch == HALF_FREQ ? "half-freq" : "DC+AC", car, lev, near_wc[s], want);
    assert_true(fabs(near_wc[s] / want - 1.0) < 0.2);
    if (sch == HALF_FREQ) {
      want_h /= cnt_h;
      const double near_half = band(psd, fs, fd / 2.0, 6.0, 40.0);
      print_message("half-freq: force noise 6-40 Hz from wc/2 %.3e (want %.3e)\n", near_half,
                    want_h);
      assert_true(fabs(near_half / want_h - 1.0) < 0.2);
      assert_true(near_half > 5.0 * near_wc[s]); /* the 1/f noise sits at wc/2 */
    }
  }
  const double ratio = near_wc[1] / near_wc[0], ratio_want = want_wc[1] / want_wc[0];
  print_message("DC+AC / half-frequency force noise near wc: %.2f (analytic %.2f)\n", ratio,
                ratio_want);
  assert_true(fabs(ratio / ratio_want - 1.0) < 0.2);
  assert_true(ratio > 2.0);
  free(fn);
  free(m1);
  free(m2);
  free(psd);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_schemes_through_dac),
      cmocka_unit_test(test_feedback_pair_schemes),
      cmocka_unit_test(test_force_law),
      cmocka_unit_test(test_electrode_stiffness),
      cmocka_unit_test(test_bad_cfg),
      cmocka_unit_test(test_low_frequency_noise_placement),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
