/* Drive amplitude and phase loops (thesis 6.4), one update per loop period dt_s
 * (gyro_tick: once per block of RATE_DECIM samples, 5 kHz; the loops close at tens of
 * Hz, and the LMSD's few hundred Hz of bandwidth leave nothing at 5 kHz to alias).
 * The caller may spread one update over several ticks (measurement of arg Z, phase PI,
 * amplitude loop, each on its own tick of the block, gyro_state.h) and turn the command into
 * voltages later still; the designer is told that delay (lag_samples).
 *
 * Measurement: the drive pickoff phasor Z = w_i + j w_q from the drive LMSD's weights
 * (gyro.h: the phasor convention). Amplitude |Z| by one VSQRT, phase arg(Z) by
 * fm_atan2f.
 *
 * Amplitude loop: e_A = A_set - |Z| (V). The thesis linearises the measured amplitude
 * around the setpoint, dA ~ d(A^2)/(2 A0) (6-24), and blames the overshoot of its real
 * loop on that approximation being far off during start-up. Here the exact |Z| is used
 * (a square root is one FPU instruction on the Cortex-M4F), and the PI's output is the
 * force amplitude f_cmd in units of Ks*V^2 rather than a voltage: the square law of the
 * electrostatic actuator (6-7) is then undone exactly by drive_synth (U = sqrt(f_cmd) for
 * half-frequency drive), so the loop sees the linear first-order plant of (6-12) at every
 * amplitude, and the clamped velocity-form PI cannot wind up while the drive is at its
 * limit during start-up. Together these remove the start-up overshoot.
 *
 * Phase loop: e_P = wrap(phase_set - arg Z) (rad); the PI output is the force phase P
 * (rad), whose effect on arg Z is one-to-one with the first-order lag of (6-17). The
 * wrapped error takes the shorter way to a new setpoint, so two setpoint changes can
 * walk P by more than a turn; a force phase is only defined modulo 2 pi, so P (the PI's
 * state with it) is kept within +-pi of its start value p_init by whole turns, and the
 * turn is reported (p_turn_rad) for the thermometer, which must not see it. The loop
 * thus never pins at a limit; drive synthesis takes the turns off its own phase
 * conversion with hysteresis (drive_synth.h).
 *
 * Amplitude setpoint changes slew (a new configuration sets the target; each update moves
 * the setpoint towards it by a constant factor). A step would leave the vibration at the
 * old amplitude while the over-amplitude trip (a multiple of the setpoint) already used
 * the new one: 0.349 V -> 0.2 V tripped at 1.5 x 0.2 V. The vibration cannot fall faster
 * than its free decay, rate 1/tau with tau = 2Q/wn (the force command stops at 0), so
 * the setpoint moves at DRIVE_AMP_SLEW_TAU / tau relative per second: a ramp that slow
 * is followed with a relative lag of at most DRIVE_AMP_SLEW_TAU, below the lowest trip
 * (sup.amp_trip_rel >= 1.2). tau is the amplitude PI's kp / ki (the designer puts the
 * zero on the plant pole); without an integral gain the rate is DRIVE_AMP_SLEW_MAX_PER_S.
 * The trip and the lock judgement use the slewed setpoint (inv_amp_set, kept with it
 * without a divide per update). The phase setpoint steps: P follows it within the phase
 * loop's bandwidth and no trip depends on it.
 *
 * Design (drive_loop_design): with the first-order plant K/(tau s + 1), tau = 2Q/wn
 * (6-12, 6-17), the PI zero is put on the plant pole (Ki/Kp = 1/tau), leaving the
 * open loop K Kp / (tau s): a first-order closed loop of bandwidth wc = K Kp / tau, with
 * no overshoot. The demodulator's lag (a first-order lag of bandwidth lmsd_bw), the
 * delay from the measured sample to the first DAC frame carrying the new command
 * (lag_samples), the one-sample DAC latency and the hold of the command between loop
 * updates (half a loop period on average) cost phase margin; wc is capped so that at
 * least 60 deg remain:
 *     PM = 90 - atan(wc / wd) - (lag + 1 + N/2) wc T   (deg, T = 1/fs, N = loop_decim).
 */
#ifndef DRIVE_LOOP_H
#define DRIVE_LOOP_H

#include <stdint.h>

#include "dsp/pi.h"
#include "gyro/drive_track.h" /* drive_notch */

/* What the loops are told (the designer, gyro_design): constant while they run. */
typedef struct {
  float dt_s;
  float amp_set_v; /* the amplitude setpoint's target (the loop slews to it) */
  float phase_set_rad;
  float amp_kp, amp_ki;     /* f_cmd (Ks*V^2) per V; per V*s */
  float phase_kp, phase_ki; /* rad per rad; per rad*s */
  float f_cmd_max_v2;       /* force command limit (u_max^2 for half-frequency drive) */
  float p_init_rad;
  /* Amplitude PI in position form (1) instead of the velocity form of pi.h (0): the
   * tracking drive's. At high Q the holding force is small (A_set / K, 0.02 Ks V^2 at
   * Q = 10^5) against the proportional term's response to the pickoff's ripple and noise
   * (kp = wc tau / K does not fall with Q), so the command keeps touching its lower limit
   * of zero force; the velocity form stores the clamped output as its integrator and so
   * ratchets upwards on every touch (the mean force rises above the holding force and the
   * amplitude creeps above its set point: +10 % in 0.3 s at Q = 10^4). The position form
   * integrates the unclamped error, its integrator clamped to the limits on its own: the
   * clipped command's mean then settles where the mean error is zero. */
  uint32_t amp_position;
  float notch_c2, notch_g; /* with amp_position: the ripple notch on |Z| (drive_track.h) */
  /* Derived (drive_loop_cfg_derive): */
  pi_coeffs_t amp, phase; /* the PIs' coefficients and limits */
  float inv_amp_set;      /* 1 / amp_set_v */
  float amp_slew_up;      /* per update: the setpoint x this while below the target ... */
  float amp_slew_down;    /* ... x this (1 / amp_slew_up) while above */
} drive_loop_cfg_t;

#define DRIVE_AMP_SLEW_TAU 0.15f
#define DRIVE_AMP_SLEW_MAX_PER_S 20.0f

/* What the loops remember. */
typedef struct {
  pi_t amp_pi;
  float amp_int;           /* the position form's integrator (amp_position), Ks V^2 */
  drive_notch_t amp_notch; /* the notch on |Z| (amp_position) */
  pi_t phase_pi;
  float amp_set_v;   /* setpoint the loop uses now, slewing towards the cfg's */
  float inv_amp_set; /* 1 / amp_set_v: the supervisor's reference */
  /* Latest measurement and outputs. */
  float amp_v;
  float phase_rad;
  float amp_err_v;
  float phase_err_rad;
  float f_cmd_v2;   /* force amplitude command, Ks*V^2 */
  float p_rad;      /* force phase P */
  float p_turn_rad; /* whole turn taken off P at the latest update (0: none), for the
                     * caller to act on and clear */
  float p_eq_rad;   /* the thermometer's phase: P in the fixed drive, the tracking drive's
                     * equivalent of P from its frequency (drive_track.h) */
} drive_loop_t;

typedef struct {
  double plant_gain;  /* K: loop output units -> measured units at resonance */
  double tau_s;       /* 2 Q / wn */
  double bw_hz;       /* wanted closed-loop bandwidth */
  double demod_bw_hz; /* LMSD bandwidth, (lmsd_bandwidth_hz) */
  double fs_hz;       /* sample rate */
  double loop_decim;  /* samples per loop update (the loop runs at fs / loop_decim and
                        * its output is held between updates); 0 or 1: every sample */
  double lag_samples; /* samples from the one whose demodulated phasor the loop measures
                        * to the first one whose DAC frame carries the resulting command
                        * (0: the same sample); the DAC's own latency of one sample comes
                        * on top */
} drive_loop_design_in_t;

typedef struct {
  double kp, ki;
  double bw_hz; /* achieved (after the phase-margin cap) */
  double phase_margin_deg;
} drive_loop_design_out_t;

/* PI gains for one loop (amplitude: K in V per Ks*V^2; phase: K = 1). Init-time, double.
 * Returns 0, or -1 for non-physical inputs. */
int drive_loop_design(const drive_loop_design_in_t *in, drive_loop_design_out_t *out);

/* Check cfg and fill in its derived fields (background). Returns 0, or -1 for a bad
 * configuration. */
int drive_loop_cfg_derive(drive_loop_cfg_t *cfg);

/* Start with the drive off (drive_loop_reset). */
void drive_loop_init(const drive_loop_cfg_t *cfg, drive_loop_t *dl);

/* A new configuration cfg takes over with the loop state kept (bumpless: new gains act
 * on the next increment; the PIs' outputs are clamped into the new limits); the
 * amplitude setpoint slews to its new target. dt_s must not change. */
void drive_loop_reconfigure(const drive_loop_cfg_t *cfg, drive_loop_t *dl);

/* Drive off: force command 0, P back to its start value, integrators cleared, the
 * amplitude setpoint at its target (a start from rest needs no slew). */
void drive_loop_reset(const drive_loop_cfg_t *cfg, drive_loop_t *dl);

/* One update: measurement from the drive LMSD's weights (w_i, w_q), then both PIs. */
void drive_loop_step(const drive_loop_cfg_t *cfg, drive_loop_t *dl, float w_i, float w_q);
/* The parts of drive_loop_step, for a caller that spreads them over several ticks:
 * the amplitude loop (|Z|, f_cmd) and the phase loop (arg Z, P; it uses the latest
 * amplitude to tell whether there is a vibration to measure), the latter itself in two
 * parts: the measurement (arg Z by fm_atan2f and its divide) and the update (the wrapped
 * error of the phase measured last, the PI). */
void drive_loop_step_amp(const drive_loop_cfg_t *cfg, drive_loop_t *dl, float w_i, float w_q);
void drive_loop_step_phase(const drive_loop_cfg_t *cfg, drive_loop_t *dl, float w_i, float w_q);
void drive_loop_measure_phase(drive_loop_t *dl, float w_i, float w_q);
/* The amplitude setpoint is still moving to its target. */
static inline int drive_loop_slewing(const drive_loop_cfg_t *cfg, const drive_loop_t *dl)
{
  return dl->amp_set_v != cfg->amp_set_v;
}
void drive_loop_update_phase(const drive_loop_cfg_t *cfg, drive_loop_t *dl);

#endif /* DRIVE_LOOP_H */
