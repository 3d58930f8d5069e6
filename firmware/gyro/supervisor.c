#include "gyro/supervisor.h"

#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"

static uint32_t blocks_of(float t_s, float dt_s)
{
  const float n = t_s / dt_s + 0.5f;
  return n < 1.0f ? 1u : (uint32_t)n;
}

int supervisor_cfg_derive(supervisor_cfg_t *cfg)
{
  if (cfg == NULL || !(cfg->dt_s > 0.0f) || !(cfg->lock_tol_rel > 0.0f) ||
      !(cfg->lost_tol_rel >= cfg->lock_tol_rel) || !(cfg->lock_phase_tol_rad > 0.0f) ||
      !(cfg->lost_phase_tol_rad >= cfg->lock_phase_tol_rad) ||
      !(cfg->amp_trip_rel > 1.0f + cfg->lost_tol_rel) || !(cfg->lock_hold_s >= 0.0f) ||
      !(cfg->amp_set_v > 0.0f) || !(cfg->amp_max_v > cfg->amp_set_v) ||
      !(cfg->acq_timeout_s > cfg->lock_hold_s) || !(cfg->acq_timeout_s < 1e4f) ||
      !(cfg->lost_hold_s >= 0.0f) || !(cfg->sat_hold_s >= 0.0f) || !(cfg->retry_s >= 0.0f) ||
      !(cfg->lock_hold_s < 1e4f && cfg->lost_hold_s < 1e4f && cfg->sat_hold_s < 1e4f &&
        cfg->retry_s < 1e4f) ||
      cfg->clip_max_count == 0u) {
    return -1;
  }
  /* 100 Hz first-order low-pass: k = 1 - exp(-2 pi 100 dt) ~ 2 pi 100 dt. */
  cfg->err_lpf_k = fm_clampf(628.3185f * cfg->dt_s, 1e-6f, 1.0f);
  cfg->lock_hold_blocks = blocks_of(cfg->lock_hold_s, cfg->dt_s);
  cfg->lost_hold_blocks = blocks_of(cfg->lost_hold_s, cfg->dt_s);
  cfg->sat_hold_blocks = blocks_of(cfg->sat_hold_s, cfg->dt_s);
  cfg->retry_blocks = blocks_of(cfg->retry_s, cfg->dt_s);
  cfg->acq_timeout_blocks = blocks_of(cfg->acq_timeout_s, cfg->dt_s);
  /* One relative trip for the sample path: the lower of the two limits. */
  const float abs_rel = cfg->amp_max_v / cfg->amp_set_v;
  cfg->amp_trip_min_rel = cfg->amp_trip_rel < abs_rel ? cfg->amp_trip_rel : abs_rel;
  return 0;
}

void supervisor_init(supervisor_t *sv)
{
  sv->mode = GYRO_MODE_OFF;
  sv->primed = 0u;
  sv->clear_req = 0u;
  sv->amp_err_f = sv->phase_err_f = 0.0f;
  sv->fault = GYRO_FAULT_NONE;
  sv->fault_count = 0u;
  sv->last_fault = GYRO_FAULT_NONE;
  sv->last_fault_step = 0u;
  sv->in_tol_blocks = sv->out_tol_blocks = sv->out_phase_blocks = sv->sat_blocks = 0u;
  sv->win_blocks = 0u;
  sv->fault_blocks = sv->mode_blocks = 0u;
  sv->clip_sum = sv->clip_pos = 0u;
  sv->steps = 0u;
  for (uint32_t i = 0; i < GYRO_CLIP_WINDOW; i++) sv->clip_window[i] = 0u;
  for (uint32_t i = 0; i < GYRO_FAULT_KINDS; i++)
    sv->kind_count[i] = sv->kind_last_step[i] = 0u;
}

GYRO_RAMFUNC static void set_mode(supervisor_t *restrict sv, gyro_mode_t m)
{
  sv->primed = 0u;
  sv->mode = m;
  sv->mode_blocks = 0u;
  sv->in_tol_blocks = sv->out_tol_blocks = sv->out_phase_blocks = sv->sat_blocks = 0u;
  sv->win_blocks = 0u;
}

void supervisor_start(supervisor_t *sv)
{
  if (sv->mode == GYRO_MODE_OFF) {
    set_mode(sv, GYRO_MODE_ACQUIRE);
  }
}

void supervisor_stop(supervisor_t *sv) { set_mode(sv, GYRO_MODE_OFF); }

void supervisor_enter_sweep(supervisor_t *sv) { set_mode(sv, GYRO_MODE_SWEEP); }

void supervisor_reacquire(supervisor_t *sv)
{
  if (sv->mode == GYRO_MODE_LOCKED) {
    set_mode(sv, GYRO_MODE_ACQUIRE);
  }
}

void supervisor_clear_fault(supervisor_t *sv) { sv->fault = GYRO_FAULT_NONE; }

GYRO_RAMFUNC static int trip(supervisor_t *restrict sv, uint32_t reason)
{
  sv->fault = reason;
  sv->last_fault = reason;
  sv->last_fault_step = sv->steps;
  sv->fault_count++;
  for (uint32_t i = 0; i < GYRO_FAULT_KINDS; i++) {
    if ((reason & (1u << i)) != 0u) {
      sv->kind_count[i]++;
      sv->kind_last_step[i] = sv->steps;
    }
  }
  sv->fault_blocks = 0u;
  set_mode(sv, GYRO_MODE_FAULT);
  sv->clear_req = 1u;
  return 1;
}

/* Rail codes over the last GYRO_CLIP_WINDOW steps (a running sum over a ring). */
GYRO_RAMFUNC static uint32_t clip_window_sum(supervisor_t *restrict sv, uint32_t count)
{
  const uint32_t pos = sv->clip_pos;
  sv->clip_sum += count - sv->clip_window[pos];
  sv->clip_window[pos] = count;
  sv->clip_pos = pos + 1u == GYRO_CLIP_WINDOW ? 0u : pos + 1u;
  return sv->clip_sum;
}

/* Which of the faults that act in every mode but OFF the evidence shows, in order of
 * precedence: NaN, lost sample, clipping, over-amplitude (not in SWEEP); 0 for none. A
 * NaN anywhere would otherwise stay in the integrators forever; a lost sample shifts
 * the NCO against the converters (one sample is 10.7 deg of carrier at 1490 Hz);
 * clipping makes the demodulated amplitude meaningless. */
GYRO_RAMFUNC static uint32_t fault_seen(const supervisor_cfg_t *restrict c,
                                        supervisor_t *restrict sv, const supervisor_in_t *in,
                                        gyro_mode_t mode)
{
  const uint32_t clips = clip_window_sum(sv, in->clip_count);
  if (!in->state_finite) return GYRO_FAULT_NAN;
  if (in->sample_lost) return GYRO_FAULT_LOST_SAMPLE;
  if (clips >= c->clip_max_count) return GYRO_FAULT_ADC_CLIP;
  if (mode != GYRO_MODE_SWEEP && in->amp_rel > c->amp_trip_min_rel) return GYRO_FAULT_OVER_AMP;
  return GYRO_FAULT_NONE;
}

/* ACQUIRE and LOCKED: the fault checks, the low-pass of the lock errors and the lock
 * decisions. The common path of the sample interrupt, kept straight. */
GYRO_RAMFUNC static int step_driving(const supervisor_cfg_t *restrict c,
                                     supervisor_t *restrict sv, const supervisor_in_t *in,
                                     gyro_mode_t mode)
{
  const uint32_t f = fault_seen(c, sv, in, mode);
  if (f != GYRO_FAULT_NONE) {
    return trip(sv, f);
  }
  /* The low-pass starts from the first error of a mode (whatever it held before, a NaN
   * included, is dropped). */
  float ea = in->amp_rel_err, ep = in->phase_err_rad;
  if (sv->primed != 0u) {
    ea = sv->amp_err_f + c->err_lpf_k * (ea - sv->amp_err_f);
    ep = sv->phase_err_f + c->err_lpf_k * (ep - sv->phase_err_f);
  }
  sv->primed = 1u;
  sv->amp_err_f = ea;
  sv->phase_err_f = ep;
  const float ae = fm_absf_cmp(ea); /* (both only compared) */
  const float pe = fm_absf_cmp(ep);
  sv->win_blocks = in->freq_at_limit ? sv->win_blocks + 1u : 0u;
  if (sv->win_blocks >= c->lost_hold_blocks) return trip(sv, GYRO_FAULT_FREQ_WINDOW);
  if (mode == GYRO_MODE_LOCKED) {
    /* Amplitude and phase each have their own count: a drive that holds its amplitude
     * while its phase has run off (a phase loop at a dead end) is not locked either. */
    sv->out_tol_blocks = (ae > c->lost_tol_rel) ? sv->out_tol_blocks + 1u : 0u;
    sv->out_phase_blocks = (pe > c->lost_phase_tol_rad) ? sv->out_phase_blocks + 1u : 0u;
    sv->sat_blocks = in->drive_at_limit ? sv->sat_blocks + 1u : 0u;
    if (sv->out_tol_blocks >= c->lost_hold_blocks) return trip(sv, GYRO_FAULT_LOST_LOCK);
    if (sv->out_phase_blocks >= c->lost_hold_blocks) return trip(sv, GYRO_FAULT_PHASE_LOST);
    if (sv->sat_blocks >= c->sat_hold_blocks) return trip(sv, GYRO_FAULT_DRIVE_SAT);
  } else {
    sv->in_tol_blocks = (ae <= c->lock_tol_rel && pe <= c->lock_phase_tol_rad)
                            ? sv->in_tol_blocks + 1u
                            : 0u;
    if (sv->in_tol_blocks >= c->lock_hold_blocks) {
      set_mode(sv, GYRO_MODE_LOCKED);
    } else if (in->setpoint_moving) {
      sv->mode_blocks = 0u;
    } else if (sv->mode_blocks >= c->acq_timeout_blocks) {
      /* Whatever held it back (the drive pinned at its limit included), acquisition
       * has taken longer than the loops' design allows. */
      return trip(sv, in->drive_at_limit ? GYRO_FAULT_DRIVE_SAT : GYRO_FAULT_ACQ_TIMEOUT);
    }
  }
  return 0;
}

GYRO_RAMFUNC int supervisor_step(const supervisor_cfg_t *restrict c, supervisor_t *restrict sv,
                                 const supervisor_in_t *in)
{
  const gyro_mode_t mode = sv->mode;
  sv->mode_blocks++;
  sv->steps++;
  if (mode == GYRO_MODE_ACQUIRE || mode == GYRO_MODE_LOCKED) {
    return step_driving(c, sv, in, mode);
  }
  if (mode == GYRO_MODE_FAULT) {
    if (++sv->fault_blocks >= c->retry_blocks) {
      set_mode(sv, GYRO_MODE_ACQUIRE);
      sv->clear_req = 1u;
      return 1;
    }
    return 0;
  }
  if (mode == GYRO_MODE_SWEEP) {
    /* No lock errors to judge (the loops are off; the low-pass restarts with the next
     * mode): only the faults. */
    const uint32_t f = fault_seen(c, sv, in, mode);
    if (f != GYRO_FAULT_NONE) {
      return trip(sv, f);
    }
  }
  return 0; /* OFF */
}
