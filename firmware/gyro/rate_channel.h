/* Rate channel (thesis ch. 5, 7): sense phasor -> rate and quadrature, output low-pass,
 * scale factor, temperature compensation in P.
 *
 * The sense LMSD gives the sense phasor S in the NCO frame (gyro.h). The Coriolis
 * acceleration 2 Omega y' is in phase with the drive velocity and the quadrature k_q y
 * with the drive displacement (2-22), so in the frame of the drive motion
 *     R = S e^{-j psi} / A_set,     psi = phase_set + phi_dm
 * puts the Coriolis part on the real axis and the quadrature on the imaginary axis once
 * phi_dm (the demodulation phase: sense-resonance and pickoff phase differences, calibrated)
 * is right. The drive motion is referenced through the phase loop's setpoint, not
 * through the measured drive phasor D: the loop holds the true drive phase at the
 * setpoint to a few thousandths of a degree, while D carries the drive pickoff's noise,
 * and every radian of reference phase noise multiplies the 1500 deg/s quadrature (2
 * uV/rtHz on a 0.35 V pickoff is 5.7e-6 rad/rtHz, 31 deg/h/rtHz of rate noise: more
 * than the Brownian floor). Likewise A_set (held by the amplitude loop) normalises the
 * Coriolis signal, which is proportional to the drive amplitude (2-28).
 * A demodulation-phase error d_phi leaks quadrature into rate as Q sin(d_phi): with
 * 1500 deg/s of quadrature, 0.01 deg is 0.26 deg/s of bias (thesis §2.4.2 B).
 *
 * Output: rate = scale * Re(R_f) * sf(P_f) - bias(P_f), R_f the Butterworth-filtered R,
 * P_f the low-passed force phase in degrees (temperature is slow: a 1 Hz low-pass keeps
 * the phase loop's noise out of the bias correction, whose slope is tens of (deg/s)/deg); bias(P) =
 * c0 + c1 P + c2 P^2 + c3 P^3 and sf(P) = 1 + c1 P + c2 P^2 + c3 P^3 (the thesis fits bias linear
 * in P, 7.3.2).
 */
#ifndef RATE_CHANNEL_H
#define RATE_CHANNEL_H

#include <stdint.h>

#include "dsp/biquad.h"

/* The channel runs on block means of RATE_DECIM ticks (fs / 10 = 5 kHz): every tick
 * only adds the sense phasor to a sum (rate_channel_accumulate); once per block
 * rate_channel_update forms R from the block mean, with the drive-phase correction, and
 * runs the output filter. R is linear in S and the correction changes far slower than
 * a block, so projecting the mean equals the mean of per-tick projections. A
 * 100 Hz 4th-order Butterworth run at 50 kHz in float has a level-dependent DC error
 * of about 1e-3 (each sample adds b0 x ~ 4e-5 x to a state the size of the output, and
 * the rounding is amplified by 1/(1 + a1 + a2) ~ 6400, see dsp/biquad.h): that would be
 * a 0.1 % scale-factor nonlinearity. At 5 kHz the same filter is accurate to 1e-7. The
 * LMSD outputs are already band-limited to a few hundred Hz, and the boxcar's nulls at
 * multiples of 5 kHz take what remains, so the decimation aliases nothing of note.
 * It also runs the filters on a tenth of the ticks. */
#define RATE_DECIM 10u
/* P is averaged over this many ticks before its low-pass: at 500 Hz the float
 * low-pass of P - p_ref has no dead band worth mentioning (at 50 kHz a 1 Hz first-order
 * update is smaller than half an ulp of P and the filter would stick). */
#define RATE_P_DECIM 100u

/* What the channel is told (the designer, gyro_design): constant while it runs. The
 * rate and the quadrature filters share the one set of output low-pass sections. */
typedef struct {
  float ref_re, ref_im; /* e^{j psi} / A_set */
  float scale_dps;      /* deg/s per unit of Re(R) */
  float bias_c_dps[4];
  float sf_c[4];
  float p_ref_deg;   /* P around which its low-pass works (the start value) */
  float p_lpf_alpha; /* first-order low-pass of P at fs / RATE_P_DECIM */
  float p_mode_k;    /* per-block factor of the resonance's lag: 1 - exp(-T_block / (2Q/wn)) */
  float min_drive_v; /* below this measured drive amplitude no rate is formed */
  uint32_t lpf_sections;
  biquad_coeffs_t lpf[BIQUAD_MAX_SECTIONS]; /* output low-pass, designed for fs / RATE_DECIM */
} rate_channel_cfg_t;

/* What the channel remembers between blocks. */
typedef struct {
  float p_acc_deg; /* sum of (P - p_ref), one sample per block, over RATE_P_DECIM ticks */
  uint32_t p_count;
  float p_dev_deg;      /* low-passed P - p_ref */
  float p_held_dev_deg; /* P_f - p_ref while held: where the fast start began */
  float p_held_w;       /* weight the held value still has in P_f (1 while held) */
  float p_mode_rad;     /* P - p_ref through the resonance's lag, rad */
  uint32_t p_hold;      /* nonzero: P is not the temperature yet, P_f holds */
  uint32_t p_n;         /* P means since the last hold (fast start) */
  float p_a_mean;       /* 1 / (p_n + 1 + prior): the fast start's next weight */
  float acc_re, acc_im; /* sense phasor summed over the current block */
  uint32_t p_new;       /* set with each new P_f (rate_channel_update_p), for the
                               * caller's checks of it; the caller clears it */
  biquad_state_t lpf_rate[BIQUAD_MAX_SECTIONS];
  biquad_state_t lpf_quad[BIQUAD_MAX_SECTIONS];
  /* Outputs of the latest block. */
  float rate_raw;     /* Re(R) of the block mean, before the output filter */
  float quad_raw;     /* Im(R) of the block mean */
  float rate_unc_dps; /* filtered, scaled, not compensated */
  float quad_dps;     /* filtered, scaled quadrature */
  float p_f_deg;      /* low-passed P */
  float rate_dps;     /* compensated rate output */
} rate_channel_t;

/* 1 when the configuration is one the channel can run, else 0 (the designer checks). */
int rate_channel_cfg_ok(const rate_channel_cfg_t *cfg);

/* Start: filters cleared, P_f at the reference. Returns 0, or -1 (nothing changed) for a
 * bad configuration. */
int rate_channel_init(const rate_channel_cfg_t *cfg, rate_channel_t *rc);

/* A new configuration takes over from old (a design change, at a block boundary): the
 * filter memory is kept when the number of sections is unchanged, cleared otherwise;
 * P_f is kept as it is, re-expressed around the new reference, and P's average starts
 * again. No libm. */
void rate_channel_rebase(const rate_channel_cfg_t *old, const rate_channel_cfg_t *cfg,
                         rate_channel_t *rc);

/* Whether two configurations give the rate output the same meaning (reference, scale,
 * compensation, output filter): 1, else 0 (the output filters must settle again). */
int rate_channel_same_path(const rate_channel_cfg_t *a, const rate_channel_cfg_t *b);

/* Clear the filters; P_f starts at p_deg. */
void rate_channel_reset(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float p_deg);

/* Every tick: add the sense LMSD's weights (w_i, w_q) to the block sum. */
static inline void rate_channel_accumulate(rate_channel_t *rc, float w_i, float w_q)
{
  rc->acc_re += w_i;
  rc->acc_im += w_q;
}

/* P is a temperature signal only while the phase loop holds the drive phase: during
 * acquisition it swings by degrees (the loop pulling the phase in), and at the bias
 * slope of tens of (deg/s)/deg a 1 Hz low-pass fed with that would carry a bias of
 * several deg/s for a second after lock. While held, P_f keeps its value (the start
 * value, or the last locked one after a fault) and P's average restarts on release. */
static inline void rate_channel_hold_p(rate_channel_t *rc, int hold)
{
  rc->p_hold = hold ? 1u : 0u;
}

/* Once per RATE_DECIM ticks, after the block's last accumulate. (w_i, w_q): the drive
 * LMSD's weights (only to tell that the drive runs); p_rad: force phase (the phase loop
 * holds it over the block), for the reference's correction; the compensation uses P_f
 * as rate_channel_update_p last left it. Rate and quadrature outputs. The same as
 * rate_channel_project, rate_channel_filter_rate and rate_channel_filter_quad in a row. */
void rate_channel_update(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float w_i,
                         float w_q, float p_rad);

/* The parts of the block update, for a caller that spreads them over the ticks of the
 * block (gyro_state.h), each once per block:
 *   rate_channel_project      block mean of S, reference correction -> rate_raw, quad_raw
 *                             (clears the sum: the next block starts here)
 *   rate_channel_filter_rate  after project: output low-pass and scale of rate_raw,
 *                             compensation in P_f -> rate_unc_dps, rate_dps
 *   rate_channel_filter_quad  after project: the same for quad_raw -> quad_dps
 *   rate_channel_update_p     any time: P's block sum, its low-pass every RATE_P_DECIM
 *                             ticks -> P_f (the compensation's from then on) */
void rate_channel_project(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float w_i,
                          float w_q, float p_rad);
void rate_channel_filter_rate(const rate_channel_cfg_t *cfg, rate_channel_t *rc);
void rate_channel_filter_quad(const rate_channel_cfg_t *cfg, rate_channel_t *rc);
/* Returns 1 when it made a new P_f (every RATE_P_DECIM ticks while not held; p_new is
 * set then as well), else 0. */
int rate_channel_update_p(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float p_rad);
/* P jumped by shift_deg without a change of temperature (the phase loop wrapped its
 * state by a whole turn, drive_loop.h): P_f and its average move with it. */
void rate_channel_shift_p(rate_channel_t *rc, float shift_deg);

#endif /* RATE_CHANNEL_H */
