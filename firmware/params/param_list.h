/* THE parameter list: the only place a parameter is declared. The value struct, the
 * metadata table, the CLI (list/get/set/diff/help), the flash image records and the host
 * tool's view (it reads `list`) all derive from these rows; adding a parameter is adding
 * one row.
 *
 * Row: X(sym, id, name, TYPE, unit, min, max, default, choices, flags, help)
 *   sym      C member of param_values_t (the ISR reads p->sym)
 *   id       stable 16-bit record id in flash, group << 8 | n. Never reuse or renumber an
 *            id; a parameter whose meaning or unit changes gets a new id (the old one is
 *            then dropped on load and the new one starts from its default).
 *   name     CLI name: dotted group, snake_case, unit suffix (_hz, _v, _deg, _dps, ...)
 *   TYPE     F32 (float), U32 (uint32_t), ENUM (uint32_t restricted to `choices`; a
 *            bool is ENUM with choices {0,1})
 *   unit     printed by `list`; "-" for dimensionless
 *   min,max  inclusive valid range (for ENUM: lowest and highest choice)
 *   choices  ENUM only: bit mask of allowed values (PARAM_CHOICE(v) | ...), else 0
 *   flags    PF_PERSIST saved to flash; PF_READONLY `set` refused; PF_LIVE may change
 *            while the drive runs (others need the loop in a safe mode); PF_RESTART
 *            the application reads it only at start-up (applies after a restart)
 *   help     one line for `list`
 *
 * Bump PARAM_LAYOUT_VERSION whenever a row is added or removed; it is written into
 * flash images for diagnosis (loading migrates by id, not by this number).
 *
 * The drive loops are designed by the firmware (gyro/drive_loop.h) from the identified
 * drive-resonance model (drive.cal_*: resonance, Q, gain, found by the self-calibration
 * sweep) for the bandwidths drive.amp_bw_hz / drive.phase_bw_hz; nonzero manual gains
 * drive.amp_kp ... override the design.
 *
 * Defaults are generic: the part family's design values (thesis §2: drive 1750 Hz,
 * Q1 50), never values identified on a part. A part's own values (the sweep's drive
 * model, the rate table's demodulation phase and scale, the self-test expectations,
 * the temperature compensation) come from its calibration (tools/calibrate, loaded with
 * gyroctl load-params), which records the drive frequency it was made at in
 * cal.ref_freq_hz: without it the part says `calibrated no` and its rate is never valid
 * (rate_valid.h, UNCALIBRATED).
 */
#ifndef PARAM_LIST_H
#define PARAM_LIST_H

#include "board.h" /* sys.fs_hz: the board's sample rate */

#define PARAM_LAYOUT_VERSION 21u

#define PARAM_CHOICE(v) (1u << (v))

/* clang-format off */
#define PARAM_LIST(X) \
  /* the family's design resonance (thesis §2: 1750 Hz); the sweep finds the part's */ \
  X(drive_freq_hz, 0x0101u, "drive.freq_hz", F32, "Hz", 500.0f, 5000.0f, 1750.0f, 0u, \
    PF_PERSIST | PF_LIVE, "drive frequency, fixed near the drive resonance found by the sweep") \
  /* half-frequency by default: 1/f voltage noise lands at wc/2, not wc (6-21, 6-23) */ \
  X(drive_mode, 0x0102u, "drive.mode", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST, "drive scheme: 0 half-frequency (6-18), 1 DC+AC (6-20); drive off to change") \
  /* 10 um of drive motion (4.6.1) at the default plant's 3.49e4 V/m drive pickoff */ \
  X(drive_amp_set_v, 0x0103u, "drive.amp_set_v", F32, "V", 0.01f, 4.5f, 0.349f, 0u, \
    PF_PERSIST | PF_LIVE, "setpoint of the demodulated drive-pickoff amplitude at the ADC") \
  /* the phase of the drive pickoff against the NCO; any value works, P absorbs it */ \
  X(drive_phase_set_deg, 0x0104u, "drive.phase_set_deg", F32, "deg", -180.0f, 180.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "setpoint of the drive pickoff phase against the NCO reference") \
  /* 0: designed from drive.cal_* (6-12); nonzero overrides the design */ \
  X(drive_amp_kp, 0x0105u, "drive.amp_kp", F32, "V^2/V", 0.0f, 100000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "amplitude PI proportional gain, force (Ks V^2) per volt; 0 = designed") \
  /* 0: designed, ki = kp / tau puts the PI zero on the amplitude pole */ \
  X(drive_amp_ki, 0x0106u, "drive.amp_ki", F32, "V^2/V/s", 0.0f, 1.0e7f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "amplitude PI integral gain; 0 = designed") \
  /* 0: designed from the unit-gain phase plant (6-17) */ \
  X(drive_phase_kp, 0x0107u, "drive.phase_kp", F32, "rad/rad", 0.0f, 1000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "phase PI proportional gain (force phase per phase error); 0 = designed") \
  /* 0: designed */ \
  X(drive_phase_ki, 0x0108u, "drive.phase_ki", F32, "rad/rad/s", 0.0f, 1.0e6f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "phase PI integral gain; 0 = designed") \
  /* table 7-1: 12.75 V drive amplitude; 15 V is the output stage's limit */ \
  X(drive_u_max_v, 0x0109u, "drive.u_max_v", F32, "V", 0.1f, 15.0f, 12.75f, 0u, \
    PF_PERSIST | PF_LIVE, "limit of each drive electrode voltage (PI output clamp)") \
  /* DC+AC only: force = 4 Ks D A (6-21); 5 V leaves headroom under u_max for A */ \
  X(drive_dc_bias_v, 0x010Au, "drive.dc_bias_v", F32, "V", 0.0f, 15.0f, 5.0f, 0u, \
    PF_PERSIST | PF_LIVE, "DC bias D of the DC+AC drive (unused in half-frequency mode)") \
  /* P at lock is the circuits' lags at resonance, unknown before the sweep measures it
   * (its hold phase); acquisition pulls in from 0 */ \
  X(drive_p_init_deg, 0x010Bu, "drive.p_init_deg", F32, "deg", -360.0f, 360.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "force phase P the phase loop starts from, and the reference of P's low-pass") \
  /* the design resonance until the sweep identifies the part's */ \
  X(drive_cal_f0_hz, 0x010Cu, "drive.cal_f0_hz", F32, "Hz", 100.0f, 20000.0f, 1750.0f, 0u, \
    PF_PERSIST | PF_LIVE, "identified undamped drive resonance (self-calibration)") \
  /* the design Q of the air package (thesis §2: 50) until the sweep identifies it */ \
  X(drive_cal_q, 0x010Du, "drive.cal_q", F32, "-", 1.0f, 1.0e6f, 50.0f, 0u, \
    PF_PERSIST | PF_LIVE, "identified drive-mode quality factor") \
  /* the design transducers (table 7-1: 8 V of drive for 10 um, 3.49e4 V/m of pickoff) at
   * the design Q 50: the gain grows as Q (6-12); the sweep measures the part's */ \
  X(drive_cal_gain_v_per_v2, 0x010Eu, "drive.cal_gain_v_per_v2", F32, "V/V^2", 1.0e-6f, 100.0f, 0.0082f, 0u, \
    PF_PERSIST | PF_LIVE, "identified drive gain at resonance, pickoff volts per Ks V^2 of force") \
  /* 30 Hz: 1 % in about 25 ms after the drive comes off its limit, 80 deg of margin */ \
  X(drive_amp_bw_hz, 0x010Fu, "drive.amp_bw_hz", F32, "Hz", 0.1f, 1000.0f, 30.0f, 0u, \
    PF_PERSIST | PF_LIVE, "designed closed-loop bandwidth of the amplitude loop") \
  /* as the amplitude loop */ \
  X(drive_phase_bw_hz, 0x0110u, "drive.phase_bw_hz", F32, "Hz", 0.1f, 1000.0f, 30.0f, 0u, \
    PF_PERSIST | PF_LIVE, "designed closed-loop bandwidth of the phase loop (tracking: of the PLL)") \
  /* fixed by default: the air-damped default part (Q 33) is calibrated in it, and it \
   * holds Q <= 5000; the sweep selects tracking beyond (gyro/drive_track.h) */ \
  X(drive_track, 0x0111u, "drive.track", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST, "0 fixed frequency, phase PI on P (Q <= 5000); 1 tracking PLL on the frequency") \
  /* 5.4: mu = 0.034 at 50 kHz; |r| = 1 makes it a normalised step (5-5) */ \
  X(demod_mu_drive, 0x0201u, "demod.mu_drive", F32, "-", 0.0001f, 0.49f, 0.034f, 0u, \
    PF_PERSIST | PF_LIVE, "LMS demodulator step size, drive pickoff (sets its bandwidth)") \
  /* same bandwidth as the drive channel */ \
  X(demod_mu_sense, 0x0202u, "demod.mu_sense", F32, "-", 0.0001f, 0.49f, 0.034f, 0u, \
    PF_PERSIST | PF_LIVE, "LMS demodulator step size, sense pickoff") \
  /* a part's own (sense resonance and pickoff lags): its rate table measures it
   * (tools/gyro-demodcal); 0 until then */ \
  X(rate_demod_phase_deg, 0x0301u, "rate.demod_phase_deg", F32, "deg", -180.0f, 180.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "angle of the Coriolis phasor against the drive phasor (separates rate from quadrature)") \
  /* 5.4.3: 100 Hz output low-pass */ \
  X(rate_lpf_cutoff_hz, 0x0302u, "rate.lpf_cutoff_hz", F32, "Hz", 1.0f, 1000.0f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "rate output low-pass cut-off (Butterworth, run at fs/10)") \
  /* 5.4.3: 4th order as two biquads (5-12, 5-13) */ \
  X(rate_lpf_order, 0x0303u, "rate.lpf_order", ENUM, "-", 2u, 8u, 4u, \
    PARAM_CHOICE(2) | PARAM_CHOICE(4) | PARAM_CHOICE(6) | PARAM_CHOICE(8), \
    PF_PERSIST | PF_LIVE, "rate output low-pass order (2 per biquad section)") \
  /* a part's own: its rate table measures it (tools/gyro-demodcal); 100 only sizes the
   * monitors' quadrature until then (the rate is not valid without a calibration) */ \
  X(rate_scale_dps, 0x0310u, "rate.scale_dps", F32, "deg/s", -1.0e7f, 1.0e7f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale factor: deg/s per unit of the sense/drive phasor ratio") \
  /* uncalibrated: 0 (the thesis part's fit was B = 34.59 P + 58.533, 7.3.2) */ \
  X(rate_bias_c0_dps, 0x0305u, "rate.bias_c0_dps", F32, "deg/s", -2000.0f, 2000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial B(x) = c0 + c1 x + c2 x^2 + c3 x^3 in x = P_c - cal.ref_p_deg, constant term") \
  /* uncalibrated: 0 */ \
  X(rate_bias_c1_dps_per_deg, 0x0306u, "rate.bias_c1_dps_per_deg", F32, "deg/s/deg", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial, linear term in x (deg)") \
  /* uncalibrated: 0 */ \
  X(rate_bias_c2_dps_per_deg2, 0x0307u, "rate.bias_c2_dps_per_deg2", F32, "deg/s/deg^2", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial, quadratic term") \
  /* uncalibrated: 0 */ \
  X(rate_bias_c3_dps_per_deg3, 0x0308u, "rate.bias_c3_dps_per_deg3", F32, "deg/s/deg^3", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial, cubic term") \
  /* uncalibrated: 0, scale factor independent of temperature */ \
  X(rate_sf_c1_per_deg, 0x0309u, "rate.sf_c1_per_deg", F32, "1/deg", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial SF(x) = 1 + c1 x + .. + c4 x^4, linear term") \
  /* uncalibrated: 0 */ \
  X(rate_sf_c2_per_deg2, 0x030Au, "rate.sf_c2_per_deg2", F32, "1/deg^2", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial, quadratic term") \
  /* uncalibrated: 0 */ \
  X(rate_sf_c3_per_deg3, 0x030Bu, "rate.sf_c3_per_deg3", F32, "1/deg^3", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial, cubic term") \
  /* uncalibrated: 0. The default part's scale factor peaks near room temperature and
   * falls 0.8 % at -40 and 1.2 % at 85 degC: a cubic in x leaves 390 ppm, a quartic 110 */ \
  X(rate_sf_c4_per_deg4, 0x0318u, "rate.sf_c4_per_deg4", F32, "1/deg^4", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial, quartic term") \
  /* uncalibrated: 0, the output linear in the sense pickoff's in-phase signal */ \
  X(rate_lin_c2_per_dps, 0x0319u, "rate.lin_c2_per_dps", F32, "1/(deg/s)", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "linearisation u + c2 u^2 + c3 u^3 of the uncompensated rate u, quadratic term") \
  /* uncalibrated: 0 */ \
  X(rate_lin_c3_per_dps2, 0x031Au, "rate.lin_c3_per_dps2", F32, "1/(deg/s)^2", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "linearisation, cubic term") \
  /* temperature is slow; 1 Hz keeps the phase loop's noise out of the bias correction */ \
  X(rate_p_lpf_hz, 0x030Cu, "rate.p_lpf_hz", F32, "Hz", 0.01f, 50.0f, 1.0f, 0u, \
    PF_PERSIST | PF_LIVE, "low-pass of P before it is used as the temperature") \
  /* 7.2.4: 7.25 mV/(deg/s) at the analog output */ \
  X(rate_out_v_per_dps, 0x030Du, "rate.out_v_per_dps", F32, "V/(deg/s)", -1.0f, 1.0f, 0.00725f, 0u, \
    PF_PERSIST | PF_LIVE, "analog rate output scale on the DAC") \
  /* outside the valid span (full scale x out_v_per_dps: 2.2 V), inside the DAC's 15 V:
   * a failed gyro never reads as one at rest (0 V), as automotive rate sensors do */ \
  X(rate_fault_out_v, 0x030Eu, "rate.fault_out_v", F32, "V", -14.0f, 14.0f, -10.0f, 0u, \
    PF_PERSIST | PF_LIVE, "analog rate output whenever the rate is not valid") \
  /* the thesis's +-300 deg/s range (its rate table stops at 160) */ \
  X(rate_full_scale_dps, 0x030Fu, "rate.full_scale_dps", F32, "deg/s", 1.0f, 10000.0f, 300.0f, 0u, \
    PF_PERSIST | PF_LIVE, "full scale: above it the rate is flagged over range and not valid") \
  /* a quarter of the 1 deg/s the output-integrity battery allows, each source alone */ \
  X(rate_valid_tol_dps, 0x0311u, "rate.valid_tol_dps", F32, "deg/s", 0.01f, 100.0f, 0.25f, 0u, \
    PF_PERSIST | PF_LIVE, "largest rate error a monitored source (phase, thermometer, settling) may leave while valid") \
  /* the shipped values carry no temperature compensation: on the default plant the bias
   * moves 34.9 (deg/s)/deg of P (0.0765 deg/K), so they hold within 1 deg/s only for
   * 0.025 deg of P (+-0.33 K) around the thermometer's reference; a temperature
   * calibration widens it to the range it was fitted over.
   * The tracking drive's thermometer is p_eq (drive_track.h), (2Q/f0) rad per Hz of the
   * tracked resonance: 25 deg/K at Q 2e4, its 0.5 % window 57000 deg at Q 1e5 */ \
  X(rate_p_range_deg, 0x0312u, "rate.p_range_deg", F32, "deg", 0.001f, 100000.0f, 0.025f, 0u, \
    PF_PERSIST | PF_LIVE, "thermometer range: largest |P_f - cal.ref_p_deg| the compensation holds for") \
  /* 0.05 deg/s of P: 0.65 K/s on the air part, far above any thermal ramp it was run on;
   * the calibration flow sets the part's own (its thermometer's slope x 0.65 K/s) */ \
  X(rate_p_slew_max_deg_s, 0x0313u, "rate.p_slew_max_deg_s", F32, "deg/s", 0.001f, 10000.0f, 0.05f, 0u, \
    PF_PERSIST | PF_LIVE, "thermometer slew: P_f moving faster than this makes the rate not valid") \
  /* uncalibrated: 0, no gradient term. The calibration flow fits it on its chamber run's
   * transitions, where the structure and the pickoff circuit part (tools/calibrate) */ \
  X(rate_bias_grad_dps_per_deg, 0x0314u, "rate.bias_grad_dps_per_deg", F32, "deg/s/deg", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias gradient term: deg/s per degree of P_f above its low-pass over rate.grad_tau_s") \
  /* a minute: of the order of the structure-to-circuit heat exchange (the flow picks the \
   * part's own) */ \
  X(rate_grad_tau_s, 0x0315u, "rate.grad_tau_s", F32, "s", 1.0f, 100000.0f, 60.0f, 0u, \
    PF_PERSIST | PF_LIVE, "time constant of the gradient term's low-pass of P_f") \
  /* uncalibrated: 0. The reciprocal Coriolis force of the sense motion (the quadrature's,
   * 1500 deg/s on the default design) on the drive mode turns the drive phase in
   * proportion to the rate; read as temperature it would move the compensation with the
   * rate (a scale-factor error of slope x this). The flow measures it on its rate table */ \
  X(rate_p_rate_deg_per_dps, 0x0316u, "rate.p_rate_deg_per_dps", F32, "deg/(deg/s)", -0.01f, 0.01f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "drive phase P per deg/s of rate, taken out of P before it is the thermometer") \
  /* uncalibrated: 0. That turn moves with temperature (the sense motion's phase to the
   * drive's is the circuits'): on the 1300 Hz, Q 200 part from -9.4e-5 deg/(deg/s) at
   * -40 degC to +6.6e-5 at 85 about its 25 degC value, a scale-factor error of 540 ppm
   * at -25 degC at its bias slope. The flow fits it from its chamber run's rate steps */ \
  X(rate_p_rate_c1_per_dps, 0x031Bu, "rate.p_rate_c1_per_dps", F32, "deg/(deg/s)/deg", -0.001f, 0.001f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "change of rate.p_rate_deg_per_dps per degree of the thermometer's deviation x") \
  /* uncalibrated: 0. The rate's own sense motion turns P as well, with its square (both
   * senses of rotation alike): on the default part 2.5e-3 deg at +-270 deg/s, 0.09 deg/s
   * of output at its bias slope, coming and going with the compensation's lags after
   * each change of rate. The flow measures it on its rate table */ \
  X(rate_p_rate2_deg_per_dps2, 0x031Cu, "rate.p_rate2_deg_per_dps2", F32, "deg/(deg/s)^2", -0.001f, 0.001f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "drive phase P per (deg/s)^2 of rate, taken out of P with the linear turn") \
  /* 0: the compensation reads P_f itself. The thermometer's own noise (the drive loop's
   * phase noise) goes into the output at the bias slope; a slower thermometer for the
   * compensation alone (the monitors keep P_f) takes it out, and its lag is the
   * calibration's to model: the flow fits the gradient term with it in place */ \
  X(rate_comp_tau_s, 0x0317u, "rate.comp_tau_s", F32, "s", 0.0f, 1000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "low-pass time constant of P_f for the compensation's polynomials (0: P_f itself)") \
  /* 1: one stage (the sets made before this parameter). The thermometer's noise is the
   * drive pickoff's phase flicker (1/f): each stage takes it down by another 1/f above
   * 1 / (2 pi rate.comp_tau_s), so that the compensation's output noise at 10 s stays
   * within 1.1x the uncompensated; the ramp lag (stages x rate.comp_tau_s) is the
   * gradient term's to take, fitted with them in place (docs/compensation-noise.md) */ \
  X(rate_comp_stages, 0x031Du, "rate.comp_stages", U32, "-", 1u, 3u, 1u, 0u, \
    PF_PERSIST | PF_LIVE, "first-order stages of rate.comp_tau_s in the compensation's low-pass of P_f") \
  /* 0: no fast path, the compensation is the slow thermometer's alone (the sets made
   * before this parameter). A slow thermometer (stages x rate.comp_tau_s of lag) keeps the
   * phase flicker out at 10 s but lags a fast transient (a cool-down's start), which its
   * gradient term takes back only for a steady rate of change: a second, fast
   * thermometer of one stage with its own gradient term carries the output while the two
   * disagree (rate.comp_blend_dps) */ \
  X(rate_comp_fast_tau_s, 0x031Eu, "rate.comp_fast_tau_s", F32, "s", 0.0f, 1000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "the fast compensation path's one low-pass of P_f (0: no fast path)") \
  /* uncalibrated: 0. Fitted by the flow with the fast thermometer in place, the same
   * polynomial and rate.grad_tau_s */ \
  X(rate_grad_fast_dps_per_deg, 0x031Fu, "rate.grad_fast_dps_per_deg", F32, "deg/s/deg", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "the fast path's gradient term: deg/s per degree of its P_c above its low-pass") \
  /* 0.1 deg/s: half the bias a compensation is held to (+-0.2 deg/s over temperature), so
   * that where the blend departs from the fast path it is by less than that; the flow sets
   * the part's own (4 sd of the two paths' difference at rest, within 0.02..0.1) */ \
  X(rate_comp_blend_dps, 0x0320u, "rate.comp_blend_dps", F32, "deg/s", 0.001f, 10.0f, 0.1f, 0u, \
    PF_PERSIST | PF_LIVE, "slow path while the fast one agrees within this; the fast path beyond twice this") \
  /* 50 % over the setpoint: beyond any PI overshoot, short of the stops */ \
  X(sup_amp_trip_rel, 0x0401u, "sup.amp_trip_rel", F32, "-", 1.2f, 5.0f, 1.5f, 0u, \
    PF_PERSIST | PF_LIVE, "over-amplitude trip, as a multiple of drive.amp_set_v") \
  /* "within 1 % of its setpoint" (issue figure); well above the amplitude noise */ \
  X(sup_lock_tol_rel, 0x0402u, "sup.lock_tol_rel", F32, "-", 0.001f, 0.1f, 0.01f, 0u, \
    PF_PERSIST | PF_LIVE, "LOCKED when the relative amplitude error stays within this") \
  /* 1 deg: P settles to a fraction of that in a few loop time constants */ \
  X(sup_lock_phase_tol_deg, 0x0403u, "sup.lock_phase_tol_deg", F32, "deg", 0.01f, 90.0f, 1.0f, 0u, \
    PF_PERSIST | PF_LIVE, "LOCKED also needs the phase error within this") \
  /* 20 ms: several loop time constants inside the tolerance */ \
  X(sup_lock_hold_s, 0x0404u, "sup.lock_hold_s", F32, "s", 0.0f, 10.0f, 0.02f, 0u, \
    PF_PERSIST | PF_LIVE, "time inside tolerance before LOCKED") \
  /* 10 %: ten times the lock tolerance */ \
  X(sup_lost_tol_rel, 0x0405u, "sup.lost_tol_rel", F32, "-", 0.01f, 0.19f, 0.1f, 0u, \
    PF_PERSIST | PF_LIVE, "lock is lost when the relative amplitude error stays beyond this") \
  /* 50 ms: longer than a loop's recovery from a resonance step */ \
  X(sup_lost_hold_s, 0x0406u, "sup.lost_hold_s", F32, "s", 0.0f, 10.0f, 0.05f, 0u, \
    PF_PERSIST | PF_LIVE, "time beyond the lost tolerance before a LOST_LOCK fault") \
  /* 0.5 s at the drive limit while LOCKED: the part no longer fits the drive */ \
  X(sup_sat_hold_s, 0x0407u, "sup.sat_hold_s", F32, "s", 0.0f, 10.0f, 0.5f, 0u, \
    PF_PERSIST | PF_LIVE, "time at the drive limit while LOCKED before a DRIVE_SAT fault") \
  /* 0.3 s: 40 ring-down time constants at Q = 33, 2.3 at Q = 600 */ \
  X(sup_retry_s, 0x0408u, "sup.retry_s", F32, "s", 0.0f, 60.0f, 0.3f, 0u, \
    PF_PERSIST | PF_LIVE, "drive-off time after a fault before re-acquiring") \
  /* half the samples of the 2 ms window on a rail: a clipped waveform, not a spike */ \
  X(sup_clip_count, 0x0409u, "sup.clip_count", U32, "-", 1u, 1000000u, 50u, 0u, \
    PF_PERSIST | PF_LIVE, "ADC rail codes within 2 ms (100 samples) that make an ADC_CLIP fault") \
  /* 5 deg: beyond the 1 deg lock tolerance, short of the 30 deg where a dead-ended phase
   * loop was seen LOCKED with a rate wrong by 800 deg/s */ \
  X(sup_lost_phase_tol_deg, 0x040Au, "sup.lost_phase_tol_deg", F32, "deg", 0.1f, 90.0f, 5.0f, 0u, \
    PF_PERSIST | PF_LIVE, "phase lock is lost (PHASE_LOST) when the phase error stays beyond this for sup.lost_hold_s") \
  /* 0.1 V on the differential sense electrodes (5 V bias): about 5.5 deg/s equivalent */ \
  X(selftest_amp_v, 0x0701u, "selftest.amp_v", F32, "V", 0.0f, 5.0f, 0.1f, 0u, \
    PF_PERSIST | PF_LIVE, "self-test force: voltage amplitude on the sense feedback electrodes") \
  /* a part's own, measured when it is calibrated; 0: none, the test cannot pass */ \
  X(selftest_expect_dps, 0x0702u, "selftest.expect_dps", F32, "deg/s", -1000.0f, 1000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "self-test: expected rate-axis response to the test force") \
  /* 10 %: well outside the test's own noise, well inside a broken channel */ \
  X(selftest_tol_rel, 0x0703u, "selftest.tol_rel", F32, "-", 0.001f, 1.0f, 0.1f, 0u, \
    PF_PERSIST | PF_LIVE, "self-test pass band, relative to the expected response") \
  /* off: the product's figures are measured without it; on, it costs no noise or
   * bandwidth within the measured scatter (README, output integrity) */ \
  X(selftest_continuous, 0x0704u, "selftest.continuous", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "continuous self-test, a tone force measured and taken out (always on with sense.mode 1)") \
  /* as the on-demand test's force */ \
  X(selftest_cont_amp_v, 0x0705u, "selftest.cont_amp_v", F32, "V", 0.001f, 5.0f, 0.1f, 0u, \
    PF_PERSIST | PF_LIVE, "continuous self-test: force voltage amplitude on the sense feedback electrodes") \
  /* 2.5 x the 100 Hz output cut-off, inside the sense demodulator's few hundred Hz */ \
  X(selftest_cont_freq_hz, 0x0706u, "selftest.cont_freq_hz", F32, "Hz", 50.0f, 1250.0f, 250.0f, 0u, \
    PF_PERSIST | PF_LIVE, "continuous self-test: modulation frequency (above the rate output band)") \
  /* a part's own, measured when it is calibrated; 0: none (the continuous test cannot be
   * switched on without it) */ \
  X(selftest_cont_expect_dps, 0x0707u, "selftest.cont_expect_dps", F32, "deg/s", 0.0f, 1000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "continuous self-test: expected amplitude of the response tone") \
  /* force rebalance (sense.mode 1): the test force goes into the loop's command, on the
   * Coriolis axis, and the loop reads it back (selftest.h); 0.2 V^2 is 6 deg/s on the
   * closed-loop tests' part at the readout, a few percent of the feedback's 100 V^2 */ \
  X(selftest_cont_fr_v2, 0x0709u, "selftest.cont_fr_v2", F32, "V^2", 0.001f, 100.0f, 0.2f, 0u, \
    PF_PERSIST | PF_LIVE, "continuous self-test in force rebalance: test force amplitude in the loop's command") \
  /* the default setpoint, at which the expectations above were measured */ \
  X(selftest_ref_amp_v, 0x0708u, "selftest.ref_amp_v", F32, "V", 0.01f, 4.5f, 0.349f, 0u, \
    PF_PERSIST | PF_LIVE, "drive amplitude setpoint at which the self-test expectations were measured") \
  /* off: a part without nulling electrodes (the default part) runs as before, bit for
   * bit; a part with them turns it on (gyro/quad_null.h). The loop identifies its own
   * gain by a probe step at every lock, so it needs no calibrated value */ \
  X(quad_null, 0x0901u, "quad.null", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "quadrature nulling: 0 off (electrodes at 0 V), 1 the loop on the nulling electrodes") \
  /* 2 Hz: 1500 deg/s of quadrature under 1 deg/s in ln(1500) / (2 pi f_c) = 0.58 s, first
   * order far under the 100 Hz output filter; at most a tenth of the 500 Hz update */ \
  X(quad_bw_hz, 0x0902u, "quad.bw_hz", F32, "Hz", 0.01f, 50.0f, 2.0f, 0u, \
    PF_PERSIST | PF_LIVE, "crossover of the quadrature-nulling loop (its closed-loop bandwidth)") \
  /* the second converter's output stage (board.h: +-15 V); 10 V leaves the rail's
   * headroom. The design refuses a limit the converter cannot put out */ \
  X(quad_v_max_v, 0x0903u, "quad.v_max_v", F32, "V", 0.1f, 15.0f, 10.0f, 0u, \
    PF_PERSIST | PF_LIVE, "limit of each nulling electrode's voltage; the loop at it never counts as settled") \
  /* the quadrature left over as nulled: 1 deg/s turns into 0.02 deg/s of rate per degree
   * of demodulation phase error */ \
  X(quad_settle_dps, 0x0904u, "quad.settle_dps", F32, "deg/s", 0.001f, 100.0f, 1.0f, 0u, \
    PF_PERSIST | PF_LIVE, "|quadrature| below this counts as nulled") \
  /* 25 updates at 500 Hz: longer than the 100 Hz filter's noise correlation */ \
  X(quad_settle_s, 0x0905u, "quad.settle_s", F32, "s", 0.0f, 10.0f, 0.05f, 0u, \
    PF_PERSIST | PF_LIVE, "the quadrature within quad.settle_dps this long before the loop counts as settled") \
  /* 2 V: 4 V^2, a step of 80 deg/s at 20 (deg/s)/V^2, small against the electrodes'
   * range, large against the quadrature's noise over the mean */ \
  X(quad_probe_v, 0x0906u, "quad.probe_v", F32, "V", 0.01f, 15.0f, 2.0f, 0u, \
    PF_PERSIST | PF_LIVE, "identification step on nulling electrode V1 at each start (at most quad.v_max_v)") \
  /* the 100 Hz output filter settles to 1e-4 in about 20 ms */ \
  X(quad_probe_wait_s, 0x0907u, "quad.probe_wait_s", F32, "s", 0.0f, 10.0f, 0.02f, 0u, \
    PF_PERSIST | PF_LIVE, "settling before each of the probe's two means") \
  /* two periods of the output filter's cut-off and more */ \
  X(quad_probe_avg_s, 0x0908u, "quad.probe_avg_s", F32, "s", 0.002f, 10.0f, 0.02f, 0u, \
    PF_PERSIST | PF_LIVE, "length of each of the probe's two means of the quadrature") \
  /* 5 deg/s: what 2 V moves at 1.25 (deg/s)/V^2, and far above the probe's error on a
   * part without electrodes (the difference of two 20 ms means of the filtered
   * quadrature: its noise and its drift over 40 ms after lock), so that such a part
   * stops rather than integrate its own noise */ \
  X(quad_min_step_dps, 0x0909u, "quad.min_step_dps", F32, "deg/s", 0.001f, 1000.0f, 5.0f, 0u, \
    PF_PERSIST | PF_LIVE, "the probe's smallest credible effect: less means no working electrodes (the loop stops)") \
  /* open loop: every part runs as before, bit for bit (gyro/sense_fr.h). Not live: the
   * loop, the sense demodulator's step and the output filter change together */ \
  X(sense_mode, 0x0A01u, "sense.mode", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST, "sense axis: 0 open loop, 1 force rebalance (the rate read from the feedback force)") \
  /* the thesis's half-frequency scheme (6-18) for the feedback pair (plant fb_mode 3);
   * DC+AC puts the AC voltage on the pair's first channel and the board's bias stage adds
   * sense.fb_bias_v (plant fb_mode 2) */ \
  X(sense_fb_scheme, 0x0A02u, "sense.fb_scheme", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST, "feedback electrodes: 0 half-frequency pair (U3, U4 at wc/2), 1 DC+AC (the board's bias +- AC)") \
  /* the second converter's output stage (board.h: +-15 V) less the rail's headroom */ \
  X(sense_fb_v_max_v, 0x0A03u, "sense.fb_v_max_v", F32, "V", 0.1f, 15.0f, 10.0f, 0u, \
    PF_PERSIST | PF_LIVE, "limit of each feedback electrode's voltage; the loop at it makes the rate not valid") \
  /* the board's bias stage of the DC+AC scheme: the force is 4 Ks Vb u */ \
  X(sense_fb_bias_v, 0x0A04u, "sense.fb_bias_v", F32, "V", 0.0f, 15.0f, 5.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias of the feedback electrodes in DC+AC (sense.fb_scheme 1), below sense.fb_v_max_v") \
  /* 0: in phase with the drive force (at the drive's resonance its velocity, and so the
   * Coriolis force, is); what the two electrodes' paths differ by moves it (a part's) */ \
  X(sense_fb_phase_deg, 0x0A05u, "sense.fb_phase_deg", F32, "deg", -180.0f, 180.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "phase of the feedback force in the Coriolis direction, against the drive force's (P)") \
  /* a placeholder of the family's size: a part's value is its own (identified or from
   * its design: the sense mode's gain at the drive frequency times the electrode's Ks).
   * The range spans a matched mode of Q 1e5 (sense.tune 1): the gain at wc is then Q
   * times the static one, 1400 times a 110 Hz split's at Q 1e4 */ \
  X(sense_fb_gain_v_per_v2, 0x0A06u, "sense.fb_gain_v_per_v2", F32, "V/V^2", -1.0e5f, 1.0e5f, 0.01f, 0u, \
    PF_PERSIST | PF_LIVE, "sense pickoff's static response (Coriolis axis, V) per V^2 of feedback force at wc; not 0") \
  /* the family's design sense resonance and Q (thesis §2.4.2), not a part's */ \
  X(sense_f0_hz, 0x0A07u, "sense.f0_hz", F32, "Hz", 100.0f, 20000.0f, 2000.0f, 0u, \
    PF_PERSIST | PF_LIVE, "sense resonance of the model the force-rebalance loop is designed from") \
  X(sense_q, 0x0A08u, "sense.q", F32, "-", 0.5f, 1.0e6f, 3.0f, 0u, \
    PF_PERSIST | PF_LIVE, "sense quality factor of that model") \
  /* 145 Hz, damping 0.8, the output filter below: with the schedule's delay (its steps,
   * gyro_slots.h) and the readout's zero on the third root (sense_fr.h), a step settles
   * to 1 % within 10 ms at any split, matched included, and the -3 dB bandwidth is above
   * 100 Hz (measured in README). The third root c = a - 2 zeta w (84 Hz here) must stay
   * in the left half plane: 2 zeta w below the lag's pole a */ \
  X(sense_fr_bw_hz, 0x0A09u, "sense.fr_bw_hz", F32, "Hz", 1.0f, 1000.0f, 145.0f, 0u, \
    PF_PERSIST | PF_LIVE, "natural frequency of the force-rebalance loop's closed-loop poles") \
  X(sense_fr_zeta, 0x0A0Au, "sense.fr_zeta", F32, "-", 0.3f, 2.0f, 0.8f, 0u, \
    PF_PERSIST | PF_LIVE, "damping of those poles") \
  /* inside the loop the demodulator is a lag: 0.15 puts its pole at 1.2 kHz, so that the
   * loop can reach 120 Hz (demod.mu_sense stays the open loop's) */ \
  X(sense_fr_mu, 0x0A0Bu, "sense.fr_mu", F32, "-", 0.0001f, 0.49f, 0.15f, 0u, \
    PF_PERSIST | PF_LIVE, "LMS step size of the sense demodulator in force rebalance (sense.mode 1)") \
  /* the loop sets the bandwidth; the filter takes the noise above it: 2nd order at 500 Hz
   * costs about 0.5 ms of the step's settling (the open loop's 100 Hz 4th order: 17 ms) */ \
  X(sense_fr_lpf_hz, 0x0A0Cu, "sense.fr_lpf_hz", F32, "Hz", 10.0f, 2000.0f, 500.0f, 0u, \
    PF_PERSIST | PF_LIVE, "cut-off of the rate's 2nd-order Butterworth output filter in force rebalance (replaces rate.lpf_*)") \
  /* the residual's low-pass at a fifth of the loop's frequency still carries about
   * 0.5 deg/s of the demodulator's noise on a part in air */ \
  X(sense_fr_settle_dps, 0x0A0Du, "sense.fr_settle_dps", F32, "deg/s", 0.001f, 100.0f, 2.0f, 0u, \
    PF_PERSIST | PF_LIVE, "the loop's residual (rate and quadrature equivalent) below this counts as settled") \
  /* 25 blocks: longer than the loop's own time constant */ \
  X(sense_fr_settle_s, 0x0A0Eu, "sense.fr_settle_s", F32, "s", 0.0f, 10.0f, 0.005f, 0u, \
    PF_PERSIST | PF_LIVE, "the residual within sense.fr_settle_dps this long before the loop counts as settled") \
  /* off: a sweep identifies the drive alone, as before (the default part's feedback
   * electrodes are the self-test's biased pair, not the half-frequency pair of the
   * default sense.fb_scheme: the sense identification would find nothing there). On, it
   * identifies the sense mode first and stages sense.f0_hz, sense.q,
   * sense.fb_gain_v_per_v2, sense.fb_phase_deg (gyro/selfcal.h) */ \
  X(sense_cal, 0x0A20u, "sense.cal", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "self-calibration identifies the sense mode too (0 drive only, 1 sense and drive)") \
  /* 3 V: a tenth of a part's reach at 10 V, so the decays stay within the sense
   * demodulator's band (a shift of tens of Hz); 0 skips the probe */ \
  X(sense_cal_tune_probe_v, 0x0A21u, "sense.cal_tune_probe_v", F32, "V", 0.0f, 15.0f, 3.0f, 0u, \
    PF_PERSIST | PF_LIVE, "tuning-electrode voltage of the sweep's tuning-slope probe (sense.cal 1); 0 none") \
  /* 0 until a sweep with sense.cal 1 identifies it: the part's own, ws^2 = ws0^2 - ke Vt^2 */ \
  X(sense_cal_tune_ke_per_s2_per_v2, 0x0A22u, "sense.cal_tune_ke_per_s2_per_v2", F32, "(1/s^2)/V^2", 0.0f, 1.0e8f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "identified tuning slope: the sense resonance's ws^2 falls by this x Vt^2 (0: no tuning electrodes)") \
  /* off: the tuning electrodes at 0 V, as before. Not live: the force-rebalance model
   * (sense.f0_hz .. sense.fb_phase_deg) is measured at the tuning (gyro/sense_tune.h) */ \
  X(sense_tune, 0x0A10u, "sense.tune", ENUM, "-", 0u, 2u, 0u, \
    PARAM_CHOICE(0) | PARAM_CHOICE(1) | PARAM_CHOICE(2), \
    PF_PERSIST, "mode tuning: 0 off, 1 sense resonance on the drive's (matched), 2 that + sense.tune_split_hz") \
  /* a design choice, not a part's: 20 Hz keeps a split part's open-loop band (f/2Q) apart
   * from the drive's while giving it five times the 110 Hz split's sense gain */ \
  X(sense_tune_split_hz, 0x0A11u, "sense.tune_split_hz", F32, "Hz", 0.0f, 1000.0f, 20.0f, 0u, \
    PF_PERSIST, "sense.tune 2: the sense resonance's target above the drive's") \
  /* the board's tuning driver (board.h: +-15 V) less the rail's headroom */ \
  X(sense_tune_v_max_v, 0x0A12u, "sense.tune_v_max_v", F32, "V", 0.1f, 15.0f, 10.0f, 0u, \
    PF_PERSIST | PF_LIVE, "limit of the tuning voltage; a target that needs more makes the rate not valid") \
  /* 0 until a sweep with sense.cal 1 and sense.tune 1 or 2 tunes the part */ \
  X(sense_cal_s0_hz, 0x0A23u, "sense.cal_s0_hz", F32, "Hz", 0.0f, 20000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "identified untuned sense resonance (tuning at 0 V) at sense.cal_tune_ref_hz") \
  X(sense_cal_tune_ref_hz, 0x0A24u, "sense.cal_tune_ref_hz", F32, "Hz", 0.0f, 20000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "drive resonance when the part was tuned: the tuning's temperature hold scales from it") \
  /* 0 until the calibration flow measures it on the tuned part (tools/calibrate --tune):
   * the monitor's loop model reads a matched part 0.7-1.35 Hz off (sense_tune.h). */ \
  X(sense_tune_disc_zero_hz, 0x0A25u, "sense.tune_disc_zero_hz", F32, "Hz", -50.0f, 50.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "the lost-match monitor's reading on this part matched: subtracted from its readings") \
  /* 0: no calibration. The compensation, the demodulation phase and the scale hold at
   * the drive frequency they were measured at: another one (a sweep, a hand change)
   * makes them stale. Equal within 2e-7 (two float steps), so that a value that went
   * through the command line's text still matches */ \
  X(cal_ref_freq_hz, 0x0801u, "cal.ref_freq_hz", F32, "Hz", 0.0f, 20000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "drive.freq_hz the calibration was made at; 0 none: the rate is valid only at it") \
  /* written by the calibration flow; 0: none */ \
  X(cal_part_id, 0x0802u, "cal.part_id", U32, "-", 0u, 0xFFFFFFFFu, 0u, 0u, \
    PF_PERSIST | PF_LIVE, "id of the part the calibration was made on") \
  /* written by the calibration flow, as yyyymmdd; 0: none */ \
  X(cal_date, 0x0803u, "cal.date", U32, "-", 0u, 99991231u, 0u, 0u, \
    PF_PERSIST | PF_LIVE, "date of the calibration, yyyymmdd") \
  /* The thermometer's reference: the compensation is in the deviation of P from it, so
   * that it stays what was fitted whatever P's absolute value (a hand-set
   * drive.p_init_deg moves the loop's start, not the compensation). Written by the
   * calibration flow (the centre of the P span it fitted over); 0 until then */ \
  X(cal_ref_p_deg, 0x0804u, "cal.ref_p_deg", F32, "deg", -100000.0f, 100000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "thermometer reference: the compensation is in x = P_c - cal.ref_p_deg") \
  /* Written by the calibration flow; 0, the default setpoint, until then */ \
  X(cal_ref_phase_set_deg, 0x0805u, "cal.ref_phase_set_deg", F32, "deg", -180.0f, 180.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "drive.phase_set_deg the calibration was made at: at another it is stale") \
  /* Written by the calibration flow (drive.track when it ran); 0, the fixed drive, until
   * then and in images of before it. The two drives' thermometers differ (P, or the
   * tracked frequency's p_eq, drive_track.h), and so do their demodulation phases */ \
  X(cal_ref_track, 0x0806u, "cal.ref_track", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "drive.track the calibration was made with: with the other it is stale") \
  /* Written by the calibration flow (gyro/sense_tune.h's voltage at the tuning's own
   * reference; 0 untuned); 0 until then. The tuned sense mode's response at the drive
   * frequency is in the demodulation phase and the scale: one DAC code of the tuning
   * moves a matched Q 1e4 resonance by most of its half-bandwidth, so another tuning
   * (a sweep that tuned again, sense.tune or its calibration changed) makes it stale */ \
  X(cal_ref_tune_v, 0x0807u, "cal.ref_tune_v", F32, "V", 0.0f, 15.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "mode tuning's voltage the calibration was made with (0 untuned): with another it is stale") \
  /* Written by the calibration flow (sense.mode and quad.null when it ran); 0, open loop
   * without nulling, until then and in images of before it. Force rebalance reads the
   * rate from the force, nulling takes away the quadrature that leaks into the rate
   * with the thermometer: the compensation, demodulation phase and scale of the one
   * configuration are not the other's */ \
  X(cal_ref_sense_mode, 0x0808u, "cal.ref_sense_mode", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "sense.mode the calibration was made with: with the other it is stale") \
  X(cal_ref_quad_null, 0x0809u, "cal.ref_quad_null", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "quad.null the calibration was made with: with the other it is stale") \
  /* The board thermometer (gyro/board_therm.h): the board sensor's model of the bias,
   * fused with the compensation in P below board.crossover_s. Off until the calibration
   * flow has fitted the model on the part (tools/calibrate --board-temp) */ \
  X(board_fuse, 0x0B01u, "board.fuse", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_LIVE, "fuse the board sensor's model of the bias with P (0 off)") \
  /* The model's lead-lag (1 + s tz1)(1 + s tz2) / ((1 + s tp1)(1 + s tp2)): the board
   * node to the bias through the part's thermal network. Uncalibrated: all equal, H = 1 */ \
  X(board_tz1_s, 0x0B02u, "board.tz1_s", F32, "s", 1.0f, 20000.0f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: zero 1") \
  X(board_tz2_s, 0x0B03u, "board.tz2_s", F32, "s", 1.0f, 20000.0f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: zero 2") \
  X(board_tp1_s, 0x0B04u, "board.tp1_s", F32, "s", 1.0f, 20000.0f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: pole 1") \
  X(board_tp2_s, 0x0B05u, "board.tp2_s", F32, "s", 1.0f, 20000.0f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: pole 2") \
  /* The cubic's reference and coefficients: uncalibrated 25 degC and 0 */ \
  X(board_ref_c, 0x0B06u, "board.ref_c", F32, "degC", -60.0f, 150.0f, 25.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: the cubic's reference") \
  X(board_c0_dps, 0x0B07u, "board.c0_dps", F32, "deg/s", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: c0") \
  X(board_c1_dps_per_c, 0x0B08u, "board.c1_dps_per_c", F32, "deg/s/degC", -1000.0f, 1000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: c1") \
  X(board_c2_dps_per_c2, 0x0B09u, "board.c2_dps_per_c2", F32, "deg/s/degC^2", -100.0f, 100.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: c2") \
  X(board_c3_dps_per_c3, 0x0B0Au, "board.c3_dps_per_c3", F32, "deg/s/degC^3", -10.0f, 10.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: c3") \
  /* The span of y the model was fitted on (the flow widens it by a margin): beyond it,
   * with the fusion weighing in, the rate is not valid (BOARD_TEMP) */ \
  X(board_min_c, 0x0B0Bu, "board.min_c", F32, "degC", -60.0f, 150.0f, -40.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: lowest y fitted") \
  X(board_max_c, 0x0B0Cu, "board.max_c", F32, "degC", -60.0f, 150.0f, 85.0f, 0u, \
    PF_PERSIST | PF_LIVE, "board model: highest y fitted") \
  /* P's phase flicker is in excess from 10 s on (docs/compensation-noise.md): the
   * crossover lies below that; above it the fused bias passes T times the rate of
   * change of P's disagreement with the model, below it the sensor's 1 s steps and noise
   * (gyrotools/boardcal.py CROSSOVER_S: the measured trade) */ \
  X(board_crossover_s, 0x0B0Du, "board.crossover_s", F32, "s", 0.2f, 1000.0f, 1.0f, 0u, \
    PF_PERSIST | PF_LIVE, "fusion crossover: P above, the board model below") \
  /* The board's own warm-up after power-on is a heat input the model does not know: an
   * hour, generic, until the flow sets five of the part's slowest thermal pole */ \
  X(board_start_s, 0x0B0Eu, "board.start_s", F32, "s", 0.0f, 100000.0f, 3600.0f, 0u, \
    PF_PERSIST | PF_LIVE, "fusion starts this long after power-on") \
  X(board_fade_s, 0x0B0Fu, "board.fade_s", F32, "s", 0.0f, 10000.0f, 300.0f, 0u, \
    PF_PERSIST | PF_LIVE, "fusion weight rises 0 -> 1 over this") \
  /* Three of the sensor's 1 s cycles */ \
  X(board_stale_s, 0x0B10u, "board.stale_s", F32, "s", 1.5f, 60.0f, 3.0f, 0u, \
    PF_PERSIST | PF_LIVE, "no reading this long: sensor stale") \
  /* A sensor that reads but is wrong (stuck, off the board): the bias in P and the
   * model part by more than either misses the part by. The flow sets three times the
   * most they parted on its chamber run; generic: 10 deg/s */ \
  X(board_agree_dps, 0x0B11u, "board.agree_dps", F32, "deg/s", 0.01f, 10000.0f, 10.0f, 0u, \
    PF_PERSIST | PF_LIVE, "P and the board model part by more: not trusted") \
  /* start the drive at power-on */ \
  X(sys_autostart, 0x0602u, "sys.autostart", ENUM, "-", 0u, 1u, 1u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_RESTART, "start acquiring at power-on") \
  /* 100 Hz matches the 100 Hz output bandwidth */ \
  X(tlm_rate_hz, 0x0501u, "tlm.rate_hz", U32, "Hz", 1u, 5000u, 100u, 0u, \
    PF_PERSIST | PF_LIVE, "telemetry frame rate") \
  /* 4.4.2: the 50 kHz tick (board.h); fixed by the timer and the filter designs */ \
  X(sys_fs_hz, 0x0601u, "sys.fs_hz", U32, "Hz", BOARD_SAMPLE_RATE_HZ, BOARD_SAMPLE_RATE_HZ, BOARD_SAMPLE_RATE_HZ, 0u, \
    PF_READONLY, "sample rate of the tick")
/* clang-format on */

#endif /* PARAM_LIST_H */
