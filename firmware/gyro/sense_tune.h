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
 * followed by the law: the lost-match monitor below measures, running, where the sense
 * resonance is, and makes the rate not valid when it has left the match.
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

/* The lost-match monitor (force rebalance, sense.mode 1, with tuning on; issue 19 item 5).
 * The continuous self-test's tone, a force on the loop's Coriolis axis (selftest.h), comes
 * out on the readout's quadrature axis too in proportion to the plant's detuning from the
 * model the loop was designed on (sense_fr_tone_cross): matched, the plant is its own
 * mirror image and the two axes do not mix. The ratio of the two axes' tones, each
 * measured by the test's LMS (selftest_t.w: rate, quadrature), less the model's ratio at
 * the model's pole c0, projected on the model's ratio per Hz of detuning u, is the
 * detuning in Hz:
 *     d = Re((r - c0) conj(u)) / |u|^2.
 * The projection keeps what the other causes of a ratio put across u out of it: a phase
 * error of the loop (the feedback's or the demodulation's) turns the ratio by 0.027 per
 * degree nearly at right angles to u (the model: 0.4 % of it along u).
 * Measured on the matched Q 1e4 part (test_cl_sense_tune.c, test_lost_match; the study
 * tests/slow/test_tune_disc_study.c out to 11.5 Hz and with the part's noise): 0.97 Hz
 * read per Hz of the plant's detuning (the model's u: 0.0059 of ratio per Hz); the
 * estimate off by -1.35 Hz at the match (-1.1 on a Q 300 part, -0.7 at a 20 Hz split:
 * what the model leaves out), its spread 0.05 Hz rms. That offset is the part's and the
 * tone's: the calibration flow measures the reading on the tuned part and stores it
 * (sense.tune_disc_zero_hz), which each reading is taken from. Its tolerance is the loop's, not
 * the half-bandwidth's (0.08 Hz at Q 1e4, under that model error): the detuning that
 * moves a root of the loop's placed pair by SENSE_TUNE_LOST_ROOT_FRAC of its natural
 * frequency (sense_fr_detune_tol_hz; 3.7 Hz for the matched part's model and the default
 * 145 Hz loop), beyond which the force-rebalance loop is no longer the one designed (its
 * step, its band, the continuous test's expectation were all placed on the model's
 * pole). It is conservative: measured, the step still settled to 1 % in 6.8 ms at
 * 5.75 and 11.5 Hz of detuning (7.0 ms matched). Background only: the ISR's LMS already measures
 * both tones; the windows, the ratio and the projection run in the application's
 * background (app_tune.c). */
#define SENSE_TUNE_LOST_ROOT_FRAC 0.05
/* Windows of the LMS weights' fit (s), and the estimate's low-pass over them (s): the
 * weights' own time constant is 0.1 s (selftest.h). */
#define SENSE_TUNE_DISC_WINDOW_S 0.1
#define SENSE_TUNE_DISC_TAU_S 0.5
/* Windows before the estimate counts as settled (the rate not valid before). */
#define SENSE_TUNE_DISC_SETTLE_WINDOWS 2u
/* The weights carry, besides the tone, a ripple at the modulation from whatever DC their
 * axis has (selftest_cont_judge): the notch's LMS turns a constant x into mu x /
 * (1 - e^(j w_m T)) e^(-j theta) on its weights, theta the modulation's phase. On the
 * quadrature axis with force rebalance that DC is the rebalanced quadrature (1500 deg/s:
 * a ripple of 19 deg/s against a tone of 0.7 deg/s there), on the rate axis the rate. A
 * mean over samples the background takes whenever it runs keeps an unknown part of it.
 * Each axis's weights, as a phasor W, are instead fitted over the window as W = T + C
 * e^(-j theta) with theta known for each sample (selftest_t.cont_phase): least squares,
 *     n T + conj(S) C = sum W,   S T + n C = sum W e^(j theta),   S = sum e^(j theta),
 * so T = (n sum W - conj(S) sum W e^(j theta)) / (n^2 - |S|^2), whatever the moments
 * the samples were taken at (a window whose phases do not spread, n^2 - |S|^2 under
 * SENSE_TUNE_DISC_MIN_SPREAD n^2, gives no estimate). */
#define SENSE_TUNE_DISC_MIN_SPREAD 0.25

typedef struct {
  uint32_t on;           /* force rebalance with tuning on and its continuous test */
  double c0_re, c0_im;   /* the model's ratio at its own pole */
  double u_re, u_im;     /* the ratio per Hz of detuning */
  double tol_hz;         /* |d| beyond this: the match is lost */
  uint32_t window_ticks; /* SENSE_TUNE_DISC_WINDOW_S in sample ticks */
  double k;              /* the estimate's low-pass per window */
  double zero_hz;        /* the reading on this part matched (sense.tune_disc_zero_hz) */
} sense_tune_disc_cfg_t;

typedef struct {
  double n;          /* samples in the window */
  double s_re, s_im; /* S = sum e^(j theta) */
  double sw[2][2];   /* per axis (rate, quadrature) sum W (re, im) */
  double swe[2][2];  /* per axis sum W e^(j theta) (re, im) */
  uint32_t t0;       /* tick of the window's start */
  uint32_t windows;  /* windows since the monitor started */
  double det_hz;     /* the detuning estimate d, low-passed */
  uint32_t lost;     /* |det_hz| > tol_hz */
} sense_tune_disc_t;

/* The monitor starts again (not settled): not LOCKED, the test's notch not converged, a
 * new design. */
void sense_tune_disc_reset(sense_tune_disc_t *s, uint32_t now_ticks);
/* One background pass with the test's weights w (selftest_t.w) and the modulation's
 * phase they go with (selftest_t.cont_phase), read together, at tick now_ticks. */
void sense_tune_disc_feed(const sense_tune_disc_cfg_t *c, sense_tune_disc_t *s,
                          const float w[4], uint32_t phase, uint32_t now_ticks);
/* Settled: enough windows for an estimate. */
static inline int sense_tune_disc_settled(const sense_tune_disc_t *s)
{
  return s->windows >= SENSE_TUNE_DISC_SETTLE_WINDOWS;
}

/* "off", "ok", "uncalibrated", "below", "limit" for status. */
const char *sense_tune_state_name(sense_tune_state_t s);

#endif /* SENSE_TUNE_H */
