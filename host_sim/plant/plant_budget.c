/* Design-point budgets of the plant: ADC range use, the drive chain's phase, and what
 * matching the sense mode takes. */
#include "plant/plant.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "plant/plant_const.h"

static const double kPi = PLANT_PI;
static const double kDeg = PLANT_RAD_PER_DEG;

/* 2nd-order low-pass w0^2 / (s^2 + w0/Q s + w0^2) at f */
static double complex lp2(double f, double f0, double q)
{
  if (f0 <= 0.0) return 1.0;
  const double complex s = I * f / f0;
  return 1.0 / (s * s + s / q + 1.0);
}

/* 1st-order high-pass s / (s + w0) at f */
static double complex hp1(double f, double f0)
{
  if (f0 <= 0.0) return 1.0;
  const double complex s = I * f / f0;
  return s / (1.0 + s);
}

/* circuit lag section of pickoff.h at f, its phase Phi at f_ref (kept to its range) */
static double complex lag_section(double f, double f_ref, double phi, bool allpass)
{
  const pickoff_lag_kind_t kind = allpass ? PICKOFF_LAG_ALLPASS : PICKOFF_LAG_LOWPASS;
  double b0, b1w, tpw;
  pickoff_lag_section(kind, pickoff_phi_clamp(kind, phi, NULL), &b0, &b1w, &tpw);
  const double x = f / f_ref;
  return (b0 + I * b1w * x) / (1.0 + I * tpw * x);
}

static double circuit_phi(double phi0_deg, double phi1, double phi2, double dt)
{
  return (phi0_deg + phi1 * dt + 0.5 * phi2 * dt * dt) * kDeg;
}

/* pickoff chain from displacement to ADC volts at f (gain, lag, band-pass) */
static double complex pick_chain(const plant_cfg_t *c, int axis, double f, double temp_k)
{
  const double dt = temp_k - c->temp_ref_k;
  const double phi = circuit_phi(PLANT_PICK(c, axis, phi0_deg),
                                 PLANT_PICK(c, axis, phi1_deg_per_k),
                                 PLANT_PICK(c, axis, phi2_deg_per_k2), dt);
  return PLANT_PICK(c, axis, gain_v_per_m) *
         pickoff_gain_factor(PLANT_PICK(c, axis, gain_tc_per_k), dt, NULL) *
         lag_section(f, c->pick_lag_ref_hz, phi, PLANT_PICK(c, axis, lag_allpass)) *
         hp1(f, PLANT_PICK(c, axis, hp_hz)) *
         lp2(f, PLANT_PICK(c, axis, lp_hz), PLANT_PICK(c, axis, lp_q));
}

void plant_drive_phase_budget(const plant_cfg_t *c, double f_hz, double temp_k,
                              plant_phase_budget_t *o)
{
  const double T = 1.0 / c->fs_hz;
  const double dt = temp_k - c->temp_ref_k;
  o->latency_deg = 360.0 * f_hz * T;
  o->zoh_deg = 180.0 * f_hz * T;
  /* half-frequency drive: the voltages at f/2, the force (their square) at twice
   * their phase (6-25) */
  o->recon_deg = -2.0 * carg(lp2(0.5 * f_hz, c->dac_recon_hz, c->dac_recon_q)) / kDeg;
  const double phi = circuit_phi(c->pick_drive_phi0_deg, c->pick_drive_phi1_deg_per_k,
                                 c->pick_drive_phi2_deg_per_k2, dt);
  o->pick_lag_deg = -carg(lag_section(f_hz, c->pick_lag_ref_hz, phi, c->pick_drive_lag_allpass)) /
                    kDeg;
  o->aa_deg = -carg(hp1(f_hz, c->pick_drive_hp_hz) *
                    lp2(f_hz, c->pick_drive_lp_hz, c->pick_drive_lp_q)) /
              kDeg;
  o->sample_delay_deg = 360.0 * f_hz * c->pick_drive_delay_s;
  o->analog_deg = o->recon_deg + o->pick_lag_deg + o->aa_deg;
  o->total_deg = o->latency_deg + o->zoh_deg + o->analog_deg + o->sample_delay_deg;
}

double plant_adc_fraction(const plant_cfg_t *c, double frac[2])
{
  const double T = 1.0 / c->fs_hz;
  const double f1 = c->f_drive_hz, w1 = 2.0 * kPi * f1;
  const double wn1 = w1, wn2 = 2.0 * kPi * c->f_sense_hz;
  const double a0 = c->drive_amp_m;
  /* drive voltage for a0 at resonance: Ks U^2 |H_recon(f/2)|^2 sinc^2(wT/2) Q1/wn1^2 */
  const double x = 0.5 * w1 * T, sinc = sin(x) / x;
  const double hr = cabs(lp2(0.5 * f1, c->dac_recon_hz, c->dac_recon_q));
  const double force = a0 * wn1 * wn1 / c->q_drive;
  double u = 0.0;
  if (c->ks_drive_mps2_per_v2 > 0.0)
    u = sqrt(force / (c->ks_drive_mps2_per_v2 * hr * hr * sinc * sinc));
  /* white noise at the ADC over the Nyquist band, 4 sigma */
  const double nd = 4.0 * c->pick_drive_noise_v_rthz * sqrt(0.5 * c->fs_hz);
  const double ns = 4.0 * c->pick_sense_noise_v_rthz * sqrt(0.5 * c->fs_hz);
  /* drive channel: motion, offset, feedthrough of both electrodes (bounded by |U|) */
  const double vd = a0 * cabs(pick_chain(c, 0, f1, c->temp_ref_k)) +
                    fabs(c->pick_drive_offset_v) +
                    (fabs(c->pick_drive_ft_u1) + fabs(c->pick_drive_ft_u2)) * u + nd;
  /* sense channel: quadrature and full-scale rate are in phase quadrature, (2-25) with
   * -k_q y: |2 Omega wc j - k_q| A0 / |D2(wc)| */
  const double kq = 2.0 * w1 * c->quad_dps * kDeg, om = c->rate_fs_dps * kDeg;
  const double complex d2 = wn2 * wn2 - w1 * w1 + I * wn2 * w1 / c->q_sense;
  const double xs = cabs(2.0 * om * w1 * I - kq) * a0 / cabs(d2);
  /* vibration along the sense axis: quasi-static through the sense resonance, then the
   * pickoff band-pass at vib_hz */
  const double wv = 2.0 * kPi * c->vib_hz;
  const double complex dv = wn2 * wn2 - wv * wv + I * wn2 * wv / c->q_sense;
  const double xv = c->vib_g * fabs(c->gs_sense_from_sense_mps2_per_g) / cabs(dv);
  const double vs = xs * cabs(pick_chain(c, 1, f1, c->temp_ref_k)) +
                    xv * cabs(pick_chain(c, 1, c->vib_hz, c->temp_ref_k)) +
                    fabs(c->pick_sense_offset_v) +
                    (fabs(c->pick_sense_ft_u1) + fabs(c->pick_sense_ft_u2)) * u + ns;
  frac[0] = vd / c->adc_full_scale_v;
  frac[1] = vs / c->adc_full_scale_v;
  return frac[0] > frac[1] ? frac[0] : frac[1];
}

/* The resonance of f_hz at temp_k by (2-32), rad/s (as mech.c's, true time). */
static double wn_at_temp(const plant_cfg_t *c, double f_hz, double temp_k)
{
  return 2.0 * kPi * f_hz * (1.0 - 0.5 * c->ket_per_k * (temp_k - c->temp_ref_k));
}

static int wt_ok(double w1, double split_hz) { return w1 + 2.0 * kPi * split_hz > 0.0; }

/* Why the target cannot be reached, into out->msg (1), or the voltage (0). */
static int match_verdict(const plant_cfg_t *c, double ke_have, plant_match_t *o)
{
  const double w2 = 2.0 * kPi * c->f_sense_hz, margin = 0.5 * w2 * w2; /* mech.h */
  const int n = (int)sizeof o->msg;
  if (o->ke_per_s2 < 0.0) {
    snprintf(o->msg, n,
             "sense resonance %.2f Hz is below the target %.2f Hz: tuning electrodes only lower "
             "it, so this part cannot be matched",
             o->f_sense_hz, o->f_target_hz);
    return 1;
  }
  if (o->ke_per_s2 > 0.0 && !(c->tune_ke_per_s2_per_v2 > 0.0)) {
    snprintf(o->msg, n,
             "no tuning electrodes (tune_ke_per_s2_per_v2 = 0): the sense resonance "
             "stays %.2f Hz, %.2f Hz from the target",
             o->f_sense_hz, o->f_sense_hz - o->f_target_hz);
    return 1;
  }
  if (ke_have + o->ke_per_s2 > margin) {
    snprintf(o->msg, n,
             "moving the sense resonance from %.2f to %.2f Hz softens it beyond half its "
             "stiffness (pull-in margin)",
             o->f_sense_hz, o->f_target_hz);
    return 1;
  }
  const double v = o->ke_per_s2 > 0.0 ? sqrt(o->ke_per_s2 / c->tune_ke_per_s2_per_v2) : 0.0;
  if (v > PLANT_ELECTRODE_MAX_V) {
    snprintf(o->msg, n, "needs %.1f V on the tuning electrodes, beyond %.0f V", v,
             PLANT_ELECTRODE_MAX_V);
    return 1;
  }
  o->tune_v = v;
  o->reachable = 1;
  snprintf(o->msg, n,
           "%.3f V on the tuning electrodes moves the sense resonance from %.2f to "
           "%.2f Hz",
           v, o->f_sense_hz, o->f_target_hz);
  return 0;
}

int plant_sense_match(const plant_cfg_t *c, double temp_k, double split_hz,
                      double ke_other_per_s2, plant_match_t *o)
{
  if (o == NULL) return -1;
  memset(o, 0, sizeof *o);
  if (plant_cfg_check(c, o->msg, sizeof o->msg) != 0) return -1;
  if (!(isfinite(temp_k) && temp_k > 0.0 && isfinite(split_hz) && isfinite(ke_other_per_s2) &&
        ke_other_per_s2 >= 0.0)) {
    snprintf(o->msg, sizeof o->msg,
             "plant_sense_match: temp_k, split_hz or ke_other_per_s2 "
             "invalid");
    return -1;
  }
  const double w1 = wn_at_temp(c, c->f_drive_hz, temp_k),
               w2 = wn_at_temp(c, c->f_sense_hz, temp_k);
  if (!(wt_ok(w1, split_hz))) {
    snprintf(o->msg, sizeof o->msg,
             "plant_sense_match: split_hz %g puts the target at or "
             "below 0 Hz",
             split_hz);
    return -1;
  }
  const double ke_have = plant_fb_softening(c) + ke_other_per_s2;
  const double w2e2 = w2 * w2 - ke_have, wt = w1 + 2.0 * kPi * split_hz;
  o->f_drive_hz = w1 / (2.0 * kPi);
  o->f_sense_hz = w2e2 > 0.0 ? sqrt(w2e2) / (2.0 * kPi) : 0.0;
  o->f_target_hz = wt / (2.0 * kPi);
  o->ke_per_s2 = w2e2 - wt * wt;
  return match_verdict(c, ke_have, o);
}
