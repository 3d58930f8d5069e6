#include "gyro/rate_valid.h"

#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"

int rate_valid_cfg_ok(const rate_valid_cfg_t *c)
{
  return c != NULL && c->tol_dps > 0.0f && fm_isfinite(c->tol_dps) &&
         c->full_scale_dps > 0.0f && fm_isfinite(c->full_scale_dps) && c->p_range_deg > 0.0f &&
         fm_isfinite(c->p_range_deg) && c->p_window_max_deg > 0.0f &&
         fm_isfinite(c->p_window_max_deg) && c->p_lag_per_deg > 0.0f &&
         fm_isfinite(c->p_lag_per_deg) && c->sense_max_v2 > 0.0f &&
         fm_isfinite(c->sense_max_v2) && c->phase_tol_rad > 0.0f &&
         fm_isfinite(c->phase_tol_rad) && c->bias_slope_dps_per_deg >= 0.0f &&
         fm_isfinite(c->bias_slope_dps_per_deg);
}

int rate_valid_init(const rate_valid_cfg_t *cfg, rate_valid_t *rv)
{
  if (rv == NULL || !rate_valid_cfg_ok(cfg)) {
    return -1;
  }
  rv->reasons = RATE_INVALID_MODE;
  rv->thermo = rv->drive = rv->range = 0u;
  rv->was_locked = 0u;
  rv->x_rate = rv->x_quad = 0.0f;
  rv->p_dev_window_deg = 0.0f;
  rv->p_updates = 0u;
  rv->slew = rv->slew_due = rv->slew_cap = 0u;
  rv->p_window_change_deg = 0.0f;
  rv->phase_err_lp_rad = 0.0f;
  rv->blocks = 0u;
  rv->onsets_pending = rv->onset_block = 0u;
  rate_valid_disturb(rv);
  return 0;
}

GYRO_RAMFUNC void rate_valid_settling(const rate_valid_cfg_t *restrict cfg,
                                      rate_valid_t *restrict rv, float rate_raw, float quad_raw,
                                      float rate_unc_dps, float quad_dps, float scale_dps)
{
  rv->x_rate += RATE_VALID_INPUT_K * (rate_raw - rv->x_rate);
  rv->x_quad += RATE_VALID_INPUT_K * (quad_raw - rv->x_quad);
  if (rv->settled != 0u) return;
  const float tol = cfg->tol_dps;
  const int inside = fm_absf(rate_unc_dps - scale_dps * rv->x_rate) <= tol &&
                     fm_absf(quad_dps - scale_dps * rv->x_quad) <= tol;
  rv->settle_run = inside ? rv->settle_run + 1u : 0u;
  if (rv->settle_run >= RATE_VALID_SETTLE_BLOCKS) rv->settled = 1u;
}

/* The rate error a lag of P_f of lag_deg makes: the quadrature rotated by the lag and
 * the bias polynomial moved along its slope. */
GYRO_RAMFUNC static float lag_error_dps(const rate_valid_cfg_t *restrict c, float lag_deg,
                                        float quad_dps)
{
  return lag_deg * (fm_absf(quad_dps) * FM_RAD_PER_DEG_F + c->bias_slope_dps_per_deg);
}

GYRO_RAMFUNC void rate_valid_thermo(const rate_valid_cfg_t *restrict c,
                                    rate_valid_t *restrict rv, float p_dev_deg,
                                    float p_held_dev_deg, float p_held_w, float quad_dps)
{
  if (p_held_w > RATE_VALID_SLEW_W_MAX) {
    /* P_f still converging from a hold (THERMO_SETTLE bounds that): no slew of the
     * temperature can be told from it, the window starts later. */
    rv->p_dev_window_deg = p_dev_deg;
    rv->p_updates = 0u;
  } else if (++rv->p_updates >= RATE_VALID_SLEW_UPDATES) {
    /* The window's change, judged by rate_valid_slew on a later tick. */
    rv->p_window_change_deg = fm_absf(p_dev_deg - rv->p_dev_window_deg);
    rv->slew_due = 1u;
    rv->p_dev_window_deg = p_dev_deg;
    rv->p_updates = 0u;
  }
  /* The reasons after the window's bookkeeping (which leaves slew alone): fewer values
   * live at once, no register to save. */
  uint32_t r = rv->slew;
  if (!(fm_absf(p_dev_deg + c->p_range_off_deg) <= c->p_range_deg))
    r |= RATE_INVALID_THERMO_RANGE;
  /* |P_f - P| <= w / (1 - w) |P_held - P_f|, compared without the divide. */
  const float gap = lag_error_dps(c, p_held_w * fm_absf(p_held_dev_deg - p_dev_deg), quad_dps);
  if (!(gap <= c->tol_dps * (1.0f - p_held_w))) r |= RATE_INVALID_THERMO_SETTLE;
  rv->thermo = r;
}

GYRO_RAMFUNC void rate_valid_slew(const rate_valid_cfg_t *restrict c, rate_valid_t *restrict rv,
                                  float quad_dps)
{
  const float change = rv->p_window_change_deg;
  const int over_cap = !(change <= c->p_window_max_deg);
  const int slewing = over_cap ||
                      !(lag_error_dps(c, change * c->p_lag_per_deg, quad_dps) <= c->tol_dps);
  rv->slew_cap = (uint32_t)over_cap;
  rv->slew = slewing ? RATE_INVALID_THERMO_SLEW : 0u;
  rv->thermo = (rv->thermo & ~RATE_INVALID_THERMO_SLEW) | rv->slew;
  rv->slew_due = 0u;
}

GYRO_RAMFUNC void rate_valid_drive(const rate_valid_cfg_t *restrict c, rate_valid_t *restrict rv,
                                   float phase_err_rad, float quad_dps, float sense_v2)
{
  /* The lock tolerance on the 100 Hz error; the quadrature it rotates into the rate on
   * its lasting part. */
  rv->phase_err_lp_rad += RATE_VALID_PHASE_K * (phase_err_rad - rv->phase_err_lp_rad);
  const float pe = fm_absf(phase_err_rad);
  const float leak_dps = fm_absf(rv->phase_err_lp_rad) * fm_absf(quad_dps);
  uint32_t r = 0u;
  if (!(pe <= c->phase_tol_rad && leak_dps <= c->tol_dps)) r |= RATE_INVALID_PHASE;
  if (!(sense_v2 <= c->sense_max_v2)) r |= RATE_INVALID_SENSE_RANGE;
  rv->drive = r;
}

const char *rate_valid_reason_name(uint32_t kind)
{
  static const char *const names[RATE_INVALID_KINDS] = {
      "MODE",          "SELFTEST", "SETTLING",     "CLIP",        "SENSE_RANGE",
      "OVER_RANGE",    "PHASE",    "THERMO_RANGE", "THERMO_SLEW", "THERMO_SETTLE",
      "CONT_SELFTEST", "TRACKING", "UNCALIBRATED"};
  return kind < RATE_INVALID_KINDS ? names[kind] : "?";
}
