/* Built-in self-test: a known force on the sense resonance through the sense feedback
 * electrodes (spare DAC channel), and a check that the rate channel answers it as it
 * did when the part was calibrated, as commercial gyros do at power-on or on command.
 *
 * The force is put in phase with the drive velocity - the phase of the Coriolis force
 * (2-22) - using the drive phase the loop holds (drive.phase_set_deg), so the response
 * lands on the rate axis of the calibrated demodulation: u = A cos(phi + theta_set),
 * with the differential electrodes' force 4 Ks_fb V_bias u. The test runs only while
 * LOCKED: a baseline of the unfiltered rate over BASE blocks, then the force, SETTLE
 * blocks for the sense resonance and the output path, the response over MEAS blocks, and the
 * force off. A block is the rate channel's (RATE_DECIM ticks): the sequence advances
 * once per block on the block's unfiltered rate (selftest_update), while the force is a
 * carrier and is formed every tick (selftest_force). Pass: |response / expected - 1| <=
 * tolerance. The rate output carries the test force while it runs (GYRO_FLAG_SELFTEST).
 *
 * Continuous self-test (cont_on), as current digital gyros run while operating: the same
 * carrier force, amplitude-modulated at cont_freq, well above the rate's output band:
 *     u = A_c cos(2 pi f_m t) cos(phi + theta_set)
 * Demodulated, its response is a tone at f_m on the block's rate and quadrature (the
 * sense resonance answers the two sidebands wc +- 2 pi f_m a little differently, hence some
 * on both axes). A two-weight LMS per axis at f_m (the LMS demodulator of (5-5), at the
 * block rate) measures the tone and subtracts it before the output filters: an adaptive
 * notch, so that no tone is left in the output (the 100 Hz Butterworth alone leaves
 * -32 dB of it at 250 Hz). The response's magnitude is the test: outside
 * (1 +- tol_rel) of the expected after the LMS has converged, the rate is not valid
 * (rate_valid.h, CONT_SELFTEST). Expected responses are calibration values measured at
 * the drive amplitude setpoint ref_amp_v: the rate channel normalises by the setpoint,
 * so a response in deg/s scales as ref_amp_v / amp_set_v (the designer applies it to
 * both tests).
 *
 * With force rebalance (sense.mode 1) the feedback electrodes carry the loop's force, so
 * the continuous test's force goes into the loop's command instead, A_c cos(2 pi f_m t)
 * on its Coriolis axis (cont_fr_v2, in the command's V^2; gyro_fr_mag): the loop cancels
 * it as it cancels the Coriolis force, and its readout carries the tone as a rate (its
 * closed-loop response at f_m, about a third at 250 Hz against the loop's 145), which
 * the same LMS measures and takes out. It proves the loop alive end to end: a dead sense
 * pickoff leaves the residual at zero, the loop "balanced" and its readout frozen, and
 * the tone then vanishes (test_cl_sense_fr.c), so force rebalance always runs it
 * (whatever cont_on's parameter says: gyro_design.c). Its expectation is the loop
 * model's (sense_fr_tone_gain), not a calibration's, and the rate waits cont_gate_blocks
 * after LOCKED for the notch: the loop's 500 Hz output filter passes the tone. It cannot
 * check the feedback's scale: the test force goes through the same electrodes as the
 * loop's, so a change of their gain scales the force and its cancellation alike.
 */
#ifndef SELFTEST_H
#define SELFTEST_H

#include <stdint.h>

/* Low-pass of the continuous test's weights before they are judged, per block: about
 * 2 Hz at the 5 kHz block rate. */
#define SELFTEST_CONT_AVG_K 0.0025f

typedef enum {
  SELFTEST_IDLE = 0,
  SELFTEST_BASE = 1,
  SELFTEST_FORCE = 2,
  SELFTEST_PASS = 3,
  SELFTEST_FAIL = 4,
  SELFTEST_ABORTED = 5 /* lock lost while testing */
} selftest_state_t;

typedef struct {
  float amp_v;              /* force voltage amplitude A on the spare DAC channel */
  uint32_t cont_on;         /* continuous self-test (always with force rebalance) */
  float cont_amp_v;         /* its force amplitude A_c */
  float cont_fr_v2;         /* force rebalance: A_c in the loop's command (V^2), 0 open loop */
  uint32_t cont_step;       /* its modulation's phase step per block (2^32 per turn) */
  float cont_mu;            /* its LMS step size per block */
  float cont_gain;          /* 1 - mu / 2: the notch's pass-band gain undone */
  float cont_lo2, cont_hi2; /* bounds of the response's squared magnitude (raw rate units) */
  float cont_expect;        /* the response expected (raw rate units; status) */
  uint32_t cont_settle_blocks; /* blocks LOCKED before the response is judged */
  uint32_t cont_gate_bits;     /* the rate's reasons for the first cont_gate_blocks LOCKED:
                                * where the output band passes the tone (force
                                * rebalance's), the notch must have converged before the
                                * rate is valid; 0 elsewhere */
  uint32_t cont_gate_blocks;
  float expect_dps;   /* response expected on the rate axis (calibrated on the part) */
  float tol_rel;      /* pass band, relative */
  float ref_c, ref_s; /* cos, sin of the drive phase setpoint */
  float scale_dps;    /* rate channel scale: deg/s per unit of the unfiltered rate */
  uint32_t base_blocks, settle_blocks, meas_blocks;
  /* Derived (selftest_cfg_derive): 1 / base_blocks, 1 / meas_blocks, 1 / expect_dps (0
   * where the divisor is 0), so that the verdict's block divides nothing (its tick's
   * budget). */
  float inv_base, inv_meas, inv_expect;
} selftest_cfg_t;

typedef struct {
  uint32_t state;           /* selftest_state_t */
  uint32_t count;           /* blocks in the current state */
  float acc_base, acc_meas; /* sums of the unfiltered rate */
  float result_dps;         /* measured response of the last test */
  uint32_t runs;
  /* The force formed every tick: a_c cos(phi) - a_s sin(phi), set once per block. */
  uint32_t force_on;
  float a_c, a_s;
  /* Continuous self-test. */
  uint32_t cont_phase;       /* modulation phase */
  float cont_c, cont_s;      /* cos, sin of the modulation of the current block */
  float w[4];                /* LMS weights: rate (cos, sin), quadrature (cos, sin) */
  float w_avg[2];            /* the rate axis's weights through SELFTEST_CONT_AVG_K */
  uint32_t cont_blocks;      /* blocks LOCKED since the LMS started */
  uint32_t cont_fail;        /* the response is judged and out of its band */
  uint32_t cont_settle_bits; /* cfg's cont_gate_bits while the notch converges, else 0 */
} selftest_t;

/* The derived fields of cfg from the others (background). */
void selftest_cfg_derive(selftest_cfg_t *cfg);
void selftest_init(const selftest_cfg_t *cfg, selftest_t *st);
/* A new configuration takes over from old (a design change): a running test carries on;
 * the continuous test's LMS starts again when its tone changed or it was switched. */
void selftest_reconfigure(const selftest_cfg_t *old, const selftest_cfg_t *cfg, selftest_t *st);
/* Start a test (ignored while one runs). Its force comes on after the baseline
 * (selftest_update). */
void selftest_start(selftest_t *st);
/* Once per block: locked = drive LOCKED, rate_raw = the rate channel's unfiltered
 * rate of the block. */
void selftest_update(const selftest_cfg_t *cfg, selftest_t *st, int locked, float rate_raw);

static inline int selftest_running(const selftest_t *st)
{
  return st->state == SELFTEST_BASE || st->state == SELFTEST_FORCE;
}

/* Every tick while force_on: the spare DAC voltage, (sin_wc, cos_wc) the NCO references:
 * A cos(phi + theta_set), in phase with the drive velocity (gyro.h phasor convention:
 * the velocity of y = Im{Z e^{j phi}} is Re{Z e^{j phi}}), A the on-demand test's
 * amplitude while it forces plus the continuous test's modulated one. */
static inline float selftest_force(const selftest_t *st, float sin_wc, float cos_wc)
{
  return st->a_c * cos_wc - st->a_s * sin_wc;
}

/* Once per block and axis (0 rate, 1 quadrature), on the block's projection (x, in
 * place) before its output filter: the continuous test's LMS measures its tone and takes
 * it out. Does nothing unless cont_on. Inline: it runs on ticks near their budget. */
static inline void selftest_cont_notch(const selftest_cfg_t *restrict c,
                                       selftest_t *restrict st, uint32_t axis, float *x)
{
  if (c->cont_on == 0u) return;
  /* (5-5) at f_m: the weights' phasor is the tone; the error is the notched signal. */
  const float mc = st->cont_c, ms = st->cont_s, mu = c->cont_mu;
  float *w = &st->w[2u * axis];
  const float e = *x - (w[0] * mc + w[1] * ms);
  w[0] += mu * e * mc;
  w[1] += mu * e * ms;
  /* The LMS with a sinusoidal reference is the notch (Widrow 1975)
   *   H(z) = (z^2 - 2 cos(w0) z + 1) / (z^2 - 2 (1 - C) cos(w0) z + 1 - 2 C),  C = mu / 2,
   * whose gain away from w0 (at DC and at the Nyquist frequency alike) is 1 / (1 - C):
   * 0.2 % of scale factor at mu = 0.004, undone here. */
  *x = e * c->cont_gain;
}
/* Once per block, after both axes' notch: the next block's modulation and force. */
void selftest_cont_advance(const selftest_cfg_t *cfg, selftest_t *st);
/* Once per block: judge the continuous test's response (locked: drive LOCKED; the
 * judgement restarts with the LMS when not). Returns cont_fail. */
uint32_t selftest_cont_judge(const selftest_cfg_t *cfg, selftest_t *st, int locked);

const char *selftest_state_name(uint32_t state);

#endif /* SELFTEST_H */
