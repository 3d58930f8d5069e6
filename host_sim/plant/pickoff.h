/* Pickoff front end of one axis (drive or sense), from its displacement to the voltage
 * at the ADC input at the sampling instant (thesis §4.3.2, §4.4.2; host plant, double).
 *
 * Signal chain (continuous time):
 *   s(t) = g(T) pos(t) + ft_u1 U1(t) + ft_u2 U2(t) + ft_spare U3(t)   ring-diode output
 *          g(T) = gain_v_per_m (1 + gain_tc_per_k (T - T0))          (4-12): gain ~ Vc - V_D
 *          (the factor is held at PICKOFF_GAIN_MIN_FACTOR below it, flagged
 *          PICKOFF_OUT_GAIN: the carrier no longer clears the diode drop)
 *          clipped at +-preamp_rail_v (preamp saturation, counted)
 *   -> circuit lag section, phase Phi_cir(T) at lag_ref_hz                  (2-40)
 *          Phi_cir(T) = phi0 + phi1 (T - T0) + 0.5 phi2 (T - T0)^2   (rad, lag positive)
 *          LAG_LOWPASS: 1 / (1 + s tau), tau = tan(Phi) / w_ref  (the ring diode's R//C
 *                       hold network, fig. 4-9: gain cos(Phi) at w_ref, drifts with it)
 *          LAG_ALLPASS: (1 - s tau) / (1 + s tau), tau = tan(Phi/2) / w_ref (pure phase)
 *          Below Phi = pm (PICKOFF_PHI_POLE_MIN_RAD) the pole's time constant would go to
 *          zero (and negative: unstable), so the law is continued with the pole held at
 *          its value at pm and a zero taking the rest of the phase (pickoff_lag_section):
 *          the lag passes through zero into a lead, phase -Phi exactly at w_ref, the
 *          filter identical to the lag's at pm. Low-pass: the lead-lag network
 *          (1 + s tz)/(1 + s tp), gain cos(pm)/cos(pm - Phi) at w_ref (about 1/cos(Phi),
 *          the mirror of the lag's cos(Phi)); all-pass: unit gain at w_ref kept.
 *          Range of the law: Phi in [pm - 1.4, 1.4] rad (low-pass), [pm/2 - 1.4, 2.8]
 *          (all-pass), i.e. leads to about 80 deg; beyond it the phase is held at the edge
 *          and flagged (PICKOFF_OUT_PHASE), which the plant counts as a warning.
 *   -> anti-alias band-pass (fig. 4-13): first-order high-pass at hp_hz (0: none)
 *      times second-order low-pass at lp_hz, quality lp_q.
 *          Why a band-pass: the useful band is 1-3 kHz; the low-pass keeps ~20 dB at
 *          25 kHz (8 kHz Butterworth: 19.8 dB), and the high-pass keeps slow
 *          acceleration/shaking signals (< 10 Hz, §4.4.2) from pushing the ADC out of
 *          range: a static 1 g on the sense axis moves the ring-diode output by
 *          ~3.8 V with the default gain, which the high-pass removes.
 *   -> + offset_v + white noise (noise_v_rthz, one-sided, as seen in the sampled data)
 *   -> sampled at t_k + sample_delay_s + jitter (jitter ~ N(0, jitter_rms_s^2), drawn
 *      per sample per channel).
 * Default phases at 1489.9 Hz: lag 3 deg, high-pass +3.8 deg, low-pass -15.3 deg.
 *
 * Electrical feedthrough: the electrode voltages couple into the ring-diode output
 * (§1.4.3 item 4, §6.3.2). Under half-frequency drive it sits at wc/2, which the
 * firmware's demodulation at wc rejects; under DC+AC it sits at wc, in band.
 *
 * Discretisation. The chain is one LTI system, state z (n = 3 or 4, time normalised to
 * the sample period T), z' = A z + B s, y = C z + D s. Between ticks the input s is the
 * cubic Hermite interpolant of its values and slopes at both ticks (the mechanics gives
 * displacement and velocity at the ticks, the DAC its output and slope), and the state
 * is advanced exactly for that cubic (augmented exponential):
 *   z_{k+1} = Phi z_k + G [s_k, T s'_k, s_{k+1}, T s'_{k+1}]^T
 * Interpolation error for a sinusoid: (wT)^4/384 = 3e-6 relative at 1.5 kHz, 50 kHz.
 * Feedthrough of the DAC's filtered staircase is interpolated the same way (its part
 * at wc under DC+AC comes out within 0.02 % of the closed form; see test_pickoff).
 *
 * Sampling instant: the output at t_k + d (d = sample_delay_s) is the Taylor series to
 * third order of the exact output, y^(j) = C A^j z + sum_i C A^(j-1-i) B s^(i) + D s^(j),
 * with the input derivatives of the last cubic: error (w d)^4 / 24 relative in steady
 * state (3e-6 at 1.5 kHz for d = 10 us). The series is folded into one row at each
 * discretisation, so the per-sample cost does not depend on d. Jitter e adds e y'(t_k + d)
 * (first order; the neglected e^2 y''/2 is (w sigma)^2/2 = 4e-5 relative at the largest
 * allowed sigma, T/20): on a sine of amplitude a, noise of rms a w sigma / sqrt(2).
 *
 * Imperfections of the front end, each off at zero:
 *   Capacitive nonlinearity (gap_m > 0). The ring diode demodulates the difference of
 *   the two sense capacitances (§4.3.2). Parallel plates at gap d: C+- = C0 d / (d -+ x),
 *   so dC+ = C0 u / (1 - u), dC- = -C0 u / (1 + u), u = x / d (Senturia, Microsystem
 *   Design, Kluwer 2001, §6.4; Kaajakari et al., J. Microelectromech. Syst. 13 (2004)
 *   715, the capacitive nonlinearity of a resonator's readout). A perfectly balanced pair
 *   reads (dC+ - dC-) / 2 = C0 (u + u^3 + ...), odd orders only; an imbalance beta
 *   between the two sides (1: one-sided) adds beta (dC+ + dC-) / 2 = C0 beta (u^2 + ...).
 *   To third order the displacement read is
 *       x_read = x (1 + beta u + u^2),   u = x / d,   beta = gap_asym,
 *   within 1 % of the parallel-plate law for |u| <= PICKOFF_GAP_MAX_U; beyond, u is held
 *   at the edge and flagged (PICKOFF_OUT_GAP). On a sine of amplitude A: second harmonic
 *   beta A^2 / (2 d) (and as much DC), third A^3 / (4 d^2), fundamental up 3 A^2 / (4 d^2).
 *   Gain flicker (gain_flicker_1hz_rthz > 0): the ring diode's gain follows Vc - V_D
 *   (4-12), and the carrier amplitude and the diodes' drop carry 1/f noise (diode and
 *   resistor flicker, F. N. Hooge, Phys. Lett. 29A (1969) 139): g(t) = g (1 + n_g(t)),
 *   n_g relative with one-sided PSD K^2 / f from flicker_fmin_hz up (white above fs/20),
 *   applied to the displacement term (not to the feedthrough).
 *   Phase flicker (phase_flicker_1hz_rad_rthz > 0): the lag network's R and C carry the
 *   same 1/f fluctuation, so Phi_cir wanders by n_p(t) rad (PSD K^2 / f). Realised as a
 *   fluctuation of the chain's delay, n_p / w_ref at the reference frequency (lag_ref_hz:
 *   the drive frequency, where both channels' signals are): the output sampled at
 *   t - n_p / w_ref, to first order y - (n_p / w_ref) y' (the jitter's derivative row),
 *   without re-discretising; error (n_p)^2 / 2 relative, 2e-6 at 0.1 deg.
 *   These two are the low-frequency gain and phase noise that turn into scale-factor
 *   and bias instability (the sense phase through the quadrature, §2.4.2 B).
 *   Timing: pickoff_step_at() samples the output dt_s later (the ADC's aperture jitter,
 *   common to both channels; adc.h), to first order through the slope as the jitter.
 *
 * Temperature: pickoff_set_temp() updates the gain at once and re-discretises the chain
 * (about 5-10 us) only when Phi_cir has moved by phase_step_rad or more since the last
 * discretisation; it may be called every sample. The default step, 1e-6 rad, is a bias
 * step of 1.5e-3 deg/s on 1500 deg/s of quadrature (0.57 mK at 0.1 deg/K); a 10 K/min
 * ramp then re-discretises about 300 times per simulated second.
 *
 * Noise streams: rng_seed(seed, PICKOFF_RNG_STREAM_NOISE + axis) for the white noise,
 * rng_seed(seed, PICKOFF_RNG_STREAM_JITTER + axis) for the jitter, _GAIN_FLICKER + axis
 * and _PHASE_FLICKER + axis for the flicker (drawn only when on).
 */
#ifndef PLANT_PICKOFF_H
#define PLANT_PICKOFF_H

#include <stdint.h>

#include "plant/dac.h"
#include "plant/flicker.h"
#include "plant/gauss_zig.h"
#include "plant/rng.h"

#define PICKOFF_RNG_STREAM_NOISE 0x7001u         /* + axis */
#define PICKOFF_RNG_STREAM_JITTER 0x7011u        /* + axis */
#define PICKOFF_RNG_STREAM_GAIN_FLICKER 0x7021u  /* + axis */
#define PICKOFF_RNG_STREAM_PHASE_FLICKER 0x7031u /* + axis */
#define PICKOFF_MAX_N 4

/* Ranges of the temperature laws (see the top of this file). */
#define PICKOFF_PHI_POLE_MIN_RAD 1e-4 /* smallest lag realised by the pole alone */
#define PICKOFF_LAG_MAX_LOWPASS_RAD 1.4
#define PICKOFF_LAG_MAX_ALLPASS_RAD 2.8
#define PICKOFF_LEAD_MIN_LOWPASS_RAD (PICKOFF_PHI_POLE_MIN_RAD - 1.4)
#define PICKOFF_LEAD_MIN_ALLPASS_RAD (0.5 * PICKOFF_PHI_POLE_MIN_RAD - 1.4)
#define PICKOFF_GAIN_MIN_FACTOR 0.1
#define PICKOFF_GAP_MAX_U 0.3 /* |x| / d of the third-order capacitive law */
/* flags of a law held at the edge of its range (pickoff_t.out_of_range) */
#define PICKOFF_OUT_PHASE 1u
#define PICKOFF_OUT_GAIN 2u
#define PICKOFF_OUT_GAP 4u /* since the last pickoff_gap_out */

typedef enum { PICKOFF_DRIVE = 0, PICKOFF_SENSE = 1 } pickoff_axis_t;
typedef enum { PICKOFF_LAG_LOWPASS = 0, PICKOFF_LAG_ALLPASS = 1 } pickoff_lag_kind_t;

typedef struct {
  pickoff_axis_t axis;
  double fs_hz;
  /* ring-diode front end */
  double gain_v_per_m;  /* output volts per metre of displacement at T0 */
  double gain_tc_per_k; /* relative gain change per kelvin (diode drop); 0 default */
  double preamp_rail_v; /* preamp output saturates at +-this, V (> 0) */
  double ft_u1;         /* feedthrough, V at the preamp output per V on U1 */
  double ft_u2;         /* ... per V on U2 */
  double ft_spare;      /* ... per V on the spare (sense feedback) DAC channel */
  /* circuit phase (2-40) */
  pickoff_lag_kind_t lag_kind;
  double lag_ref_hz;      /* frequency at which the lag equals Phi_cir (drive freq) */
  double temp_ref_k;      /* T0 */
  double phi0_rad;        /* Phi_cir(T0), lag positive */
  double phi1_rad_per_k;  /* dPhi/dT at T0 */
  double phi2_rad_per_k2; /* d2Phi/dT2 at T0 */
  /* anti-alias band-pass */
  double hp_hz; /* first-order high-pass corner; 0: none */
  double lp_hz; /* second-order low-pass natural frequency */
  double lp_q;  /* its quality factor */
  /* ADC input */
  double offset_v;       /* added after the filters, V */
  double noise_v_rthz;   /* white, one-sided, V/sqrt(Hz) */
  double sample_delay_s; /* fixed sampling instant after the tick, |.| <= T/2 */
  double jitter_rms_s;   /* rms random timing error, <= T/20 */
  double phase_step_rad; /* Phi_cir change that triggers a re-discretisation, >= 0 */
  /* imperfections (see the top), 0: off */
  double gap_m;                      /* parallel-plate gap d of the capacitive pickoff */
  double gap_asym;                   /* imbalance beta of the pair, 0..1 */
  double gain_flicker_1hz_rthz;      /* relative gain 1/f density at 1 Hz, 1/sqrt(Hz) */
  double phase_flicker_1hz_rad_rthz; /* circuit phase 1/f density at 1 Hz, rad/sqrt(Hz) */
  double flicker_fmin_hz;            /* both flicker spectra flatten below this */
} pickoff_cfg_t;

typedef struct {
  pickoff_cfg_t cfg;
  int n;                       /* states in use (3 or 4; the rest stay zero) */
  double t_s, inv_t;           /* sample period and its inverse */
  double temp_k;               /* circuit temperature now */
  double phi_rad;              /* Phi_cir realised by the current discretisation */
  uint64_t rediscretise_count; /* re-discretisations by pickoff_set_temp */
  double gain_now;             /* g(temp_k) */
  unsigned out_of_range;       /* PICKOFF_OUT_* of the laws at temp_k */
  double phi[PICKOFF_MAX_N][PICKOFF_MAX_N];
  double g[PICKOFF_MAX_N][4];
  double out_z[PICKOFF_MAX_N];  /* output at the nominal sampling instant: state row */
  double out_u[4];              /* ... and weights of [s, T s', T^2 s'', T^3 s'''] */
  double dout_z[PICKOFF_MAX_N]; /* T d(output)/dt there (for the jitter): state row */
  double dout_u[4];             /* ... input weights */
  double z[PICKOFF_MAX_N];
  double s_prev, m_prev; /* input and T * slope at the previous tick */
  double noise_sd;
  rng_t rng_noise, rng_jitter;
  uint64_t preamp_clip_count;
  /* imperfections */
  int gap_on, gain_fl_on, phase_fl_on;
  double inv_gap;         /* 1 / d */
  double inv_wref;        /* 1 / (2 pi lag_ref_hz), s/rad */
  double gain_noise;      /* n_g of the last sample */
  double phase_noise_rad; /* n_p of the last sample */
  unsigned gap_out;       /* PICKOFF_OUT_GAP since the last pickoff_gap_out */
  flicker_t gain_fl, phase_fl;
} pickoff_t;

/* Defaults for one axis (thesis linear gyro, 1489.9 Hz drive, 50 kHz):
 *   drive: 3.0e5 V/m (10 um -> 2.99 V at the ADC), feedthrough U1 2e-4, U2 -1.5e-4,
 *          phi0 3 deg, phi1 0.01 deg/K, offset +5 mV, sampled at the tick;
 *   sense: 6.18e7 V/m, so 1 deg/s of Coriolis motion (4.06e-11 m at 10 um drive
 *          amplitude, (2-28)) gives 2.5 mV at the ADC (§4.6.1) and 1500 deg/s of
 *          quadrature 3.75 V; feedthrough U1 1e-4, U2 6e-5, spare 1e-3, phi0 3 deg,
 *          phi1 0.1 deg/K (table 7-4), offset -3 mV, sampled 4 us after the drive
 *          channel (multiplexed converter);
 *   both: low-pass lag referred to 1489.9 Hz, T0 298.15 K, high-pass 100 Hz, low-pass
 *         8 kHz Butterworth, preamp rail 13.5 V, noise 2 uV/sqrt(Hz), no jitter,
 *         phase step 1e-6 rad.
 * The feedthrough, offsets, phases and noise are placeholders for calibration. */
void pickoff_default_cfg(pickoff_cfg_t *cfg, pickoff_axis_t axis);

/* Validates cfg, discretises at the circuit temperature temp_k, zero state, seeds the
 * noise and jitter sources. Returns 0, or -1 (bad cfg or non-finite temperature) with
 * p unchanged. A law outside its range at temp_k is held at its edge and flagged in
 * p->out_of_range. */
int pickoff_init(pickoff_t *p, const pickoff_cfg_t *cfg, double temp_k, uint64_t seed);

/* New circuit temperature (K): the gain follows at once, Phi_cir (2-40) to within
 * phase_step_rad. Returns the PICKOFF_OUT_* flags of the laws held at an edge (0 when
 * both are in range), or -1 if temp_k is not finite (p then unchanged). */
int pickoff_set_temp(pickoff_t *p, double temp_k);

/* Phi kept to the range of the lag section of kind; *outside (may be NULL) is set to 1
 * if it had to move (a non-finite Phi gives 0 rad). */
double pickoff_phi_clamp(pickoff_lag_kind_t kind, double phi_rad, int *outside);

/* Gain factor 1 + tc dT of (4-12), held at PICKOFF_GAIN_MIN_FACTOR below it (*outside). */
double pickoff_gain_factor(double tc_per_k, double dt_k, int *outside);

/* The lag section at phase phi_rad (in range) as (b0 + j x b1_w)/(1 + j x tp_w) with
 * x = f / lag_ref_hz: its phase at x = 1 is -phi_rad. */
void pickoff_lag_section(pickoff_lag_kind_t kind, double phi_rad, double *b0, double *b1_w,
                         double *tp_w);

/* Advance one sample to tick t_{k+1}: pos_m, vel_mps are the axis displacement and
 * velocity at t_{k+1}; dac the DAC output of the sample just finished (its end values
 * are the electrode voltages at t_{k+1}), or NULL for no feedthrough. Returns the
 * voltage at the ADC input sampled at t_{k+1} + delay + jitter. */
double pickoff_step(pickoff_t *p, double pos_m, double vel_mps, const dac_out_t *dac);

/* The same, the output sampled dt_s later (|dt_s| well below T/2; first order). */
double pickoff_step_at(pickoff_t *p, double pos_m, double vel_mps, const dac_out_t *dac,
                       double dt_s);

/* PICKOFF_OUT_GAP if the capacitive law was held at its edge since the last call (cleared). */
unsigned pickoff_gap_out(pickoff_t *p);

#endif /* PLANT_PICKOFF_H */
