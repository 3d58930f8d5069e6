#include "gyro/drive_loop.h"

#include <math.h>
#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"

/* Start value of P: one turn either way, the range of drive.p_init_deg (+-360 deg). Drive
 * synthesis carries whole turns of P itself (drive_synth_set), so the phase conversion's
 * domain (SINCOS_HALF_RAD_MAX_F) sets no limit here. */
#define DRIVE_P_LIMIT_RAD FM_TWO_PI_F

int drive_loop_design(const drive_loop_design_in_t *in, drive_loop_design_out_t *out)
{
  if (in == NULL || out == NULL || !(in->plant_gain > 0.0) || !(in->tau_s > 0.0) ||
      !(in->bw_hz > 0.0) || !(in->demod_bw_hz > 0.0) || !(in->fs_hz > 0.0) ||
      !isfinite(in->plant_gain) || !isfinite(in->tau_s)) {
    return -1;
  }
  /* Loop phase at crossover wc of the first-order open loop K Kp/(tau s) with the demod
   * lag and the delays: from the measured sample to the first DAC frame of the command
   * (lag), the DAC's latency of one sample and the hold of a loop period N T (N T / 2):
   * 90 - atan(wc/wd) - (lag + 1 + N/2) wc T. */
  if (!(in->loop_decim >= 0.0) || !(in->loop_decim <= 1000.0) || !(in->lag_samples >= 0.0) ||
      !(in->lag_samples <= 1000.0)) {
    return -1;
  }
  const double n_hold = in->loop_decim > 1.0 ? in->loop_decim : 1.0;
  const double wd = 2.0 * FM_PI * in->demod_bw_hz;
  const double delay_s = (in->lag_samples + 1.0 + 0.5 * n_hold) / in->fs_hz;
  double wc = 2.0 * FM_PI * in->bw_hz;
  double pm = 0.0;
  for (int i = 0; i < 60; i++) {
    pm = 90.0 - (atan(wc / wd) + wc * delay_s) * 180.0 / FM_PI;
    if (pm >= 60.0) break;
    wc *= 0.9;
  }
  out->kp = wc * in->tau_s / in->plant_gain;
  out->ki = out->kp / in->tau_s;
  out->bw_hz = wc / (2.0 * FM_PI);
  out->phase_margin_deg = pm;
  return 0;
}

static int cfg_ok(const drive_loop_cfg_t *c)
{
  return c != NULL && c->dt_s > 0.0f && c->amp_set_v > 0.0f && c->f_cmd_max_v2 > 0.0f &&
         fm_isfinite(c->amp_set_v) && fm_isfinite(c->phase_set_rad) && fm_isfinite(c->amp_kp) &&
         fm_isfinite(c->amp_ki) && fm_isfinite(c->phase_kp) && fm_isfinite(c->phase_ki) &&
         fm_isfinite(c->f_cmd_max_v2) && fm_isfinite(c->p_init_rad) &&
         fm_absf(c->p_init_rad) <= DRIVE_P_LIMIT_RAD;
}

int drive_loop_cfg_derive(drive_loop_cfg_t *cfg)
{
  if (!cfg_ok(cfg)) {
    return -1;
  }
  const pi_cfg_t amp = {cfg->amp_kp, cfg->amp_ki, cfg->dt_s, 0.0f, cfg->f_cmd_max_v2, 0.0f};
  /* P is kept within +-pi of p_init by whole turns (drive_loop_update_phase): limits a
   * turn beyond that are never reached. */
  const pi_cfg_t ph = {cfg->phase_kp,
                       cfg->phase_ki,
                       cfg->dt_s,
                       cfg->p_init_rad - 2.0f * FM_TWO_PI_F,
                       cfg->p_init_rad + 2.0f * FM_TWO_PI_F,
                       cfg->p_init_rad};
  pi_coeffs_t amp_c, ph_c;
  if (pi_design(&amp, &amp_c) != 0 || pi_design(&ph, &ph_c) != 0) {
    return -1;
  }
  cfg->amp = amp_c;
  cfg->phase = ph_c;
  float rate_per_s = DRIVE_AMP_SLEW_MAX_PER_S;
  if (cfg->amp_ki > 0.0f && cfg->amp_kp > 0.0f &&
      DRIVE_AMP_SLEW_TAU * cfg->amp_ki < rate_per_s * cfg->amp_kp) {
    rate_per_s = DRIVE_AMP_SLEW_TAU * cfg->amp_ki / cfg->amp_kp; /* DRIVE_AMP_SLEW_TAU / tau */
  }
  cfg->amp_slew_up = 1.0f + rate_per_s * cfg->dt_s;
  cfg->amp_slew_down = 1.0f / cfg->amp_slew_up;
  cfg->inv_amp_set = 1.0f / cfg->amp_set_v;
  return 0;
}

void drive_loop_init(const drive_loop_cfg_t *cfg, drive_loop_t *dl)
{
  drive_loop_reset(cfg, dl);
}

void drive_loop_reconfigure(const drive_loop_cfg_t *cfg, drive_loop_t *dl)
{
  dl->amp_int = fm_clampf(dl->amp_int, cfg->amp.u_min, cfg->amp.u_max);
  pi_limit(&cfg->amp, &dl->amp_pi);
  pi_limit(&cfg->phase, &dl->phase_pi);
}

/* Geometric (a constant relative rate: a constant relative lag), the reciprocal moved by
 * the inverse factor; both land exactly on the target. */
GYRO_RAMFUNC static void slew_amp(const drive_loop_cfg_t *restrict c, drive_loop_t *restrict dl)
{
  const int up = dl->amp_set_v < c->amp_set_v;
  dl->amp_set_v *= up ? c->amp_slew_up : c->amp_slew_down;
  dl->inv_amp_set *= up ? c->amp_slew_down : c->amp_slew_up;
  if (up ? dl->amp_set_v >= c->amp_set_v : dl->amp_set_v <= c->amp_set_v) {
    dl->amp_set_v = c->amp_set_v;
    dl->inv_amp_set = c->inv_amp_set;
  }
}

GYRO_RAMFUNC void drive_loop_reset(const drive_loop_cfg_t *restrict c, drive_loop_t *restrict dl)
{
  dl->amp_set_v = c->amp_set_v;
  dl->inv_amp_set = c->inv_amp_set;
  (void)pi_reset(&c->amp, &dl->amp_pi, 0.0f, 0.0f);
  (void)pi_reset(&c->phase, &dl->phase_pi, c->p_init_rad, 0.0f);
  dl->amp_v = 0.0f;
  dl->phase_rad = 0.0f;
  dl->amp_err_v = 0.0f;
  dl->phase_err_rad = 0.0f;
  dl->f_cmd_v2 = 0.0f;
  dl->amp_int = 0.0f;
  dl->amp_notch.x1 = dl->amp_notch.x2 = 0.0f;
  dl->p_rad = c->p_init_rad;
  dl->p_eq_rad = c->p_init_rad;
  dl->p_turn_rad = 0.0f;
}

GYRO_RAMFUNC void drive_loop_step_amp(const drive_loop_cfg_t *restrict c,
                                      drive_loop_t *restrict dl, float w_i, float w_q)
{
  if (drive_loop_slewing(c, dl)) slew_amp(c, dl);
  dl->amp_v = fm_sqrtf(w_i * w_i + w_q * w_q);
  float e = dl->amp_set_v - dl->amp_v;
  dl->amp_err_v = e;
  if (c->amp_position == 0u) {
    dl->f_cmd_v2 = pi_step(&c->amp, &dl->amp_pi, e);
    return;
  }
  /* Position form (drive_loop_cfg_t.amp_position) on the error of the notched amplitude
   * (drive_track.h). */
  e = dl->amp_set_v - drive_notch(c->notch_c2, c->notch_g, &dl->amp_notch, dl->amp_v);
  dl->f_cmd_v2 = pi_step_position(&c->amp, &dl->amp_pi, &dl->amp_int, e);
}

GYRO_RAMFUNC void drive_loop_measure_phase(drive_loop_t *restrict dl, float w_i, float w_q)
{
  dl->phase_rad = fm_atan2f(w_q, w_i);
}

GYRO_RAMFUNC void drive_loop_update_phase(const drive_loop_cfg_t *restrict c,
                                          drive_loop_t *restrict dl)
{
  dl->phase_err_rad = fm_wrap_pi(c->phase_set_rad - dl->phase_rad);
  /* While the amplitude is still tiny its phase is noise; hold P until there is a
   * vibration to measure (10 % of the setpoint). */
  if (dl->amp_v > 0.1f * dl->amp_set_v) {
    float p = pi_step(&c->phase, &dl->phase_pi, dl->phase_err_rad);
    const float dev = p - c->p_init_rad;
    if (dev > FM_PI_F || dev < -FM_PI_F) {
      const float turn = dev > 0.0f ? FM_TWO_PI_F : -FM_TWO_PI_F;
      p -= turn;
      dl->phase_pi.u = p;
      dl->p_turn_rad -= turn;
    }
    dl->p_rad = p;
  } else {
    (void)pi_reset(&c->phase, &dl->phase_pi, dl->p_rad, dl->phase_err_rad);
  }
}

void drive_loop_step_phase(const drive_loop_cfg_t *cfg, drive_loop_t *dl, float w_i, float w_q)
{
  drive_loop_measure_phase(dl, w_i, w_q);
  drive_loop_update_phase(cfg, dl);
}

void drive_loop_step(const drive_loop_cfg_t *cfg, drive_loop_t *dl, float w_i, float w_q)
{
  drive_loop_step_amp(cfg, dl, w_i, w_q);
  drive_loop_step_phase(cfg, dl, w_i, w_q);
}
