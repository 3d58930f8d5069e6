/* Two-resonance mechanics of the vibratory gyro: drive axis y, sense axis x, exact
 * discretisation per sample (host plant, double precision).
 *
 * Equations (thesis (2-22), per unit mass, completed with the terms of the full
 * linear-gyro equation (2-20) that (2-21) drops), Omega = body rate about the sensitive
 * axis, alpha = dOmega/dt:
 *
 *   y'' + (wn1/Q1) y' + wn1^2 y = f_y + n_y                           (2-22) drive
 *                                 [ - 2 Omega x' - alpha x + Omega^2 y ]   (2-20)
 *   x'' + (wn2/Q2) x' + wn2^2 x = 2 Omega y' + f_x + n_x - k_q y - d_q y'  (2-22) sense
 *                                 [ + alpha y + Omega^2 x ]                (2-20)
 *
 * Sign convention: the thesis writes the Coriolis term as -2 Omega y' on the left of
 * (2-22), i.e. +2 Omega y' as a force on the sense axis; its reaction on the drive
 * axis is -2 Omega x' ((2-20), first line, 2 m theta' x' on the left). The bracketed
 * (2-20) terms (reciprocal Coriolis, centrifugal softening, Euler force) are present
 * when cfg.full_kinematics is set; they change the drive by < 1e-4 relative at
 * 1000 deg/s and the thesis neglects them, but the reciprocal Coriolis term is real
 * and the other two are of the same order, so they come together.
 *   k_q y  : anisoelastic coupling -> quadrature (equivalent rate k_q / (2 wc)).
 *   d_q y' : damping coupling -> in-phase bias (equivalent rate d_q / 2). Not in the
 *            thesis model.
 *   n_y, n_x: Brownian force noise (4-20), one-sided force PSD 4 kB T D with
 *            D = m wn / Q, i.e. acceleration PSD S = 4 kB T wn / (Q m) (m/s^2)^2/Hz.
 *            Applied as a zero-order-held white sequence: a held value of variance
 *            s^2 has a PSD of s^2 T sinc^2(f T) two-sided, 2 s^2 T one-sided at low
 *            frequency, so s^2 = S fs / 2. The sinc^2 droop lowers the resonant
 *            response by 0.3 % (drive, 1.49 kHz) and 0.5 % (sense, 2 kHz) at 50 kHz.
 *
 * Temperature (2-29..2-32): wn_i(T) = wn_i(T0) (1 - 0.5 kET (T - T0)) for both resonances
 * (the structure temperature); every stiffness term (including k_q) scales with wn^2,
 * every damping term with wn / Q(T), Q(T) = Q(T0) times the law cfg.q_law (qlaw.h;
 * QLAW_CONST: Q constant, the damping scales with wn alone). The blocks below hold one
 * Q: they are recomputed when Q(T) has moved by refresh_eps relative since they were
 * made, so the damping follows its law to within refresh_eps (1e-3 by default: every
 * 0.4 K under the gas law, 0.07 K under the thermoelastic law).
 *
 * Electrostatic spring softening (thesis (6-3); Senturia, Microsystem Design, Kluwer
 * 2001, §6.4.3): a parallel-plate electrode pair of gap d at DC voltages V_j pulls with
 * F = eps A V^2 / (2 (d -+ x)^2), whose stiffness -dF/dx at x = 0 is -eps A V^2 / d^3 per
 * electrode: a negative spring k_e that lowers the sense resonance,
 *     wn2_eff^2 = wn2^2 - k_e / m,   df = -f2 k_e / (2 k) to first order.
 * cfg.ke2_per_s2 is k_e / m (the plant derives it from the feedback electrodes' bias,
 * plant.fb_gap_m); it is not a property of the silicon, so it does not scale with
 * (2-32), and it leaves the damping (c = m wn2 / Q2) alone. It sits in the generator
 * like the other stiffness terms (exact).
 *
 * Electrostatic stiffness of the sense electrodes (mech_set_elec; the plant's actuator
 * gives it from their voltages, actuator.h): a coupling k_yx that adds to k_q (the
 * quadrature-nulling electrodes, -k_yx y on the sense axis) and a softening k_e that adds
 * to cfg.ke2_per_s2 (tuning, nulling and feedback-pair electrodes, +k_e x), per unit
 * mass, set every sample. Like ke2_per_s2 neither scales with (2-32) nor touches the
 * damping. The reaction of the nulling electrodes on the drive axis, -k_yx x, is left
 * out as the anisoelastic coupling's is (|x| / |y| ~ 1e-2 and k_yx / wn1^2 ~ 3e-3: a
 * drive force 3e-5 of its stiffness force). A varying stiffness cannot sit in the
 * generator (each change would be a re-discretisation, ~0.2 ms), so the generator
 * carries the values of its last discretisation and the difference is a held force
 * (below), f_x -= (k_yx - k_yx,d) y_m - (k_e - k_e,d) x_m; the sample means since the
 * last call are rebased into the generator by mech_elec_rebase (the plant calls it at
 * every thermal update, 1 ms) when they have moved from the generator's by more than
 *   k_e:   2 refresh_eps wn2^2  (a relative shift of the sense resonance of refresh_eps,
 *          as a temperature refresh; the held part's error, 1 - sinc(wT/2) of it, is
 *          then 2.6e-6 of the frequency at 2 kHz);
 *   k_yx:  an equivalent quadrature k_yx / (2 wn1) of refresh_eps x 1e4 deg/s (10 deg/s
 *          at the default, whose held error, 1 - sinc(wn1 T/2) = 0.145 % of it, is
 *          0.015 deg/s).
 * So a steady voltage is exact (in the generator) from the second thermal update after it
 * is set, the electrode noise and the feedback pair's parametric part at 2 wc stay held
 * forces, and a loop that moves a voltage re-discretises at most once per millisecond,
 * only while it moves. The softening is held at the pull-in margin of the configured
 * one, cfg.ke2_per_s2 + k_e <= wn2(T0)^2 / 2, and flagged (MECH_OUT_PULL_IN).
 *
 * Held forces (not in the generator; added to the inputs f_y, f_x of the sample, only
 * when switched on), each evaluated from the motion at the middle of the sample: the
 * cubic Hermite interpolant between the state at its start and the state at its end
 * without these forces (y_m = (y0 + y1)/2 + T (y0' - y1')/8, y'_m likewise; exact for a
 * cubic, (w T)^4 / 384 = 3e-6 on a sine at 1.5 kHz, whatever its frequency), then their
 * share of the step added through Gamma (the step is linear in its inputs); the forces'
 * own effect within the sample is left out of the interpolant (second order in them).
 * The mid-sample value, held, has no phase error against the motion and a gain of
 * sinc(w T/2) on it, 0.99855 at 1.49 kHz and 0.99737 at 2 kHz (50 kHz): the lead of the
 * mid-sample value cancels the hold's lag, as for the rate in A and the DAC's per-sample
 * means (dac.h):
 *   - cubic suspension stiffness (Duffing): f_y -= wn1^2 k3_drive y_m^3, f_x -= wn2^2
 *     k3_sense x_m^3 with k3 = k3/k (1/m^2), restoring force k (y + (k3/k) y^3). A free
 *     oscillation of amplitude A then runs at f (1 + 3 (k3/k) A^2 / 8) to first order
 *     (Lindstedt-Poincare, A. H. Nayfeh & D. T. Mook, Nonlinear Oscillations, Wiley 1979,
 *     §4.1.1; for silicon flexures V. Kaajakari et al., J. Microelectromech. Syst. 13
 *     (2004) 715). k3/k follows E like k, so it has no temperature law. Range of the
 *     expansion: |k3/k| y^2 <= MECH_DUFFING_MAX (the cubic term at most a tenth of the
 *     linear one); beyond it the cubic term is held at its edge and flagged.
 *   - amplitude-dependent drive damping (nonlinear damping of the van der Pol kind):
 *     f_y -= (wn1 / Q1) c y_m^2 y'_m with c = nl_damp_drive_per_m2 (1/m^2), the drive's
 *     damping force growing as (1 + c y^2). Its fundamental on y = A sin(w t) is
 *     (wn1/Q1) (c A^2 / 4) y': the drive's effective Q is Q1 / (1 + c A^2 / 4), with no
 *     shift of the resonance (unlike the Duffing term), so the amplitude at a fixed
 *     frequency grows more slowly than the force at large amplitudes. Air damping of a
 *     comb-driven proof mass grows with the stroke when the fingers' overlap and the
 *     squeeze-film regions change over it (S. Zaitsev et al., Nonlinear Dyn. 67 (2012)
 *     859; A. Eichler et al., Nature Nanotech. 6 (2011) 339 for the model); the thesis's
 *     table 7-1 shows the compression (docs/honest-part.md). No temperature law beyond
 *     Q1's own; no range law (c A^2 / 4 is a few % at the largest strokes);
 *   - slow drift of the couplings (drift.h; set by mech_set_coupling_drift):
 *     f_x -= dk_q y_m + dd_q y'_m, scaled with the structure temperature like k_q, d_q.
 *     They act as the configured couplings do; held rather than in the generator so
 *     that a drift needs no re-discretisation.
 *
 * Discretisation. State s = [y, y', x, x'] (m, m/s); inputs u = [f_y, f_x] (forces
 * per unit mass, m/s^2) held over the sample (zero-order hold). Over one sample
 * s(k+1) = Phi s(k) + Gamma u(k) with [Phi Gamma; 0 I] = exp([A B; 0 0] T), exact.
 * The rate is NOT a held force (that would lag the Coriolis force by wc T / 2, 5 deg
 * at 1.5 kHz): it sits inside A. A is polynomial in three small parameters,
 * w = Omega/wr, a = alpha/wr^2 and e = wn(T)/wn(T_d) - 1 (T_d: temperature of the
 * last discretisation), and exp(A T) is expanded in them:
 *   [Phi Gamma](w,a,e) = sum over the 12 monomials m in
 *     {1, e, e^2, w, w e, w e^2, w^2, w^2 e, w^3, a, w a, a e}  of  m * P_m
 * The P_m are the exact Taylor coefficients: sum_m m P_m is exp(A(w,a,e) T) taken in
 * the truncated polynomial algebra spanned by those monomials (Van Loan's
 * block-triangular trick for d/dOmega expm, generalised to several parameters and
 * higher orders). The exponential is computed in the algebra itself (12 blocks of
 * 4x6, product (XY)_i = sum over mono_g mono_j = mono_i of X_g Y_j; scaling and
 * squaring with a degree-18 Taylor series), about 2.5 kB of stack; it equals the first
 * block column of the exponential of the 72 x 72 left-regular representation
 * (test_mech_alg, 1e-13 per block against Eigen). Without full_kinematics A is block triangular and affine in Omega,
 * so the expansion is exact in Omega (P_w2 = P_w3 = 0). Measured against a
 * per-sample Eigen expm of the exact model (test_mech): < 1e-9 relative with rate up
 * to 500 deg/s and 20 Hz, a 60 K temperature ramp and 1500 deg/s quadrature; the
 * temperature remainder is about 860 e^3 at resonance, so the blocks are recomputed
 * ("refresh") only when |e| exceeds cfg.refresh_eps (default 1e-3, i.e. every 50 K).
 * The rate is taken at the middle of the sample, its slope as alpha (first order
 * within the sample); a sinusoidal rate at f_r then costs (2 pi f_r T)^2 / 24 of the
 * Coriolis response (1.7e-7 at 20 Hz against 4 reference sub-steps per sample).
 *
 * Per sample: one 4x6 matrix-vector product (24 multiply-adds) and two Gaussian
 * deviates (ziggurat, gauss_zig.h); when the rate changes, 4x6x6 multiply-adds to re-sum the blocks; when the
 * temperature changes (thermal update), 12x24.
 *
 * Internally the state is scaled to z = [y, y'/wr, x, x'/wr] with wr = wn1(T0) so
 * that every block is O(1) for the matrix exponential.
 */
#ifndef PLANT_MECH_H
#define PLANT_MECH_H

#include <stdint.h>

#include "plant/gauss_zig.h"
#include "plant/rng.h"

#define MECH_NMONO 12 /* Taylor blocks, see mech.c */
#define MECH_NS 4     /* states */
#define MECH_NU 2     /* inputs */

/* Noise stream ids (rng_seed(seed, stream)): one rng_t per noise source. */
#define MECH_RNG_STREAM_DRIVE 0x6d01u
#define MECH_RNG_STREAM_SENSE 0x6d02u

#define MECH_KB_J_PER_K 1.380649e-23 /* Boltzmann constant (SI 2019, exact) */
#define MECH_DUFFING_MAX 0.1         /* largest |k3/k| y^2 of the cubic expansion */

/* Laws held at an edge (mech_laws_out). */
#define MECH_OUT_Q 1u             /* Q(T) outside its law's temperature range, now */
#define MECH_OUT_DUFFING_DRIVE 2u /* drive cubic term beyond MECH_DUFFING_MAX, since last */
#define MECH_OUT_DUFFING_SENSE 4u /* sense cubic term beyond MECH_DUFFING_MAX, since last */
#define MECH_OUT_PULL_IN 8u /* electrode softening held at the pull-in margin, since last */

/* Rebase threshold of the electrostatic coupling: an equivalent quadrature of
 * refresh_eps times this (mech.h above). */
#define MECH_ELEC_KYX_REFRESH_DPS 1e4

typedef struct {
  double f1_hz;           /* drive resonance at temp_ref_k */
  double q1;              /* drive quality factor (temperature independent) */
  double f2_hz;           /* sense resonance at temp_ref_k */
  double q2;              /* sense quality factor */
  double temp_ref_k;      /* T0 of (2-32) */
  double ket_per_k;       /* kET, temperature coefficient of Young's modulus (2-29) */
  double kq_per_s2;       /* k_q at T0: quadrature stiffness coupling per unit mass */
  double dq_per_s;        /* d_q at T0: damping coupling per unit mass */
  double mass_kg;         /* proof mass m: sets the Brownian noise (4-20) */
  double fs_hz;           /* sample rate */
  double refresh_eps;     /* |wn(T)/wn(T_d) - 1| (or of Q) that triggers a re-discretisation */
  double k3_drive_per_m2; /* Duffing k3/k of the drive suspension, 1/m^2; 0: linear */
  double k3_sense_per_m2; /* ... of the sense suspension */
  double nl_damp_drive_per_m2; /* amplitude-dependent drive damping: (1 + c y^2), 1/m^2 */
  double ke2_per_s2;           /* electrostatic softening k_e/m of the sense axis, >= 0 */
  int q_law;                   /* qlaw_kind_t of both Q; QLAW_CONST (0): constant */
  int full_kinematics;         /* 1: reciprocal Coriolis, centrifugal and Euler terms (2-20) */
  int brownian;                /* 1: Brownian force noise on both axes */
} mech_cfg_t;

typedef struct {
  double y_m, vy_mps; /* drive displacement, velocity */
  double x_m, vx_mps; /* sense displacement, velocity */
} mech_state_t;

typedef struct {
  mech_cfg_t cfg;
  double wr;          /* scaling frequency wn1(T0), rad/s */
  double temp_k;      /* structure temperature now */
  double temp_disc_k; /* temperature of the current Taylor blocks */
  double eps;         /* wn(temp_k) clock/(wn(temp_disc_k) clock_disc) - 1 */
  double clock;       /* time scale of the sample clock: wn seen per sample, 1 = exact */
  double clock_disc;  /* ... of the current Taylor blocks */
  double blk[MECH_NMONO][MECH_NS][MECH_NS + MECH_NU]; /* Taylor blocks [Phi Gamma] */
  double q[4][2][MECH_NS][MECH_NS + MECH_NU];         /* blocks of w^p a^r summed over e^k */
  double qmax[4][2];                    /* largest entry of each, to skip negligible terms */
  double k[MECH_NS][MECH_NS + MECH_NU]; /* [Phi Gamma] at the current (w, a, e) */
  double coef[2];                       /* (w, a) that k[][] was built for */
  int q_valid, k_valid;
  double z[MECH_NS];        /* scaled state */
  double noise_sd[MECH_NU]; /* per-sample sd of the held noise, scaled units */
  rng_t rng[MECH_NU];       /* one source per axis; normal deviates by gauss_zig.h */
  uint64_t refresh_count;
  double q_now[2];        /* Q of drive, sense at temp_k (the law) */
  double q_disc[2];       /* ... of the current Taylor blocks */
  double drift_kq_per_s2; /* coupling drift at T0 (mech_set_coupling_drift) */
  double drift_dq_per_s;
  double elec_kyx_per_s2, elec_ke_per_s2; /* electrode stiffness now (mech_set_elec) */
  double elec_disc[2];                    /* k_yx, k_e in the current Taylor blocks */
  double elec_sum[2];                     /* sums of k_yx, k_e since the last rebase */
  long elec_n;                            /* samples in them */
  int elec_on;                            /* mech_set_elec was given a non-zero stiffness */
  int held;                               /* a held force of the header is on */
  unsigned q_out;                         /* MECH_OUT_Q at temp_k */
  unsigned duffing_out; /* MECH_OUT_DUFFING_*, MECH_OUT_PULL_IN since the last mech_laws_out */
} mech_t;

/* Defaults: the thesis linear gyro (fn1 1489.9 Hz, Q1 33.33, fn2 2000 Hz, Q2 3,
 * m 0.26 mg, kET 40 ppm/K, T0 298.15 K, 50 kHz), no quadrature, noise on. */
void mech_default_cfg(mech_cfg_t *cfg);

/* Validates cfg; returns 0 or a negative value and, if key != NULL, the name of the
 * first offending field. */
int mech_cfg_check(const mech_cfg_t *cfg, const char **key);

/* Validates, discretises at the structure temperature temp_k, zero state, seeds the
 * two noise sources from seed. Returns 0, -1 (bad cfg or temperature: m unchanged)
 * or -2 (matrix exponential failed). */
int mech_init(mech_t *m, const mech_cfg_t *cfg, double temp_k, uint64_t seed);

/* temp_k kept to the range of (2-32) in this model (|0.5 kET (T - T0)| < 0.2, 0..2000 K,
 * where temp_ok accepts it); *outside (may be NULL) is 1 if it had to move. */
double mech_temp_clamp(const mech_cfg_t *cfg, double temp_k, int *outside);

/* New structure temperature (K). Cheap unless |e| passes refresh_eps. Non-finite or
 * non-positive temperatures are ignored (returns -1). */
int mech_set_temp(mech_t *m, double temp_k);

/* Advance one sample. f_drive_mps2, f_sense_mps2: forces per unit mass (m/s^2, the
 * f_y, f_x of (2-22); actuator and accel give them in this unit) held over the sample;
 * rate_rad_s, rate_dot_rad_s2: Omega and dOmega/dt at the middle of the sample. */
void mech_step(mech_t *m, double f_drive_mps2, double f_sense_mps2, double rate_rad_s,
               double rate_dot_rad_s2);

mech_state_t mech_state(const mech_t *m);
void mech_set_state(mech_t *m, const mech_state_t *s);

/* Resonances at the current structure temperature (2-32), rad/s (mechanical: without
 * the electrostatic softening). */
/* The sample clock runs fast by e (a crystal's error): the plant's physics see the
 * sample period 1/(fs (1 + e)), so every rate of the mechanics per sample (resonances,
 * their damping, the couplings: the generator's e-expansion) scales by
 * clock = 1 / (1 + e). The Coriolis term and the input forces keep true time: their
 * error is e itself (ppm of scale), against the resonance's e times 2Q of phase.
 * Re-discretises like mech_set_temp. -1 for a non-finite or non-positive clock. */
int mech_set_clock(mech_t *m, double clock);
double mech_wn1(const mech_t *m);
double mech_wn2(const mech_t *m);

/* Quality factors at the current structure temperature (the law cfg.q_law). */
double mech_q1(const mech_t *m);
double mech_q2(const mech_t *m);

/* The drifts of the couplings k_q (1/s^2) and d_q (1/s) on top of the configured ones,
 * at T0 (held until the next call). Non-finite values are ignored (returns -1). */
int mech_set_coupling_drift(mech_t *m, double dkq_per_s2, double ddq_per_s);

/* The electrodes' stiffness per unit mass over the coming samples (mech.h above): the
 * coupling k_yx (1/s^2, adds to k_q) and the softening k_e (1/s^2, >= 0, adds to
 * cfg.ke2_per_s2; held at the pull-in margin, flagged). Returns -1 (nothing changed)
 * for a non-finite value, |k_yx| > 1e9 or k_e < 0; 1 when k_e was held at the margin;
 * 0 otherwise. */
int mech_set_elec(mech_t *m, double kyx_per_s2, double ke_per_s2);

/* Rebase the electrodes' stiffness into the generator: the means since the last call
 * replace the generator's values when they have moved by the thresholds of the header
 * (a re-discretisation). Returns 1 when it re-discretised, 0 otherwise (also with no
 * samples since the last call), -2 if the exponential failed (blocks unchanged). */
int mech_elec_rebase(mech_t *m);

/* The sense-from-drive stiffness coupling now, per unit mass (1/s^2): k_q and its drift
 * at the structure temperature plus the electrodes' k_yx (the quadrature is this over
 * 2 wc). */
double mech_kyx_total(const mech_t *m);

/* The sense resonance now with the electrostatic softening (configured and electrodes'),
 * rad/s of the sample clock as mech_wn2; sqrt(wn2^2 - k_e). */
double mech_wn2_eff(const mech_t *m);

/* MECH_OUT_* of the laws held at an edge: the Q law at the present temperature, the
 * cubic terms and the pull-in margin since the last call (cleared). */
unsigned mech_laws_out(mech_t *m);

/* One-sided acceleration noise PSD of resonance 1 (drive) or 2 (sense) at the current temperature,
 * (m/s^2)^2/Hz (4-20): 4 kB T wn / (Q m). */
double mech_noise_psd(const mech_t *m, int resonance);

#endif /* PLANT_MECH_H */
