/* Parameters of the plant: defaults with their sources, the descriptor table generated
 * from PLANT_PARAMS, validation, presets. */
#include "plant/plant.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "plant/plant_const.h"
#include "board.h"

#define PLANT_DESC(ctype, name, kind, lo, hi, unit, doc) \
  {#name, offsetof(plant_cfg_t, name), PLANT_PARAM_##kind, (lo), (hi), (unit), (doc)},
static const plant_param_desc_t kParams[] = {PLANT_PARAMS(PLANT_DESC)};
#undef PLANT_DESC

#define NPARAMS (sizeof kParams / sizeof kParams[0])

size_t plant_param_count(void) { return NPARAMS; }

const plant_param_desc_t *plant_param_at(size_t i) { return i < NPARAMS ? &kParams[i] : NULL; }

const plant_param_desc_t *plant_param_find(const char *name)
{
  if (name == NULL) return NULL;
  for (size_t i = 0; i < NPARAMS; i++)
    if (strcmp(kParams[i].name, name) == 0) return &kParams[i];
  return NULL;
}

double plant_param_get(const plant_cfg_t *cfg, const plant_param_desc_t *d)
{
  const unsigned char *base = (const unsigned char *)cfg + d->offset;
  switch (d->type) {
  case PLANT_PARAM_INT: {
    int v;
    memcpy(&v, base, sizeof v);
    return (double)v;
  }
  case PLANT_PARAM_BOOL: {
    bool v;
    memcpy(&v, base, sizeof v);
    return v ? 1.0 : 0.0;
  }
  case PLANT_PARAM_DOUBLE:
  default: {
    double v;
    memcpy(&v, base, sizeof v);
    return v;
  }
  }
}

static void put(plant_cfg_t *cfg, const plant_param_desc_t *d, double value)
{
  unsigned char *base = (unsigned char *)cfg + d->offset;
  if (d->type == PLANT_PARAM_INT) {
    const int v = (int)value;
    memcpy(base, &v, sizeof v);
  } else if (d->type == PLANT_PARAM_BOOL) {
    const bool v = value != 0.0;
    memcpy(base, &v, sizeof v);
  } else {
    memcpy(base, &value, sizeof value);
  }
}

__attribute__((format(printf, 3, 4))) static void errf(char *buf, size_t n, const char *fmt, ...)
{
  if (buf == NULL || n == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, n, fmt, ap);
  va_end(ap);
}

/* Range and type of one value for descriptor d; 0 or -1 with the message. */
static int check_value(const plant_param_desc_t *d, double value, char *buf, size_t n)
{
  if (!isfinite(value)) {
    errf(buf, n, "%s: not a finite number (allowed %g .. %g)", d->name, d->min, d->max);
    return -1;
  }
  if (value < d->min || value > d->max) {
    errf(buf, n, "%s: out of range (allowed %g .. %g)", d->name, d->min, d->max);
    return -1;
  }
  if ((d->type == PLANT_PARAM_INT || d->type == PLANT_PARAM_BOOL) && value != floor(value)) {
    errf(buf, n, "%s: must be a whole number (allowed %g .. %g)", d->name, d->min, d->max);
    return -1;
  }
  return 0;
}

int plant_param_set(plant_cfg_t *cfg, const char *name, double value, char *errbuf, size_t errlen)
{
  const plant_param_desc_t *d = plant_param_find(name);
  if (d == NULL) {
    if (errbuf != NULL && errlen > 0)
      snprintf(errbuf, errlen, "%s: no such plant parameter", name ? name : "(null)");
    return -1;
  }
  if (cfg == NULL || check_value(d, value, errbuf, errlen) != 0) return -1;
  put(cfg, d, value);
  return 0;
}

/* Sources of the defaults. Sections are the thesis's; "table" is the system spec's
 * table "thesis linear gyro, air package". Values the thesis does not give are
 * chosen to reproduce a measured relation, and say which. */
/* The thermal network's figures of a preset into the flat configuration. */
static void set_thermal(plant_cfg_t *c, const thermal_cfg_t *t)
{
  c->tau_struct_s = t->tau_s[THERMAL_STRUCT];
  c->tau_circuit_s = t->tau_s[THERMAL_CIRCUIT];
  c->tau_board_s = t->tau_s[THERMAL_BOARD];
  c->couple_sc_per_s = t->couple_per_s[THERMAL_PAIR_SC];
  c->couple_sb_per_s = t->couple_per_s[THERMAL_PAIR_SB];
  c->couple_cb_per_s = t->couple_per_s[THERMAL_PAIR_CB];
  c->rise_struct_k = t->rise_k[THERMAL_STRUCT];
  c->rise_circuit_k = t->rise_k[THERMAL_CIRCUIT];
  c->rise_board_k = t->rise_k[THERMAL_BOARD];
}

/* The ideal part's electrodes and their voltage noise (plant_ideal_cfg). */
static void set_ideal_actuators(plant_cfg_t *c)
{
  /* actuators. Ks: the 10 um default amplitude needs A0 wn1^2 / Q1 = 26.3 m/s^2 at
   * resonance; Ks/m = 0.411 gives it at 8.0 V half-frequency amplitude (table 7-1
   * drives up to 12.75 V; the DAC gives 15 V). Voltage noise: placeholders (fig. 6-5
   * shows only the 1/f shape), small against the Brownian floor. */
  c->ks_drive_mps2_per_v2 = 0.411;
  c->drive_noise_white_v_rthz = 200e-9;
  c->drive_noise_1hz_v_rthz = 2e-6;
  c->drive_noise_fmin_hz = 1e-3;
  c->fb_mode = 2; /* differential sense electrodes, biased: the self-test
                                  force (the thesis's sense axis is otherwise open loop) */
  c->ks_fb_mps2_per_v2 = 0.01;
  c->fb_bias_v = 5.0;
  c->fb_noise_white_v_rthz = 200e-9;
  c->fb_noise_1hz_v_rthz = 2e-6;
  c->fb_noise_fmin_hz = 1e-3;
  /* No quadrature-nulling or tuning electrodes: the thesis's part rejects its 1500 deg/s
   * of quadrature by the demodulation phase alone and runs 510 Hz apart (the constants
   * quadnull_dps_per_v2, tune_ke_per_s2_per_v2 stay 0, and quadnull_overlap_per_gap, their
   * softening, too). When a part has them, their voltages carry the same noise as the
   * other electrodes' (placeholders as above). */
  c->quadnull_noise_white_v_rthz = 200e-9;
  c->quadnull_noise_1hz_v_rthz = 2e-6;
  c->quadnull_noise_fmin_hz = 1e-3;
  c->tune_noise_white_v_rthz = 200e-9;
  c->tune_noise_1hz_v_rthz = 2e-6;
  c->tune_noise_fmin_hz = 1e-3;
}

/* The board's temperature sensor (board.h, board_sensor.h): a TMP117, one part's
 * accuracy error well inside its data sheet's (SNOSD82D 6.5: +-0.1 degC over -20..50 degC,
 * +-0.2 over -40..100): +0.04 degC at 25 degC, -0.8 mK/K, so +0.092 degC at -40 and
 * -0.008 degC at 85 degC. It is the board's sensor, not the gyro's imperfection: both
 * presets have it (random numbers of its own, so the gyro's samples do not move). */
static void set_board_sensor(plant_cfg_t *c)
{
  c->board_sensor = BOARD_SENSOR_TMP117;
  c->board_sensor_offset_c = 0.04;
  c->board_sensor_slope = -0.0008;
  c->board_sensor_fault_s = -1.0; /* answers for the whole run */
}

void plant_ideal_cfg(plant_cfg_t *c)
{
  memset(c, 0, sizeof *c);
  /* run */
  c->fs_hz = (double)BOARD_SAMPLE_RATE_HZ; /* §4.4.2, table */
  c->temp_k = 298.15;                      /* room, 25 degC (= T0) */
  c->rate_dps = 0.0;
  c->drive_amp_m = 10e-6; /* §4.6.1, table (15 um in §2.4.2) */
  c->rate_fs_dps = 160.0; /* largest rate of the scale-factor test, table 7-2 */
  /* Range budget vibration: 0.25 g at 100 Hz along the sense axis (0.7 V at the sense
   * ADC after the 100 Hz high-pass); with 1500 deg/s quadrature at 2.5 mV/(deg/s) there
   * is room for little more (§4.4.2: shaking can push the pickoff out of range). */
  c->vib_g = 0.25;
  c->vib_hz = 100.0;
  /* Which board: its converters' INL patterns are drawn from this, never from the run's
   * noise seed, so that a calibration and the runs after it see one board. */
  c->board_seed = 1;
  c->truth_decim = 8;          /* phasor truth every 0.16 ms: 40x faster than the drive
                                  loop's 7 ms time constant, 1/8 of the cost */
  c->truth_force_tau_s = 1e-3; /* the 2-sample force phasor carries the DAC's quantisation
                                  (0.03 deg); 1 ms of averaging: 0.003 deg, and 1/7 of the
                                  drive loop's time constant */
  c->truth_tau_s = 0.02;       /* 14-bit DAC codes make the force a slightly distorted tone:
                                  20 ms of averaging keep the frequency within ~1e-5 */
  /* mechanics */
  c->f_drive_hz = 1489.9; /* §7.2.2 sweep, table (design 1750 Hz) */
  c->q_drive = 33.33;     /* §7.2.2 (-3 dB points), table (design 50) */
  c->f_sense_hz = 2000.0; /* design, §2.4.2, table */
  c->q_sense = 3.0;       /* design, §2.2.2 (air), table */
  c->mass_kg = 0.26e-6;   /* §4.6.1: 0.26 mg, table */
  c->temp_ref_k = 298.15;
  /* kET: (2-29) gives 25..75 ppm/K and uses 50. Table 7-4 measures the drive phase P
   * moving 0.6919 deg over 9 K = 0.0769 deg/K; with fixed-frequency drive that slope is
   * kET Q1 (2-35, 2-41) plus the drive circuit's own drift, which the thesis finds
   * negligible (§2.4.2 C, §7.3.1). 40 ppm/K gives kET Q1 = 0.0764 deg/K with no drive
   * circuit drift; 50 ppm/K would need an invented -0.019 deg/K circuit term. */
  c->ket_per_k = 40e-6;
  c->quad_dps = 1500.0;      /* §7.2.2: quadrature about 1500 deg/s, table */
  c->inphase_bias_dps = 0.0; /* damping coupling: not in the thesis model */
  /* Beyond the thesis's linear gyro, every imperfection is off in the ideal part (zero,
   * by the memset): quad_drift_dps, inphase_drift_dps, k3_*_per_m2, fb_gap_m,
   * pick_*_gap_m, pick_*_flicker_*, adc_inl_*, dac_inl_*, adc_aperture_jitter_s,
   * vref_noise_*, q_temp_law (the default part sets some: plant_default_cfg). Their
   * shape parameters get values that make sense once one is on: */
  c->quad_drift_tau_s = 600.0; /* minutes: a package-stress relaxation's time scale */
  c->inphase_drift_tau_s = 600.0;
  c->pick_flicker_fmin_hz = 1e-3; /* as the electrode-voltage noise below */
  c->vref_noise_fmin_hz = 1e-3;
  c->full_kinematics = true;
  c->brownian = true;
  c->mech_refresh_eps = 1e-3; /* mech.c: < 1e-9 error, one refresh per 50 K */
  set_ideal_actuators(c);
  /* DAC: fig. 4-14 low-pass after the DAC. 30 kHz Butterworth: 2.0 deg at the 745 Hz
   * drive voltage, 4.0 deg on the 1490 Hz force (see the phase budget below). */
  c->dac_recon_hz = 30000.0;
  c->dac_recon_q = 0.70710678118654752;
  c->dac_gain_u1 = c->dac_gain_u2 = c->dac_gain_rate = c->dac_gain_spare = 1.0;
  c->dac_offset_u1_v = c->dac_offset_u2_v = c->dac_offset_rate_v = c->dac_offset_spare_v = 0.0;
  /* the second converter (the sense electrodes): the same part and driver stage, ideal */
  c->dac_gain_fb_u2 = c->dac_gain_quadnull_v1 = c->dac_gain_quadnull_v2 = c->dac_gain_tune = 1.0;
  c->dac_offset_fb_u2_v = c->dac_offset_quadnull_v1_v = c->dac_offset_quadnull_v2_v = 0.0;
  c->dac_offset_tune_v = 0.0;
  /* Drive pickoff gain from table 7-1: the demodulated drive amplitude is
   * 5.4246e-3 V per V^2 of half-frequency amplitude (least squares through the origin
   * of the 16 points, 1.5..12.75 V, at 1490 Hz). At resonance that is
   * g * (Ks/m) Q1/wn1^2 * |H_recon(745 Hz)|^2 sinc^2(wc T/2) * |H_pick(1490 Hz)|, so
   * g = 3.494e4 V/m: 10 um gives 0.348 V at the ADC, 12.75 V gives 0.882 V (thesis
   * 0.8754). */
  c->pick_drive_gain_v_per_m = 3.494e4;
  c->pick_drive_gain_tc_per_k = 0.0; /* §2.4.2 B: gain changes < 0.78 % over 80 K */
  c->pick_drive_rail_v = 13.5;
  c->pick_drive_ft_u1 = 2e-4; /* feedthrough: placeholders for calibration */
  c->pick_drive_ft_u2 = -1.5e-4;
  c->pick_drive_ft_spare = 0.0;
  c->pick_drive_lag_allpass = false;
  /* §7.2.2: the DSP sees -99.56 deg at resonance, 9.56 deg of circuit and algorithm
   * lag (DAC low-pass, preamplifier, demodulation). The steady-state LMSD adds none, so
   * the analog drive chain gets all of it at 1489.9 Hz: recon 4.025 deg (force) +
   * anti-alias low-pass 6.047 - high-pass lead 3.840 + circuit lag 3.328 = 9.560 deg
   * (plant_drive_phase_budget). The board's sampling delays (one-sample DAC latency,
   * hold) come on top and are the firmware's to compensate. */
  c->pick_drive_phi0_deg = 3.328;
  c->pick_drive_phi1_deg_per_k = 0.0; /* see ket_per_k */
  c->pick_drive_phi2_deg_per_k2 = 0.0;
  c->pick_drive_hp_hz = 100.0;   /* fig. 4-13 band-pass: keeps < 10 Hz shaking out */
  c->pick_drive_lp_hz = 20000.0; /* 2nd-order Butterworth */
  c->pick_drive_lp_q = 0.70710678118654752;
  c->pick_drive_offset_v = 5e-3; /* placeholder */
  /* 2 uV/rtHz one-sided: the Brownian floor is ~12.5 uV/rtHz at the sense ADC (§4.6.1:
   * 18 deg/h/rtHz x 2.5 mV/(deg/s)); this adds 1.3 % to it */
  c->pick_drive_noise_v_rthz = 2e-6;
  c->pick_drive_delay_s = 0.0;
  c->pick_drive_jitter_s = 0.0;
  c->pick_drive_temp_node = THERMAL_CIRCUIT;
  /* Sense pickoff gain: §4.6.1, 1 deg/s -> 2.5 mV at the ADC with a 10 um drive:
   * (2-28) gives 4.060e-11 m per deg/s, the chain passes 0.9963 of it at 1490 Hz ->
   * 6.18e7 V/m; then 1500 deg/s of quadrature is 3.75 V. */
  c->pick_sense_gain_v_per_m = 6.18e7;
  c->pick_sense_gain_tc_per_k = 0.0;
  c->pick_sense_rail_v = 13.5;
  c->pick_sense_ft_u1 = 1e-4;
  c->pick_sense_ft_u2 = 6e-5;
  c->pick_sense_ft_spare = 1e-3;
  c->pick_sense_lag_allpass = false;
  c->pick_sense_phi0_deg = 3.0; /* placeholder; the demodulation phase absorbs it */
  /* Table 7-4: bias 21.21 -> 45.20 deg/s over 26 -> 35 degC = 2.666 deg/s/K; with
   * 1500 deg/s quadrature that is a sense phase drift of 0.1018 deg/K relative to the
   * drive reference. The structural part (2-39) is 0.0017 deg/K (40 ppm/K, 1490 Hz,
   * 2000 Hz, Q2 3), so the circuit gets 0.100 deg/K (§2.4.2 B: the circuit dominates,
   * here by 60x; the thesis's 7-10x is for its 1750 Hz design, where (2-39) is larger). */
  c->pick_sense_phi1_deg_per_k = 0.100;
  c->pick_sense_phi2_deg_per_k2 = 0.0;
  c->pick_sense_hp_hz = 100.0; /* same circuit design as the drive channel (2-40) */
  c->pick_sense_lp_hz = 20000.0;
  c->pick_sense_lp_q = 0.70710678118654752;
  c->pick_sense_offset_v = -3e-3; /* placeholder */
  c->pick_sense_noise_v_rthz = 2e-6;
  c->pick_sense_delay_s = 4e-6; /* multiplexed converter: sense after drive */
  c->pick_sense_jitter_s = 0.0;
  c->pick_sense_temp_node = THERMAL_CIRCUIT;
  c->pick_lag_ref_hz = 1489.9;
  /* A pickoff re-discretisation costs ~10 us (measured, host-release); it happens when
   * the circuit phase has moved by this step: 1e-6 rad (pickoff.h default) is a bias
   * step of 1.5e-3 deg/s (5 deg/h) through 1500 deg/s of quadrature, 0.57 mK of sense
   * circuit temperature. In a 0.03 K/s cool-down: 52 per second, 10 ns per sample. */
  c->pick_phase_step_rad = 1e-6;
  /* ADC: board.h, +-5 V (§4.4.2) */
  c->adc_full_scale_v = 5.0;
  /* g-sensitivity: a single proof mass on springs feels -m a along its own axis;
   * the thesis's linear gyro has no cancelling twin (§2.2.2) */
  c->gs_drive_from_drive_mps2_per_g = -ACCEL_G0_MPS2;
  c->gs_sense_from_sense_mps2_per_g = -ACCEL_G0_MPS2;
  /* thermal network: default preset (thermal.c) */
  thermal_cfg_t th;
  thermal_preset(&th, THERMAL_PRESET_DEFAULT);
  set_thermal(c, &th);
  c->thermal_dt_s = th.dt_s;
  set_board_sensor(c);
}

/* The default part: the ideal part plus the imperfections that make it measure, with
 * the product's own tools, what the thesis measured on its hardware (docs/honest-part.md
 * has each figure, its command and the derivation):
 *  - bias stability 31.3 deg/h, the lowest point of the Allan deviation of a 1.5 h static
 *    run (table 7-3): 1/f noise of the two circuit phases. The thesis finds the sense
 *    bias's drift dominated by the pickoff circuit's phase (§2.4.2 B), and 1500 deg/s of
 *    quadrature turns a phase error phi into a bias of 1500 phi (2-38). A flicker
 *    floor sigma = sqrt(2 ln 2 h) (IEEE 952 annex C) of 31.3 deg/h is h = (7.4e-3
 *    deg/s)^2/Hz at 1 Hz, a phase density of 4.9e-6 rad/rtHz; the drive and sense
 *    circuits are one design (2-40), so each channel gets the same density, which the
 *    measurement (static_allan) then sets: PLANT_THESIS_PHASE_FLICKER_DEG_RTHZ. The
 *    spectrum stays 1/f down to 1e-5 Hz, below the 1.5 h run's lowest frequency, so
 *    the floor is flat over the whole Allan plot as the thesis's is (fig. 7-11);
 *  - square-law nonlinearity 0.25 % (table 7-1: RMS residual of a line with intercept
 *    through amplitude against U^2, over the largest amplitude; 0.2417 % on the thesis's
 *    own points): amplitude-dependent drive damping (mech.h). Table 7-1's ratio
 *    amplitude / U^2 falls by 1.6 % from 9 V to 12.75 V (25 um) while the 12 V sweep
 *    still peaks at 1489.90 Hz with Q 33.33 (§7.2.2): the response compresses without
 *    moving the resonance, which a Duffing spring (k3_drive) cannot do (1.6 % at 25 um
 *    needs a 3 Hz shift at 12 V). c = 1.26e8 1/m^2 (the drive's damping 1 % higher at
 *    20 um, 0.3 % at the 10 um working amplitude) gives 0.24 % in square_law;
 *  - scale-factor nonlinearity about 0.06 % FS, read as the thesis read it (§7.2.4): a
 *    multimeter on the analog output, the mean of CW and CCW at each rate, the RMS
 *    residual of a line over +-20..160 deg/s. The rate path itself is linear to about
 *    0.01 % (the residual is the bias's wander over the 1 s windows; odd-order
 *    nonlinearities of the sense path act at the 1500 deg/s quadrature's level and would
 *    need an absurd pickoff gap, docs/honest-part.md). What the meter adds is the output
 *    converter: at 7.25 mV/(deg/s) one step of the 14-bit +-15 V DAC is 0.25 deg/s, and
 *    its integral nonlinearity over the +-1.2 V the table uses is the residual. The
 *    thesis's DAC is "4-channel 14-bit" (§4.4.2) and unnamed; an MSB weight error of
 *    1.75 LSB rms (inl.h; end-point INL about +-2 LSB on a typical draw) gives a median
 *    of 0.058 % over 12 boards (board_seed 1..12: 0.024..0.151 %; the default board,
 *    board_seed 1, 0.054 %). The board's AD5554 in its B grade (+-0.5 LSB, MSB error
 *    0.44 LSB rms) gives 0.019 % (0.012..0.040 %); the digital output has no converter.
 * The chamber and the rate ramp are discussed in docs/honest-part.md. */
#define PLANT_THESIS_PHASE_FLICKER_DEG_RTHZ 2.0e-4
#define PLANT_THESIS_FLICKER_FMIN_HZ 1e-5
#define PLANT_THESIS_NL_DAMP_DRIVE_PER_M2 1.26e8
#define PLANT_THESIS_DAC_INL_CODE_LSB 1.75
void plant_default_cfg(plant_cfg_t *c)
{
  plant_ideal_cfg(c);
  c->pick_drive_phase_flicker_1hz_deg_rthz = PLANT_THESIS_PHASE_FLICKER_DEG_RTHZ;
  c->pick_sense_phase_flicker_1hz_deg_rthz = PLANT_THESIS_PHASE_FLICKER_DEG_RTHZ;
  c->pick_flicker_fmin_hz = PLANT_THESIS_FLICKER_FMIN_HZ;
  c->nl_damp_drive_per_m2 = PLANT_THESIS_NL_DAMP_DRIVE_PER_M2;
  c->dac_inl_code_lsb = PLANT_THESIS_DAC_INL_CODE_LSB;
}

int plant_preset(plant_cfg_t *c, const char *name)
{
  if (c == NULL || name == NULL) return -1;
  if (strcmp(name, "thesis") == 0) plant_default_cfg(c);
  else if (strcmp(name, "ideal") == 0) plant_ideal_cfg(c);
  else return -1;
  return 0;
}

int plant_thermal_preset(plant_cfg_t *c, const char *name)
{
  thermal_preset_t which;
  if (name == NULL) return -1;
  if (strcmp(name, "default") == 0) which = THERMAL_PRESET_DEFAULT;
  else if (strcmp(name, "tight") == 0) which = THERMAL_PRESET_TIGHT;
  else if (strcmp(name, "loose") == 0) which = THERMAL_PRESET_LOOSE;
  else return -1;
  thermal_cfg_t th;
  thermal_preset(&th, which);
  set_thermal(c, &th);
  return 0;
}

/* Cross-field limits of the imperfections (plant.h), each named by its parameter. */
static int check_imperfections(const plant_cfg_t *c, char *buf, size_t n)
{
  const double fmax = c->fs_hz / 1000.0, T = 1.0 / c->fs_hz;
  const int pick_fl = c->pick_drive_gain_flicker_1hz_rthz > 0.0 ||
                      c->pick_drive_phase_flicker_1hz_deg_rthz > 0.0 ||
                      c->pick_sense_gain_flicker_1hz_rthz > 0.0 ||
                      c->pick_sense_phase_flicker_1hz_deg_rthz > 0.0;
  if (pick_fl && c->pick_flicker_fmin_hz > fmax) {
    errf(buf, n, "%s: must not exceed fs_hz/1000 (%g Hz)", "pick_flicker_fmin_hz", fmax);
    return -1;
  }
  if (c->vref_noise_1hz_rthz > 0.0 && c->vref_noise_fmin_hz > fmax) {
    errf(buf, n, "%s: must not exceed fs_hz/1000 (%g Hz)", "vref_noise_fmin_hz", fmax);
    return -1;
  }
  if (c->adc_aperture_jitter_s > T / 20.0) {
    errf(buf, n, "%s: must not exceed T/20 (%g s)", "adc_aperture_jitter_s", T / 20.0);
    return -1;
  }
  /* the bias's softening must stay well short of the sense stiffness (pull-in, (6-4)) */
  const double ke = plant_fb_softening(c), w2 = 2.0 * PLANT_PI * c->f_sense_hz;
  if (ke >= 0.5 * w2 * w2) {
    errf(buf, n,
         "%s: the bias's spring softening 4 ks_fb Vb^2/gap (%g 1/s^2) reaches half the "
         "sense stiffness (%g 1/s^2): pull-in",
         "fb_gap_m", ke, 0.5 * w2 * w2);
    return -1;
  }
  return 0;
}

int plant_cfg_check(const plant_cfg_t *c, char *buf, size_t n)
{
  if (c == NULL) {
    if (buf != NULL && n > 0) snprintf(buf, n, "cfg: null");
    return -1;
  }
  for (size_t i = 0; i < NPARAMS; i++)
    if (check_value(&kParams[i], plant_param_get(c, &kParams[i]), buf, n) != 0) return -1;
  /* cross-field limits, each named by the parameter that has to move */
  const double nyq = 0.45 * c->fs_hz, T = 1.0 / c->fs_hz;
  const double kDeg = PLANT_RAD_PER_DEG;
  if (c->f_drive_hz > nyq) {
    errf(buf, n, "%s: must be below 0.45 fs_hz (%g Hz)", "f_drive_hz", nyq);
    return -1;
  }
  if (c->f_sense_hz > nyq) {
    errf(buf, n, "%s: must be below 0.45 fs_hz (%g Hz)", "f_sense_hz", nyq);
    return -1;
  }
  if (c->pick_lag_ref_hz >= 0.5 * c->fs_hz) {
    errf(buf, n, "%s: must be below fs_hz/2 (%g Hz)", "pick_lag_ref_hz", 0.5 * c->fs_hz);
    return -1;
  }
  if (c->dac_recon_hz > c->fs_hz) {
    errf(buf, n, "%s: must not exceed fs_hz (%g Hz)", "dac_recon_hz", c->fs_hz);
    return -1;
  }
  const struct {
    const char *hp, *lp, *delay, *jitter, *phi0;
    double hp_hz, lp_hz, delay_s, jitter_s, phi0_deg;
    bool allpass;
  } ch[2] = {
      {"pick_drive_hp_hz", "pick_drive_lp_hz", "pick_drive_delay_s", "pick_drive_jitter_s",
       "pick_drive_phi0_deg", c->pick_drive_hp_hz, c->pick_drive_lp_hz, c->pick_drive_delay_s,
       c->pick_drive_jitter_s, c->pick_drive_phi0_deg, c->pick_drive_lag_allpass},
      {"pick_sense_hp_hz", "pick_sense_lp_hz", "pick_sense_delay_s", "pick_sense_jitter_s",
       "pick_sense_phi0_deg", c->pick_sense_hp_hz, c->pick_sense_lp_hz, c->pick_sense_delay_s,
       c->pick_sense_jitter_s, c->pick_sense_phi0_deg, c->pick_sense_lag_allpass}};
  for (int i = 0; i < 2; i++) {
    if (ch[i].hp_hz >= 0.5 * c->fs_hz) {
      errf(buf, n, "%s: must be below fs_hz/2 (%g Hz)", ch[i].hp, 0.5 * c->fs_hz);
      return -1;
    }
    if (ch[i].lp_hz > 10.0 * c->fs_hz) {
      errf(buf, n, "%s: must not exceed 10 fs_hz (%g Hz)", ch[i].lp, 10.0 * c->fs_hz);
      return -1;
    }
    if (fabs(ch[i].delay_s) > 0.5 * T) {
      errf(buf, n, "%s: |delay| must not exceed T/2 (%g s)", ch[i].delay, 0.5 * T);
      return -1;
    }
    if (ch[i].jitter_s > T / 20.0) {
      errf(buf, n, "%s: must not exceed T/20 (%g s)", ch[i].jitter, T / 20.0);
      return -1;
    }
    const double lim = ch[i].allpass ? 160.0 : 80.0; /* (2-40) law must stay in range */
    if (ch[i].phi0_deg * kDeg >= lim * kDeg) {
      errf(buf, n, "%s: must be below %g deg", ch[i].phi0, lim);
      return -1;
    }
  }
  if (c->drive_noise_1hz_v_rthz > 0.0 && c->drive_noise_fmin_hz > c->fs_hz / 1000.0) {
    errf(buf, n, "%s: must not exceed fs_hz/1000 (%g Hz)", "drive_noise_fmin_hz",
         c->fs_hz / 1000.0);
    return -1;
  }
  const struct {
    const char *key;
    double k_1hz, fmin_hz;
  } fl[3] = {{"fb_noise_fmin_hz", c->fb_noise_1hz_v_rthz, c->fb_noise_fmin_hz},
             {"quadnull_noise_fmin_hz", c->quadnull_noise_1hz_v_rthz, c->quadnull_noise_fmin_hz},
             {"tune_noise_fmin_hz", c->tune_noise_1hz_v_rthz, c->tune_noise_fmin_hz}};
  for (int i = 0; i < 3; i++)
    if (fl[i].k_1hz > 0.0 && fl[i].fmin_hz > c->fs_hz / 1000.0) {
      errf(buf, n, "%s: must not exceed fs_hz/1000 (%g Hz)", fl[i].key, c->fs_hz / 1000.0);
      return -1;
    }
  if (check_imperfections(c, buf, n) != 0) return -1;
  const struct {
    const char *key;
    double v;
  } gains[8] = {{"dac_gain_u1", c->dac_gain_u1},
                {"dac_gain_u2", c->dac_gain_u2},
                {"dac_gain_rate", c->dac_gain_rate},
                {"dac_gain_spare", c->dac_gain_spare},
                {"dac_gain_fb_u2", c->dac_gain_fb_u2},
                {"dac_gain_quadnull_v1", c->dac_gain_quadnull_v1},
                {"dac_gain_quadnull_v2", c->dac_gain_quadnull_v2},
                {"dac_gain_tune", c->dac_gain_tune}};
  for (int i = 0; i < 8; i++)
    if (gains[i].v == 0.0) {
      errf(buf, n, "%s: must be non-zero", gains[i].key);
      return -1;
    }
  if (c->thermal_dt_s < T) {
    errf(buf, n, "%s: must be at least one sample (%g s)", "thermal_dt_s", T);
    return -1;
  }
  if (fabs(0.5 * c->ket_per_k * (c->temp_k - c->temp_ref_k)) >= 0.2) {
    errf(buf, n, "%s: (2-32) leaves its range at this ambient (%g K)", "ket_per_k", c->temp_k);
    return -1;
  }
  if (buf != NULL && n > 0) buf[0] = '\0';
  return 0;
}
