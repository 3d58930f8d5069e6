/* Force rebalance of the sense mode (sense.mode 1): the sense phasor -> a feedback force
 * at the drive frequency that cancels the Coriolis (and quadrature) force, so that the
 * sense motion stays near zero and the rate is read from the force.
 *
 * The model (2-22), sense axis, per unit mass: x'' + (ws/Q) x' + ws^2 x = f_c + f_fb,
 * both forces at the carrier wc. In the rate channel's frame (rate_channel.h: R = S e^{-j
 * psi} / A_set, Coriolis on the real axis, quadrature on the imaginary) the envelope of a
 * mode driven at wc obeys, exactly for the linear mode,
 *     R'' + (2 j wc + ws/Q) R' + (ws^2 - wc^2 + j wc ws/Q) R = c (F + F_c)
 * whose slow root is p = -sigma + j (wd - wc), sigma = ws / (2Q), wd = sqrt(ws^2 -
 * sigma^2) (the other lies 2 wc away, outside every bandwidth here). So the sense mode is,
 * seen through the demodulator, a first-order complex plant
 *     R = g (-p) / (s - p) (F + F_c),   g = R per V^2 of feedback force at DC,
 * a pole turning at the split wd - wc and decaying at sigma: at Q = 10^4 and a 110 Hz
 * split the open loop rings at 110 Hz for seconds (issue 19's measurement). g is the
 * sense pickoff's static response to the feedback force (sense.fb_gain_v_per_v2, the
 * sense mode's gain at wc times the electrode's Ks_fb and the pickoff's) over A_set; its
 * sign and the force's phase against the Coriolis force (sense.fb_phase_deg) put a force
 * in the Coriolis direction on the real axis of R, a force in phase with the drive
 * displacement on the imaginary axis (the mapping is a complex scalar: the same mode and
 * pickoff carry both).
 *
 * The demodulator's LMS lag (pole at mu fs, lmsd.h) and the schedule's delay (the block
 * mean, the command's jobs, the DAC's latency and hold) add a lag, modelled as one pole
 * at a = 1 / (1 / (mu fs) + delay). The controller is a PI with complex gains on the
 * complex error R (a PI on each axis with cross-coupling), F = -(Kp R + Ki int R), and
 * pole placement puts the closed loop of the model
 *     s (s - p)(s + a) + g (-p) a (Kp s + Ki) = (s + c)(s^2 + 2 zeta w s + w^2)
 * at the designed natural frequency w (sense.fr_bw_hz) and damping zeta, c = a - p -
 * 2 zeta w the third root, which must lie in the left half plane: 2 zeta w < a + sigma
 * (the design refuses a w beyond the lag's reach). Every root is placed, the mode's own
 * pole included: the loop damps the ringing rather than cancelling it (a controller
 * zero on p would leave the 110 Hz ringing undamped in the sense motion, out of sight
 * of the force). The same design serves any split and Q: matched, the pole sits at
 * -sigma and the proportional path carries the loop; at a low Q (the thesis's 3) the
 * plant is fast already.
 *
 * The rate: in the steady state the force cancels the Coriolis force, F = -F_c, and the
 * open-loop rate channel would have read R_c = g F_c = -g F. The force itself, though,
 * answers a step of F_c through the controller's zero, Kp s + Ki: -Ki / Kp lies below
 * the placed roots (42 Hz against 130 Hz on a matched part, where the plant is nearly an
 * integrator), and -g F overshot a matched part's step by 25 % (test_cl_sense_tune.c).
 * The readout is instead g (I + Kr R) with Kr = Ki / c: in the steady state R = 0 and it
 * is -g F; in a transient its zero, Kr s + Ki, sits on the third root -c and cancels it,
 * so a step of the rate comes out through the placed pair (w, zeta) alone, at any split
 * (the 110 Hz split's step at 130 Hz: 9.4 ms with -g F, 8.0 with g I alone, 7.8 with
 * g (I + Kr R); 6.6 at the 145 Hz it allowed; measured in README). So
 * the channel's input in sense.mode 1 is that readout (rate_raw its real part, quad_raw
 * its imaginary part), and its scale
 * (rate.scale_dps), compensation and output filter apply as in open loop. The force
 * rebalance's scale factor is then rate.scale_dps g = Ks_fb / (2 A0 wc) per V^2 (the
 * sense mode's gain cancels between the two, measured on the same part): from then on it
 * no longer follows the sense resonance, only the electrode and the drive's momentum.
 * Its accuracy is that of the two identifications (g and the scale) at the temperature
 * they were made; the calibration flow refines rate.scale_dps on the closed loop.
 *
 * Limits: |F| <= f_max (the electrodes' voltage limit in the scheme used: v_max^2
 * half-frequency, 4 D (v_max - D) DC+AC); a force at the limit is scaled back along its
 * direction and the integrator held (F = -(Kp R + I) at the limit), at_limit set, and the
 * loop never counts as settled. Settled: |R_f| <= settle (the residual the loop has not
 * rebalanced, in R units, low-passed at a fifth of w) for settle_s without a break; the rate is not valid otherwise
 * (rate_valid.h, SENSE_FR).
 */
#ifndef SENSE_FR_H
#define SENSE_FR_H

#include <stdint.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"
#include "gyro/settle_count.h"

typedef struct {
  float bw_hz;       /* w / 2 pi, the closed loop's natural frequency; > 0 */
  float zeta;        /* its damping; > 0 */
  float f_sense_hz;  /* the sense resonance of the model; > 0 */
  float q_sense;     /* its quality factor; >= 0.5 */
  float f_drive_hz;  /* the carrier wc / 2 pi; > 0 */
  float gain_per_v2; /* g: R per V^2 of force in the Coriolis direction, static; != 0 */
  float lag_s;       /* 1 / a: the demodulator's and the schedule's lag; > 0 */
  float f_max_v2;    /* force limit; > 0 */
  float settle_r;    /* |R| below this (the residual, in R's units) counts as
                            balanced; > 0 */
  float settle_s;    /* for this long; >= 0 */
  float dt_s;        /* update period (a block); > 0 */
} sense_fr_cfg_t;

/* What the update uses, from sense_fr_design. */
typedef struct {
  float kp_re, kp_im;   /* Kp: V^2 per unit of R */
  float kit_re, kit_im; /* Ki T */
  float gain_per_v2;    /* g, for the readout g (I + Kr R) */
  float krg_re, krg_im; /* g Kr = g Ki / c: the readout's residual term */
  float f_max_v2, f_max2_v4;
  float settle2;  /* settle_r^2: |R_f|^2 below it counts */
  float settle_k; /* the residual's low-pass per update (sense_fr_settle) */
  uint32_t settle_blocks;
  /* What the design achieved, for status: the plant's pole p and the third root -c. */
  float p_re, p_im, c_re, c_im;
} sense_fr_design_t;

typedef struct {
  uint32_t run;         /* the loop is closed (LOCKED) */
  float e_re, e_im;     /* this update's residual R */
  float ef_re, ef_im;   /* its low-pass (the settling test) */
  float i_re, i_im;     /* the integral term Ki int R, V^2 */
  float f_re, f_im;     /* the force command in the frame of R, V^2 (after the limit) */
  float m2_v4;          /* |F|^2 before the limit */
  float out_re, out_im; /* g (I + Kr R): the rate channel's input (rate_raw, quad_raw) */
  uint32_t in_band;     /* consecutive updates with |R| <= settle */
  uint8_t settled;
  uint8_t at_limit;
  uint8_t skip; /* the update's measurement was not finite */
} sense_fr_t;

/* Validates cfg (every value finite and in its range; the third root c in the left half
 * plane) and derives the design. Returns 0, or -1 with *d unchanged. Background (double
 * precision, libm). */
int sense_fr_design(const sense_fr_cfg_t *cfg, sense_fr_design_t *d);

/* The continuous self-test's tone through the closed loop (selftest.h): a force
 * A cos(2 pi f t) added to the command on the Coriolis axis comes out of the readout's
 * real part (the rate axis) as a tone of amplitude A times this, in R units per V^2.
 * Y / T = g (Ki / s + Kr) G / (1 + G (Kp + Ki / s)): g at DC (the loop takes the whole
 * test force over), less above the loop's band. The design lumps the demodulator's lag
 * and the schedule's delay into one pole (lag_s); above the band that pole would cut the
 * tone where a delay only turns it (at 250 Hz against a 145 Hz loop the lumped model
 * read the tone 29 % low, at 800 Hz 59 %), so G here has them apart: the demodulator's
 * pole and a pure delay. -1 for a configuration sense_fr_design refuses, a frequency not
 * positive or a lag out of range. Background (double). */
typedef struct {
  double demod_pole_per_s; /* the LMS demodulator's pole, mu fs; > 0 */
  double delay_s;          /* the schedule's delay (the block mean, the jobs, the hold); >= 0 */
} sense_fr_lag_t;
double sense_fr_tone_gain(const sense_fr_cfg_t *cfg, const sense_fr_lag_t *lag, double f_hz);

/* The lost-match discriminator (sense_tune.h, sense_tune_disc_*): the same tone on the
 * Coriolis axis also comes out on the readout's imaginary part (the quadrature axis) when
 * the plant is not its own mirror image. A matched mode's envelope plant b / (s - p), p
 * real, commutes with conjugation and so does the loop designed on it: a real tone in, a
 * real tone out. Detuned by d, p = -sigma + j 2 pi d and the tone leaks into the
 * quadrature axis in proportion to d, with its sign; the ratio of the two axes' tones
 * (both measured by the continuous test's LMS) is then a frequency discriminator.
 * Two other parts of the loop are not mirror images either and set the ratio at the
 * match: the mode's second root, 2 wc away (the two sidebands wc +- w_m meet (ws + w) of
 * different size: +-8 % at 250 Hz around 1.49 kHz), and the demodulator's LMS, whose
 * update couples its estimate to its own conjugate at 2 wc (lmsd.h: the 2 wc ripple);
 * exactly, for W(n+1) = W + 2 mu e e^(-j wc n) with e = x - Re(W e^(j wc n)), an envelope
 * tone at w answers with
 *     L(w) = mu (1 - mu / D) / (e^(j w T) - 1 + mu - mu^2 / D),  D = e^(j (w + 2 wc) T) - 1 + mu.
 * Without them the model read a matched part 41 Hz off; with them 0.7-1.35 Hz (measured
 * on three parts, test_cl_sense_tune.c). cross = the quadrature axis's tone over the rate
 * axis's, both as phasors a - j b of their LMS weights (a cos + b sin), with the plant's
 * pole moved by det_hz from the model's, the LMS's mu = demod_pole_per_s / fs_hz. Returns
 * 0, or -1 as sense_fr_tone_gain refuses or for fs_hz not positive. Background (double). */
int sense_fr_tone_cross(const sense_fr_cfg_t *cfg, const sense_fr_lag_t *lag, double fs_hz,
                        double f_hz, double det_hz, double cross[2]);

/* The detuning (Hz, of the plant's pole from the model's) that moves a root of the placed
 * pair by frac of the loop's natural frequency w, to first order: with the plant b / (s -
 * p) (b = g (-p) fixed: the envelope equation's force coupling over the other root's
 * distance, 2 wc, which a detuning of a few Hz does not change),
 * the characteristic polynomial P(s) = s (s - p)(s + a) + b a (Kp s + Ki) moves with p by
 * dP/dp = -s (s + a), so a root r moves by dr = j r (r + a) / P'(r) per rad/s of
 * detuning. -1 for a configuration sense_fr_design refuses. Background (double). */
double sense_fr_detune_tol_hz(const sense_fr_cfg_t *cfg, double frac);

/* The loop open, its state and force at zero (not settled). */
void sense_fr_reset(sense_fr_t *fr);

/* One update on the block's projection (R = rate_raw + j quad_raw), as the steps below in
 * turn; the sample interrupt spreads them over the ticks of a block (gyro_block.c). */
void sense_fr_update(const sense_fr_design_t *d, sense_fr_t *fr, float r_re, float r_im);

/* The steps:
 *   take       the measurement (skip when not finite: the loop holds, not settled, the
 *              readout g I); the readout g (I + Kr R)
 *   integrate  Ki T R into the integral, F = -(Kp R + I)
 *   limit      |F| against f_max: scaled back along its direction, the integral held
 *   settle     the settling test
 * The synthesis takes F as it is, a phasor (drive_synth_set_phasor). */
GYRO_RAMFUNC static inline void sense_fr_take(const sense_fr_design_t *d, sense_fr_t *fr,
                                              float r_re, float r_im)
{
  const float g = d->gain_per_v2;
  fr->out_re = g * fr->i_re;
  fr->out_im = g * fr->i_im;
  if (!fm_isfinite(r_re + r_im)) {
    fr->skip = 1u;
    fr->in_band = 0u;
    fr->settled = 0u;
    return;
  }
  fr->out_re += d->krg_re * r_re - d->krg_im * r_im;
  fr->out_im += d->krg_re * r_im + d->krg_im * r_re;
  fr->skip = 0u;
  fr->e_re = r_re;
  fr->e_im = r_im;
}

GYRO_RAMFUNC static inline void sense_fr_integrate(const sense_fr_design_t *d, sense_fr_t *fr)
{
  const float er = fr->e_re, ei = fr->e_im;
  const float ir = fr->i_re + (d->kit_re * er - d->kit_im * ei);
  const float ii = fr->i_im + (d->kit_re * ei + d->kit_im * er);
  fr->i_re = ir;
  fr->i_im = ii;
  const float fre = -(ir + (d->kp_re * er - d->kp_im * ei));
  const float fim = -(ii + (d->kp_re * ei + d->kp_im * er));
  fr->f_re = fre;
  fr->f_im = fim;
  fr->m2_v4 = fre * fre + fim * fim;
}

GYRO_RAMFUNC static inline void sense_fr_limit(const sense_fr_design_t *d, sense_fr_t *fr)
{
  if (fr->m2_v4 <= d->f_max2_v4) {
    fr->at_limit = 0u;
    return;
  }
  /* Along its direction back to the limit (rare: a square root and a divide); the
   * integral takes what the proportional part leaves, so that it does not wind up. */
  const float k = d->f_max_v2 / fm_sqrtf(fr->m2_v4);
  const float fre = fr->f_re * k, fim = fr->f_im * k;
  const float er = fr->e_re, ei = fr->e_im;
  fr->f_re = fre;
  fr->f_im = fim;
  fr->i_re = -fre - (d->kp_re * er - d->kp_im * ei);
  fr->i_im = -fim - (d->kp_re * ei + d->kp_im * er);
  fr->m2_v4 = d->f_max2_v4;
  fr->at_limit = 1u;
}

GYRO_RAMFUNC static inline void sense_fr_settle(const sense_fr_design_t *d, sense_fr_t *fr)
{
  /* The residual's mean is what the force has not taken yet; its noise (the demodulator's
   * wide band inside the loop) averages out in the force: the test is on a first-order
   * low-pass of R at a fifth of the loop's natural frequency. */
  const float k = d->settle_k;
  fr->ef_re += k * (fr->e_re - fr->ef_re);
  fr->ef_im += k * (fr->e_im - fr->ef_im);
  const float e2 = fr->ef_re * fr->ef_re + fr->ef_im * fr->ef_im;
  const uint32_t n = settle_count(fr->in_band, e2 <= d->settle2 && !fr->at_limit,
                                  d->settle_blocks);
  fr->in_band = n;
  fr->settled = n >= d->settle_blocks ? 1u : 0u;
}

#endif /* SENSE_FR_H */
