/* Rate validity: whether the rate output can be trusted, block by block.
 *
 * The rate is always computed; this verdict says whether to use it. It is valid only
 * when none of these reasons holds (each a bit of rate_valid_t.reasons, counted with the
 * step of its latest onset for `status`):
 *   MODE          the drive is not LOCKED (acquiring, sweeping, off, in a fault)
 *   SELFTEST      the self-test force is on the sense resonance
 *   SETTLING      the output filters have not settled since the last disturbance
 *                 (entering LOCKED, a change of the rate path's coefficients, the end
 *                 of a self-test, a rail code, a wrap of P): settled is measured, both
 *                 the rate and the quadrature filter outputs within tol_dps of a fast
 *                 low-pass of their inputs for RATE_VALID_SETTLE_BLOCKS blocks in a row;
 *                 once settled, the quadrature's difference beyond RATE_VALID_RING_TOLS
 *                 tolerances is a disturbance too (the sense mode ringing at the split)
 *   CLIP          an ADC rail code in the latest block (the demodulated phasors are
 *                 then wrong by an unknown amount)
 *   SENSE_RANGE   the sense pickoff amplitude above RATE_VALID_SENSE_FRAC of the ADC
 *                 range: a little more rate, quadrature or vibration clips it
 *   OVER_RANGE    |rate| above the full scale
 *   PHASE         the drive phase error, turned into rate through the quadrature it
 *                 rotates (Q sin(e), thesis §2.4.2 B), above tol_dps, or the phase
 *                 error beyond the lock tolerance
 *   THERMO_RANGE  the thermometer P_f outside the range its compensation holds for
 *   THERMO_SLEW   the thermometer moving faster than it was validated for
 *                 (p_slew_max), or so fast that P_f's low-pass lags it by more than
 *                 tol_dps of rate: a lag of P_f shifts the bias polynomial (slope x
 *                 lag; the rate reference follows P itself, rate_channel.h, so no
 *                 quadrature is rotated by it); and afterwards, while what such a move
 *                 left in the compensation's filters (comp_filters.h: P_c's lag, the
 *                 gradient term's high-pass) could still make more than tol_dps. A
 *                 shadow of those filters holds their error: it runs on the moves beyond
 *                 p_slew_max alone (a shock on the drive phase, not a temperature), so
 *                 the rate is invalid for as long as the move's own trace lasts: seconds
 *                 for a kick of a few tenths of a degree, nothing for a window P_f's
 *                 noise tipped over the cap in a ramp. After a move beyond
 *                 RATE_VALID_RESTART_CAPS caps (the loop pulling in after a setpoint
 *                 change) the filters restart instead, once P_f has come to rest (the
 *                 first window under the cap), and the shadow takes on what the restart
 *                 drops: the filters' content at the last P update with the checks
 *                 passed before the move (the gradient of a ramp in progress). (A
 *                 restart on any move beyond the cap, as before, left the rate valid
 *                 and 1 deg/s wrong for the gradient term's time constant.)
 *   THERMO_SETTLE P_f not yet at P after a hold (acquisition, a fault): how far it may
 *                 still be is known without noise from the weight w the held value
 *                 keeps in P_f, |P_f - P| = w / (1 - w) |P_held - P_f|, and the rate
 *                 error that makes as above
 *   CONT_SELFTEST the continuous self-test's response missing or out of its band
 *                 (selftest.h)
 *   TRACKING      the tracking drive runs (drive.track 1) on a calibration made with
 *                 the fixed drive (cal.ref_track 0): its reference, scale and compensation
 *                 are the fixed drive's, its thermometer p_eq is not the P they were
 *                 fitted on (measured valid, it read up to 28 deg/s wrong on a
 *                 self-calibrated Q 10^3 part at rest). The calibration flow calibrates
 *                 a part in the mode its sweep chose and records it (UNCALIBRATED too)
 *   UNCALIBRATED  the part has no calibration (cal.ref_freq_hz 0), or its calibration is
 *                 stale: made at another drive frequency than drive.freq_hz (a sweep, a
 *                 hand change), another phase setpoint, the other drive mode or another
 *                 mode tuning (cal.ref_tune_v against the tuning's voltage). The
 *                 demodulation phase and scale are a part's own; measured valid without
 *                 them, a 1300 Hz part read its rate with the sign inverted
 *   QUAD_NULL     quadrature nulling is on (quad.null 1) and its loop has not nulled the
 *                 quadrature: not running (not LOCKED yet), identifying its gain,
 *                 not yet within quad.settle_dps for quad.settle_s, at its electrodes'
 *                 limit (a quadrature they cannot reach), or its probe saw no effect of
 *                 the electrodes (none fitted or wired: they stay at 0 V). While the
 *                 quadrature moves by hundreds of deg/s, a demodulation phase error of
 *                 a tenth of a degree puts a moving deg/s into the rate
 *   SENSE_FR      force rebalance is on (sense.mode 1) and its loop has not balanced the
 *                 sense axis: not running (not LOCKED yet), its residual not yet within
 *                 sense.fr_settle_dps for sense.fr_settle_s, or its force at the
 *                 feedback electrodes' limit (a Coriolis or quadrature force they cannot
 *                 cancel: the force read as the rate is then not the Coriolis force)
 *   TUNE          mode tuning is on (sense.tune 1 or 2) and the sense resonance is not
 *                 at its target: not yet tuned (before LOCKED, before the background
 *                 applied the voltage), not calibrated (no sweep with sense.cal 1 has
 *                 tuned the part), or the target out of the electrodes' reach at this
 *                 temperature (below the untuned resonance, or beyond
 *                 sense.tune_v_max_v): the force-rebalance model, and open loop the
 *                 scale and demodulation phase, were measured on the tuned part; and with
 *                 force rebalance, the match lost: the lost-match monitor (sense_tune.h)
 *                 has no estimate yet after LOCKED (the continuous test's notch
 *                 converging, then two 0.1 s windows), or it finds the sense resonance
 *                 farther from the loop's model than the loop's tolerance (the detuning
 *                 that moves its placed roots by 5 % of its frequency): the law's
 *                 voltage no longer puts the resonance where the loop was designed for
 * Each check is a few multiplies and compares per block; no divide, no libm. */
#ifndef RATE_VALID_H
#define RATE_VALID_H

#include <stdint.h>

#include "gyro/comp_filters.h"
#include "gyro/rate_channel.h"

#define RATE_INVALID_MODE (1u << 0)
#define RATE_INVALID_SELFTEST (1u << 1)
#define RATE_INVALID_SETTLING (1u << 2)
#define RATE_INVALID_CLIP (1u << 3)
#define RATE_INVALID_SENSE_RANGE (1u << 4)
#define RATE_INVALID_OVER_RANGE (1u << 5)
#define RATE_INVALID_PHASE (1u << 6)
#define RATE_INVALID_THERMO_RANGE (1u << 7)
#define RATE_INVALID_THERMO_SLEW (1u << 8)
#define RATE_INVALID_THERMO_SETTLE (1u << 9)
#define RATE_INVALID_CONT_SELFTEST (1u << 10)
#define RATE_INVALID_TRACKING (1u << 11)
#define RATE_INVALID_UNCALIBRATED (1u << 12)
#define RATE_INVALID_QUAD_NULL (1u << 13)
#define RATE_INVALID_SENSE_FR (1u << 14)
#define RATE_INVALID_TUNE (1u << 15)
#define RATE_INVALID_BOARD_TEMP (1u << 16)
#define RATE_INVALID_KINDS 17u

/* Blocks in a row inside the settling tolerance (2 ms): longer than the noise's
 * correlation time at the filters' 100 Hz, far shorter than their settling. */
#define RATE_VALID_SETTLE_BLOCKS 10u
/* Once settled, the quadrature filter's difference from its reference with an rms
 * beyond this many tol_dps is a disturbance (settling again, SETTLING): the sense mode
 * ringing. Open loop, a lightly damped sense mode (Q 300, 10^4, a 110 Hz split) answers
 * a change of rate with its free response: after demodulation a phasor turning at the
 * split, decaying with tau = 2Q / w_sense (60 ms at Q 300, 2 s at 10^4), on both axes
 * alike. The rate's 100 Hz Butterworth passes a 110 Hz beat at 0.56, the 160 Hz
 * reference at 0.82 and 35 degrees of lag: their difference carries 1.4 times the beat,
 * 2.4 times what reaches the output, so an rms of 2 x 0.25 deg/s on the quadrature axis
 * is a ringing of 0.3 deg/s amplitude on the rate's, under the integrity rule's 1 deg/s.
 * Settling again needs the difference within tol_dps for RATE_VALID_SETTLE_BLOCKS, as at
 * any disturbance: the ringing is then below 0.2 deg/s on the output.
 * The quadrature axis alone is judged: a rate the part follows (a step, a sine in the
 * band) moves the rate axis, whose output lags its reference by the filter's delay (tens
 * of deg/s in a fast move), and such a lag is the band's, not an invalid rate. On a
 * clean part the quadrature's difference is its noise, wide-band (0.14 deg/s rms on the
 * default part, single blocks up to 0.58 deg/s in 4 s), and a slow move of the
 * quadrature (the drive amplitude still settling after the first lock), whence a mean
 * square rather than single blocks (a check of single blocks at 2 tol_dps tripped in the
 * start-up): the noise's mean square is 0.019 (deg/s)^2, its low-pass's largest value
 * 0.055-0.077 in 4 s over six noise seeds, under a third of the threshold's 0.25. */
#define RATE_VALID_RING_TOLS 2.0f
/* The mean square's low-pass per block: 64 blocks (12.8 ms). The difference's noise is
 * a band of 100-300 Hz, a few independent values in 3 ms: over 16 blocks its mean square
 * reached 7 times its mean in 4 s (0.14 against 0.019 (deg/s)^2), over 64 blocks 4 times
 * (0.077), under a third of the threshold. Short beside a ringing's decay (60 ms at Q
 * 300); and the step that starts a ringing puts its whole size on the difference at once
 * (100 deg/s of step: some 10^4 (deg/s)^2), so it trips within a block or two. */
#define RATE_VALID_RING_K 0.015625f
/* P_f updates over which its slew is judged (0.1 s at 500 Hz): a slew of the
 * temperature, not the noise of P_f. */
#define RATE_VALID_SLEW_UPDATES 50u
/* The slew is judged once the held value weighs less than this in P_f. */
#define RATE_VALID_SLEW_W_MAX 0.05f
/* Low-pass of the drive phase error for the PHASE check, per block: about 1 Hz, so
 * that the pickoff's noise on the measured phase (0.03 deg rms at 100 Hz on the
 * default part, which does not reach the rate: the rate channel references the
 * setpoint, not the measurement) is not taken for a lasting error of the true phase. */
#define RATE_VALID_PHASE_K 0.00126f
/* Low-pass of the filters' inputs the settling is judged against: per block, a time
 * constant of 5 blocks (1 ms, a corner of about 160 Hz), faster than the 100 Hz
 * output filter it checks. With another output filter (force rebalance's,
 * sense.fr_lpf_hz) the corner keeps that ratio, RATE_VALID_INPUT_RATIO times the
 * filter's (gyro_design): a reference much slower than the filter would read the noise
 * the wider filter passes as a transient, and the rate would never be judged settled. */
#define RATE_VALID_INPUT_K 0.2f
#define RATE_VALID_INPUT_RATIO 1.6f
/* With force rebalance the output's band (sense.fr_lpf_hz, hundreds of Hz) passes a
 * noise comparable to the tolerance (0.24 deg/s rms on the default part's noise at
 * 500 Hz), which the difference of filter and reference carries too: the difference is
 * judged through a low-pass of this corner, which leaves a filter transient (ms) and
 * takes the noise down by the root of the bands' ratio. */
#define RATE_VALID_SETTLE_DIFF_HZ 50.0
/* A window's move of P_f beyond this many caps restarts the compensation's filters:
 * what they would carry of it outweighs the gradient the restart drops. */
#define RATE_VALID_RESTART_CAPS 10.0f
/* Fraction of the ADC range the sense amplitude may use. */
#define RATE_VALID_SENSE_FRAC 0.8f

/* The shadow's state: the move left in P_f, P_c's stages' lags, the gradient term's input,
 * then the fast path's lag and gradient input (rate_channel.h; rows of 0 without one). */
#define RATE_VALID_SPUR_HP (COMP_STAGES_MAX + 1u)
#define RATE_VALID_SPUR_FAST_LAG (COMP_STAGES_MAX + 2u)
#define RATE_VALID_SPUR_FAST_HP (COMP_STAGES_MAX + 3u)
#define RATE_VALID_SPUR_N (COMP_STAGES_MAX + 4u)
#define RATE_VALID_SPUR_M (RATE_VALID_SPUR_N * (RATE_VALID_SPUR_N + 1u) / 2u)

typedef struct {
  float tol_dps; /* the largest rate error each source may leave */
  float full_scale_dps;
  float p_range_deg;            /* |x| the compensation holds for (rate_channel.h) */
  float p_window_max_deg;       /* largest change of P_f over RATE_VALID_SLEW_UPDATES updates */
  float p_lag_per_deg;          /* P_f's lag per degree of change over that window:
                             * its time constant / the window's length */
  float sense_max_v2;           /* (RATE_VALID_SENSE_FRAC x ADC full scale)^2 */
  float phase_tol_rad;          /* the lock tolerance of the drive phase */
  float bias_slope_dps_per_deg; /* |dB/dP| of the compensation over its range */
  float p_range_off_deg;        /* x = p_dev + this at P_f (rate_channel.h) */
  float grad_k_abs_dps_per_deg; /* |k| of the gradient term */
  float grad_fast_abs_dps_per_deg; /* |k| of the fast path's gradient term */
  float grad_a;                    /* the gradient term's 1 - exp(-T / tau) per P update */
  uint32_t fast_on;                /* the compensation has a fast path (comp_fast_a > 0) */
  float spur_m[RATE_VALID_SPUR_M]; /* the shadow's transition over a slew window */
  float settle_k;      /* the settling reference's low-pass per block (RATE_VALID_INPUT_K) */
  float settle_diff_k; /* the settling difference's low-pass per block, 1: none */
} rate_valid_cfg_t;

typedef struct {
  uint32_t reasons;       /* RATE_INVALID_* of the latest verdict */
  uint32_t thermo;        /* RATE_INVALID_THERMO_* of the latest P update */
  uint32_t drive;         /* RATE_INVALID_PHASE, _SENSE_RANGE of the latest block */
  uint32_t range;         /* RATE_INVALID_OVER_RANGE of the latest block */
  uint32_t settled;       /* nonzero once settled since the last disturbance */
  uint32_t settle_run;    /* blocks in a row inside the settling tolerance */
  uint32_t was_locked;    /* LOCKED at the previous verdict (entering it disturbs) */
  float x_rate, x_quad;   /* fast low-passes of the filters' inputs (raw units) */
  float d_rate, d_quad;   /* the settling differences, low-passed (settle_diff_k < 1), deg/s */
  float ring_ms;          /* the quadrature's difference's mean square (RATE_VALID_RING_K)
                           * since settled */
  float p_dev_window_deg; /* P_f - p_ref at the start of the slew window */
  uint32_t p_updates;     /* P_f updates into the slew window */
  uint32_t slew;          /* RATE_INVALID_THERMO_SLEW of the latest window */
  uint32_t slew_due;      /* a window ended: rate_valid_slew judges it */
  float p_window_change_deg;         /* change of P_f over the window that ended */
  float spur_deg[RATE_VALID_SPUR_N]; /* the shadow: the moves beyond the cap in P_f,
                                      * and in the compensation's filters (their mid
                                      * stages', P_f - P_c, the gradient term's input;
                                      * comp_filters.h), at the next window's end */
  uint32_t restart_armed;            /* a window's move beyond RATE_VALID_RESTART_CAPS caps */
  uint32_t displaced;                /* P_f moved as no temperature does, not back yet */
  uint32_t shadow_phase;             /* the shadow's job still to run (rate_valid_shadow):
                                      * 1..5, 0 none */
  float e_now_dps;                   /* the shadow's error at the judged window's end */
  float trend_p_deg;    /* P_f - p_ref where the temperature alone would have it: the
                           * latest passed window's end, carried on at its trend */
  float trend_step_deg; /* that trend per P update (the gradient term's input x grad_a) */
  float snap_lag_deg;   /* the compensation's filters at the latest window's end */
  float snap_mid_deg[COMP_STAGES_MAX - 1u];
  float snap_hp_deg;                         /* with the checks passed and no restart armed */
  float snap_fast_lag_deg, snap_fast_hp_deg; /* the fast path's, the same */
  uint32_t spur;           /* RATE_INVALID_THERMO_SLEW while the shadow's error is beyond tol */
  uint32_t filters_held;   /* the compensation's filters wait for P_f (comp_filters.h) */
  float phase_err_lp_rad;  /* the drive phase error through RATE_VALID_PHASE_K */
  uint32_t blocks;         /* verdicts since power-on */
  uint32_t onsets_pending; /* reasons that set in, not yet in the history */
  uint32_t onset_block;    /* the verdict that saw the latest of them */
} rate_valid_t;

/* The history of the reasons for `status`: written only when a reason sets in, so it
 * lives apart from the state the sample path reads every block (gyro_t keeps it last). */
typedef struct {
  uint32_t count[RATE_INVALID_KINDS];      /* onsets of each reason */
  uint32_t last_block[RATE_INVALID_KINDS]; /* block count of each reason's latest onset */
} rate_valid_history_t;

/* 1 when the configuration is one the monitors can run, else 0 (the designer checks). */
int rate_valid_cfg_ok(const rate_valid_cfg_t *cfg);
/* Start: not valid (MODE), nothing settled. Returns 0, or -1 (nothing changed) for a bad
 * configuration. */
int rate_valid_init(const rate_valid_cfg_t *cfg, rate_valid_t *rv);

/* The thermometer's checks start again as at power-on (rate_valid_init), with the rate
 * channel's own start from the reference (rate_channel_reset: a start of the drive from
 * OFF, a fault's clear): what they found about the P_f of before (a slew window, a move in
 * the shadow, a restart armed, a trend, THERMO_SLEW itself) is of a thermometer that
 * starts again from another value, and a THERMO_SLEW left standing would hold the
 * compensation's fast path out (rate_channel_fast_hold) for its settling after the new
 * lock. The verdict's history and the settling check are left alone (not LOCKED is MODE,
 * and entering LOCKED disturbs). */
void rate_valid_restart(rate_valid_t *rv);

/* The filters must settle again before the rate is valid. */
static inline void rate_valid_disturb(rate_valid_t *rv)
{
  rv->settled = 0u;
  rv->settle_run = 0u;
}

/* Once per block, after both output filters ran: (rate_raw, quad_raw) their inputs,
 * (rate_unc_dps, quad_dps) their outputs, scale_dps the scale between the two. */
void rate_valid_settling(const rate_valid_cfg_t *cfg, rate_valid_t *rv, float rate_raw,
                         float quad_raw, float rate_unc_dps, float quad_dps, float scale_dps);

/* At each new P_f (rate_channel_update_p): p_dev_deg = P_f - p_ref; p_held_dev_deg and
 * p_held_w where P_f's fast start began and the weight that value still has in P_f. */
void rate_valid_thermo(const rate_valid_cfg_t *cfg, rate_valid_t *rv, float p_dev_deg,
                       float p_held_dev_deg, float p_held_w);
/* On a tick after rate_valid_thermo ended a slew window (slew_due): THERMO_SLEW from the
 * window's change of P_f, the move into the shadow, its error at the window's end (apart
 * from the thermometer checks, so that no tick carries both). Returns 1 when the filters
 * must restart now (rate_channel_comp_restart). Sets shadow_phase: */
int rate_valid_slew(const rate_valid_cfg_t *cfg, rate_valid_t *rv);
/* on each of the next ticks with shadow_phase set, a part of the shadow's work, so that
 * none carries more than a few dozen instructions of it: (1) its error at the window's
 * end, judged (THERMO_SLEW beyond half the tolerance); (2) (3) (4) the window's
 * transition, its rows in three parts, and on (4) its verdict at both ends; (5) with
 * every check passed, the compensation's filters' content (rc: the slow path's lag, mids
 * and high-pass, the fast path's lag and high-pass) and P_f's trend, kept for what a
 * later move drops. */
void rate_valid_shadow(const rate_valid_cfg_t *cfg, rate_valid_t *rv, const rate_channel_t *rc);
/* The shadow's transition over RATE_VALID_SLEW_UPDATES P updates for the compensation's
 * filter weights comp_a, grad_a, its stages and the fast path's weight fast_a (0: none)
 * (rate_channel_cfg_t): lower triangular in the state (s, mid[0], mid[1], lag, hp,
 * fast lag, fast hp) (comp_filters.h; the row of a mid stage not in use, and the fast
 * path's without one, are 0), its rows packed in order (row i holds i + 1 entries).
 * Design time (double). */
void rate_valid_spur_matrix(float comp_a, float grad_a, uint32_t stages, float fast_a,
                            float m[RATE_VALID_SPUR_M]);

/* Once per block, after the quadrature filter: the drive phase error as the supervisor
 * low-passed it, the quadrature output and the squared sense pickoff amplitude ->
 * PHASE, SENSE_RANGE. */
void rate_valid_drive(const rate_valid_cfg_t *cfg, rate_valid_t *rv, float phase_err_rad,
                      float quad_dps, float sense_v2);

/* P_f jumped by shift_deg without a change of temperature (rate_channel_shift_p): the
 * slew window's start moves with it, or the jump would read as a slew. */
static inline void rate_valid_shift_p(rate_valid_t *rv, float shift_deg)
{
  rv->p_dev_window_deg += shift_deg;
  rv->trend_p_deg += shift_deg;
}

/* Once per block, after the rate's output filter: OVER_RANGE. */
static inline void rate_valid_range(const rate_valid_cfg_t *cfg, rate_valid_t *rv, float rate_dps)
{
  rv->range = (rate_dps <= cfg->full_scale_dps && rate_dps >= -cfg->full_scale_dps)
                  ? 0u
                  : RATE_INVALID_OVER_RANGE;
}

/* The onsets the verdict noted (onsets_pending) into the history, on a later, lighter
 * tick than the verdict's (the supervisor's; rare: only when the set of reasons grew).
 * Inline: the call would cost that tick as much as the counting. */
static inline void rate_valid_count_onsets(rate_valid_t *restrict rv, rate_valid_history_t *h)
{
  /* Only the bits that are set (usually one). */
  uint32_t onsets = rv->onsets_pending;
  rv->onsets_pending = 0u;
  while (onsets != 0u) {
    const uint32_t i = (uint32_t)__builtin_ctz(onsets);
    h->count[i]++;
    h->last_block[i] = rv->onset_block;
    onsets &= onsets - 1u;
  }
}

/* Once per block, last: the verdict (0: valid, else RATE_INVALID_* bits) from the
 * block's own evidence, block_bits (MODE, SELFTEST, CLIP, found by the caller), and what
 * rate_valid_drive, rate_valid_thermo, rate_valid_range and rate_valid_settling found.
 * Entering LOCKED and a rail code are disturbances. Integer work only: it runs on the
 * snapshot's tick. Onsets of reasons wait in onsets_pending for
 * rate_valid_count_onsets. */
static inline uint32_t rate_valid_verdict(rate_valid_t *rv, uint32_t block_bits)
{
  rv->blocks++;
  const uint32_t locked = (block_bits & RATE_INVALID_MODE) == 0u;
  if (locked > rv->was_locked || (block_bits & RATE_INVALID_CLIP) != 0u) {
    /* Entering LOCKED: the lasting phase error's low-pass starts from zero, not from
     * what acquisition left in it nor from the 100 Hz error's noise (at lock the phase
     * PI's integrator removes a lasting error within its own time constant, unless the
     * loop is at a dead end, which builds up here and in PHASE_LOST within tens of
     * milliseconds). */
    if (locked > rv->was_locked) rv->phase_err_lp_rad = 0.0f;
    rate_valid_disturb(rv);
  }
  rv->was_locked = locked;
  const uint32_t r = block_bits | rv->thermo | rv->drive | rv->range |
                     (rv->settled != 0u ? 0u : RATE_INVALID_SETTLING);
  const uint32_t onsets = r & ~rv->reasons;
  if (onsets != 0u) {
    rv->onsets_pending |= onsets;
    rv->onset_block = rv->blocks;
  }
  rv->reasons = r;
  return r;
}

const char *rate_valid_reason_name(uint32_t kind);

#endif /* RATE_VALID_H */
