#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <complex.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "plant/dac.h"
#include "plant/pickoff.h"
#include "sine_fit_ref.h"

static const double k_pi = 3.14159265358979323846;
static const double k_deg = 3.14159265358979323846 / 180.0;
#define T0_K 298.15
#define WARM 4000
#define NFIT 4000

static void quiet(pickoff_cfg_t *c, pickoff_axis_t axis)
{
  pickoff_default_cfg(c, axis);
  c->noise_v_rthz = 0.0;
  c->jitter_rms_s = 0.0;
  c->sample_delay_s = 0.0;
}

/* Anti-alias band-pass of the cfg at w, closed form. */
static double complex aa(const pickoff_cfg_t *c, double w)
{
  double complex h = 1.0;
  if (c->hp_hz > 0.0) {
    const double th = 1.0 / (2.0 * k_pi * c->hp_hz);
    h *= I * w * th / (1.0 + I * w * th);
  }
  const double w0 = 2.0 * k_pi * c->lp_hz;
  return h * w0 * w0 / (w0 * w0 - w * w + I * w * w0 / c->lp_q);
}

/* Drive the pickoff with pos = a sin(w t) (exact displacement and velocity at every
 * tick), fit the sampled output, return the complex gain output/displacement (V/m),
 * i.e. y_k = Re(G a (-j) e^{j w t_k}) + c0. */
static double complex sine_gain(pickoff_t *p, double f, double a, double *c0, double *rms_res)
{
  const double T = 1.0 / p->cfg.fs_hz, w = 2.0 * k_pi * f;
  double *y = malloc(NFIT * sizeof *y);
  assert_non_null(y);
  for (int k = 0; k < WARM + NFIT; k++) {
    const double t = (double)(k + 1) * T;
    const double v = pickoff_step(p, a * sin(w * t), a * w * cos(w * t), NULL);
    if (k >= WARM) y[k - WARM] = v;
  }
  double coef[3];
  const double r = ref_sine_fit(y, NFIT, (double)(WARM + 1) * T, T, &f, 1, coef);
  free(y);
  if (c0) *c0 = coef[0];
  if (rms_res) *rms_res = r;
  /* a1 cos + b1 sin = Re((a1 - j b1) e^{jwt}) = Re(G a (-j) e^{jwt}) */
  return (coef[1] - I * coef[2]) / (-I * a);
}

/* The circuit phase (2-40) is a real first-order low-pass acting on the signal: at the
 * reference (drive) frequency its lag equals Phi0 + Phi1 dT + Phi2 dT^2 / 2 and its gain
 * cos(Phi); at 2 kHz it is 1 / (1 + j (2000/1489.9) tan Phi), as a low-pass must be.
 * The ring-diode gain follows its temperature coefficient. The band-pass is removed
 * with its closed form. Over temperatures from -15 K to +40 K. */
static void test_phase_vs_temperature(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  c.phi2_rad_per_k2 = 0.004 * k_deg;
  c.gain_tc_per_k = 5e-4;
  const double dts[4] = {0.0, 20.0, -15.0, 40.0};
  for (int i = 0; i < 4; i++) {
    const double tk = T0_K + dts[i];
    pickoff_t p;
    assert_int_equal(pickoff_init(&p, &c, T0_K, 3u), 0);
    assert_int_equal(pickoff_set_temp(&p, tk), 0);
    const double phi = c.phi0_rad + c.phi1_rad_per_k * dts[i] +
                       0.5 * c.phi2_rad_per_k2 * dts[i] * dts[i];
    const double g = c.gain_v_per_m * (1.0 + c.gain_tc_per_k * dts[i]);
    double c0, res;
    const double complex h = sine_gain(&p, c.lag_ref_hz, 1e-8, &c0, &res) /
                             (g * aa(&c, 2.0 * k_pi * c.lag_ref_hz));
    print_message("dT %+5.1f K: lag %.6f deg (want %.6f), gain %.7f (want %.7f), offset %.2e\n",
                  dts[i], -carg(h) / k_deg, phi / k_deg, cabs(h), cos(phi), c0);
    assert_true(fabs(-carg(h) - phi) < 1e-5);
    assert_true(fabs(cabs(h) - cos(phi)) < 1e-5);
    assert_true(fabs(c0 - c.offset_v) < 1e-6);
    assert_true(fabs(p.phi_rad - phi) < 1e-15);
    /* off the reference frequency */
    pickoff_t q;
    assert_int_equal(pickoff_init(&q, &c, tk, 3u), 0);
    const double f2 = 2000.0;
    const double complex h2 = sine_gain(&q, f2, 1e-8, NULL, NULL) / (g * aa(&c, 2.0 * k_pi * f2));
    const double complex want = 1.0 / (1.0 + I * (f2 / c.lag_ref_hz) * tan(phi));
    assert_true(cabs(h2 - want) < 1e-5);
  }
}

/* The all-pass variant: unit gain, lag Phi at the reference, 2 atan((w/wref) tan(Phi/2))
 * elsewhere. */
static void test_allpass(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_DRIVE);
  c.lag_kind = PICKOFF_LAG_ALLPASS;
  c.phi0_rad = 9.56 * k_deg;
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 3u), 0);
  const double fr[2] = {c.lag_ref_hz, 700.0};
  for (int i = 0; i < 2; i++) {
    assert_int_equal(pickoff_init(&p, &c, T0_K, 3u), 0);
    const double complex h = sine_gain(&p, fr[i], 1e-5, NULL, NULL) /
                             (c.gain_v_per_m * aa(&c, 2.0 * k_pi * fr[i]));
    const double lag = 2.0 * atan(fr[i] / c.lag_ref_hz * tan(0.5 * c.phi0_rad));
    assert_true(fabs(cabs(h) - 1.0) < 1e-5);
    assert_true(fabs(-carg(h) - lag) < 1e-5);
  }
  assert_true(fabs(2.0 * atan(tan(0.5 * c.phi0_rad)) - c.phi0_rad) < 1e-15);
}

/* Measured lag section (band-pass and gain removed) at f with the circuit at tk. */
static double complex lag_measured(const pickoff_cfg_t *c, double tk, double f)
{
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, c, tk, 3u), 0);
  return sine_gain(&p, f, 1e-8, NULL, NULL) / (c->gain_v_per_m * aa(c, 2.0 * k_pi * f));
}

/* The thesis's sense circuit (3 deg at T0, +0.1 deg/K, (2-40)) passes through zero at
 * -30 K and is a lead below: at -65 K (-40 degC) the law asks for -3.5 deg. Below the
 * pole's smallest lag pm the section is the lead-lag (1 + s tz)/(1 + s tp), tp held at
 * tan(pm)/w, tz = tan(pm - Phi)/w: phase -Phi at the reference, gain
 * cos(pm)/cos(pm - Phi), and the same filter as the low-pass at Phi = pm. */
static void test_lag_into_lead(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  const double pm = PICKOFF_PHI_POLE_MIN_RAD;
  const double t_zero = T0_K - c.phi0_rad / c.phi1_rad_per_k; /* the law's zero */
  const double t_pm = t_zero + pm / c.phi1_rad_per_k;         /* the old boundary */
  const double tks[4] = {t_pm + 1e-3, t_pm - 1e-3, t_zero, T0_K - 65.0};
  double complex hs[4], want_s[4];
  for (int i = 0; i < 4; i++) {
    const double phi = c.phi0_rad + c.phi1_rad_per_k * (tks[i] - T0_K);
    const double complex h = lag_measured(&c, tks[i], c.lag_ref_hz);
    const double g = phi >= pm ? cos(phi) : cos(pm) / cos(pm - phi);
    print_message("T %.4f K: law %+.6f deg, lag %+.6f deg, gain %.8f (want %.8f)\n", tks[i],
                  phi / k_deg, -carg(h) / k_deg, cabs(h), g);
    assert_true(fabs(-carg(h) - phi) < 1e-5);
    assert_true(fabs(cabs(h) - g) < 1e-5);
    hs[i] = h;
    want_s[i] = g * cexp(-I * phi);
    /* off the reference frequency: the lead-lag's own response */
    const double f2 = 2000.0, x = f2 / c.lag_ref_hz;
    const double complex h2 = lag_measured(&c, tks[i], f2);
    const double complex want = phi >= pm
                                    ? 1.0 / (1.0 + I * x * tan(phi))
                                    : (1.0 + I * x * tan(pm - phi)) / (1.0 + I * x * tan(pm));
    assert_true(cabs(h2 - want) < 1e-5);
  }
  /* across the old boundary (2 mK) the response moves by the law's change only: the
   * measurement's own error (interpolation, 3e-6) cancels in the difference */
  print_message("step across pm: %.3e (law %.3e)\n", cabs(hs[0] - hs[1]),
                cabs(want_s[0] - want_s[1]));
  assert_true(cabs((hs[0] - hs[1]) - (want_s[0] - want_s[1])) < 1e-9);
  /* at the old boundary the two forms are one filter; just past it they differ by the
   * law's own change (continuity of the section, not only of its phase) */
  double b0, b1, tp, b0n, b1n, tpn;
  pickoff_lag_section(PICKOFF_LAG_LOWPASS, pm, &b0, &b1, &tp);
  pickoff_lag_section(PICKOFF_LAG_LOWPASS, pm * (1.0 - 1e-9), &b0n, &b1n, &tpn);
  assert_true(b0 == 1.0 && b1 == 0.0 && b0n == 1.0 && fabs(b1n) < 1e-12 && fabs(tpn - tp) < 1e-12);
  /* -40 degC ambient in a run: the state carries through the crossing without a step */
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K - 25.0, 3u), 0);
  assert_int_equal(p.out_of_range, 0u);
  for (int k = 1; k <= 400; k++)
    assert_int_equal(pickoff_set_temp(&p, T0_K - 25.0 - 0.1 * k), 0);
  assert_true(fabs(p.phi_rad - (c.phi0_rad - 65.0 * c.phi1_rad_per_k)) < c.phase_step_rad);
}

/* The all-pass continued below pm: unit gain at the reference, phase -Phi (a lead). */
static void test_allpass_lead(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_DRIVE);
  c.lag_kind = PICKOFF_LAG_ALLPASS;
  c.phi0_rad = 1.0 * k_deg;
  c.phi1_rad_per_k = 0.1 * k_deg;
  const double tks[2] = {T0_K - 10.0 + 1e-3, T0_K - 40.0}; /* just a lag, a 3 deg lead */
  for (int i = 0; i < 2; i++) {
    const double phi = c.phi0_rad + c.phi1_rad_per_k * (tks[i] - T0_K);
    const double complex h = lag_measured(&c, tks[i], c.lag_ref_hz);
    assert_true(fabs(cabs(h) - 1.0) < 1e-5);
    assert_true(fabs(-carg(h) - phi) < 1e-5);
  }
  double b0, b1, tp;
  pickoff_lag_section(PICKOFF_LAG_ALLPASS, PICKOFF_PHI_POLE_MIN_RAD, &b0, &b1, &tp);
  assert_true(b0 == 1.0 && b1 == -tp);
  pickoff_lag_section(PICKOFF_LAG_ALLPASS, PICKOFF_PHI_POLE_MIN_RAD * (1.0 - 1e-9), &b0, &b1,
                      &tp);
  assert_true(fabs(b0 - 1.0) < 1e-12 && fabs(b1 + tp) < 1e-12);
}

/* Beyond a law's range: held at the edge and flagged, never refused. Phase: 80 deg of
 * lag or lead; gain factor: 0.1. */
static void test_law_edges(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  c.phi1_rad_per_k = 1.0 * k_deg;
  c.gain_tc_per_k = 0.01;
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 3u), 0);
  assert_int_equal(pickoff_set_temp(&p, T0_K + 60.0), 0); /* 63 deg */
  assert_int_equal(pickoff_set_temp(&p, T0_K + 80.0), (int)PICKOFF_OUT_PHASE);
  assert_true(p.phi_rad == PICKOFF_LAG_MAX_LOWPASS_RAD);
  assert_int_equal(pickoff_set_temp(&p, T0_K - 60.0), 0); /* -57 deg */
  /* -92 deg of lead, and the gain factor 1 - 0.01 * 95 < 0.1 */
  assert_int_equal(pickoff_set_temp(&p, T0_K - 95.0),
                   (int)(PICKOFF_OUT_PHASE | PICKOFF_OUT_GAIN));
  assert_true(p.phi_rad == PICKOFF_LEAD_MIN_LOWPASS_RAD);
  assert_true(p.gain_now == c.gain_v_per_m * PICKOFF_GAIN_MIN_FACTOR);
  assert_int_equal(p.out_of_range, PICKOFF_OUT_PHASE | PICKOFF_OUT_GAIN);
  assert_int_equal(pickoff_set_temp(&p, T0_K), 0);
  assert_int_equal(p.out_of_range, 0u);
  /* init beyond the range is not refused either */
  assert_int_equal(pickoff_init(&p, &c, T0_K + 100.0, 3u), 0);
  assert_int_equal(p.out_of_range, PICKOFF_OUT_PHASE);
  int out = 0;
  assert_true(pickoff_phi_clamp(PICKOFF_LAG_ALLPASS, 2.0, &out) == 2.0 && out == 0);
  assert_true(pickoff_phi_clamp(PICKOFF_LAG_ALLPASS, NAN, &out) == 0.0 && out == 1);
}

/* A fixed sampling delay d multiplies the sampled sinusoid by e^{j w d} (third-order
 * Taylor extrapolation of the exact output: (w d)^4/24 = 3e-6 at 10 us). */
static void test_sample_delay(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  const double f = 1489.9, w = 2.0 * k_pi * f;
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), 0);
  const double complex g0 = sine_gain(&p, f, 1e-8, NULL, NULL);
  const double delays[3] = {10e-6, -8e-6, 4e-6};
  for (int i = 0; i < 3; i++) {
    c.sample_delay_s = delays[i];
    assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), 0);
    const double complex r = sine_gain(&p, f, 1e-8, NULL, NULL) / g0;
    print_message("delay %+.1f us: |ratio - e^{jwd}| = %.2e\n", delays[i] * 1e6,
                  cabs(r - cexp(I * w * delays[i])));
    assert_true(cabs(r - cexp(I * w * delays[i])) < 1e-5);
  }
}

/* Timing jitter sigma on a sine of amplitude Y (at the ADC) and frequency w adds noise
 * of rms Y w sigma / sqrt(2): jittered minus clean output of the same input. */
static void test_jitter(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  pickoff_t clean, jit;
  assert_int_equal(pickoff_init(&clean, &c, T0_K, 1u), 0);
  c.jitter_rms_s = 1e-6;
  assert_int_equal(pickoff_init(&jit, &c, T0_K, 1u), 0);
  const double f = 1489.9, w = 2.0 * k_pi * f, T = 1.0 / c.fs_hz, a = 6e-8; /* ~3.7 V */
  const int n = 60000;
  double *y = malloc((size_t)n * sizeof *y);
  assert_non_null(y);
  double s1 = 0.0, s2 = 0.0;
  for (int k = 0; k < WARM + n; k++) {
    const double t = (double)(k + 1) * T;
    const double x = a * sin(w * t), v = a * w * cos(w * t);
    const double yc = pickoff_step(&clean, x, v, NULL), yj = pickoff_step(&jit, x, v, NULL);
    if (k >= WARM) {
      y[k - WARM] = yc;
      s1 += yj - yc;
      s2 += (yj - yc) * (yj - yc);
    }
  }
  double coef[3];
  ref_sine_fit(y, (size_t)n, (double)(WARM + 1) * T, T, &f, 1, coef);
  const double amp = hypot(coef[1], coef[2]);
  const double rms = sqrt(s2 / n), want = amp * w * c.jitter_rms_s / sqrt(2.0);
  print_message("amplitude %.4f V: jitter noise %.4e V rms (want %.4e)\n", amp, rms, want);
  assert_true(fabs(rms / want - 1.0) < 0.03);
  assert_true(fabs(s1 / n) < 5.0 * want / sqrt((double)n));
  free(y);
}

/* White electronic noise: rms density * sqrt(fs/2) about the offset. */
static void test_noise(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  pickoff_default_cfg(&c, PICKOFF_DRIVE);
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 9u), 0);
  const int n = 100000;
  double s1 = 0.0, s2 = 0.0;
  for (int k = 0; k < n; k++) {
    const double v = pickoff_step(&p, 0.0, 0.0, NULL) - c.offset_v;
    s1 += v;
    s2 += v * v;
  }
  const double sd = c.noise_v_rthz * sqrt(c.fs_hz / 2.0);
  assert_true(fabs(sqrt(s2 / n) / sd - 1.0) < 0.02);
  assert_true(fabs(s1 / n) < 5.0 * sd / sqrt((double)n));
}

typedef struct {
  double half_at_wc, half_at_half, dcac_at_wc, dcac_dc;
} ft_result_t;

/* Drive voltages only (no motion) through the real DAC into the sense pickoff, fitted at
 * wc/2 and wc. */
static void feedthrough_run(int half, double f, double complex *y_half, double complex *y_wc,
                            double *c0)
{
  dac_cfg_t dc;
  dac_default_cfg(&dc);
  dac_t d;
  assert_int_equal(dac_init(&d, &dc), 0);
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), 0);
  const double T = 1.0 / c.fs_hz;
  const int n = 20000;
  double *y = malloc((size_t)n * sizeof *y);
  assert_non_null(y);
  for (int k = 0; k < WARM + n; k++) {
    const double t = (double)k * T;
    hal_dac_frame_t fr;
    for (int ch = 0; ch < DAC_NCH; ch++) fr.code[ch] = (uint16_t)HAL_DAC_CODE_MID;
    if (half) {
      fr.code[0] = dac_v_to_code(10.0 * cos(k_pi * f * t));
      fr.code[1] = dac_v_to_code(10.0 * sin(k_pi * f * t));
    } else {
      fr.code[0] = dac_v_to_code(5.0 + 5.0 * cos(2.0 * k_pi * f * t));
      fr.code[1] = dac_v_to_code(5.0 - 5.0 * cos(2.0 * k_pi * f * t));
    }
    dac_write(&d, &fr);
    dac_out_t o;
    dac_step(&d, &o);
    const double v = pickoff_step(&p, 0.0, 0.0, &o);
    if (k >= WARM) y[k - WARM] = v;
  }
  double coef[5];
  const double fr2[2] = {f / 2.0, f};
  ref_sine_fit(y, (size_t)n, (double)(WARM + 1) * T, T, fr2, 2, coef);
  *c0 = coef[0];
  *y_half = coef[1] - I * coef[2];
  *y_wc = coef[3] - I * coef[4];
  free(y);
}

/* Electrical feedthrough (§6.3.2). Half-frequency: the pickoff sees the drive voltages
 * at wc/2 and nothing at wc, so demodulation at wc rejects it. DC+AC: it sees
 * (ft_u1 - ft_u2) A at wc, in the signal band; its size against the closed form
 * (ZOH sinc, reconstruction filter, pickoff chain) shows the error of the cubic
 * interpolation of the DAC output between ticks. The DC part of DC+AC is blocked by
 * the high-pass. */
static void test_feedthrough(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  dac_cfg_t dc;
  dac_default_cfg(&dc);
  const double f = 1489.9, w = 2.0 * k_pi * f, T = 1.0 / dc.fs_hz;
  const double w0 = 2.0 * k_pi * dc.recon_cutoff_hz;
  double complex yh, yw;
  double c0;
  /* closed-form chain gain from electrode voltage to ADC at frequency v */
#define CHAIN(v) \
  ((sin((v)*T / 2.0) / ((v)*T / 2.0)) * \
   (w0 * w0 / (w0 * w0 - (v) * (v) + I * (v)*w0 / dc.recon_q)) * \
   (1.0 / (1.0 + I * (v) / (2.0 * k_pi * c.lag_ref_hz) * tan(c.phi0_rad))) * aa(&c, (v)))
  feedthrough_run(1, f, &yh, &yw, &c0);
  const double half_want = 10.0 * hypot(c.ft_u1, c.ft_u2) * cabs(CHAIN(w / 2.0));
  print_message("half-frequency: at wc/2 %.4e V (closed form %.4e), at wc %.2e V\n", cabs(yh),
                half_want, cabs(yw));
  assert_true(cabs(yw) < 1e-4 * cabs(yh));
  assert_true(fabs(cabs(yh) / half_want - 1.0) < 0.02);
  feedthrough_run(0, f, &yh, &yw, &c0);
  const double dcac_want = 5.0 * fabs(c.ft_u1 - c.ft_u2) * cabs(CHAIN(w));
  print_message("DC+AC: at wc %.4e V (closed form %.4e, error %.2f %%), mean %.2e V\n",
                cabs(yw), dcac_want, 100.0 * (cabs(yw) / dcac_want - 1.0), c0 - c.offset_v);
  assert_true(fabs(cabs(yw) / dcac_want - 1.0) < 0.02);
  assert_true(fabs(c0 - c.offset_v) < 1e-6);
#undef CHAIN
}

/* A displacement beyond the preamp's rail saturates it and is counted; the output stays
 * bounded. */
static void test_preamp_clip(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), 0);
  const double T = 1.0 / c.fs_hz, w = 2.0 * k_pi * 1489.9, a = 1e-6; /* 62 V unclipped */
  double peak = 0.0;
  for (int k = 0; k < 5000; k++) {
    const double t = (double)(k + 1) * T;
    peak = fmax(peak, fabs(pickoff_step(&p, a * sin(w * t), a * w * cos(w * t), NULL)));
  }
  assert_true(p.preamp_clip_count > 1000);
  assert_true(peak < 1.5 * c.preamp_rail_v);
}

/* Temperature updates: the gain follows every call; the chain is re-discretised only when
 * Phi_cir has moved by phase_step_rad, so the realised phase stays within one step of
 * (2-40) however often set_temp is called. */
static void test_phase_step(void **state)
{
  (void)state;
  pickoff_cfg_t c;
  quiet(&c, PICKOFF_SENSE);
  c.gain_tc_per_k = 1e-3;
  pickoff_t p;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 3u), 0);
  /* 0.1 deg/K and 1e-6 rad: one step per 0.573 mK; ramp 20 mK in 0.1 mK increments */
  for (int i = 1; i <= 200; i++) {
    const double tk = T0_K + 1e-4 * i;
    assert_int_equal(pickoff_set_temp(&p, tk), 0);
    const double law = c.phi0_rad + c.phi1_rad_per_k * (tk - T0_K);
    assert_true(fabs(p.phi_rad - law) < c.phase_step_rad);
    assert_true(fabs(p.gain_now - c.gain_v_per_m * (1.0 + 1e-3 * (tk - T0_K))) <
                1e-9 * c.gain_v_per_m);
  }
  const double steps = 0.02 * c.phi1_rad_per_k / c.phase_step_rad; /* 34.9 */
  print_message("re-discretisations over 20 mK: %llu (phase moved %.1f steps)\n",
                (unsigned long long)p.rediscretise_count, steps);
  assert_true(p.rediscretise_count >= (uint64_t)floor(steps) - 1 &&
              p.rediscretise_count <= (uint64_t)ceil(steps));
}

/* Bad configurations and temperatures are refused and change nothing. */
static void test_bad_input(void **state)
{
  (void)state;
  pickoff_cfg_t good, c;
  pickoff_default_cfg(&good, PICKOFF_SENSE);
  pickoff_t p, before;
  memset(&p, 0x42, sizeof p);
  before = p;
  c = good;
  c.gain_v_per_m = 0.0;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), -1);
  c = good;
  c.lp_hz = NAN;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), -1);
  c = good;
  c.sample_delay_s = 15e-6; /* more than T/2 */
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), -1);
  c = good;
  c.jitter_rms_s = 2e-6; /* more than T/20 */
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), -1);
  c = good;
  c.phase_step_rad = -1.0;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), -1);
  c = good;
  c.axis = (pickoff_axis_t)5;
  assert_int_equal(pickoff_init(&p, &c, T0_K, 1u), -1);
  assert_int_equal(pickoff_init(&p, &good, NAN, 1u), -1);
  assert_memory_equal(&p, &before, sizeof p);

  assert_int_equal(pickoff_init(&p, &good, T0_K, 1u), 0);
  for (int k = 0; k < 10; k++) (void)pickoff_step(&p, 1e-9 * k, 0.0, NULL);
  before = p;
  assert_int_equal(pickoff_set_temp(&p, NAN), -1);
  assert_memory_equal(&p, &before, sizeof p);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_phase_vs_temperature),
      cmocka_unit_test(test_allpass),
      cmocka_unit_test(test_lag_into_lead),
      cmocka_unit_test(test_allpass_lead),
      cmocka_unit_test(test_law_edges),
      cmocka_unit_test(test_sample_delay),
      cmocka_unit_test(test_jitter),
      cmocka_unit_test(test_noise),
      cmocka_unit_test(test_feedthrough),
      cmocka_unit_test(test_preamp_clip),
      cmocka_unit_test(test_phase_step),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
