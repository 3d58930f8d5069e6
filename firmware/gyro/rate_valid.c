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
  for (uint32_t i = 0u; i < RATE_VALID_SPUR_M; i++) ok = ok && fm_isfinite(m[i]);
  for (uint32_t i = 0u; i < RATE_VALID_SPUR_N; i++) {
    const float d = m[i * (i + 1u) / 2u + i]; /* row i's diagonal */
    ok = ok && d >= 0.0f && d < 1.0f;
  }
  return ok;
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
         fm_isfinite(c->grad_k_abs_dps_per_deg) && c->grad_fast_abs_dps_per_deg >= 0.0f &&
         fm_isfinite(c->grad_fast_abs_dps_per_deg) && spur_m_ok(c->spur_m);
}

GYRO_RAMFUNC void rate_valid_restart(rate_valid_t *rv)
{
  rv->thermo = 0u;
  rv->p_dev_window_deg = 0.0f;
  rv->p_updates = 0u;
  rv->slew = rv->slew_due = rv->restart_armed = rv->spur = rv->displaced = 0u;
  rv->shadow_phase = 0u;
  rv->e_now_dps = 0.0f;
  rv->trend_p_deg = rv->trend_step_deg = 0.0f;
  rv->filters_held = 1u;
  rv->snap_lag_deg = rv->snap_hp_deg = 0.0f;
  rv->snap_mid_deg[0] = rv->snap_mid_deg[1] = 0.0f;
  rv->snap_fast_lag_deg = rv->snap_fast_hp_deg = 0.0f;
  rv->p_window_change_deg = 0.0f;
  for (uint32_t i = 0u; i < RATE_VALID_SPUR_N; i++) rv->spur_deg[i] = 0.0f;
}

int rate_valid_init(const rate_valid_cfg_t *cfg, rate_valid_t *rv)
{
  if (rv == NULL || !rate_valid_cfg_ok(cfg)) {
    return -1;
  }
  rv->reasons = RATE_INVALID_MODE;
  rate_valid_restart(rv);
  rv->drive = rv->range = 0u;
  rv->was_locked = 0u;
  rv->x_rate = rv->x_quad = 0.0f;
  rv->ring_ms = 0.0f;
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
  rv->x_rate += cfg->settle_k * (rate_raw - rv->x_rate);
  rv->x_quad += cfg->settle_k * (quad_raw - rv->x_quad);
  float dr = rate_unc_dps - scale_dps * rv->x_rate;
  float dq = quad_dps - scale_dps * rv->x_quad;
  if (cfg->settle_diff_k < 1.0f) { /* a wide output band's noise averaged (rate_valid.h) */
    rv->d_rate += cfg->settle_diff_k * (dr - rv->d_rate);
    rv->d_quad += cfg->settle_diff_k * (dq - rv->d_quad);
    dr = rv->d_rate;
    dq = rv->d_quad;
  }
  const float tol = cfg->tol_dps;
  if (rv->settled != 0u) {
    /* Settled: the quadrature axis's difference watched on, its mean square over about
     * 13 ms (rate_valid.h, RATE_VALID_RING_TOLS). A lightly damped sense mode answers a
     * change of rate or quadrature with its free response, a phasor turning at the split
     * |f_sense - f_drive| that decays over 2Q / w_sense, as much on this axis as on the
     * rate's; the output filter passes a beat near its corner, the fast reference more,
     * so their difference holds it. A rate the part follows moves the rate axis alone. */
    rv->ring_ms += RATE_VALID_RING_K * (dq * dq - rv->ring_ms);
    const float ring_tol = RATE_VALID_RING_TOLS * tol;
    if (!(rv->ring_ms <= ring_tol * ring_tol)) rate_valid_disturb(rv);
    return;
  }
  /* Settling: the mean square starts from 0 once settled (settling is itself the
   * difference within tol_dps for RATE_VALID_SETTLE_BLOCKS: a ringing then left is under
   * the threshold), not from what the transient before it left. */
  rv->ring_ms = 0.0f;
  const int inside = fm_absf_cmp(dr) <= tol && fm_absf_cmp(dq) <= tol;
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
  } else if (!(fm_absf_cmp(p_dev_deg - rv->p_dev_window_deg) <= c->p_window_max_deg)) {
    /* The window is over its cap before its end: THERMO_SLEW now, not a window later
     * (rate_valid_slew judges the whole window at its end). A kick of P moves the
     * compensation's fast path within that time (rate_channel_comp_refresh). */
    rv->slew = RATE_INVALID_THERMO_SLEW;
  }
  /* The reasons after the window's bookkeeping (which leaves slew alone): fewer values
   * live at once, no register to save. */
  rv->filters_held = p_held_w > COMP_FILTERS_HELD_W_MAX;
  uint32_t r = rv->slew | rv->spur;
  /* After a move no temperature makes (a window beyond the cap), P_f is trusted again
   * only back where the temperature alone would have it (its trend before the move,
   * carried on), to half the tolerance (the other half is the filters', the shadow's): a
   * move that lasts (a change of the drive circuit's phase) would otherwise be read as
   * one of temperature once the filters have taken it in. A hold (the drive acquiring
   * again) ends it. */
  rv->trend_p_deg += rv->trend_step_deg;
  if (rv->filters_held != 0u ||
      lag_error_dps(c, fm_absf_cmp(p_dev_deg - rv->trend_p_deg)) <= 0.5f * c->tol_dps)
    rv->displaced = 0u;
  if (rv->displaced != 0u) r |= RATE_INVALID_THERMO_SLEW;
  if (!(fm_absf_cmp(p_dev_deg + c->p_range_off_deg) <= c->p_range_deg))
    r |= RATE_INVALID_THERMO_RANGE;
  /* |P_f - P| <= w / (1 - w) |P_held - P_f|, compared without the divide. */
  const float gap = lag_error_dps(c, p_held_w * fm_absf_cmp(p_held_dev_deg - p_dev_deg));
  if (!(gap <= c->tol_dps * (1.0f - p_held_w))) r |= RATE_INVALID_THERMO_SETTLE;
  rv->thermo = r;
}

/* The shadow's rate error: P_c's part (s - lag) at the bias slope, the gradient term's;
 * with a fast path the larger of the two paths' (the blend lies between them,
 * rate_channel_comp_refresh). */
GYRO_RAMFUNC static inline float spur_error_dps(const rate_valid_cfg_t *restrict c,
                                                const float x[RATE_VALID_SPUR_N])
{
  const float e = c->bias_slope_dps_per_deg * fm_absf(x[0] - x[COMP_STAGES_MAX]) +
                  c->grad_k_abs_dps_per_deg * fm_absf(x[RATE_VALID_SPUR_HP]);
  if (c->fast_on == 0u) return e;
  const float e_fast = c->bias_slope_dps_per_deg * fm_absf(x[0] - x[RATE_VALID_SPUR_FAST_LAG]) +
                       c->grad_fast_abs_dps_per_deg * fm_absf(x[RATE_VALID_SPUR_FAST_HP]);
  return fm_maxf(e, e_fast);
}

GYRO_RAMFUNC int rate_valid_slew(const rate_valid_cfg_t *restrict c, rate_valid_t *restrict rv)
{
  const float move = rv->p_window_change_deg, change = fm_absf_cmp(move);
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
  if (over_cap) rv->displaced = 1u;
  if (restart && rv->filters_held == 0u) {
    /* P_f, returning from the move, is still about one window's move short of its end
     * (its 1 Hz low-pass covers about half the way in a window), and P_c = P_f has it.
     * (Not while the filters wait for P_f: they took none of the move, and start on P_f
     * once its held value has gone.) */
    x[0] = -move;
    x[1] = -rv->snap_mid_deg[0];
    x[2] = -rv->snap_mid_deg[1];
    x[COMP_STAGES_MAX] = -rv->snap_lag_deg;
    x[RATE_VALID_SPUR_HP] = -rv->snap_hp_deg;
    x[RATE_VALID_SPUR_FAST_LAG] = -rv->snap_fast_lag_deg;
    x[RATE_VALID_SPUR_FAST_HP] = -rv->snap_fast_hp_deg;
  } else if (over_cap && rv->filters_held == 0u) {
    /* P_f moved, no stage yet: every lag grows by the move (a stage not in use, and the
     * fast path without one, have a zero row and column in the transition) */
    for (uint32_t i = 0u; i <= COMP_STAGES_MAX; i++) x[i] += move;
    x[RATE_VALID_SPUR_FAST_LAG] += move;
  }
  rv->slew = slewing ? RATE_INVALID_THERMO_SLEW : 0u;
  rv->thermo = (rv->thermo & ~RATE_INVALID_THERMO_SLEW) | rv->slew | rv->spur |
               (rv->displaced != 0u ? RATE_INVALID_THERMO_SLEW : 0u);
  rv->slew_due = 0u;
  rv->shadow_phase = 1u;
  return restart;
}

/* Rows hi - 1 down to lo of the shadow's window transition, in place (lower triangular:
 * row i reads x[0..i], none of which a later row of the same pass has written). Inlined
 * with constant bounds and unrolled: a multiply-add per entry, the state in registers
 * (the loops as loops cost eight instructions an entry). */
GYRO_RAMFUNC static inline __attribute__((always_inline)) void
shadow_rows(const float *restrict m, float *restrict x, uint32_t hi, uint32_t lo)
{
#pragma GCC unroll 8
  for (uint32_t i = hi; i-- > lo;) {
    const float *row = &m[i * (i + 1u) / 2u];
    float y = 0.0f;
#pragma GCC unroll 8
    for (uint32_t j = 0u; j <= i; j++) y += row[j] * x[j];
    x[i] = y;
  }
}

/* THERMO_SLEW from the shadow's verdict (and the window's slew, a lasting move). */
GYRO_RAMFUNC static inline void shadow_verdict(rate_valid_t *restrict rv, int beyond)
{
  if (beyond) rv->spur = RATE_INVALID_THERMO_SLEW;
  rv->thermo = (rv->thermo & ~RATE_INVALID_THERMO_SLEW) | rv->slew | rv->spur |
               (rv->displaced != 0u ? RATE_INVALID_THERMO_SLEW : 0u);
}

GYRO_RAMFUNC void rate_valid_shadow(const rate_valid_cfg_t *restrict c,
                                    rate_valid_t *restrict rv, const rate_channel_t *restrict rc)
{
  float *x = rv->spur_deg;
  /* Half the tolerance: the other half is P_f's own way back to its trend (displaced,
   * rate_valid_thermo), which the shadow does not hold. */
  const float half_tol = 0.5f * c->tol_dps;
  switch (rv->shadow_phase) {
  case 1u: /* its error at the window's end, judged at once */
    rv->e_now_dps = spur_error_dps(c, x);
    shadow_verdict(rv, !(rv->e_now_dps <= half_tol));
    break;
  case 2u: { /* the fast path's rows (they read s and the fast path's own states alone),
              * then the gradient term's */
    const float *m = c->spur_m;
    const float *r6 = &m[RATE_VALID_SPUR_FAST_HP * (RATE_VALID_SPUR_FAST_HP + 1u) / 2u];
    const float *r5 = &m[RATE_VALID_SPUR_FAST_LAG * (RATE_VALID_SPUR_FAST_LAG + 1u) / 2u];
    x[RATE_VALID_SPUR_FAST_HP] = r6[0] * x[0] +
                                 r6[RATE_VALID_SPUR_FAST_LAG] * x[RATE_VALID_SPUR_FAST_LAG] +
                                 r6[RATE_VALID_SPUR_FAST_HP] * x[RATE_VALID_SPUR_FAST_HP];
    x[RATE_VALID_SPUR_FAST_LAG] = r5[0] * x[0] +
                                  r5[RATE_VALID_SPUR_FAST_LAG] * x[RATE_VALID_SPUR_FAST_LAG];
    shadow_rows(m, x, RATE_VALID_SPUR_FAST_LAG, RATE_VALID_SPUR_HP);
    break;
  }
  case 3u: shadow_rows(c->spur_m, x, RATE_VALID_SPUR_HP, 1u); break;
  case 4u: { /* at the next window's end: judged at both ends, the error between them
              * is judged with it */
    shadow_rows(c->spur_m, x, 1u, 0u);
    const float e_next = spur_error_dps(c, x);
    rv->spur = 0u;
    shadow_verdict(rv, !(rv->e_now_dps <= half_tol && e_next <= half_tol));
    rv->shadow_phase = (rv->thermo | rv->restart_armed) == 0u ? 5u : 0u;
    return;
  }
  default: /* every check passed: what a later move would drop */
    rv->snap_lag_deg = rc->p_comp_lag_deg;
    rv->snap_mid_deg[0] = rc->p_comp_mid_deg[0];
    rv->snap_mid_deg[1] = rc->p_comp_mid_deg[1];
    rv->snap_hp_deg = rc->p_hp_deg;
    rv->snap_fast_lag_deg = rc->p_fast_lag_deg;
    rv->snap_fast_hp_deg = rc->p_fast_hp_deg;
    /* The trend of a passed window: P_f at its end, moving as the gradient term's input
     * says (a ramp at r holds it at r tau_g: r T per update is that times grad_a). */
    rv->trend_p_deg = rv->p_dev_window_deg;
    rv->trend_step_deg = rc->p_hp_deg * c->grad_a;
    rv->shadow_phase = 0u;
    return;
  }
  rv->shadow_phase++;
}

/* One P update of the compensation's filters (comp_filters_step) in double, on the
 * shadow's state (s, mid[0], mid[1], lag, hp, fast lag, fast hp) without input: s leaks
 * by comp_a, and its step goes through the filters like a step of P_f. */
static void spur_update(double x[RATE_VALID_SPUR_N], double ca, double ga, uint32_t stages,
                        double fa)
{
  const double step = -ca * x[0];
  x[0] += step;
  double lag_before = 0.0, step_before = step;
  for (uint32_t k = 0u; k < stages; k++) {
    double *lag = k + 1u == stages ? &x[COMP_STAGES_MAX] : &x[1u + k];
    const double d = (*lag - lag_before) + step_before;
    const double step_k = ca * d;
    lag_before = *lag;
    *lag = (*lag + step) - step_k;
    step_before = step_k;
  }
  x[RATE_VALID_SPUR_HP] = (1.0 - ga) * (x[RATE_VALID_SPUR_HP] + step_before);
  const double step_f = fa * (x[RATE_VALID_SPUR_FAST_LAG] + step);
  x[RATE_VALID_SPUR_FAST_LAG] += step - step_f;
  x[RATE_VALID_SPUR_FAST_HP] = (1.0 - ga) * (x[RATE_VALID_SPUR_FAST_HP] + step_f);
}

void rate_valid_spur_matrix(float comp_a, float grad_a, uint32_t stages, float fast_a,
                            float m[RATE_VALID_SPUR_M])
{
  /* The update is linear: its matrix column by column from the unit states (a mid stage
   * not in use stays where it was, so its row is taken as 0), then its power. */
  enum { N = RATE_VALID_SPUR_N };
  double t[N][N], p[N][N];
  for (uint32_t j = 0u; j < N; j++) {
    double x[N] = {0.0};
    x[j] = 1.0;
    spur_update(x, (double)comp_a, (double)grad_a, stages, (double)fast_a);
    for (uint32_t i = 0u; i < N; i++) {
      const int unused = (i >= 1u && i < COMP_STAGES_MAX && i >= stages) ||
                         (i >= RATE_VALID_SPUR_FAST_LAG && !(fast_a > 0.0f));
      t[i][j] = unused ? 0.0 : x[i];
      p[i][j] = i == j ? 1.0 : 0.0;
    }
  }
  for (uint32_t n = 0; n < RATE_VALID_SLEW_UPDATES; n++) {
    double q[N][N];
    for (uint32_t i = 0u; i < N; i++) {
      for (uint32_t j = 0u; j < N; j++) {
        double acc = 0.0;
        for (uint32_t k = 0u; k < N; k++) acc += t[i][k] * p[k][j];
        q[i][j] = acc;
      }
    }
    memcpy(p, q, sizeof p);
  }
  uint32_t k = 0u;
  for (uint32_t i = 0u; i < N; i++) {
    for (uint32_t j = 0u; j <= i; j++) m[k++] = (float)p[i][j];
  }
}

GYRO_RAMFUNC void rate_valid_drive(const rate_valid_cfg_t *restrict c, rate_valid_t *restrict rv,
                                   float phase_err_rad, float quad_dps, float sense_v2)
{
  /* The lock tolerance on the 100 Hz error; the quadrature it rotates into the rate on
   * its lasting part. */
  rv->phase_err_lp_rad += RATE_VALID_PHASE_K * (phase_err_rad - rv->phase_err_lp_rad);
  const float pe = fm_absf_cmp(phase_err_rad);
  const float leak_dps = fm_absf_cmp(rv->phase_err_lp_rad) * fm_absf_cmp(quad_dps);
  uint32_t r = 0u;
  if (!(pe <= c->phase_tol_rad && leak_dps <= c->tol_dps)) r |= RATE_INVALID_PHASE;
  if (!(sense_v2 <= c->sense_max_v2)) r |= RATE_INVALID_SENSE_RANGE;
  rv->drive = r;
}

const char *rate_valid_reason_name(uint32_t kind)
{
  static const char *const names[RATE_INVALID_KINDS] = {
      "MODE",          "SELFTEST",  "SETTLING",     "CLIP",        "SENSE_RANGE",
      "OVER_RANGE",    "PHASE",     "THERMO_RANGE", "THERMO_SLEW", "THERMO_SETTLE",
      "CONT_SELFTEST", "TRACKING",  "UNCALIBRATED", "QUAD_NULL",   "SENSE_FR",
      "TUNE",          "BOARD_TEMP"};
  return kind < RATE_INVALID_KINDS ? names[kind] : "?";
}
