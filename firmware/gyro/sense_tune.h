/* Mode tuning (sense.tune): the sense resonance put at the drive's (1, matched) or at the
 * drive's plus a chosen split (2), by a DC voltage Vt on the tuning electrodes.
 *
 * The electrodes soften the sense spring (a parallel-plate pair, 6-3): ws^2 = ws0^2 -
 * ke Vt^2, ke >= 0, so tuning only lowers the sense resonance: a part whose sense mode is
 * at or below the target (the drive's resonance, plus the split) cannot be tuned there.
 * The voltage for a target wt is
 *     Vt^2 = (ws0^2 - wt^2) / ke.
 * Self-calibration (selfcal.h, S4) finds it on the part: the untuned resonance ws0 (S1),
 * the slope ke (S2), then ring-downs at the predicted voltage until the free frequency is
 * within a fraction of the sense bandwidth of the target (or one DAC code's move, when
 * that is larger), ke refined by each (a secant on Vt^2). It stages the untuned resonance
 * (sense.cal_s0_hz), the refined slope (sense.cal_tune_ke_per_s2_per_v2) and the drive's
 * resonance they were measured against (sense.cal_tune_ref_hz); the force-rebalance model
 * (sense.f0_hz, sense.q, the feedback gain and phase) is measured with the tuning on.
 *
 * Over temperature both resonances move by the same factor (2-32: one material, one
 * Young's modulus), the electrostatic softening does not. With the drive's resonance
 * f_d(T) known, the untuned sense resonance follows as f_s0 f_d(T) / f_ref, and the
 * voltage is recomputed for the target at f_d(T): the hold needs the drive's resonance,
 * which the tracking drive (drive.track 1) follows; the fixed drive's frequency is a
 * constant, and with it the voltage stays at its calibrated value (a high-Q sense mode
 * is a vacuum part, whose drive is tracked). Matched, the hold is Vt(T) = Vt_ref f_d(T) /
 * f_ref exactly; a split adds a small term. What the law does not know (the two modes'
 * tempcos differing, the gap's expansion changing ke, a drifting electrode gain) is not
 * followed: the match is held only as well as the law holds, without a discriminator
 * that would measure it running (a pilot tone or the quadrature's phase).
 *
 * Background only (double precision); the voltage reaches the DAC through the
 * application's request (app.c), so the interrupt does nothing per sample for it. */
#ifndef SENSE_TUNE_H
#define SENSE_TUNE_H

#include <stdint.h>

#define SENSE_TUNE_OFF 0u
#define SENSE_TUNE_MATCHED 1u
#define SENSE_TUNE_SPLIT 2u

typedef struct {
  uint32_t mode;           /* SENSE_TUNE_* */
  double split_hz;         /* SPLIT: the sense resonance's target above the drive's */
  double v_max_v;          /* the tuning electrodes' limit; > 0 */
  double s0_hz;            /* the untuned sense resonance at ref_hz (0: not calibrated) */
  double ref_hz;           /* the drive's resonance it was measured against */
  double ke_per_s2_per_v2; /* the softening per V^2 (0: no electrodes) */
} sense_tune_cfg_t;

typedef enum {
  SENSE_TUNE_IS_OFF = 0,   /* mode OFF: 0 V */
  SENSE_TUNE_OK,           /* the voltage puts the sense resonance at the target */
  SENSE_TUNE_UNCALIBRATED, /* s0_hz, ref_hz or ke is 0: no sweep has calibrated it */
  SENSE_TUNE_BELOW,        /* the untuned resonance is at or below the target */
  SENSE_TUNE_LIMIT         /* it needs more than v_max (held at v_max) */
} sense_tune_state_t;

typedef struct {
  sense_tune_state_t state;
  double target_hz; /* the sense resonance aimed at */
  double s0_hz;     /* the untuned sense resonance at this drive frequency */
  double v_v;       /* the voltage to apply (0 unless OK or LIMIT) */
} sense_tune_out_t;

/* The voltage for the drive's resonance f_drive_hz (the hold above). A non-finite or
 * non-positive f_drive_hz is taken as ref_hz. */
void sense_tune_at(const sense_tune_cfg_t *c, double f_drive_hz, sense_tune_out_t *o);

/* The voltage that puts a resonance s0_hz (untuned) at target_hz with slope ke; -1 when
 * it cannot (target at or above s0, ke not positive, or not finite). */
double sense_tune_volts(double s0_hz, double target_hz, double ke_per_s2_per_v2);

/* "off", "ok", "uncalibrated", "below", "limit" for status. */
const char *sense_tune_state_name(sense_tune_state_t s);

#endif /* SENSE_TUNE_H */
