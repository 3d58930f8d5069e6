#include "gyro/supervisor.h"

#include <stddef.h>

#include "dsp/fastmath.h"

static uint32_t ticks_of(float t_s, float dt_s)
{
  const float n = t_s / dt_s + 0.5f;
  return n < 1.0f ? 1u : (uint32_t)n;
}

int supervisor_init(supervisor_t *sv, const supervisor_cfg_t *cfg)
{
  if (sv == NULL || cfg == NULL || !(cfg->dt_s > 0.0f) || !(cfg->lock_tol_rel > 0.0f) ||
      !(cfg->lost_tol_rel >= cfg->lock_tol_rel) || !(cfg->lock_phase_tol_rad > 0.0f) ||
      !(cfg->amp_trip_rel > 1.0f + cfg->lost_tol_rel) || !(cfg->lock_hold_s >= 0.0f) ||
      !(cfg->lost_hold_s >= 0.0f) || !(cfg->sat_hold_s >= 0.0f) || !(cfg->retry_s >= 0.0f) ||
      !(cfg->lock_hold_s < 1e4f && cfg->lost_hold_s < 1e4f && cfg->sat_hold_s < 1e4f &&
        cfg->retry_s < 1e4f) ||
      cfg->clip_max_count == 0u) {
    return -1;
  }
  sv->mode = GYRO_MODE_OFF;
  sv->primed = 0u;
  sv->clear_req = 0u;
  sv->amp_err_f = sv->phase_err_f = 0.0f;
  sv->fault = GYRO_FAULT_NONE;
  sv->fault_count = 0u;
  sv->last_fault = GYRO_FAULT_NONE;
  sv->last_fault_step = sv->steps = 0u;
  sv->in_tol_ticks = sv->out_tol_ticks = sv->sat_ticks = 0u;
  sv->fault_ticks = sv->mode_ticks = 0u;
  supervisor_retune(sv, cfg);
  return 0;
}

void supervisor_retune(supervisor_t *sv, const supervisor_cfg_t *cfg)
{
  /* 100 Hz first-order low-pass: k = 1 - exp(-2 pi 100 dt) ~ 2 pi 100 dt. */
  sv->err_lpf_k = fm_clampf(628.3185f * cfg->dt_s, 1e-6f, 1.0f);
  sv->lock_ticks_needed = ticks_of(cfg->lock_hold_s, cfg->dt_s);
  sv->lost_ticks_needed = ticks_of(cfg->lost_hold_s, cfg->dt_s);
  sv->sat_ticks_needed = ticks_of(cfg->sat_hold_s, cfg->dt_s);
  sv->retry_ticks = ticks_of(cfg->retry_s, cfg->dt_s);
  sv->clip_max_count = cfg->clip_max_count;
  sv->lock_tol_rel = cfg->lock_tol_rel;
  sv->lock_phase_tol_rad = cfg->lock_phase_tol_rad;
  sv->lost_tol_rel = cfg->lost_tol_rel;
  sv->amp_trip_rel = cfg->amp_trip_rel;
}

static void set_mode(supervisor_t *sv, gyro_mode_t m)
{
  sv->primed = 0u;
  sv->mode = m;
  sv->mode_ticks = 0u;
  sv->in_tol_ticks = sv->out_tol_ticks = sv->sat_ticks = 0u;
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

static int trip(supervisor_t *sv, uint32_t reason)
{
  sv->fault = reason;
  sv->last_fault = reason;
  sv->last_fault_step = sv->steps;
  sv->fault_count++;
  sv->fault_ticks = 0u;
  set_mode(sv, GYRO_MODE_FAULT);
  sv->clear_req = 1u;
  return 1;
}

/* Which of the faults that act in every mode but OFF the evidence shows, in order of
 * precedence: NaN, clipping, over-amplitude (not in SWEEP); 0 for none. A NaN anywhere
 * would otherwise stay in the integrators forever; clipping makes the demodulated
 * amplitude meaningless. */
static uint32_t fault_seen(const supervisor_t *sv, const supervisor_in_t *in, gyro_mode_t mode)
{
  if (!in->state_finite) return GYRO_FAULT_NAN;
  if (in->clip_run >= sv->clip_max_count) return GYRO_FAULT_ADC_CLIP;
  if (mode != GYRO_MODE_SWEEP && in->amp_rel > sv->amp_trip_rel) return GYRO_FAULT_OVER_AMP;
  return GYRO_FAULT_NONE;
}

/* ACQUIRE and LOCKED: the fault checks, the low-pass of the lock errors and the lock
 * decisions. The common path of the sample interrupt, kept straight. */
static int step_driving(supervisor_t *sv, const supervisor_in_t *in, gyro_mode_t mode)
{
  const uint32_t f = fault_seen(sv, in, mode);
  if (f != GYRO_FAULT_NONE) {
    return trip(sv, f);
  }
  /* The low-pass starts from the first error of a mode (whatever it held before, a NaN
   * included, is dropped). */
  float ea = in->amp_rel_err, ep = in->phase_err_rad;
  if (sv->primed != 0u) {
    ea = sv->amp_err_f + sv->err_lpf_k * (ea - sv->amp_err_f);
    ep = sv->phase_err_f + sv->err_lpf_k * (ep - sv->phase_err_f);
  }
  sv->primed = 1u;
  sv->amp_err_f = ea;
  sv->phase_err_f = ep;
  const float ae = fm_absf(ea);
  if (mode == GYRO_MODE_LOCKED) {
    sv->out_tol_ticks = (ae > sv->lost_tol_rel) ? sv->out_tol_ticks + 1u : 0u;
    sv->sat_ticks = in->drive_at_limit ? sv->sat_ticks + 1u : 0u;
    if (sv->out_tol_ticks >= sv->lost_ticks_needed) return trip(sv, GYRO_FAULT_LOST_LOCK);
    if (sv->sat_ticks >= sv->sat_ticks_needed) return trip(sv, GYRO_FAULT_DRIVE_SAT);
  } else {
    const float pe = fm_absf(ep);
    sv->in_tol_ticks = (ae <= sv->lock_tol_rel && pe <= sv->lock_phase_tol_rad)
                           ? sv->in_tol_ticks + 1u : 0u;
    if (sv->in_tol_ticks >= sv->lock_ticks_needed) {
      set_mode(sv, GYRO_MODE_LOCKED);
    }
  }
  return 0;
}

int supervisor_step(supervisor_t *sv, const supervisor_in_t *in)
{
  const gyro_mode_t mode = sv->mode;
  sv->mode_ticks++;
  sv->steps++;
  if (mode == GYRO_MODE_ACQUIRE || mode == GYRO_MODE_LOCKED) {
    return step_driving(sv, in, mode);
  }
  if (mode == GYRO_MODE_FAULT) {
    if (++sv->fault_ticks >= sv->retry_ticks) {
      set_mode(sv, GYRO_MODE_ACQUIRE);
      sv->clear_req = 1u;
      return 1;
    }
    return 0;
  }
  if (mode == GYRO_MODE_SWEEP) {
    /* No lock errors to judge (the loops are off; the low-pass restarts with the next
     * mode): only the faults. */
    const uint32_t f = fault_seen(sv, in, mode);
    if (f != GYRO_FAULT_NONE) {
      return trip(sv, f);
    }
  }
  return 0; /* OFF */
}
