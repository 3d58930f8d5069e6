#include "gyro/rate_valid.h"

#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"
#include "gyro/comp_filters.h" /* COMP_FILTERS_HELD_W_MAX */

/* The shadow's transition decays: each diagonal in [0, 1), the rest finite. */
static int spur_m_ok(const float *m)
{
  int ok = 1;
  for (int i = 0; i < 10; i++) ok = ok && fm_isfinite(m[i]);
  return ok && m[0] >= 0.0f && m[0] < 1.0f && m[2] >= 0.0f && m[2] < 1.0f && m[5] >= 0.0f &&
         m[5] < 1.0f && m[9] >= 0.0f && m[9] < 1.0f;
}

int rate_valid_cfg_ok(const rate_valid_cfg_t *c)
{
  return c != NULL && c->tol_dps > 0.0f && fm_isfinite(c->tol_dps) &&
         c->full_scale_dps > 0.0f && fm_isfinite(c->full_scale_dps) && c->p_range_deg > 0.0f &&
         fm_isfinite(c->p_range_deg) && c->p_window_max_deg > 0.0f &&
         fm_isfinite(c->p_window_max_deg) && c->p_lag_per_deg > 0.0f &&
         fm_isfinite(c->p_lag_per_deg) && c->sense_max_v2 > 0.0f &&
         fm_isfinite(c->sense_max_v2) && c->phase_tol_rad > 0.0f &&
         fm_isfinite(c->phase_tol_rad) && c->bias_slope_dps_per_deg >= 0.0f &&
         fm_isfinite(c->bias_slope_dps_per_deg) && c->grad_k_abs_dps_per_deg >= 0.0f &&
         fm_isfinite(c->grad_k_abs_dps_per_deg) && spur_m_ok(c->spur_m);
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
  rv->slew = rv->slew_due = rv->restart_armed = rv->spur = 0u;
  rv->filters_held = 1u;
  rv->snap_lag_deg = rv->snap_lag1_deg = rv->snap_hp_deg = 0.0f;
  rv->p_window_change_deg = 0.0f;
  rv->spur_deg[0] = rv->spur_deg[1] = rv->spur_deg[2] = rv->spur_deg[3] = 0.0f;
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

/* The rate error a lag of P_f of lag_deg makes: the bias polynomial moved along its
 * slope. (Not the quadrature: the rate reference follows P itself through the mode's lag
 * and its type-2 low-pass, rate_channel.h, and reads no P_f.) */
GYRO_RAMFUNC static float lag_error_dps(const rate_valid_cfg_t *restrict c, float lag_deg)
{
  return lag_deg * c->bias_slope_dps_per_deg;
}

GYRO_RAMFUNC void rate_valid_thermo(const rate_valid_cfg_t *restrict c, rate_valid_t *restrict rv,
                                    float p_dev_deg, float p_held_dev_deg, float p_held_w)
{
  if (p_held_w > RATE_VALID_SLEW_W_MAX) {
    /* P_f still converging from a hold (THERMO_SETTLE bounds that): no slew of the
     * temperature can be told from it, the window starts later. */
    rv->p_dev_window_deg = p_dev_deg;
    rv->p_updates = 0u;
  } else if (++rv->p_updates >= RATE_VALID_SLEW_UPDATES) {
    /* The window's change, judged by rate_valid_slew on a later tick. */
    rv->p_window_change_deg = p_dev_deg - rv->p_dev_window_deg;
    rv->slew_due = 1u;
    rv->p_dev_window_deg = p_dev_deg;
    rv->p_updates = 0u;
  }
  /* The reasons after the window's bookkeeping (which leaves slew alone): fewer values
   * live at once, no register to save. */
  rv->filters_held = p_held_w > COMP_FILTERS_HELD_W_MAX;
  uint32_t r = rv->slew | rv->spur;
  if (!(fm_absf(p_dev_deg + c->p_range_off_deg) <= c->p_range_deg))
    r |= RATE_INVALID_THERMO_RANGE;
  /* |P_f - P| <= w / (1 - w) |P_held - P_f|, compared without the divide. */
  const float gap = lag_error_dps(c, p_held_w * fm_absf(p_held_dev_deg - p_dev_deg));
  if (!(gap <= c->tol_dps * (1.0f - p_held_w))) r |= RATE_INVALID_THERMO_SETTLE;
  rv->thermo = r;
}

/* The shadow's rate error: P_c's part (s - lag) at the bias slope, the gradient term's. */
GYRO_RAMFUNC static inline float spur_error_dps(const rate_valid_cfg_t *restrict c,
                                                const float x[4])
{
  return c->bias_slope_dps_per_deg * fm_absf(x[0] - x[2]) +
         c->grad_k_abs_dps_per_deg * fm_absf(x[3]);
}

GYRO_RAMFUNC int rate_valid_slew(const rate_valid_cfg_t *restrict c, rate_valid_t *restrict rv,
                                 float comp_lag_deg, float comp_lag1_deg, float comp_hp_deg)
{
  const float move = rv->p_window_change_deg, change = fm_absf(move);
  const int over_cap = !(change <= c->p_window_max_deg);
  const int slewing = over_cap || rv->restart_armed != 0u ||
                      !(lag_error_dps(c, change * c->p_lag_per_deg) <= c->tol_dps);
  int restart = 0;
  if (!(change <= RATE_VALID_RESTART_CAPS * c->p_window_max_deg)) {
    rv->restart_armed = 1u;
  } else if (!over_cap && rv->restart_armed != 0u) {
    rv->restart_armed = 0u;
    restart = 1;
  }
  /* The shadow (state at this window's end): a restart leaves P_c = P_f and drops the
   * trusted content (what is left of the move in P_f is then the shadow's P_f); a move
   * beyond the cap is P_f's and the filters' next step (whole: the compensation saw it
   * all; not while the filters wait for P_f's fast start, they take none of its moves).
   * Such a move of P returns (the phase loop pulls P back to the temperature's, P_f
   * follows in a second) and its return is counted too; what the count misses (the
   * return's last windows, under the cap) leaks away over rate.comp_tau_s, or a noise
   * trip in a ramp, one-sided, would pile up in the shadow as if P_f were off for good. */
  float *x = rv->spur_deg;
  if (restart) {
    /* P_f, returning from the move, is still about one window's move short of its end
     * (its 1 Hz low-pass covers about half the way in a window), and P_c = P_f has it. */
    x[0] = -move;
    x[1] = -rv->snap_lag1_deg;
    x[2] = -rv->snap_lag_deg;
    x[3] = -rv->snap_hp_deg;
  } else if (over_cap && rv->filters_held == 0u) {
    x[0] += move;
    x[1] += move;
    x[2] += move;
  }
  const float e_now = spur_error_dps(c, x);
  /* On to the next window's end (the window's transition, lower triangular): judged at
   * both ends, the error between them is judged with it. */
  const float *m = c->spur_m;
  x[3] = m[6] * x[0] + m[7] * x[1] + m[8] * x[2] + m[9] * x[3];
  x[2] = m[3] * x[0] + m[4] * x[1] + m[5] * x[2];
  x[1] = m[1] * x[0] + m[2] * x[1];
  x[0] = m[0] * x[0];
  const float e_next = spur_error_dps(c, x);
  rv->spur = (e_now <= c->tol_dps && e_next <= c->tol_dps) ? 0u : RATE_INVALID_THERMO_SLEW;
  rv->slew = slewing ? RATE_INVALID_THERMO_SLEW : 0u;
  rv->thermo = (rv->thermo & ~RATE_INVALID_THERMO_SLEW) | rv->slew | rv->spur;
  rv->slew_due = 0u;
  if ((rv->thermo | rv->restart_armed) == 0u) {
    rv->snap_lag_deg = comp_lag_deg;
    rv->snap_lag1_deg = comp_lag1_deg;
    rv->snap_hp_deg = comp_hp_deg;
  }
  return restart;
}

void rate_valid_spur_matrix(float comp_a, float grad_a, uint32_t stages, float m[10])
{
  /* One P update of the shadow (s, lag1, lag, hp) without input: s leaks by comp_a, and
   * its step goes through the filters (comp_filters.h) like a step of P_f. */
  const double ca = (double)comp_a, kc = 1.0 - ca, kg = 1.0 - (double)grad_a;
  double t[4][4] = {{kc, 0.0, 0.0, 0.0},
                    {0.0, 0.0, 0.0, 0.0},
                    {-ca * kc, 0.0, kc, 0.0},
                    {-kg * ca * ca, 0.0, kg * ca, kg}};
  if (stages >= 2u) {
    /* step = -ca s; lag1' = kc (lag1 + step); P_1's step ca (lag1 + step) into the
     * second stage: lag' = kc (lag + step + P_1's step), hp' = kg (hp + P_c's step). */
    const double t2[4][4] = {{kc, 0.0, 0.0, 0.0},
                             {-kc * ca, kc, 0.0, 0.0},
                             {-kc * ca * (1.0 + ca), kc * ca, kc, 0.0},
                             {-kg * ca * ca * ca, -kg * ca * kc, kg * ca, kg}};
    memcpy(t, t2, sizeof t);
  }
  double p[4][4] = {
      {1.0, 0.0, 0.0, 0.0}, {0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}, {0.0, 0.0, 0.0, 1.0}};
  for (uint32_t n = 0; n < RATE_VALID_SLEW_UPDATES; n++) {
    double q[4][4];
    for (int i = 0; i < 4; i++) {
      for (int j = 0; j < 4; j++) {
        q[i][j] = t[i][0] * p[0][j] + t[i][1] * p[1][j] + t[i][2] * p[2][j] + t[i][3] * p[3][j];
      }
    }
    memcpy(p, q, sizeof p);
  }
  int k = 0;
  for (int i = 0; i < 4; i++) {
    for (int j = 0; j <= i; j++) m[k++] = (float)p[i][j];
  }
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
