/* Supervisor: operating modes and faults of the gyro.
 *
 *   OFF -> (start) -> ACQUIRE -> (amplitude and phase inside tolerance for lock_hold_s)
 *   -> LOCKED -> (outside lost tolerance for lost_hold_s, or the amplitude loop pinned
 *   at the drive limit for sat_hold_s) -> FAULT
 *   any mode -> FAULT at once on: over-amplitude (structure protection), ADC clipping
 *   (clip_max_count consecutive rail codes), a non-finite value in the loop state.
 *   FAULT: drive off for retry_s (the drive mode rings down with tau = 2Q/wn), loop state
 *   cleared, then ACQUIRE again by itself. SWEEP belongs to self-calibration.
 * Lock is judged on the amplitude and phase errors low-passed at about 100 Hz: the
 * demodulated drive amplitude carries the residue of the drive-voltage feedthrough at
 * wc/2 (an LMSD of a few hundred Hz bandwidth passes part of a 745 Hz offset) and of
 * the pickoff noise, which would otherwise break the consecutive-tick count.
 * The supervisor only decides; gyro_tick acts on its decisions. It steps once per block
 * of the gyro (dt_s = RATE_DECIM / fs, 0.2 ms): every threshold is a time, and a fault
 * is seen within one block.
 */
#ifndef SUPERVISOR_H
#define SUPERVISOR_H

#include <stdint.h>

typedef enum {
  GYRO_MODE_OFF = 0,
  GYRO_MODE_SWEEP = 1,
  GYRO_MODE_ACQUIRE = 2,
  GYRO_MODE_LOCKED = 3,
  GYRO_MODE_FAULT = 4
} gyro_mode_t;

/* Fault reasons, one bit each (the latched set is reported by `status`). */
typedef enum {
  GYRO_FAULT_NONE = 0u,
  GYRO_FAULT_ADC_CLIP = 1u << 0,
  GYRO_FAULT_NAN = 1u << 1,
  GYRO_FAULT_LOST_LOCK = 1u << 2,
  GYRO_FAULT_DRIVE_SAT = 1u << 3,
  GYRO_FAULT_OVER_AMP = 1u << 4
} gyro_fault_t;

typedef struct {
  float dt_s;
  float lock_tol_rel, lock_phase_tol_rad, lock_hold_s;
  float lost_tol_rel, lost_hold_s;
  float amp_trip_rel;
  float sat_hold_s;
  float retry_s;
  uint32_t clip_max_count;
} supervisor_cfg_t;

typedef struct {
  gyro_mode_t mode;
  uint32_t fault;          /* reason of the current/last fault (gyro_fault_t bits), shown
                            * until cleared (supervisor_clear_fault) */
  uint32_t fault_count;    /* faults since power-on */
  uint32_t last_fault;     /* history: reason of the latest fault, kept by a clear */
  uint32_t last_fault_step; /* steps count when it tripped */
  uint32_t steps;          /* supervisor_step calls since init (wraps after 9.9 days) */
  uint32_t lock_ticks_needed, lost_ticks_needed, sat_ticks_needed, retry_ticks;
  uint32_t clip_max_count;
  float lock_tol_rel, lock_phase_tol_rad, lost_tol_rel, amp_trip_rel;
  uint32_t in_tol_ticks;   /* consecutive ticks inside lock tolerance */
  uint32_t out_tol_ticks;  /* consecutive ticks outside lost tolerance while LOCKED */
  uint32_t sat_ticks;
  uint32_t fault_ticks;    /* ticks spent in FAULT */
  uint32_t mode_ticks;     /* ticks spent in the current mode */
  float err_lpf_k;         /* first-order low-pass (~100 Hz) of the lock errors */
  float amp_err_f, phase_err_f;
  uint32_t primed;         /* the low-pass starts from the first error seen in a mode */
  uint32_t clear_req;      /* set whenever supervisor_step returns 1, for a caller that
                            * acts on it later; the caller clears it */
} supervisor_t;

/* What one tick saw, for the supervisor to judge. */
typedef struct {
  float amp_rel_err;   /* (A - A_set) / A_set */
  float amp_rel;       /* A / A_set */
  float phase_err_rad;
  int drive_at_limit;  /* amplitude PI pinned at its maximum */
  uint32_t clip_run;   /* longest run of consecutive ADC rail codes (either channel)
                        * that reached into the period since the last step */
  int state_finite;    /* every loop state value finite */
} supervisor_in_t;

/* Returns 0, or -1 (nothing changed) for a bad configuration. */
int supervisor_init(supervisor_t *sv, const supervisor_cfg_t *cfg);

/* New thresholds and times; mode, fault record and running counts are kept. The cfg
 * must have passed supervisor_init once (the designer checks it). */
void supervisor_retune(supervisor_t *sv, const supervisor_cfg_t *cfg);

/* Requests from the application (background loop or CLI). */
void supervisor_start(supervisor_t *sv);
void supervisor_stop(supervisor_t *sv);
void supervisor_enter_sweep(supervisor_t *sv);
/* LOCKED -> ACQUIRE (e.g. a new setpoint): lock is declared again once inside tolerance. */
void supervisor_reacquire(supervisor_t *sv);
/* The operator has seen the fault: no longer shown as active (fault = none); the mode is
 * untouched and last_fault / last_fault_step keep the record. */
void supervisor_clear_fault(supervisor_t *sv);

/* One tick. Returns 1 when the loop state must be cleared (entering FAULT or leaving it
 * to re-acquire), else 0; a 1 is also latched in clear_req. */
int supervisor_step(supervisor_t *sv, const supervisor_in_t *in);

static inline int supervisor_drive_enabled(const supervisor_t *sv)
{
  return sv->mode == GYRO_MODE_ACQUIRE || sv->mode == GYRO_MODE_LOCKED;
}

#endif /* SUPERVISOR_H */
