#include "gyro/drive_track.h"

#include <math.h>
#include <stddef.h>

#include "dsp/math_const.h"
#include "dsp/ramfunc.h"

/* NCO half-steps per Hz: 2^31 / fs (nco.h). */
static double steps_per_hz(double fs_hz) { return 2147483648.0 / fs_hz; }

/* Phase margin (deg) of the loop at crossover wc: PI zero wz, plant pole 1/tau, the
 * demodulator's lag wd and the delay (header). */
static double margin_deg(double wc, double wz, double tau, double wd, double delay_s)
{
  return 90.0 + (atan(wc / wz) - atan(wc * tau) - atan(wc / wd) - wc * delay_s) * FM_DEG_PER_RAD;
}

/* The zero: on the pole at low Q (1/tau above a quarter of the crossover), a quarter of
 * the crossover at high Q. */
static double zero_of(double wc, double tau)
{
  return 1.0 / tau > 0.25 * wc ? 1.0 / tau : 0.25 * wc;
}

/* Crossover wanted_hz, lowered until the margin is 60 deg; kp (Hz/rad) for |L(j wc)| = 1. */
static double design_wc(double wanted_hz, double tau, double wd, double delay_s, double *pm)
{
  double wc = 2.0 * FM_PI * wanted_hz;
  for (int i = 0; i < 80; i++) {
    *pm = margin_deg(wc, zero_of(wc, tau), tau, wd, delay_s);
    if (*pm >= 60.0) break;
    wc *= 0.95;
  }
  return wc;
}

static double kp_of(double wc, double tau)
{
  const double wz = zero_of(wc, tau);
  return wc * sqrt(1.0 + wc * tau * wc * tau) / (2.0 * FM_PI * tau * sqrt(wc * wc + wz * wz));
}

int drive_track_design(const drive_track_design_in_t *in, drive_track_cfg_t *cfg,
                       drive_track_design_out_t *out)
{
  if (in == NULL || cfg == NULL || out == NULL || !(in->q > 0.0) || !(in->f0_hz > 0.0) ||
      !(in->bw_hz > 0.0) || !(in->acq_bw_factor >= 1.0) || !(in->demod_bw_hz > 0.0) ||
      !(in->fs_hz > 0.0) || !(in->loop_decim >= 1.0) || !(in->lag_samples >= 0.0) ||
      !(in->window_rel > 0.0 && in->window_rel < 0.1) || !isfinite(in->q) ||
      !isfinite(in->p_init_rad) || !(in->min_amp_rel > 0.0 && in->min_amp_rel < 1.0)) {
    return -1;
  }
  const double tau = 2.0 * in->q / (2.0 * FM_PI * in->f0_hz); /* (6-12) */
  const double wd = 2.0 * FM_PI * in->demod_bw_hz;
  /* + one update: the ripple notch's delay (header) */
  const double delay_s = (in->lag_samples + 1.0 + 1.5 * in->loop_decim) / in->fs_hz;
  double pm_lock = 0.0, pm_acq = 0.0;
  const double wc = design_wc(in->bw_hz, tau, wd, delay_s, &pm_lock);
  const double wc_acq = design_wc(in->bw_hz * in->acq_bw_factor, tau, wd, delay_s, &pm_acq);
  const double k = steps_per_hz(in->fs_hz), dt = in->loop_decim / in->fs_hz;
  const double kp = kp_of(wc, tau), kp_acq = kp_of(wc_acq, tau);
  const double ki = kp * zero_of(wc, tau), ki_acq = kp_acq * zero_of(wc_acq, tau);
  const double win = in->window_rel * in->f0_hz * k;
  /* int32 headroom: |offset| + kp |e| with |e| <= pi stays below 2^31. */
  if (!(win >= 1.0 && win < 1.0e8) || !(kp_acq * k < 5.0e8) || !(kp * k < 5.0e8)) return -1;
  cfg->kp_lock = (float)(kp * k);
  cfg->ki_dt_lock = (float)(ki * dt * k);
  cfg->kp_acq = (float)(kp_acq * k);
  cfg->ki_dt_acq = (float)(ki_acq * dt * k);
  cfg->win_steps = (int32_t)win;
  /* (2Q/f0) rad per Hz, per step: the static phase-to-frequency slope at the resonance. */
  cfg->p_eq_per_step_rad = (float)(2.0 * in->q / in->f0_hz / k);
  cfg->p_init_rad = (float)in->p_init_rad;
  cfg->min_amp_rel = (float)in->min_amp_rel;
  drive_track_notch(in->f0_hz, in->fs_hz, in->loop_decim, &cfg->notch_c2, &cfg->notch_g);
  out->bw_hz = wc / (2.0 * FM_PI);
  out->acq_bw_hz = wc_acq / (2.0 * FM_PI);
  out->phase_margin_deg = pm_lock;
  out->kp_hz_per_rad = kp;
  out->ki_hz_per_rad_s = ki;
  return 0;
}

void drive_track_notch(double f0_hz, double fs_hz, double loop_decim, float *c2, float *g)
{
  const double c = 2.0 * cos(2.0 * FM_PI * f0_hz * loop_decim / fs_hz);
  *c2 = (float)c;
  *g = (float)(1.0 / (2.0 - c));
}

GYRO_RAMFUNC void drive_track_reset(drive_track_t *t)
{
  /* Every member at zero (the integrator, the offset, the flags, the notch's memory), as
   * one assignment: stored in pairs (a fault's clear runs it on a tick near its budget). */
  *t = (drive_track_t){0};
}

GYRO_RAMFUNC float drive_track_error(const drive_track_cfg_t *restrict c,
                                     drive_track_t *restrict t, float e_rad, float amp_rel)
{
  /* The notch starts afresh when there is a vibration to measure. */
  if (amp_rel < c->min_amp_rel) {
    t->notch.x1 = t->notch.x2 = e_rad;
    return e_rad;
  }
  return drive_notch(c->notch_c2, c->notch_g, &t->notch, e_rad);
}

/* Round to the nearest whole step without libm (|x| well inside int32). */
static inline int32_t round_steps(float x)
{
  return (int32_t)(x >= 0.0f ? x + 0.5f : x - 0.5f);
}

static inline int32_t clamp_steps(int32_t x, int32_t w)
{
  return x > w ? w : (x < -w ? -w : x);
}

GYRO_RAMFUNC int32_t drive_track_update(const drive_track_cfg_t *restrict c,
                                        drive_track_t *restrict t, float e_rad, float amp_rel,
                                        int locked)
{
  /* While the amplitude is tiny its phase is noise: hold the frequency. */
  if (amp_rel < c->min_amp_rel) return t->off_steps;
  const uint32_t lk = locked ? 1u : 0u;
  const float kp = lk ? c->kp_lock : c->kp_acq;
  float acc = t->int_frac - (lk ? c->ki_dt_lock : c->ki_dt_acq) * e_rad;
  if (lk != t->locked) {
    /* Bumpless: the output -kp e + int keeps its value under the new kp. */
    acc += (kp - (t->locked ? c->kp_lock : c->kp_acq)) * e_rad;
    t->locked = lk;
  }
  const int32_t n = round_steps(acc);
  t->int_frac = acc - (float)n;
  const int32_t w = c->win_steps;
  t->int_steps = clamp_steps(t->int_steps + n, w);
  const int32_t want = t->int_steps - round_steps(kp * e_rad);
  const int32_t off = clamp_steps(want, w);
  t->at_limit = off != want || off == w || off == -w ? 1u : 0u;
  t->off_steps = off;
  return off;
}
