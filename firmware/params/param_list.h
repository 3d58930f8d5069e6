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
 * Controller defaults below assume the thesis part: drive resonance 1489.9 Hz,
 * Q1 = 33.33, so amplitude and phase both answer the drive force as a first-order lag
 * with tau = 2 Q1 / wn1 = 7.1 ms (6-12, 6-17). Each PI puts its zero on that pole
 * (ki / kp = 1 / tau) and crosses over at 30 rad/s, which locks in about 0.1-0.2 s like
 * the thesis's loop (6.4). The closed-loop design refines them from the sweep.
 */
#ifndef PARAM_LIST_H
#define PARAM_LIST_H

#define PARAM_LAYOUT_VERSION 1u

#define PARAM_CHOICE(v) (1u << (v))

/* clang-format off */
#define PARAM_LIST(X) \
  /* 7.2.2: measured drive resonance of the thesis part */ \
  X(drive_freq_hz, 0x0101u, "drive.freq_hz", F32, "Hz", 500.0f, 5000.0f, 1489.9f, 0u, \
    PF_PERSIST | PF_LIVE, "drive frequency, fixed near the drive resonance found by the sweep") \
  /* half-frequency by default: 1/f voltage noise lands at wc/2, not wc (6-21, 6-23) */ \
  X(drive_mode, 0x0102u, "drive.mode", ENUM, "-", 0u, 1u, 0u, PARAM_CHOICE(0) | PARAM_CHOICE(1), \
    PF_PERSIST | PF_RESTART, "drive scheme: 0 half-frequency (6-18), 1 DC+AC (6-20)") \
  /* 1 V is 20 % of the +-5 V ADC: room for feedthrough and the start-up overshoot */ \
  X(drive_amp_set_v, 0x0103u, "drive.amp_set_v", F32, "V", 0.05f, 4.5f, 1.0f, 0u, \
    PF_PERSIST | PF_LIVE, "setpoint of the demodulated drive-pickoff amplitude at the ADC") \
  /* 7.2.2: -90 deg at resonance plus 9.56 deg circuit and algorithm lag */ \
  X(drive_phase_set_deg, 0x0104u, "drive.phase_set_deg", F32, "deg", -180.0f, 180.0f, -99.56f, 0u, \
    PF_PERSIST | PF_LIVE, "setpoint of the drive vibration phase against the force reference") \
  /* kp = wc tau / G with wc = 30 rad/s, tau = 7.1 ms, small-signal gain G ~ 0.33 V/V */ \
  X(drive_amp_kp, 0x0105u, "drive.amp_kp", F32, "V/V", 0.0f, 100.0f, 0.65f, 0u, \
    PF_PERSIST | PF_LIVE, "amplitude PI proportional gain (drive volts per volt of error)") \
  /* ki = kp / tau: the PI zero cancels the amplitude pole (6-12) */ \
  X(drive_amp_ki, 0x0106u, "drive.amp_ki", F32, "V/V/s", 0.0f, 100000.0f, 91.0f, 0u, \
    PF_PERSIST | PF_LIVE, "amplitude PI integral gain") \
  /* the phase plant has unit gain (6-17): kp = wc tau */ \
  X(drive_phase_kp, 0x0107u, "drive.phase_kp", F32, "deg/deg", 0.0f, 100.0f, 0.21f, 0u, \
    PF_PERSIST | PF_LIVE, "phase PI proportional gain (force-phase degrees per degree of error)") \
  /* ki = kp / tau = wc */ \
  X(drive_phase_ki, 0x0108u, "drive.phase_ki", F32, "deg/deg/s", 0.0f, 100000.0f, 30.0f, 0u, \
    PF_PERSIST | PF_LIVE, "phase PI integral gain") \
  /* table 7-1: 12.75 V drive amplitude; 15 V is the output stage's limit */ \
  X(drive_u_max_v, 0x0109u, "drive.u_max_v", F32, "V", 0.1f, 15.0f, 12.75f, 0u, \
    PF_PERSIST | PF_LIVE, "limit of each drive electrode voltage (PI output clamp)") \
  /* DC+AC only: force = 4 Ks D A (6-21); 5 V leaves headroom under u_max for A */ \
  X(drive_dc_bias_v, 0x010Au, "drive.dc_bias_v", F32, "V", 0.0f, 15.0f, 5.0f, 0u, \
    PF_PERSIST | PF_LIVE, "DC bias D of the DC+AC drive (unused in half-frequency mode)") \
  /* 5.4: mu ~ 0.03 at 50 kHz; |r| = 1 makes it a normalised step (5-5) */ \
  X(demod_mu_drive, 0x0201u, "demod.mu_drive", F32, "-", 0.0001f, 0.49f, 0.03f, 0u, \
    PF_PERSIST | PF_LIVE, "LMS demodulator step size, drive pickoff (sets its bandwidth)") \
  /* same bandwidth as the drive channel */ \
  X(demod_mu_sense, 0x0202u, "demod.mu_sense", F32, "-", 0.0001f, 0.49f, 0.03f, 0u, \
    PF_PERSIST | PF_LIVE, "LMS demodulator step size, sense pickoff") \
  /* calibrated per part; 0 until the quadrature-nulling calibration has run */ \
  X(rate_demod_phase_deg, 0x0301u, "rate.demod_phase_deg", F32, "deg", -180.0f, 180.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "rotation of sense I/Q that separates rate from quadrature") \
  /* 5.4.3: 100 Hz output low-pass */ \
  X(rate_lpf_cutoff_hz, 0x0302u, "rate.lpf_cutoff_hz", F32, "Hz", 1.0f, 1000.0f, 100.0f, 0u, \
    PF_PERSIST | PF_LIVE, "rate output low-pass cut-off (Butterworth)") \
  /* 5.4.3: 4th order as two biquads (5-12, 5-13) */ \
  X(rate_lpf_order, 0x0303u, "rate.lpf_order", ENUM, "-", 2u, 8u, 4u, \
    PARAM_CHOICE(2) | PARAM_CHOICE(4) | PARAM_CHOICE(6) | PARAM_CHOICE(8), \
    PF_PERSIST | PF_LIVE, "rate output low-pass order (2 per biquad section)") \
  /* 4.6.1: 1 deg/s gives about 2.5 mV at the ADC */ \
  X(rate_scale_dps_per_v, 0x0304u, "rate.scale_dps_per_v", F32, "deg/s/V", -100000.0f, 100000.0f, 400.0f, 0u, \
    PF_PERSIST | PF_LIVE, "rate scale factor from demodulated sense volts") \
  /* uncalibrated: 0 (the thesis part's fit was B = 34.59 P + 58.533, 7.3.2) */ \
  X(rate_bias_c0_dps, 0x0305u, "rate.bias_c0_dps", F32, "deg/s", -2000.0f, 2000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial B(P) = c0 + c1 P + c2 P^2 + c3 P^3, constant term") \
  /* uncalibrated: 0 */ \
  X(rate_bias_c1_dps_per_deg, 0x0306u, "rate.bias_c1_dps_per_deg", F32, "deg/s/deg", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial, linear term in the drive phase P (deg)") \
  /* uncalibrated: 0 */ \
  X(rate_bias_c2_dps_per_deg2, 0x0307u, "rate.bias_c2_dps_per_deg2", F32, "deg/s/deg^2", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial, quadratic term") \
  /* uncalibrated: 0 */ \
  X(rate_bias_c3_dps_per_deg3, 0x0308u, "rate.bias_c3_dps_per_deg3", F32, "deg/s/deg^3", -10000.0f, 10000.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "bias polynomial, cubic term") \
  /* uncalibrated: 0, scale factor independent of temperature */ \
  X(rate_sf_c1_per_deg, 0x0309u, "rate.sf_c1_per_deg", F32, "1/deg", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial SF(P) = 1 + c1 P + c2 P^2 + c3 P^3, linear term") \
  /* uncalibrated: 0 */ \
  X(rate_sf_c2_per_deg2, 0x030Au, "rate.sf_c2_per_deg2", F32, "1/deg^2", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial, quadratic term") \
  /* uncalibrated: 0 */ \
  X(rate_sf_c3_per_deg3, 0x030Bu, "rate.sf_c3_per_deg3", F32, "1/deg^3", -1.0f, 1.0f, 0.0f, 0u, \
    PF_PERSIST | PF_LIVE, "scale-factor polynomial, cubic term") \
  /* 50 % over the setpoint: beyond any PI overshoot seen at lock (6.4), short of the stops */ \
  X(sup_amp_trip_rel, 0x0401u, "sup.amp_trip_rel", F32, "-", 1.05f, 5.0f, 1.5f, 0u, \
    PF_PERSIST | PF_LIVE, "over-amplitude trip, as a multiple of drive.amp_set_v") \
  /* 2 %: well above the demodulated amplitude noise at mu = 0.03, tight enough that LOCKED means settled */ \
  X(sup_lock_tol_rel, 0x0402u, "sup.lock_tol_rel", F32, "-", 0.001f, 0.5f, 0.02f, 0u, \
    PF_PERSIST | PF_LIVE, "LOCKED when the relative amplitude error stays within this") \
  /* 100 Hz matches the 100 Hz output bandwidth */ \
  X(tlm_rate_hz, 0x0501u, "tlm.rate_hz", U32, "Hz", 1u, 5000u, 100u, 0u, \
    PF_PERSIST | PF_LIVE, "telemetry frame rate") \
  /* 4.4.2: the 50 kHz tick; fixed by the timer and the filter designs */ \
  X(sys_fs_hz, 0x0601u, "sys.fs_hz", U32, "Hz", 50000u, 50000u, 50000u, 0u, \
    PF_READONLY, "sample rate of the tick")
/* clang-format on */

#endif /* PARAM_LIST_H */
