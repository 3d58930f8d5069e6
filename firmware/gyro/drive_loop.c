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

static void set_targets(drive_loop_t *dl, const drive_loop_cfg_t *cfg)
{
  float rate_per_s = DRIVE_AMP_SLEW_MAX_PER_S;
  if (cfg->amp_ki > 0.0f && cfg->amp_kp > 0.0f && DRIVE_AMP_SLEW_TAU * cfg->amp_ki < rate_per_s * cfg->amp_kp) {
    rate_per_s = DRIVE_AMP_SLEW_TAU * cfg->amp_ki / cfg->amp_kp; /* DRIVE_AMP_SLEW_TAU / tau */
  }
  dl->amp_slew_up = 1.0f + rate_per_s * cfg->dt_s;
  dl->amp_slew_down = 1.0f / dl->amp_slew_up;
  dl->amp_target_v = cfg->amp_set_v;
  dl->inv_amp_target = 1.0f / cfg->amp_set_v;
  dl->phase_set_rad = cfg->phase_set_rad;
  dl->p_init_rad = cfg->p_init_rad;
}

static int cfg_ok(const drive_loop_cfg_t *c)
{
  return c != NULL && c->dt_s > 0.0f && c->amp_set_v > 0.0f && c->f_cmd_max_v2 > 0.0f &&
         fm_isfinite(c->amp_set_v) && fm_isfinite(c->phase_set_rad) &&
         fm_isfinite(c->amp_kp) && fm_isfinite(c->amp_ki) && fm_isfinite(c->phase_kp) &&
         fm_isfinite(c->phase_ki) && fm_isfinite(c->f_cmd_max_v2) &&
         fm_isfinite(c->p_init_rad) && fm_absf(c->p_init_rad) <= DRIVE_P_LIMIT_RAD;
}

int drive_loop_init(drive_loop_t *dl, const drive_loop_cfg_t *cfg)
{
  if (dl == NULL || !cfg_ok(cfg)) {
    return -1;
  }
  const pi_cfg_t amp = {cfg->amp_kp, cfg->amp_ki, cfg->dt_s, 0.0f, cfg->f_cmd_max_v2, 0.0f};
  /* P is kept within +-pi of p_init by whole turns (drive_loop_update_phase): limits a
   * turn beyond that are never reached. */
  const pi_cfg_t ph = {cfg->phase_kp, cfg->phase_ki, cfg->dt_s,
                       cfg->p_init_rad - 2.0f * FM_TWO_PI_F, cfg->p_init_rad + 2.0f * FM_TWO_PI_F,
                       cfg->p_init_rad};
  pi_t amp_pi, phase_pi;
  if (pi_init(&amp_pi, &amp) != 0 || pi_init(&phase_pi, &ph) != 0) {
    return -1;
  }
  dl->amp_pi = amp_pi;
  dl->phase_pi = phase_pi;
  set_targets(dl, cfg);
  drive_loop_reset(dl);
  return 0;
}

void drive_loop_retune(drive_loop_t *dl, const drive_loop_cfg_t *cfg)
{
  (void)pi_set_gains(&dl->amp_pi, cfg->amp_kp, cfg->amp_ki);
  (void)pi_set_gains(&dl->phase_pi, cfg->phase_kp, cfg->phase_ki);
  (void)pi_set_limits(&dl->amp_pi, 0.0f, cfg->f_cmd_max_v2);
  (void)pi_set_limits(&dl->phase_pi, cfg->p_init_rad - 2.0f * FM_TWO_PI_F,
                      cfg->p_init_rad + 2.0f * FM_TWO_PI_F);
  set_targets(dl, cfg);
}

/* Geometric (a constant relative rate: a constant relative lag), the reciprocal moved by
 * the inverse factor; both land exactly on the target. */
GYRO_RAMFUNC static void slew_amp(drive_loop_t *dl)
{
  const int up = dl->amp_set_v < dl->amp_target_v;
  dl->amp_set_v *= up ? dl->amp_slew_up : dl->amp_slew_down;
  dl->inv_amp_set *= up ? dl->amp_slew_down : dl->amp_slew_up;
  if (up ? dl->amp_set_v >= dl->amp_target_v : dl->amp_set_v <= dl->amp_target_v) {
    dl->amp_set_v = dl->amp_target_v;
    dl->inv_amp_set = dl->inv_amp_target;
  }
}

GYRO_RAMFUNC void drive_loop_reset(drive_loop_t *dl)
{
  dl->amp_set_v = dl->amp_target_v;
  dl->inv_amp_set = dl->inv_amp_target;
  (void)pi_reset(&dl->amp_pi, 0.0f, 0.0f);
  (void)pi_reset(&dl->phase_pi, dl->p_init_rad, 0.0f);
  dl->amp_v = 0.0f;
  dl->phase_rad = 0.0f;
  dl->amp_err_v = 0.0f;
  dl->phase_err_rad = 0.0f;
  dl->f_cmd_v2 = 0.0f;
  dl->p_rad = dl->p_init_rad;
  dl->p_turn_rad = 0.0f;
}

GYRO_RAMFUNC void drive_loop_step_amp(drive_loop_t *dl, float w_s, float w_c)
{
  if (drive_loop_slewing(dl)) slew_amp(dl);
  dl->amp_v = fm_sqrtf(w_s * w_s + w_c * w_c);
  dl->amp_err_v = dl->amp_set_v - dl->amp_v;
  dl->f_cmd_v2 = pi_step(&dl->amp_pi, dl->amp_err_v);
}

GYRO_RAMFUNC void drive_loop_measure_phase(drive_loop_t *dl, float w_s, float w_c)
{
  dl->phase_rad = fm_atan2f(w_c, w_s);
}

GYRO_RAMFUNC void drive_loop_update_phase(drive_loop_t *dl)
{
  dl->phase_err_rad = fm_wrap_pi(dl->phase_set_rad - dl->phase_rad);
  /* While the amplitude is still tiny its phase is noise; hold P until there is a
   * vibration to measure (10 % of the setpoint). */
  if (dl->amp_v > 0.1f * dl->amp_set_v) {
    float p = pi_step(&dl->phase_pi, dl->phase_err_rad);
    const float dev = p - dl->p_init_rad;
    if (dev > FM_PI_F || dev < -FM_PI_F) {
      const float turn = dev > 0.0f ? FM_TWO_PI_F : -FM_TWO_PI_F;
      p -= turn;
      dl->phase_pi.u = p;
      dl->p_turn_rad -= turn;
    }
    dl->p_rad = p;
  } else {
    (void)pi_reset(&dl->phase_pi, dl->p_rad, dl->phase_err_rad);
  }
}

void drive_loop_step_phase(drive_loop_t *dl, float w_s, float w_c)
{
  drive_loop_measure_phase(dl, w_s, w_c);
  drive_loop_update_phase(dl);
}

void drive_loop_step(drive_loop_t *dl, float w_s, float w_c)
{
  drive_loop_step_amp(dl, w_s, w_c);
  drive_loop_step_phase(dl, w_s, w_c);
}
