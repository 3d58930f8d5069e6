/* Rate channel (thesis ch. 5, 7): sense phasor -> rate and quadrature, output low-pass,
 * scale factor, temperature compensation in P.
 *
 * The sense LMSD gives the sense phasor S in the NCO frame (gyro.h). The Coriolis
 * acceleration 2 Omega y' is in phase with the drive velocity and the quadrature k_q y
 * with the drive displacement (2-22), so in the frame of the drive motion
 *     R = S e^{-j psi} / A_set,     psi = phase_set + phi_dm
 * puts the Coriolis part on the real axis and the quadrature on the imaginary axis once
 * phi_dm (the demodulation phase: sense-resonance and pickoff phase differences, calibrated)
 * is right. Every radian of error in the reference's phase multiplies the 1500 deg/s
 * quadrature, so the reference must follow the true drive phase theta, and neither
 * the setpoint nor the measured phasor D is it: below the phase loop's bandwidth the
 * loop writes the drive pickoff's noise n onto theta (theta - set ~ -n), and D carries n
 * itself (2 uV/rtHz on a 0.35 V pickoff is 8e-6 rad/rtHz, 44 deg/h/rtHz of rate
 * noise: more than the Brownian floor). What does know theta without n is the loop's
 * own force phase P: the mode turns it into theta through its lag (6-17),
 *     theta = LP_tau(P) + const,   tau = 2Q/wn
 * (the tracking drive's p_eq the same way, drive_track.h). The constant (the resonance's
 * phase at the drive frequency) moves with temperature, so the reference is a
 * complementary filter: the model's high frequencies, the measurement's low ones,
 *     delta = theta - set = LP_tau(P) - LP2(LP_tau(P) + e),   e = set - arg D,
 * LP2 a type-2 low-pass of RATE_REF_LP_HZ (the estimate of the static phase: it follows
 * a temperature ramp of the resonance without a lag; at Q = 10^4 a 10 K/min ramp moves
 * that phase by 0.07 rad/s, which a first-order 1 Hz low-pass would trail by 0.01 rad:
 * 16 deg/s of rate). What is left is q LP2(n): n over LP2's 3.3 Hz of noise bandwidth
 * instead of the loop's tens of Hz, and no rise with Q (at Q = 5000 the loop moves P by
 * 200 times theta's own swing at 30 Hz: a reference built on a 1 Hz low-pass of P, as
 * before, left 6 times the error of no correction at all).
 * Likewise A_set (held by the amplitude loop) normalises the
 * Coriolis signal, which is proportional to the drive amplitude (2-28).
 * A demodulation-phase error d_phi leaks quadrature into rate as Q sin(d_phi): with
 * 1500 deg/s of quadrature, 0.01 deg is 0.26 deg/s of bias (thesis §2.4.2 B).
 *
 * Output: rate = L(u) * sf(x) - bias(x) - k h, u = scale * Re(R_f) the uncompensated rate
 * (R_f the Butterworth-filtered R), L(u) = u + c2 u^2 + c3 u^3 its linearisation (the
 * sense pickoff's gain falls with the square of the whole sense amplitude, quadrature
 * and bias included, so its rate nonlinearity is a polynomial in u, fitted by the
 * calibration flow over the full scale), x = P_c - cal.ref_p_deg the thermometer's
 * deviation from the calibration's reference (P_c: the force phase P low-passed at 1 Hz,
 * P_f, and again over rate.comp_tau_s; temperature is slow and the bias slope is tens of
 * (deg/s)/deg), bias(x) a cubic and sf(x) = 1 + c1 x + .. + c4 x^4 (the thesis fits the
 * bias linear in P, 7.3.2), k h the gradient term (rate_channel.c).
 */
#ifndef RATE_CHANNEL_H
#define RATE_CHANNEL_H

#include <stdint.h>

#include "dsp/biquad.h"
#include "gyro/comp_filters.h"

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
/* Blocks of RATE_DECIM ticks per low-pass sample of P. */
#define RATE_P_BLOCKS (RATE_P_DECIM / RATE_DECIM)
/* The reference's complementary low-pass (above): natural frequency and damping of
 * LP2. Low enough that little of the pickoff's phase noise reaches the reference, high
 * enough that a change of the resonance's own phase (a thermal transient) is followed
 * within a second. */
#define RATE_REF_LP_HZ 1.0
#define RATE_REF_LP_ZETA 0.7071
/* After each lock the model starts from the mode settled on P, which is off by P's
 * own swing at that moment (its noise: 0.035 rad at Q = 5000, 0.07 rad on the tracking
 * drive's p_eq at 10^4); that error decays with tau, and LP2 passes (w tau / wn)^2 of it
 * ... 1/40 at 1 Hz and tau = 1 s. So LP2 is wide for RATE_REF_WIDE_TAUS tau after the
 * release (1/4000 of the error), then narrow: more of the pickoff's phase noise for that
 * while (as much as the loop writes on the true phase), no bias. */
#define RATE_REF_WIDE_HZ 10.0
#define RATE_REF_WIDE_TAUS 4.0
/* ... and at least this long (a few of its own time constants: the acquisition's tail
 * it took in has left), then narrowed to RATE_REF_LP_HZ geometrically over
 * RATE_REF_NARROW_S. */
#define RATE_REF_WIDE_MIN_S 0.1
#define RATE_REF_NARROW_S 0.25
/* Before lock the reference follows the measured phase (the model's constant is not
 * known yet), limited to the small angles its rotation is formed for. */
#define RATE_REF_DEV_MAX_RAD 0.05f

/* What the channel is told (the designer, gyro_design): constant while it runs. The
 * rate and the quadrature filters share the one set of output low-pass sections. */
/* Within full scale the turn is the rate's; up to ten times it, a rate read through a
 * stale demodulation phase (the 1500 deg/s quadrature turned into it), it is taken as
 * well: dropping it there moved P_f by 0.05 deg while a phase setpoint was walked, which
 * kept the rate not valid 39 s after the walk's return instead of 14.5
 * (test_cl_integrity.c). */
#define RATE_TURN_MAX_FS 10.0f

typedef struct {
  float ref_re, ref_im; /* e^{j psi} / A_set */
  float scale_dps;      /* deg/s per unit of Re(R) */
  float bias_c_dps[4];
  float sf_c[5];        /* [0] unused: SF(x) = 1 + c1 x + .. + c4 x^4 */
  float lin_c2_per_dps; /* L(u) = u + c2 u^2 + c3 u^3 */
  float lin_c3_per_dps2;
  float p_ref_deg;            /* P around which its low-pass works (the start value) */
  float p_poly_off_deg;       /* p_ref - cal.ref_p_deg: x = p_dev + this at P_f, the
                             * compensation polynomials' variable */
  float p_lpf_alpha;          /* first-order low-pass of P at fs / RATE_P_DECIM */
  float grad_k_dps_per_deg;   /* bias per degree of P_f's high-pass: the thermal gradient */
  float grad_a;               /* that high-pass's 1 - exp(-T / tau) per new P_f */
  float p_rate_deg_per_dps;   /* P's turn per deg/s of rate, taken out of the thermometer */
  float p_rate_c1_per_dps;    /* its change per degree of x (the compensation's variable) */
  float p_rate2_deg_per_dps2; /* P's turn per (deg/s)^2 of rate */
  /* The largest rate that turn is taken for (RATE_TURN_MAX_FS times rate.full_scale_dps);
   * beyond it the channel's rate is no rate at all (a scale stale by orders: 1.9e6 deg/s
   * after a sweep that tuned the sense mode to the drive, whose square in the turn ran
   * P_f away until the supervisor faulted) and P is taken as it is */
  float turn_max_dps;
  float comp_a;                  /* P_c's low-pass of P_f: 1 - exp(-T / comp_tau) per new P_f */
  uint32_t comp_stages;          /* first-order stages of that low-pass, 1..COMP_STAGES_MAX */
  float comp_fast_a;             /* the fast path's one low-pass of P_f (0: no fast path) */
  float grad_fast_k_dps_per_deg; /* the fast path's gradient term */
  float blend_dps;               /* the paths' difference where the fast one starts to weigh */
  float blend_inv_per_dps;       /* 1 / blend_dps */
  uint32_t fast_hold_updates;    /* P updates the fast path sits out after a move of P_f no
                                  * temperature made: its own settling (3 (its tau + the
                                  * gradient term's)) */
  float p_mode_k;  /* per-block factor of the resonance's lag: 1 - exp(-T_block / (2Q/wn)) */
  float ref_lp_kp; /* LP2 per block: 2 zeta wn T_block ... */
  float ref_lp_ki; /* ... and (wn T_block)^2 */
  float ref_wide_kp, ref_wide_ki; /* the same at RATE_REF_WIDE_HZ ... */
  uint32_t ref_wide_blocks;       /* ... for this many blocks after a release, */
  float ref_narrow_k;             /* then kp x this per block (ki x its square) */
  float min_drive_v;              /* below this measured drive amplitude no rate is formed */
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
  float p_hp_deg;       /* P_c - LP_tau(P_c): the gradient term's input */
  float p_comp_lag_deg; /* P_f - P_c: P_c the compensation's thermometer */
  float p_comp_mid_deg[COMP_STAGES_MAX - 1u]; /* P_f - P_k, P_c's stages before its last */
  float p_fast_lag_deg;                       /* P_f - P_c of the fast path */
  float p_fast_hp_deg;                        /* its P_c - LP_tau(P_c) */
  float comp_bias_dps;    /* the compensation's bias and scale factor at the filters' latest */
  float comp_sf;          /* state (rate_channel_comp_refresh) */
  float comp_fast_w;      /* the fast path's weight in that bias, 0..1 */
  uint32_t fast_hold;     /* P updates the fast path still sits out (rate_channel_fast_hold) */
  uint32_t comp_due;      /* the filters moved: the compensation is to be refreshed */
  uint32_t filters_due;   /* a new P_f: the filters are to take its step (p_step_deg) */
  float p_step_deg;       /* the step P_f took at its latest update */
  float p_last_rad;       /* P at the last projection */
  float p_lag_rad;        /* P - LP_tau(P): the resonance's lag still to come */
  float ref_dev_rad;      /* the reference's correction delta = theta - set */
  float ref_slope_rad;    /* LP2's slope state, per block */
  uint32_t ref_wide_left; /* blocks LP2 is still wide */
  float ref_kp, ref_ki;   /* LP2's gains now (wide, narrowing, narrow) */
  uint32_t p_hold;        /* nonzero: P is not the temperature yet, P_f holds */
  uint32_t p_n;           /* P means since the last hold (fast start) */
  float p_a_mean;         /* 1 / (p_n + 1 + prior): the fast start's next weight */
  float acc_re, acc_im;   /* sense phasor summed over the current block */
  uint32_t p_new;         /* set with each new P_f (rate_channel_update_p), for the
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
 * P_f is kept as it is, re-expressed around the new reference (the caller moves the
 * thermometer checks' window with it, rate_valid_shift_p), and P's average starts
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

/* P_f moved by far more than any temperature (rate_valid.h, RATE_VALID_RESTART_CAPS):
 * the compensation's own thermometer P_c and the gradient term's high-pass restart from
 * P_f rather than carry that move for their time constants. */
static inline void rate_channel_comp_restart(rate_channel_t *rc)
{
  rc->p_comp_lag_deg = 0.0f;
  rc->p_comp_mid_deg[0] = rc->p_comp_mid_deg[1] = 0.0f;
  rc->p_hp_deg = 0.0f;
  rc->p_fast_lag_deg = 0.0f;
  rc->p_fast_hp_deg = 0.0f;
  rc->comp_due = 1u;
  rc->filters_due = 0u;
}

/* 1 when this block's rate_channel_update_p makes a new P_f: that tick carries the
 * low-pass and no other job of the thermometer (gyro_block_p). */
static inline int rate_channel_p_update_now(const rate_channel_t *rc)
{
  /* & rather than &&: both are words at hand, and the P slot's path stays branch-free */
  return (rc->p_hold == 0u) & (rc->p_count + 1u == RATE_P_BLOCKS);
}

/* The compensation's filters take P_f's latest step (filters_due, from
 * rate_channel_update_p), on a block of their own (gyro_block_p), then comp_due. */
void rate_channel_comp_filters(const rate_channel_cfg_t *cfg, rate_channel_t *rc);

/* The thermometer checks saw a move of P_f no temperature makes (THERMO_SLEW): the fast
 * path sits out for cfg->fast_hold_updates from now. What such a move leaves in the
 * compensation's filters is known only in part (rate_valid.h: the shadow counts the
 * windows beyond the cap), and the fast path takes more of it in than the slow one, for
 * less time: the slow path alone carries the output until the fast one has settled. */
static inline void rate_channel_fast_hold(const rate_channel_cfg_t *cfg, rate_channel_t *rc)
{
  rc->fast_hold = cfg->fast_hold_updates;
  rc->comp_due = 1u;
}

/* The temperature compensation (bias, scale factor) from the filters' state, where
 * rate_channel_filter_rate takes it. The filters move only with a new P_f (every
 * RATE_P_BLOCKS blocks), a hold, a restart or a wrap, each of which sets comp_due: the
 * caller refreshes on a block whose P slot has room (gyro_block_p), so the rate's own
 * tick carries no polynomial. With a fast path (comp_fast_a > 0) the bias blends the two:
 *   d = B_fast - B_slow,  w = clamp((|d| - blend) / blend, 0, 1),  B = B_slow + w d,
 * the slow thermometer's (low noise at 10 s) while the two agree within blend_dps, the
 * fast one's beyond twice that (a transient the slow one lags), and never further from
 * the fast one than blend_dps in between. */
void rate_channel_comp_refresh(const rate_channel_cfg_t *cfg, rate_channel_t *rc);

/* The compensation's variable at the filters' state: x = P_c - cal.ref_p_deg. */
static inline float rate_channel_comp_x_deg(const rate_channel_cfg_t *cfg,
                                            const rate_channel_t *rc)
{
  return (rc->p_dev_deg + cfg->p_poly_off_deg) - rc->p_comp_lag_deg;
}

/* The compensation's static bias B(x), its cubic alone (no gradient term, no fast path):
 * rate_channel_comp_refresh's, and the board thermometer's B_s (board_therm.h). */
static inline float rate_channel_bias_static_dps(const rate_channel_cfg_t *cfg, float x)
{
  const float *b3 = cfg->bias_c_dps;
  return b3[0] + x * (b3[1] + x * (b3[2] + x * b3[3]));
}

/* Once per RATE_DECIM ticks, after the block's last accumulate. (w_i, w_q): the drive
 * LMSD's weights (only to tell that the drive runs); p_rad: force phase (the phase loop
 * holds it over the block) and e_rad: the phase loop's error set - arg D, for the
 * reference's correction; the compensation uses P_f
 * as rate_channel_update_p last left it. Rate and quadrature outputs. The same as
 * rate_channel_project, rate_channel_filter_rate and rate_channel_filter_quad in a row. */
void rate_channel_update(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float w_i,
                         float w_q, float p_rad, float e_rad);

/* The parts of the block update, for a caller that spreads them over the ticks of the
 * block (gyro_state.h), each once per block:
 *   rate_channel_project      block mean of S, reference correction -> rate_raw, quad_raw
 *                             (clears the sum: the next block starts here)
 *   rate_channel_filter_rate  after project: output low-pass and scale of rate_raw,
 *                             the compensation's latest refresh -> rate_unc_dps, rate_dps
 *   rate_channel_filter_quad  after project: the same for quad_raw -> quad_dps
 *   rate_channel_update_p     any time: P's block sum, its low-pass every RATE_P_DECIM
 *                             ticks -> P_f (the compensation's filters take its step in
 *                             rate_channel_comp_filters, then rate_channel_comp_refresh) */
void rate_channel_project(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float w_i,
                          float w_q, float p_rad, float e_rad);
void rate_channel_filter_rate(const rate_channel_cfg_t *cfg, rate_channel_t *rc);
void rate_channel_filter_quad(const rate_channel_cfg_t *cfg, rate_channel_t *rc);
/* Returns 1 when it made a new P_f (every RATE_P_DECIM ticks while not held; p_new is
 * set then as well), else 0. */
int rate_channel_update_p(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float p_rad);
/* P jumped by shift_deg without a change of temperature (the phase loop wrapped its
 * state by a whole turn, drive_loop.h): P_f and its average move with it. */
void rate_channel_shift_p(rate_channel_t *rc, float shift_deg);

#endif /* RATE_CHANNEL_H */
