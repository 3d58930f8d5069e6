/* Supervisor: operating modes and faults of the gyro.
 *
 *   OFF -> (start) -> ACQUIRE -> (amplitude and phase inside tolerance for lock_hold_s)
 *   -> LOCKED -> (amplitude outside lost tolerance for lost_hold_s: LOST_LOCK; phase
 *   error beyond lost_phase_tol for lost_hold_s: PHASE_LOST; the amplitude loop pinned
 *   at the drive limit for sat_hold_s: DRIVE_SAT) -> FAULT
 *   ACQUIRE -> FAULT (ACQ_TIMEOUT) when lock is not reached within acq_timeout_s, a time
 *   the designer derives from the drive resonance's time constant and the loop bandwidths: a part
 *   the loops cannot hold (resonance out of reach, drive pinned at its limit, a
 *   setpoint the drive cannot reach) faults instead of acquiring for ever.
 *   ACQUIRE or LOCKED -> FAULT (FREQ_WINDOW) when the tracking drive's frequency stays at
 *   the edge of its window (drive_track.h) for lost_hold_s: the resonance is outside it.
 *   any mode -> FAULT at once on: over-amplitude (above amp_trip_rel times the setpoint,
 *   or above amp_max_v, an absolute level the ADC can still measure: structure
 *   protection whatever the setpoint), drive ADC clipping (clip_max_count rail codes
 *   within a window of GYRO_CLIP_WINDOW supervisor steps), a non-finite value in the loop state,
 *   a lost sample (the NCO's phase then no longer matches the converters').
 *   FAULT: drive off for retry_s (the drive resonance rings down with tau = 2Q/wn), loop state
 *   cleared, then ACQUIRE again by itself. SWEEP belongs to self-calibration.
 * Lock is judged on the amplitude and phase errors low-passed at about 100 Hz: the
 * demodulated drive amplitude carries the residue of the drive-voltage feedthrough at
 * wc/2 (an LMSD of a few hundred Hz bandwidth passes part of a 745 Hz offset) and of
 * the pickoff noise, which would otherwise break the count of consecutive blocks.
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
  GYRO_FAULT_OVER_AMP = 1u << 4,
  GYRO_FAULT_PHASE_LOST = 1u << 5,
  GYRO_FAULT_ACQ_TIMEOUT = 1u << 6,
  GYRO_FAULT_LOST_SAMPLE = 1u << 7,
  GYRO_FAULT_FREQ_WINDOW = 1u << 8
} gyro_fault_t;
#define GYRO_FAULT_KINDS 9u

/* Supervisor steps (blocks) over which rail codes are counted against clip_max_count:
 * 2 ms, about three carrier cycles, so that a waveform clipped only at its peaks (a
 * few codes per cycle, never a long run) is seen as well as a rail held. */
#define GYRO_CLIP_WINDOW 10u

typedef struct {
  float dt_s;
  float lock_tol_rel, lock_phase_tol_rad, lock_hold_s;
  float lost_tol_rel, lost_hold_s;
  float lost_phase_tol_rad;
  float amp_trip_rel;
  float amp_max_v; /* absolute over-amplitude trip, V of drive pickoff */
  float amp_set_v; /* the setpoint amp_trip_rel multiplies */
  float acq_timeout_s;
  float sat_hold_s;
  float retry_s;
  uint32_t clip_max_count;
  /* Derived (supervisor_cfg_derive): the times in supervisor steps (blocks), the lock
   * errors' low-pass and the one relative over-amplitude trip the sample path uses. */
  uint32_t lock_hold_blocks, lost_hold_blocks, sat_hold_blocks, retry_blocks, acq_timeout_blocks;
  float err_lpf_k;        /* first-order low-pass (~100 Hz) of the lock errors, per step */
  float amp_trip_min_rel; /* min(amp_trip_rel A_set, amp_max_v) / A_set */
} supervisor_cfg_t;

typedef struct {
  gyro_mode_t mode;
  uint32_t fault;           /* reason of the current/last fault (gyro_fault_t bits), shown
                            * until cleared (supervisor_clear_fault) */
  uint32_t fault_count;     /* faults since power-on */
  uint32_t last_fault;      /* history: reason of the latest fault, kept by a clear */
  uint32_t last_fault_step; /* steps count when it tripped */
  uint32_t clip_window[GYRO_CLIP_WINDOW]; /* rail codes of the last steps */
  uint32_t clip_sum, clip_pos;
  uint32_t steps; /* supervisor steps since power-on (the fault history's clock) */
  uint32_t kind_count[GYRO_FAULT_KINDS];     /* faults of each kind (bit n of gyro_fault_t) */
  uint32_t kind_last_step[GYRO_FAULT_KINDS]; /* step of each kind's latest fault */
  uint32_t in_tol_blocks;                    /* consecutive steps inside lock tolerance */
  uint32_t out_tol_blocks;   /* consecutive steps outside lost tolerance while LOCKED */
  uint32_t out_phase_blocks; /* consecutive steps beyond the lost phase tolerance */
  uint32_t sat_blocks;       /* consecutive steps with the drive at its limit */
  uint32_t win_blocks;       /* consecutive steps with the frequency at its window's edge */
  uint32_t fault_blocks;     /* steps spent in FAULT */
  uint32_t mode_blocks;      /* steps spent in the current mode (ACQUIRE: since the end of
                            * a setpoint move, the acquisition timeout's clock) */
  float amp_err_f, phase_err_f;
  uint32_t primed;    /* the low-pass starts from the first error seen in a mode */
  uint32_t clear_req; /* set whenever supervisor_step returns 1, for a caller that
                            * acts on it later; the caller clears it */
} supervisor_t;

/* What one block saw, for the supervisor to judge. */
typedef struct {
  float amp_rel_err; /* (A - A_set) / A_set */
  float amp_rel;     /* A / A_set */
  float phase_err_rad;
  int drive_at_limit;  /* amplitude PI pinned at its maximum */
  int freq_at_limit;   /* the tracking drive's frequency at its window's edge */
  uint32_t clip_count; /* drive-channel ADC rail codes since the last step */
  int state_finite;    /* every loop state value finite */
  int sample_lost;     /* a sample was lost since the last step */
  int setpoint_moving; /* the amplitude setpoint is slewing to a new value (drive_loop.h):
                        * acquisition is timed from the end of the move */
} supervisor_in_t;

/* Check cfg and fill in its derived fields (background). Returns 0, or -1 for a bad
 * configuration. */
int supervisor_cfg_derive(supervisor_cfg_t *cfg);

/* OFF, no fault, counts cleared. A new configuration needs nothing: mode, fault record
 * and running counts carry on under the new thresholds. */
void supervisor_init(supervisor_t *sv);

/* Requests from the application (background loop or CLI). */
void supervisor_start(supervisor_t *sv);
void supervisor_stop(supervisor_t *sv);
void supervisor_enter_sweep(supervisor_t *sv);
/* LOCKED -> ACQUIRE (e.g. a new setpoint): lock is declared again once inside tolerance. */
void supervisor_reacquire(supervisor_t *sv);
/* The operator has seen the fault: no longer shown as active (fault = none); the mode is
 * untouched and last_fault / last_fault_step keep the record. */
void supervisor_clear_fault(supervisor_t *sv);

/* One step (once per block). Returns 1 when the loop state must be cleared (entering
 * FAULT or leaving it to re-acquire), else 0; a 1 is also latched in clear_req. */
int supervisor_step(const supervisor_cfg_t *cfg, supervisor_t *sv, const supervisor_in_t *in);

static inline int supervisor_drive_enabled(const supervisor_t *sv)
{
  return sv->mode == GYRO_MODE_ACQUIRE || sv->mode == GYRO_MODE_LOCKED;
}

#endif /* SUPERVISOR_H */
