/* The gyro plant: mechanics, electronics, converters, noise and temperature, one call
 * per 50 kHz sample (host simulator, double precision). This is the model the host HAL
 * stub feeds; it never includes firmware internals.
 *
 * One sample, plant_step(p, dac, adc), covering [t_k, t_k+1), t_k = k / fs:
 *   1. thermal network (every thermal_dt_s): ambient profile at mid-interval ->
 *      structure / circuit / board-sensor temperatures (thermal.h; they start in the
 *      steady state of the ambient at t = 0, or with cold_start all at that ambient,
 *      warming as after a power-on); the structure
 *      temperature moves the resonances (2-32) and the quality factors (q_temp_law,
 *      qlaw.h) (mech.h), the circuit temperature (of the node chosen by
 *      pick_*_temp_node) the pickoff phases and gains (2-40) (pickoff.h, re-discretised
 *      when the phase moved by pick_phase_step_rad); the slow drifts of the couplings
 *      (drift.h) take their next value;
 *   2. DAC (dac.h): the frame passed in is the one on the converter outputs during
 *      this interval (the host HAL stub applies the board's one-sample latency: it
 *      passes the frame the firmware wrote at the previous tick); zero-order hold,
 *      INL, output amplifier, reconstruction low-pass; the shared reference's noise
 *      (vref.h) on it and on the ADC;
 *   3. actuator (actuator.h): F = Ks (U1^2 - U2^2) (6-7) with 1/f electrode-voltage
 *      noise, mean over the sample, per unit mass; the sense electrodes (the feedback pair
 *      of fb_mode 3, the quadrature-nulling and the tuning electrodes), driven by the DAC's
 *      channels 3..7 (hal_dac.h) in series with plant_set_electrodes' voltages, give their
 *      force and their stiffness (a coupling that adds to k_q, a softening of the sense
 *      spring); plus the inertial and g-sensitivity
 *      forces of the acceleration profile (accel.h, exact mean over the sample of the
 *      constant, sine and half-sine shock parts; random vibration from vib.h);
 *   4. mechanics (mech.h): exact discretisation of (2-22)/(2-20) with the rate profile
 *      at mid-sample inside the transition matrix, Brownian force noise (4-20), the
 *      electrostatic softening of the biased feedback electrodes (6-3); held cubic
 *      stiffness and coupling drift forces; the electrodes' stiffness (held, rebased into
 *      the transition matrix at the thermal updates while it moves, mech.h);
 *   5. pickoffs (pickoff.h): ring-diode front end (capacitive nonlinearity, gain and
 *      phase flicker), feedthrough, circuit phase, anti-alias band-pass, offset, noise,
 *      sampled at t_k+1 (+ delay, jitter, the ADC's aperture jitter);
 *   6. ADC (adc.h): 16-bit quantiser (INL), clip and fault counters -> the frame
 *      returned, which the firmware reads at tick k+1.
 * Beside the chain, the board's temperature sensor (board_sensor.h, plant.board_sensor*)
 * reads the board node once per 1 s conversion, from random numbers of its own: the
 * chain's samples are the same with it and without it. The host HAL reads it through
 * plant_board_temp_hal.
 *
 * Every imperfection beyond the thesis's linear gyro (the q_temp_law, k3_*,
 * nl_damp_drive_per_m2, *_drift_*, fb_gap_m, pick_*_gap_*, pick_*_flicker_*, adc_inl_*,
 * dac_inl_*, adc_aperture_jitter_s, vref_noise_* parameters, the shocks and random
 * vibration of the acceleration profile) is off at zero. The ideal part
 * (plant_ideal_cfg) has every one off; the default part (plant_default_cfg) has the
 * circuit phases' flicker and the amplitude-dependent drive damping on, set to reproduce
 * the thesis's measured bias stability and square law (docs/honest-part.md). Neither
 * has quadrature-nulling or tuning electrodes (quadnull_dps_per_v2 and
 * tune_ke_per_s2_per_v2 zero: the thesis's part has none); a part with them sets those.
 *
 * Units and signs: rates in deg/s at the API (rad/s inside the mechanics), positive
 * rate gives a Coriolis force +2 Omega y' on the sense axis (thesis (2-22)); the
 * quadrature coupling is -k_q y with k_q = 2 wc quad_dps (rad), so quad_dps > 0 and a
 * growing sense-channel lag give a growing positive bias, as in table 7-4.
 *
 * Configuration: plant_cfg_t is flat and generated from the list PLANT_PARAMS, which
 * also generates the descriptor table (plant_param_*: name = field name, snake case
 * with unit suffix, type, range, unit, one-line doc), so every field is a parameter.
 * plant_default_cfg() is the table "thesis linear gyro, air package" of the system
 * spec, each value with its source. Input profiles (rate, ambient, acceleration) are
 * set separately (plant_set_profiles), defaulting to constants from rate_dps and
 * temp_k.
 */
#ifndef PLANT_PLANT_H
#define PLANT_PLANT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/hal_adc.h"
#include "hal/hal_dac.h"
#include "plant/accel.h"
#include "plant/actuator.h"
#include "plant/adc.h"
#include "plant/board_sensor.h"
#include "plant/dac.h"
#include "plant/drift.h"
#include "plant/mech.h"
#include "plant/pickoff.h"
#include "plant/profile.h"
#include "plant/thermal.h"
#include "plant/vib.h"
#include "plant/vref.h"

#define PLANT_RNG_STREAM_QUAD_DRIFT 0x7601u
#define PLANT_RNG_STREAM_INPHASE_DRIFT 0x7602u

/* The parameter list: X(c_type, name, kind, min, max, unit, doc). It generates the
 * fields of plant_cfg_t and the descriptor table, so every field is a parameter.
 * Ranges are inclusive; cross-field limits (e.g. f < 0.45 fs) are in plant_cfg_check. */
#define PLANT_PARAMS(X) \
  /* run, truth and range budget */ \
  X(double, fs_hz, DOUBLE, 1e3, 1e7, "Hz", "converter and plant sample rate") \
  X(double, temp_k, DOUBLE, 150.0, 450.0, "K", \
    "ambient temperature when no ambient profile is set") \
  X(double, rate_dps, DOUBLE, -1e4, 1e4, "deg/s", "input rate when no rate profile is set") \
  X(double, drive_amp_m, DOUBLE, 1e-8, 1e-4, "m", \
    "nominal drive amplitude: design point of gains and budgets") \
  X(double, rate_fs_dps, DOUBLE, 0.0, 1e4, "deg/s", "full-scale rate of the ADC range budget") \
  X(double, vib_g, DOUBLE, 0.0, 100.0, "g", \
    "vibration amplitude along the sense axis in the range budget") \
  X(double, vib_hz, DOUBLE, 0.0, 1e4, "Hz", "frequency of that vibration") \
  X(double, truth_tau_s, DOUBLE, 1e-4, 10.0, "s", \
    "averaging time of the truth's drive-frequency estimate") \
  X(double, truth_force_tau_s, DOUBLE, 1e-5, 1.0, "s", \
    "averaging time of the truth's drive-force phasor") \
  /* mechanics (mech.h) */ \
  X(double, f_drive_hz, DOUBLE, 10.0, 1e6, "Hz", "drive resonance at temp_ref_k") \
  X(double, q_drive, DOUBLE, 0.5, 1e6, "", "drive resonance quality factor") \
  X(double, f_sense_hz, DOUBLE, 10.0, 1e6, "Hz", "sense resonance at temp_ref_k") \
  X(double, q_sense, DOUBLE, 0.5, 1e6, "", "sense resonance quality factor") \
  X(double, mass_kg, DOUBLE, 1e-12, 1.0, "kg", "proof mass (Brownian noise, 4-20)") \
  X(double, temp_ref_k, DOUBLE, 150.0, 450.0, "K", \
    "reference temperature T0 of (2-32) and (2-40)") \
  X(double, ket_per_k, DOUBLE, -1e-3, 1e-3, "1/K", \
    "temperature coefficient of Young's modulus kET (2-29)") \
  X(double, quad_dps, DOUBLE, -1e5, 1e5, "deg/s", \
    "quadrature (stiffness coupling k_q) as an equivalent rate k_q/(2 wc)") \
  X(double, inphase_bias_dps, DOUBLE, -1e4, 1e4, "deg/s", \
    "damping coupling d_q as an equivalent rate d_q/2") \
  X(double, quad_drift_dps, DOUBLE, 0.0, 1e4, "deg/s", \
    "rms of the quadrature's slow drift (first-order Gauss-Markov, drift.h), 0 = none") \
  X(double, quad_drift_tau_s, DOUBLE, 1e-2, 1e9, "s", "correlation time of that drift") \
  X(double, inphase_drift_dps, DOUBLE, 0.0, 1e4, "deg/s", \
    "rms of the damping coupling's slow drift (Gauss-Markov), 0 = none") \
  X(double, inphase_drift_tau_s, DOUBLE, 1e-2, 1e9, "s", "correlation time of that drift") \
  X(double, k3_drive_per_m2, DOUBLE, -1e12, 1e12, "1/m^2", \
    "cubic stiffness k3/k of the drive suspension (Duffing), 0 = linear") \
  X(double, k3_sense_per_m2, DOUBLE, -1e12, 1e12, "1/m^2", \
    "cubic stiffness k3/k of the sense suspension (Duffing), 0 = linear") \
  X(double, nl_damp_drive_per_m2, DOUBLE, 0.0, 1e12, "1/m^2", \
    "amplitude-dependent drive damping c: damping grows as (1 + c y^2), Q1 / (1 + c A^2 / 4) " \
    "at amplitude A (mech.h), 0 = linear") \
  X(double, mech_refresh_eps, DOUBLE, 1e-9, 1e-2, "", \
    "relative resonance shift that re-discretises the mechanics") \
  /* actuators (actuator.h) */ \
  X(double, ks_drive_mps2_per_v2, DOUBLE, 0.0, 1e3, "(m/s^2)/V^2", \
    "drive comb Ks/m of F = Ks (U1^2 - U2^2) (6-7)") \
  X(double, drive_noise_white_v_rthz, DOUBLE, 0.0, 1e-3, "V/rtHz", \
    "white noise on each drive electrode voltage, one-sided") \
  X(double, drive_noise_1hz_v_rthz, DOUBLE, 0.0, 1e-2, "V/rtHz", \
    "1/f noise density at 1 Hz on each drive electrode") \
  X(double, drive_noise_fmin_hz, DOUBLE, 1e-7, 1.0, "Hz", "1/f spectrum flattens below this") \
  X(double, ks_fb_mps2_per_v2, DOUBLE, 0.0, 1e3, "(m/s^2)/V^2", "sense feedback electrodes Ks/m") \
  X(double, fb_bias_v, DOUBLE, -100.0, 100.0, "V", "bias of differential sense feedback") \
  X(double, fb_noise_white_v_rthz, DOUBLE, 0.0, 1e-3, "V/rtHz", \
    "white noise on each feedback electrode") \
  X(double, fb_noise_1hz_v_rthz, DOUBLE, 0.0, 1e-2, "V/rtHz", \
    "1/f noise at 1 Hz on each feedback electrode") \
  X(double, fb_noise_fmin_hz, DOUBLE, 1e-7, 1.0, "Hz", \
    "feedback 1/f spectrum flattens below this") \
  X(double, fb_gap_m, DOUBLE, 0.0, 1e-3, "m", \
    "parallel-plate gap of the feedback electrodes: their bias (fb_mode 2) or their voltages " \
    "(fb_mode 3) soften the sense spring (6-3), 0 = none") \
  X(double, quadnull_dps_per_v2, DOUBLE, 0.0, 1e4, "(deg/s)/V^2", \
    "quadrature-nulling electrodes: coupling k_yx = c (V1^2 - V2^2) added to k_q, c as an " \
    "equivalent quadrature c/(2 wc) per V^2 (actuator.h), 0 = none") \
  X(double, quadnull_overlap_per_gap, DOUBLE, 0.0, 1e3, "", \
    "overlap at rest over gap, l0/d, of the nulling electrodes: they soften the sense spring " \
    "by 2 c (l0/d) (V1^2 + V2^2), 0 = none") \
  X(double, quadnull_noise_white_v_rthz, DOUBLE, 0.0, 1e-3, "V/rtHz", \
    "white noise on each nulling electrode") \
  X(double, quadnull_noise_1hz_v_rthz, DOUBLE, 0.0, 1e-2, "V/rtHz", \
    "1/f noise at 1 Hz on each nulling electrode") \
  X(double, quadnull_noise_fmin_hz, DOUBLE, 1e-7, 1.0, "Hz", \
    "nulling electrodes' 1/f spectrum flattens below this") \
  X(double, tune_ke_per_s2_per_v2, DOUBLE, 0.0, 1e8, "(1/s^2)/V^2", \
    "sense tuning electrodes: spring softening k_e/m = this x Vt^2 (a parallel-plate pair, " \
    "2 eps A/(m g^3)); lowers the sense resonance only, 0 = none") \
  X(double, tune_noise_white_v_rthz, DOUBLE, 0.0, 1e-3, "V/rtHz", \
    "white noise on the tuning electrodes' voltage") \
  X(double, tune_noise_1hz_v_rthz, DOUBLE, 0.0, 1e-2, "V/rtHz", \
    "1/f noise at 1 Hz on the tuning electrodes' voltage") \
  X(double, tune_noise_fmin_hz, DOUBLE, 1e-7, 1.0, "Hz", \
    "tuning electrodes' 1/f spectrum flattens below this") \
  /* DAC (dac.h) */ \
  X(double, dac_recon_hz, DOUBLE, 0.0, 1e7, "Hz", \
    "reconstruction low-pass natural frequency, 0 = none") \
  X(double, dac_recon_q, DOUBLE, 0.1, 10.0, "", "reconstruction low-pass quality factor") \
  X(double, dac_gain_u1, DOUBLE, -2.0, 2.0, "", "output amplifier gain, drive electrode U1") \
  X(double, dac_gain_u2, DOUBLE, -2.0, 2.0, "", "output amplifier gain, drive electrode U2") \
  X(double, dac_gain_rate, DOUBLE, -2.0, 2.0, "", "output amplifier gain, analog rate output") \
  X(double, dac_gain_spare, DOUBLE, -2.0, 2.0, "", \
    "output amplifier gain, spare (sense feedback)") \
  X(double, dac_offset_u1_v, DOUBLE, -15.0, 15.0, "V", "output offset, U1") \
  X(double, dac_offset_u2_v, DOUBLE, -15.0, 15.0, "V", "output offset, U2") \
  X(double, dac_offset_rate_v, DOUBLE, -15.0, 15.0, "V", "output offset, rate output") \
  X(double, dac_offset_spare_v, DOUBLE, -15.0, 15.0, "V", "output offset, spare") \
  X(double, dac_gain_fb_u2, DOUBLE, -2.0, 2.0, "", \
    "output amplifier gain, sense feedback pair's second electrode U4 (second converter)") \
  X(double, dac_gain_quadnull_v1, DOUBLE, -2.0, 2.0, "", \
    "output amplifier gain, quadrature-nulling set 1 (V1)") \
  X(double, dac_gain_quadnull_v2, DOUBLE, -2.0, 2.0, "", \
    "output amplifier gain, quadrature-nulling set 2 (V2)") \
  X(double, dac_gain_tune, DOUBLE, -2.0, 2.0, "", "output amplifier gain, tuning electrodes") \
  X(double, dac_offset_fb_u2_v, DOUBLE, -15.0, 15.0, "V", "output offset, feedback U4") \
  X(double, dac_offset_quadnull_v1_v, DOUBLE, -15.0, 15.0, "V", "output offset, nulling V1") \
  X(double, dac_offset_quadnull_v2_v, DOUBLE, -15.0, 15.0, "V", "output offset, nulling V2") \
  X(double, dac_offset_tune_v, DOUBLE, -15.0, 15.0, "V", "output offset, tuning electrodes") \
  X(double, dac_inl_bow_lsb, DOUBLE, -64.0, 64.0, "LSB", \
    "DAC INL bow at mid-scale, zero at the ends (inl.h), 0 = none") \
  X(double, dac_inl_code_lsb, DOUBLE, 0.0, 64.0, "LSB", \
    "DAC per-code INL: rms weight error of the MSB (inl.h), 0 = none") \
  /* drive pickoff (pickoff.h) */ \
  X(double, pick_drive_gain_v_per_m, DOUBLE, 1.0, 1e12, "V/m", \
    "drive ring-diode gain at T0 (4-12)") \
  X(double, pick_drive_gain_tc_per_k, DOUBLE, -0.099, 0.099, "1/K", \
    "relative drive pickoff gain change per kelvin") \
  X(double, pick_drive_rail_v, DOUBLE, 0.01, 100.0, "V", "drive preamplifier saturation") \
  X(double, pick_drive_ft_u1, DOUBLE, -1.0, 1.0, "V/V", \
    "feedthrough of U1 into the drive pickoff") \
  X(double, pick_drive_ft_u2, DOUBLE, -1.0, 1.0, "V/V", \
    "feedthrough of U2 into the drive pickoff") \
  X(double, pick_drive_ft_spare, DOUBLE, -1.0, 1.0, "V/V", \
    "feedthrough of the spare channel into the drive pickoff") \
  X(double, pick_drive_phi0_deg, DOUBLE, -80.0, 80.0, "deg", \
    "drive circuit lag at T0 and pick_lag_ref_hz (2-40), negative: a lead") \
  X(double, pick_drive_phi1_deg_per_k, DOUBLE, -1.0, 1.0, "deg/K", \
    "its first temperature derivative (2-40)") \
  X(double, pick_drive_phi2_deg_per_k2, DOUBLE, -0.1, 0.1, "deg/K^2", \
    "its second temperature derivative (2-40)") \
  X(double, pick_drive_hp_hz, DOUBLE, 0.0, 1e6, "Hz", \
    "drive anti-alias high-pass corner, 0 = none") \
  X(double, pick_drive_lp_hz, DOUBLE, 1.0, 1e8, "Hz", \
    "drive anti-alias low-pass natural frequency") \
  X(double, pick_drive_lp_q, DOUBLE, 0.1, 10.0, "", "drive anti-alias low-pass quality factor") \
  X(double, pick_drive_offset_v, DOUBLE, -5.0, 5.0, "V", "drive channel offset at the ADC") \
  X(double, pick_drive_noise_v_rthz, DOUBLE, 0.0, 1e-2, "V/rtHz", \
    "drive channel white noise at the ADC, one-sided") \
  X(double, pick_drive_delay_s, DOUBLE, -1e-3, 1e-3, "s", \
    "drive sampling instant after the tick (|.| <= T/2)") \
  X(double, pick_drive_jitter_s, DOUBLE, 0.0, 1e-3, "s", "drive sampling jitter rms (<= T/20)") \
  X(double, pick_drive_gap_m, DOUBLE, 0.0, 1e-3, "m", \
    "drive pickoff parallel-plate gap: capacitive nonlinearity, 0 = linear") \
  X(double, pick_drive_gap_asym, DOUBLE, 0.0, 1.0, "", \
    "imbalance of the drive pickoff pair (0 balanced: odd orders only, 1 one-sided)") \
  X(double, pick_drive_gain_flicker_1hz_rthz, DOUBLE, 0.0, 1e-2, "1/rtHz", \
    "relative 1/f noise of the drive pickoff gain at 1 Hz, 0 = none") \
  X(double, pick_drive_phase_flicker_1hz_deg_rthz, DOUBLE, 0.0, 1.0, "deg/rtHz", \
    "1/f noise of the drive circuit phase at 1 Hz, 0 = none") \
  /* sense pickoff */ \
  X(double, pick_sense_gain_v_per_m, DOUBLE, 1.0, 1e12, "V/m", \
    "sense ring-diode gain at T0 (4-12)") \
  X(double, pick_sense_gain_tc_per_k, DOUBLE, -0.099, 0.099, "1/K", \
    "relative sense pickoff gain change per kelvin") \
  X(double, pick_sense_rail_v, DOUBLE, 0.01, 100.0, "V", "sense preamplifier saturation") \
  X(double, pick_sense_ft_u1, DOUBLE, -1.0, 1.0, "V/V", \
    "feedthrough of U1 into the sense pickoff") \
  X(double, pick_sense_ft_u2, DOUBLE, -1.0, 1.0, "V/V", \
    "feedthrough of U2 into the sense pickoff") \
  X(double, pick_sense_ft_spare, DOUBLE, -1.0, 1.0, "V/V", \
    "feedthrough of the spare channel into the sense pickoff") \
  X(double, pick_sense_phi0_deg, DOUBLE, -80.0, 80.0, "deg", \
    "sense circuit lag at T0 and pick_lag_ref_hz (2-40), negative: a lead") \
  X(double, pick_sense_phi1_deg_per_k, DOUBLE, -1.0, 1.0, "deg/K", \
    "its first temperature derivative (2-40)") \
  X(double, pick_sense_phi2_deg_per_k2, DOUBLE, -0.1, 0.1, "deg/K^2", \
    "its second temperature derivative (2-40)") \
  X(double, pick_sense_hp_hz, DOUBLE, 0.0, 1e6, "Hz", \
    "sense anti-alias high-pass corner, 0 = none") \
  X(double, pick_sense_lp_hz, DOUBLE, 1.0, 1e8, "Hz", \
    "sense anti-alias low-pass natural frequency") \
  X(double, pick_sense_lp_q, DOUBLE, 0.1, 10.0, "", "sense anti-alias low-pass quality factor") \
  X(double, pick_sense_offset_v, DOUBLE, -5.0, 5.0, "V", "sense channel offset at the ADC") \
  X(double, pick_sense_noise_v_rthz, DOUBLE, 0.0, 1e-2, "V/rtHz", \
    "sense channel white noise at the ADC, one-sided") \
  X(double, pick_sense_delay_s, DOUBLE, -1e-3, 1e-3, "s", \
    "sense sampling instant after the tick (|.| <= T/2)") \
  X(double, pick_sense_jitter_s, DOUBLE, 0.0, 1e-3, "s", "sense sampling jitter rms (<= T/20)") \
  X(double, pick_sense_gap_m, DOUBLE, 0.0, 1e-3, "m", \
    "sense pickoff parallel-plate gap: capacitive nonlinearity, 0 = linear") \
  X(double, pick_sense_gap_asym, DOUBLE, 0.0, 1.0, "", \
    "imbalance of the sense pickoff pair (0 balanced: odd orders only, 1 one-sided)") \
  X(double, pick_sense_gain_flicker_1hz_rthz, DOUBLE, 0.0, 1e-2, "1/rtHz", \
    "relative 1/f noise of the sense pickoff gain at 1 Hz, 0 = none") \
  X(double, pick_sense_phase_flicker_1hz_deg_rthz, DOUBLE, 0.0, 1.0, "deg/rtHz", \
    "1/f noise of the sense circuit phase at 1 Hz, 0 = none") \
  X(double, pick_lag_ref_hz, DOUBLE, 1.0, 1e6, "Hz", \
    "frequency at which the circuit lags equal phi (< fs/2)") \
  X(double, pick_phase_step_rad, DOUBLE, 0.0, 0.01, "rad", \
    "circuit phase change that re-discretises a pickoff") \
  X(double, pick_flicker_fmin_hz, DOUBLE, 1e-7, 1.0, "Hz", \
    "the pickoff gain and phase 1/f spectra flatten below this") \
  /* ADC (adc.h) and the shared reference (vref.h) */ \
  X(double, adc_full_scale_v, DOUBLE, 0.01, 100.0, "V", "ADC full scale, +-") \
  X(double, adc_inl_bow_lsb, DOUBLE, -64.0, 64.0, "LSB", \
    "ADC INL bow at mid-scale, zero at the ends (inl.h), 0 = none") \
  X(double, adc_inl_code_lsb, DOUBLE, 0.0, 64.0, "LSB", \
    "ADC per-code INL: rms weight error of the MSB (inl.h), 0 = none") \
  X(double, adc_aperture_jitter_s, DOUBLE, 0.0, 1e-3, "s", \
    "ADC aperture jitter rms, common to both channels (<= T/20), 0 = none") \
  X(double, vref_noise_white_rthz, DOUBLE, 0.0, 1e-3, "1/rtHz", \
    "relative white noise of the reference shared by ADC and DAC, 0 = none") \
  X(double, vref_noise_1hz_rthz, DOUBLE, 0.0, 1e-2, "1/rtHz", \
    "relative 1/f noise of that reference at 1 Hz, 0 = none") \
  X(double, vref_noise_fmin_hz, DOUBLE, 1e-7, 1.0, "Hz", \
    "reference 1/f spectrum flattens below this") \
  /* acceleration (accel.h): force per unit mass per g */ \
  X(double, gs_drive_from_drive_mps2_per_g, DOUBLE, -1e3, 1e3, "(m/s^2)/g", \
    "drive-axis force per g along the drive axis") \
  X(double, gs_drive_from_sense_mps2_per_g, DOUBLE, -1e3, 1e3, "(m/s^2)/g", \
    "drive-axis force per g along the sense axis") \
  X(double, gs_drive_from_normal_mps2_per_g, DOUBLE, -1e3, 1e3, "(m/s^2)/g", \
    "drive-axis force per g along the rate axis") \
  X(double, gs_sense_from_drive_mps2_per_g, DOUBLE, -1e3, 1e3, "(m/s^2)/g", \
    "sense-axis force per g along the drive axis") \
  X(double, gs_sense_from_sense_mps2_per_g, DOUBLE, -1e3, 1e3, "(m/s^2)/g", \
    "sense-axis force per g along the sense axis") \
  X(double, gs_sense_from_normal_mps2_per_g, DOUBLE, -1e3, 1e3, "(m/s^2)/g", \
    "sense-axis force per g along the rate axis") \
  /* thermal network (thermal.h) */ \
  X(double, tau_struct_s, DOUBLE, 1e-3, 1e9, "s", "structure node time constant to ambient") \
  X(double, tau_circuit_s, DOUBLE, 1e-3, 1e9, "s", \
    "pickoff circuit node time constant to ambient") \
  X(double, tau_board_s, DOUBLE, 1e-3, 1e9, "s", "board sensor node time constant to ambient") \
  X(double, couple_sc_per_s, DOUBLE, 0.0, 1e3, "1/s", "structure-circuit heat exchange rate") \
  X(double, couple_sb_per_s, DOUBLE, 0.0, 1e3, "1/s", "structure-board heat exchange rate") \
  X(double, couple_cb_per_s, DOUBLE, 0.0, 1e3, "1/s", "circuit-board heat exchange rate") \
  X(double, rise_struct_k, DOUBLE, -100.0, 500.0, "K", "structure self-heating rise if alone") \
  X(double, rise_circuit_k, DOUBLE, -100.0, 500.0, "K", "circuit self-heating rise if alone") \
  X(double, rise_board_k, DOUBLE, -100.0, 500.0, "K", \
    "board sensor spot self-heating rise if alone") \
  X(double, thermal_dt_s, DOUBLE, 1e-5, 10.0, "s", \
    "thermal update period (rounded to whole samples)") \
  /* the sample clock (the MCU's crystal): the firmware's time; the plant's physics keep \
   * true time (mech_set_clock) */ \
  X(double, clock_ppm, DOUBLE, -1000.0, 1000.0, "ppm", \
    "sample clock's error at 25 degC board temperature, time zero (+: fast)") \
  X(double, clock_tempco_ppm_per_k, DOUBLE, -10.0, 10.0, "ppm/K", \
    "sample clock's change with the board node's temperature (linear about 25 degC)") \
  X(double, clock_ageing_ppm_per_day, DOUBLE, -10.0, 10.0, "ppm/day", \
    "sample clock's drift with time since power-on (ageing, linear)") \
  /* the board's temperature sensor (board_sensor.h): a TMP117 reading the board node */ \
  X(double, board_sensor_offset_c, DOUBLE, -1.0, 1.0, "degC", \
    "board temperature sensor's accuracy error at 25 degC (TMP117: +-0.1 degC over " \
    "-20..50 degC, SNOSD82D 6.5)") \
  X(double, board_sensor_slope, DOUBLE, -0.01, 0.01, "K/K", \
    "that error's change per K away from 25 degC (TMP117: +-0.2 degC over -40..100 degC)") \
  X(double, board_sensor_fault_s, DOUBLE, -1.0, 1e9, "s", \
    "time from which the board temperature sensor stops answering (the HAL reports FAULT " \
    "at each result it misses), negative = never") \
  /* switches (kept at the end so the struct has no padding between fields) */ \
  X(int, truth_decim, INT, 1, 1000000, "", "phasor truth (amplitudes, phases) every n samples") \
  X(int, fb_mode, INT, 0, 3, "", \
    "sense feedback actuator: 0 off, 1 single electrode, 2 differential (DC+AC: fb_bias_v " \
    "+- the spare DAC), 3 pair driven from the electrode input (half-frequency, or DC+AC)") \
  X(int, pick_drive_temp_node, INT, 0, 2, "", \
    "thermal node of the drive circuit laws: 0 structure, 1 circuit, 2 board") \
  X(int, pick_sense_temp_node, INT, 0, 2, "", \
    "thermal node of the sense circuit laws: 0 structure, 1 circuit, 2 board") \
  X(int, board_seed, INT, 0, 1000000000, "", \
    "the board's draw of its converters' INL patterns (ADC, DAC): a property of the board, " \
    "the same in every run whatever the noise seed; a lot draws one per part") \
  X(int, q_temp_law, INT, 0, 2, "", \
    "Q against structure temperature: 0 constant, 1 gas damping (air), 2 thermoelastic " \
    "(vacuum) (qlaw.h)") \
  X(int, board_sensor, INT, 0, 1, "", \
    "board temperature sensor: 0 none (the HAL reports ABSENT), 1 a TMP117 on the board " \
    "node, a result every 1 s (board_sensor.h)") \
  X(bool, full_kinematics, BOOL, 0, 1, "", \
    "reciprocal Coriolis, centrifugal and Euler terms of (2-20)") \
  X(bool, brownian, BOOL, 0, 1, "", "Brownian force noise on both axes (4-20)") \
  X(bool, pick_drive_lag_allpass, BOOL, 0, 1, "", \
    "drive circuit lag as an all-pass (pure phase) instead of a low-pass") \
  X(bool, pick_sense_lag_allpass, BOOL, 0, 1, "", \
    "sense circuit lag as an all-pass instead of a low-pass") \
  X(bool, cold_start, BOOL, 0, 1, "", \
    "power-on after a long power-off: every thermal node starts at the ambient and the " \
    "self-heating (rise_*) then warms it; 0: the run starts in the thermal steady state")

#define PLANT_CFG_FIELD(ctype, name, kind, lo, hi, unit, doc) ctype name;
typedef struct {
  PLANT_PARAMS(PLANT_CFG_FIELD)
} plant_cfg_t;

/* The pickoff parameter `name` of an axis (0 drive, 1 sense): pick_drive_<name> or
 * pick_sense_<name>. The two chains are built from one list of parameters this way. */
#define PLANT_PICK(c, axis, name) \
  ((axis) == 0 ? (c)->pick_drive_##name : (c)->pick_sense_##name)
#undef PLANT_CFG_FIELD

/* Voltages of the sense electrodes, V: the feedback pair U3, U4 (fb_mode 3; U3 is the DAC's
 * spare channel), the nulling sets V1, V2 and the tuning electrodes Vt (DAC channels
 * HAL_DAC_SENSE_FB_U1 .. HAL_DAC_TUNE). An electrode the part does not have (its constant
 * 0, or the feedback pair outside fb_mode 3) ignores its voltage, and its DAC channel is
 * not modelled (dac.h: no cost per sample). */
typedef struct {
  double fb_u1_v, fb_u2_v;             /* feedback pair U3, U4 (fb_mode 3) */
  double quadnull_v1_v, quadnull_v2_v; /* nulling sets: k_yx = c (V1^2 - V2^2) */
  double tune_v;                       /* tuning electrodes */
} plant_electrodes_t;

#define PLANT_ELECTRODE_MAX_V 100.0 /* largest |voltage| plant_set_electrodes accepts */
#define PLANT_ELECTRODES 5          /* fb U3, fb U4, nulling V1, V2, tuning Vt */

typedef struct {
  profile_t rate_dps;      /* angular rate, deg/s */
  profile_t ambient_k;     /* ambient temperature, K */
  accel_profile_t accel_g; /* case acceleration, g (ACCEL_AXIS_* order) */
} plant_profiles_t;

typedef struct {
  uint64_t sample; /* samples done; the state below is at t_s */
  double t_s;
  /* inputs */
  double rate_dps;
  double accel_g[3]; /* mean over the last sample */
  /* temperatures */
  double ambient_k, struct_k, circuit_k, board_k;
  double board_meas_c;   /* the board temperature sensor's latest result (board_sensor.h), as
                          the firmware reads it: a whole number of LSB, degC; NaN before
                          its first result, without a sensor, and while it does not answer */
  double wn_drive_rad_s; /* drive resonance now (2-32), per second of the sample clock */
  double clock_ppm;      /* the sample clock's error now (+: fast; plant_cfg_t clock_*) */
  double q_drive;        /* drive quality factor now (q_temp_law) */
  double wn_sense_rad_s; /* sense resonance now (2-32) without the electrostatic
                              softening, per second of the sample clock */
  double q_sense;        /* sense quality factor now (q_temp_law) */
  /* motion (state at t_s) */
  double y_m, vy_mps, x_m, vx_mps;
  /* phasors at the drive frequency (every truth_decim samples): */
  double drive_freq_hz;    /* of the drive force, estimated from its samples */
  double drive_force_mps2; /* amplitude of the held drive force's fundamental */
  double drive_amp_m;      /* |drive displacement| */
  double drive_phase_rad;  /* displacement relative to the held force's fundamental;
                                 -pi/2 at resonance, (2-24); 0 without force */
  double sense_vel_m;      /* sense displacement in phase with the drive velocity
                                 (Coriolis direction, (2-28)) */
  double sense_disp_m;     /* in phase with the drive displacement (quadrature) */
  /* sense electrodes and what they do (every truth_decim samples, and at plant_init): */
  plant_electrodes_t elec_v;      /* the series voltages last set (plant_set_electrodes) */
  plant_electrodes_t elec_mean_v; /* every sample: each electrode's mean voltage over the last
                                     sample as the part sees it (its DAC channel plus the
                                     series voltage, without the electrode noise); 0 for an
                                     electrode the part does not have */
  double quadnull_v;              /* the nulling sets as one signed voltage: sign(m1 - m2)
                                sqrt|m1 - m2|, m the sets' mean squares, so k_yx =
                                c quadnull_v |quadnull_v|: +V1 with set 1 alone driven,
                                -V2 with set 2 alone (the one that cancels a positive
                                k_q); 0 without nulling electrodes */
  double quad_true_dps;  /* the quadrature as an equivalent rate: the stiffness coupling
                                (k_q and its drift at the structure temperature, plus the
                                nulling electrodes' k_yx) over 2 wc, wc the drive frequency
                                above (drive_freq_hz) */
  double sense_freq_hz;  /* sense resonance sqrt(wn2^2 - k_e) with the electrostatic
                                softening k_e (fb bias and electrodes), sample clock */
  double sense_shift_hz; /* its shift by k_e, <= 0 */
  /* electrical */
  double f_drive_mps2, f_sense_mps2;       /* actuator + acceleration forces per unit mass */
  double dac_held_v[HAL_DAC_NUM_CHANNELS]; /* DAC output levels over the last sample (0 V
                                              on a channel that is not modelled, dac.h) */
  double adc_v[2];     /* analog voltages at the ADC inputs (drive, sense) */
  hal_adc_frame_t adc; /* the codes returned */
  uint64_t adc_clip[2], dac_rejects;
  uint64_t mech_refreshes;
} plant_truth_t;

/* Laws of the plant with a range (plant_law_name gives the JSON key):
 *   PICK_*_PHASE  circuit phase (2-40), pickoff.h: [-80, 80] deg low-pass lag section
 *                 ([-80, 160] all-pass), a lag passing through zero into a lead;
 *   PICK_*_GAIN   ring-diode gain factor 1 + tc (T - T0) (4-12) >= 0.1;
 *   RESONANCE     (2-32) at the structure temperature, |0.5 kET (T - T0)| < 0.2;
 *   AMBIENT       the thermal network's input, 1..2000 K;
 *   Q_TEMP        the Q law (qlaw.h) at the structure temperature: 170..1900 K (gas),
 *                 200..500 K (thermoelastic);
 *   DUFFING_*     the cubic suspension term, |k3/k| x^2 <= 0.1 (mech.h);
 *   PICK_*_GAP    the capacitive pickoff law, |x| / gap <= 0.3 (pickoff.h);
 *   SENSE_PULL_IN the electrostatic softening of the sense spring, at most half of it
 *                 (mech.h): the electrodes' voltages beyond it are held at the margin.
 * Every law holds over the -40..85 degC ambient of the default part and of the ranges
 * of the parameters' defaults. Outside its range a law is held at the edge (the ambient
 * at its last sane value) and each evaluation there (every thermal update, and once at
 * plant_init; the amplitude laws DUFFING_* and PICK_*_GAP once per thermal update in
 * which a sample left the range; SENSE_PULL_IN likewise) is counted, never refused. */
typedef enum {
  PLANT_LAW_PICK_DRIVE_PHASE = 0,
  PLANT_LAW_PICK_SENSE_PHASE,
  PLANT_LAW_PICK_DRIVE_GAIN,
  PLANT_LAW_PICK_SENSE_GAIN,
  PLANT_LAW_RESONANCE,
  PLANT_LAW_AMBIENT,
  PLANT_LAW_Q_TEMP,
  PLANT_LAW_DUFFING_DRIVE,
  PLANT_LAW_DUFFING_SENSE,
  PLANT_LAW_PICK_DRIVE_GAP,
  PLANT_LAW_PICK_SENSE_GAP,
  PLANT_LAW_SENSE_PULL_IN,
  PLANT_LAWS
} plant_law_t;

typedef struct {
  uint64_t count;   /* evaluations outside the law's range */
  double first_t_s; /* plant time of the first one (meaningful when count > 0) */
} plant_warning_t;

typedef struct {
  plant_cfg_t cfg;
  plant_profiles_t prof;
  mech_t mech;
  thermal_t thermal;
  dac_t dac;
  dac_out_t dout; /* the DAC's outputs over the current sample (unmodelled channels 0 V) */
  actuator_t act;
  pickoff_t pick[2];
  adc_t adc;
  accel_t accel;
  vref_t vref;                            /* the converters' shared reference */
  vib_t vib;                              /* random vibration of the acceleration profile */
  actuator_elec_in_t elec_in;             /* the electrodes' voltages over the sample, as the
                                             actuator takes them (DAC + series) */
  plant_electrodes_t elec_series;         /* plant_set_electrodes' voltages */
  uint8_t elec_has[PLANT_ELECTRODES];     /* the part has that electrode (fb U3, U4, V1,
                                             V2, Vt) */
  drift_t drift[2];                       /* slow drift of k_q and d_q */
  board_sensor_t board_sensor;            /* the board's temperature sensor (board_sensor.h) */
  double drift_kq_per_s2, drift_dq_per_s; /* per unit of the drifts' values (deg/s) */
  uint64_t seed;
  double T;                     /* sample period */
  uint64_t k;                   /* samples done */
  int thermal_every;            /* samples per thermal update */
  int accel_any, accel_dynamic; /* acceleration profile non-zero / has a sine or a shock */
  int vib_on, drift_on;         /* random vibration / a coupling drift is on */
  /* truth: drive-frequency estimate from the force samples */
  double f_prev[2]; /* F_{k-1}, F_{k-2} */
  double est_num, est_den, est_alpha;
  double cw, sw, inv_sw; /* cos, sin, 1/sin of w T of the current frequency estimate */
  int thermal_countdown, truth_countdown; /* samples to the next update */
  double fz_re, fz_im, fz_alpha;          /* force phasor at mid-sample, rotating average */
  plant_truth_t truth;
  plant_warning_t warn[PLANT_LAWS];
  char err[192];
} plant_t;

/* ----------------------------------------------------------------- life cycle -- */

/* The default part, preset "thesis": the table "thesis linear gyro, air package"
 * (system spec §2) plus the imperfections that reproduce the thesis's measured figures
 * (bias stability, square law; plant_cfg.c and docs/honest-part.md give each value's
 * source). */
void plant_default_cfg(plant_cfg_t *cfg);

/* Preset "ideal": the same table with every imperfection beyond the thesis's linear gyro
 * off (the q_temp_law, k3_*, *_drift_*, fb_gap_m, pick_*_gap_*, pick_*_flicker_*,
 * adc_inl_*, dac_inl_*, adc_aperture_jitter_s, vref_noise_* parameters at zero): the
 * part the simulator modelled before the imperfections existed. */
void plant_ideal_cfg(plant_cfg_t *cfg);

/* Part presets by name into cfg (the whole configuration replaced): "thesis" (=
 * plant_default_cfg) or "ideal" (plant_ideal_cfg). 0, or -1 if the name is unknown
 * (cfg unchanged). PLANT_PRESET_NAMES lists them for messages. */
int plant_preset(plant_cfg_t *cfg, const char *name);
#define PLANT_PRESET_NAMES "thesis (the default) or ideal"

/* Thermal presets "default", "tight", "loose" (thermal.h) into cfg; -1 if unknown. */
int plant_thermal_preset(plant_cfg_t *cfg, const char *name);

/* Ranges of every parameter plus cross-checks. 0, or -1 with the offending key and
 * the reason in errbuf (if errbuf != NULL). */
int plant_cfg_check(const plant_cfg_t *cfg, char *errbuf, size_t errlen);

/* Validates and builds every module at the start of a run: thermal nodes settled at
 * the ambient temp_k, converters at mid-scale, motion at rest, constant profiles from
 * rate_dps and temp_k. Returns 0; or -1 (bad cfg: plant_cfg_check) with the reason in
 * plant_error(p) and nothing else in p changed; or -2 if a module refused a cfg that
 * plant_cfg_check passed (a gap in the checks, not expected), reason in plant_error(p)
 * and p zeroed (not usable until a successful plant_init). The plant is built in
 * place, without a scratch copy on the stack (a target has little of it); cfg may be
 * &p->cfg. */
int plant_init(plant_t *p, const plant_cfg_t *cfg, uint64_t seed);
const char *plant_error(const plant_t *p);

/* Replace the input profiles (validated; on error -1, profiles unchanged, reason in
 * plant_error). The ambient profile takes effect at the next thermal update; the
 * thermal nodes are not reset. */
int plant_set_profiles(plant_t *p, const plant_profiles_t *prof);

/* An input moved while the plant runs: the rate table's rate (deg/s) or the chamber's
 * ambient (K) goes from its value now to `to` along a linear edge of edge_s, then holds
 * (the emulated board's `emu rate`, gyro-sim's bench commands on its pty). Returns 0, or
 * -1 with nothing changed (a value outside the plant's rate_dps or temp_k range, an edge
 * not in (0, 1e5] s; reason in plant_error). */
typedef enum { PLANT_INPUT_RATE = 0, PLANT_INPUT_AMBIENT = 1 } plant_input_t;
int plant_move_input(plant_t *p, plant_input_t which, double to, double edge_s);
/* The input's value now (deg/s or K). */
double plant_input_now(const plant_t *p, plant_input_t which);
/* The part after a long power-off at the ambient now: every thermal node at the ambient
 * (as plant.cold_start at power-on), from which its own dissipation warms it again (the
 * simulated bench's power cycle; the firmware's restart is the caller's). Returns 0. */
int plant_cold_soak(plant_t *p);

/* One sample (see the top of this file). dac: the frame on the converter outputs over
 * this interval; a frame with an out-of-range code is rejected (counted, the previous
 * frame held). adc: the frame sampled at the end of the interval. */
void plant_step(plant_t *p, const hal_dac_frame_t *dac, hal_adc_frame_t *adc);

/* Voltages in series with the electrodes' DAC channels (plant_electrodes_t), from the next
 * sample on, held: a source between the board's driver and the electrode (a bench supply
 * in a test, a bias beyond the driver's +-15 V). The electrode sees its channel's output
 * (filtered, per-sample mean and mean square, dac.h) plus this level; 0 V at plant_init,
 * so the DAC alone drives the electrodes. Each finite and within +-PLANT_ELECTRODE_MAX_V,
 * else -1 with the key in plant_error(p) and nothing changed. */
int plant_set_electrodes(plant_t *p, const plant_electrodes_t *v);

/* The same step in the shape of hal_host_plant_step_fn (hal/host/hal_host.h), so the
 * host HAL stub can attach a plant_t without a cast: plant is a plant_t *. */
void plant_step_hal(void *plant, const hal_dac_frame_t *dac, hal_adc_frame_t *adc);

/* The board temperature sensor (board_sensor.h) as the HAL reads it at time t_s, in the
 * shape of hal_host_board_temp_fn (hal/host/hal_host.h): plant is a plant_t *. NEW with
 * *code the latest finished result and *conversion its number; NONE before the first;
 * FAULT from board_sensor_fault_s on; ABSENT with board_sensor 0. t_s not before the
 * start of the last sample run (the host HAL passes its ticks over the rate: the plant
 * has run one sample more). */
hal_board_temp_event_t plant_board_temp_hal(void *plant, double t_s, int16_t *code,
                                            uint64_t *conversion);

/* The truth of the last completed sample. */
const plant_truth_t *plant_truth(const plant_t *p);

/* Warnings of the temperature laws, PLANT_LAWS entries in plant_law_t order. */
const plant_warning_t *plant_warnings(const plant_t *p);
/* Evaluations outside their range, all laws together. */
uint64_t plant_warning_total(const plant_t *p);
/* "pick_drive_phase", ..., NULL past the end. */
const char *plant_law_name(int law);

/* k_e / m (1/s^2) of the electrostatic spring softening of the sense axis by the DC
 * bias of the feedback electrodes (thesis (6-3), parallel plates of gap fb_gap_m):
 * 4 ks_fb_mps2_per_v2 fb_bias_v^2 / fb_gap_m in differential mode (fb_mode 2), 0 in
 * the other modes (no DC on the electrodes) or with fb_gap_m = 0. */
double plant_fb_softening(const plant_cfg_t *cfg);

/* k_e / m per V^2 of the feedback pair's softening in fb_mode 3, 2 ks_fb / fb_gap_m (the
 * sum U3^2 + U4^2 multiplies it); 0 in the other modes or with fb_gap_m = 0. */
double plant_fb_pair_softening(const plant_cfg_t *cfg);

/* The rate equivalent of the sense feedback force, deg/s per V^2 of force command: the
 * force Ks_fb per V^2 (ks_fb_mps2_per_v2, per unit mass) balances the Coriolis force
 * 2 Omega A0 wc (2-28) of a drive of amplitude amp_m at f_drive_hz. The force-rebalance
 * scale factor rate.scale_dps g (sense_fr.h) is this when both are the part's. 0 for a
 * non-positive amplitude or frequency. */
double plant_fb_rate_dps_per_v2(const plant_cfg_t *cfg, double f_drive_hz, double amp_m);

/* ------------------------------------------------------------ budgets -------- */

/* Whether the tuning electrodes can put the sense resonance at the drive resonance plus
 * split_hz (0: matched), and with which voltage, at structure temperature temp_k ((2-32)
 * moves both resonances, the electrostatic softening stays). Tuning only lowers the sense
 * resonance (k_e >= 0), so a part whose sense resonance (with the softening already on:
 * the fb bias's and ke_other_per_s2, e.g. the nulling electrodes' at their voltages) is
 * below the target cannot be reached; nor beyond the pull-in margin (half the sense
 * stiffness, mech.h) or PLANT_ELECTRODE_MAX_V, nor without tuning electrodes. */
typedef struct {
  int reachable;      /* 1: tune_v puts the sense resonance at the target */
  double f_drive_hz;  /* drive resonance at temp_k */
  double f_sense_hz;  /* sense resonance at temp_k with the softening already on */
  double f_target_hz; /* f_drive_hz + split_hz */
  double ke_per_s2;   /* softening the tuning has to add, 1/s^2 (< 0: the target is above) */
  double tune_v;      /* the voltage that does (0 when not reachable) */
  char msg[200];      /* one line: the voltage and the move, or why it cannot be done */
} plant_match_t;

/* Fills out; 0 when reachable, 1 when not (out->msg says why), -1 for an invalid cfg or a
 * non-finite argument (out->msg says which). */
int plant_sense_match(const plant_cfg_t *cfg, double temp_k, double split_hz,
                      double ke_other_per_s2, plant_match_t *out);

/* Worst-case fraction of the ADC full scale used by each channel (drive, sense) at
 * the design point: drive amplitude drive_amp_m (largest drive voltage), quadrature,
 * full-scale rate rate_fs_dps, vibration vib_g at vib_hz along the sense axis,
 * offsets and drive feedthrough, all peaks added. Returns the larger of the two. */
double plant_adc_fraction(const plant_cfg_t *cfg, double frac[2]);

typedef struct {
  double latency_deg;      /* one-sample DAC latency of the board, wc T */
  double zoh_deg;          /* zero-order hold, wc T / 2 */
  double recon_deg;        /* reconstruction low-pass, on the force (2x the voltage's) */
  double pick_lag_deg;     /* circuit lag Phi_cir(T) of the drive pickoff */
  double aa_deg;           /* anti-alias band-pass (high-pass lead, low-pass lag) */
  double sample_delay_deg; /* drive channel sampling delay */
  double analog_deg;       /* recon + pick_lag + aa: the thesis's "circuit" lag */
  double total_deg;        /* everything above */
} plant_phase_budget_t;

/* Phase lags of the drive signal chain at frequency f_hz (force at f, voltages at f/2
 * for half-frequency drive) with the drive pickoff circuit at temp_k. With the
 * defaults, analog_deg = 9.56 at 1489.9 Hz and T0 (§7.2.2: -99.56 deg at resonance).
 * A sweep by the firmware sees -90 - total_deg minus whatever of the latency and hold
 * its drive synthesis does not advance. */
void plant_drive_phase_budget(const plant_cfg_t *cfg, double f_hz, double temp_k,
                              plant_phase_budget_t *out);

/* ------------------------------------------------------------ parameters ----- */

typedef enum {
  PLANT_PARAM_DOUBLE = 0,
  PLANT_PARAM_INT = 1,
  PLANT_PARAM_BOOL = 2
} plant_param_type_t;

typedef struct {
  const char *name; /* = the plant_cfg_t field */
  size_t offset;    /* offsetof(plant_cfg_t, field) */
  plant_param_type_t type;
  double min, max; /* inclusive */
  const char *unit;
  const char *doc;
} plant_param_desc_t;

size_t plant_param_count(void);
const plant_param_desc_t *plant_param_at(size_t i); /* NULL past the end */
const plant_param_desc_t *plant_param_find(const char *name);
/* Value of a parameter as a double. */
double plant_param_get(const plant_cfg_t *cfg, const plant_param_desc_t *d);
/* Set by name: finite, in range, integral for int, 0/1 for bool. Returns 0, or -1 with
 * the key and the allowed range in errbuf and cfg unchanged. */
int plant_param_set(plant_cfg_t *cfg, const char *name, double value, char *errbuf,
                    size_t errlen);

#endif /* PLANT_PLANT_H */
