/* gyro_design: the parameter values -> every module's configuration, in the
 * background (libm allowed here, never in the sample path). The loop designs follow
 * (6-12), (6-17); the rate channel's reference and compensation rate_channel.h. */
#include "gyro/gyro_design.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "dsp/butter.h"
#include "dsp/fastmath.h"
#include "gyro/gyro_dac.h"
#include "gyro/gyro_slots.h"
#include "gyro/selfcal.h" /* SELFCAL_Q_FIXED_MAX */

/* The absolute over-amplitude trip, as a fraction of the ADC's range: the highest
 * drive-pickoff amplitude the ADC still measures with headroom for the carrier's noise. */
#define GYRO_AMP_MAX_FRAC 0.95f

/* How long acquisition may take before it is a fault (ACQ_TIMEOUT): the drive mode
 * rings up within a few time constants 2Q/wn at full force (10 of them here), the
 * slower loop settles within three of its time constants after that, lock needs its
 * hold time, and 0.1 s covers the demodulator and the noise. The loops' bandwidths are
 * those of the gains in use (manual gains included): K kp / (2 pi tau) for the
 * first-order loops of drive_loop.h. */
static double acq_timeout_s(const param_values_t *v, double tau_s, const gyro_design_t *t)
{
  const double bw_amp = (double)v->drive_cal_gain_v_per_v2 * (double)t->drive.amp_kp /
                        (2.0 * FM_PI * tau_s);
  const double bw_ph = (double)t->drive.phase_kp / (2.0 * FM_PI * tau_s);
  double bw = bw_amp < bw_ph ? bw_amp : bw_ph;
  if (!(bw > 1e-3)) bw = 1e-3; /* a loop of no gain: the hour below */
  /* Tracking drive: the ring-up is force-limited, not tau-limited (at resonance the
   * amplitude grows at K f_max / tau from rest: A_set tau / (K f_max), Q-independent),
   * and the PLL's bandwidth is its own. */
  double ring_s = 10.0 * tau_s;
  if (v->drive_track != 0u) {
    const double up = 10.0 * (double)v->drive_amp_set_v * tau_s /
                      ((double)v->drive_cal_gain_v_per_v2 * (double)t->drive.f_cmd_max_v2);
    if (up < ring_s) ring_s = up;
    bw = bw_amp < t->track_design.bw_hz ? bw_amp : t->track_design.bw_hz;
    if (!(bw > 1e-3)) bw = 1e-3;
  }
  const double t_s = 0.1 + ring_s + 3.0 / (2.0 * FM_PI * bw) + (double)v->sup_lock_hold_s;
  return t_s < 3600.0 ? t_s : 3600.0; /* an hour: beyond it the part is not acquiring */
}

/* Largest |dB/dP| of the bias polynomial (in x, rate_channel.h) over
 * the thermometer's range around that reference, from nine points: how far a lag of
 * P_f moves the compensation. */
static double bias_slope_max(const param_values_t *v)
{
  const double c1 = (double)v->rate_bias_c1_dps_per_deg;
  const double c2 = (double)v->rate_bias_c2_dps_per_deg2;
  const double c3 = (double)v->rate_bias_c3_dps_per_deg3;
  double m = 0.0;
  for (int i = -4; i <= 4; i++) {
    const double p = 0.25 * i * (double)v->rate_p_range_deg;
    const double d = fabs(c1 + 2.0 * c2 * p + 3.0 * c3 * p * p);
    if (d > m) m = d;
  }
  /* Not the gradient term's |k|: it acts on P_c - LP_tau(P_c), whose lag behind P in a
   * transient is what the calibration fitted it to (rate_channel.c). */
  return m;
}

/* P_f's low-pass works around drive.p_init_deg (rate_channel.h), the compensation
 * around cal.ref_p_deg: the offset between them, formed in double so that a reference
 * equal to the start value gives exactly 0. */
static float p_poly_off_deg(const param_values_t *v)
{
  return (float)((double)v->drive_p_init_deg - (double)v->cal_ref_p_deg);
}

/* The rate-valid monitors (rate_valid.h; after design_rate, whose compensation filters
 * THERMO_SLEW's shadow mirrors) and the analog fault level. The fault level
 * must lie outside the span full scale x out_v_per_dps (with 10 % for the output
 * stage's gain and offset), or a failed gyro could read as a rate. */
/* A low-pass of the settling check per block, 1 - exp(-2 pi f T_block), with force
 * rebalance (rate_valid.h: its reference at RATE_VALID_INPUT_RATIO times the output
 * filter's corner, its difference at RATE_VALID_SETTLE_DIFF_HZ); open loop the 100 Hz
 * filter's reference (RATE_VALID_INPUT_K) and no low-pass of the difference (1). */
static float settle_k(const param_values_t *v, double f_hz)
{
  if (v->sense_mode != 1u) return f_hz == RATE_VALID_SETTLE_DIFF_HZ ? 1.0f : RATE_VALID_INPUT_K;
  const double f_block_hz = (double)v->sys_fs_hz / (double)RATE_DECIM;
  return (float)(1.0 - exp(-2.0 * FM_PI * f_hz / f_block_hz));
}

static gyro_design_status_t design_validity(const param_values_t *v, gyro_design_t *t)
{
  const float span_v = v->rate_full_scale_dps * fm_absf(v->rate_out_v_per_dps);
  if (!(fm_absf(v->rate_fault_out_v) > 1.1f * span_v)) return GYRO_DESIGN_FAULT_OUT;
  const double slope = bias_slope_max(v);
  if (!isfinite(slope) || slope > 1e30) return GYRO_DESIGN_BIAS_SLOPE;
  const float sense_max_v = RATE_VALID_SENSE_FRAC * HAL_ADC_FULL_SCALE_V;
  const float window_s = (float)(RATE_VALID_SLEW_UPDATES * RATE_P_DECIM) / (float)v->sys_fs_hz;
  const rate_valid_cfg_t c = {v->rate_valid_tol_dps,
                              v->rate_full_scale_dps,
                              v->rate_p_range_deg,
                              v->rate_p_slew_max_deg_s * window_s,
                              (float)(1.0 / (2.0 * FM_PI * (double)v->rate_p_lpf_hz)) / window_s,
                              sense_max_v * sense_max_v,
                              v->sup_lock_phase_tol_deg * FM_RAD_PER_DEG_F,
                              (float)slope,
                              p_poly_off_deg(v),
                              fm_absf(v->rate_bias_grad_dps_per_deg),
                              fm_absf(v->rate_grad_fast_dps_per_deg),
                              t->rate.grad_a,
                              t->rate.comp_fast_a > 0.0f ? 1u : 0u,
                              {0.0f},
                              settle_k(v, (double)(v->sense_fr_lpf_hz * RATE_VALID_INPUT_RATIO)),
                              settle_k(v, RATE_VALID_SETTLE_DIFF_HZ)};
  t->valid = c;
  rate_valid_spur_matrix(t->rate.comp_a, t->rate.grad_a, t->rate.comp_stages,
                         t->rate.comp_fast_a, t->valid.spur_m);
  t->rate_fault_out_v = v->rate_fault_out_v;
  return GYRO_DESIGN_OK;
}

/* Continuous self-test's LMS: a convergence time constant of 0.1 s, 2 / mu blocks for
 * two weights on a reference of power 1/2 each (a notch about 3 Hz wide); its response
 * is judged after five of them. */
#define GYRO_CONT_TAU_S 0.1

/* The continuous test's expected response e (raw rate units) and its band, relative tol,
 * as the verdict compares them: squared magnitudes. */
static void cont_band(selftest_cfg_t *st, double e, double tol)
{
  st->cont_expect = (float)e;
  st->cont_lo2 = (float)(e * e * (1.0 - tol) * (1.0 - tol));
  st->cont_hi2 = (float)(e * e * (1.0 + tol) * (1.0 + tol));
}

/* Both self-tests (selftest.h). Their expectations were measured at the setpoint
 * selftest.ref_amp_v; the rate channel divides by the setpoint, so a response in deg/s
 * scales as ref_amp_v / amp_set_v. The continuous test's tone must lie above the rate's
 * output band (the notch would otherwise take rate out of it) and below a quarter of
 * the block rate. */
static gyro_design_status_t design_selftest(const param_values_t *v, gyro_design_t *t)
{
  const double th = (double)v->drive_phase_set_deg * FM_PI / 180.0;
  const double amp_k = (double)v->selftest_ref_amp_v / (double)v->drive_amp_set_v;
  const double block_hz = (double)v->sys_fs_hz / GYRO_BLOCK;
  selftest_cfg_t st;
  memset(&st, 0, sizeof st);
  st.amp_v = v->selftest_amp_v;
  st.expect_dps = (float)((double)v->selftest_expect_dps * amp_k);
  st.tol_rel = v->selftest_tol_rel;
  st.ref_c = (float)cos(th);
  st.ref_s = (float)sin(th);
  st.scale_dps = v->rate_scale_dps;
  st.base_blocks = v->sys_fs_hz / (5u * GYRO_BLOCK);    /* 0.2 s */
  st.settle_blocks = v->sys_fs_hz / (10u * GYRO_BLOCK); /* 0.1 s */
  st.meas_blocks = v->sys_fs_hz / (5u * GYRO_BLOCK);    /* 0.2 s */
  /* Force rebalance always runs it: without it a dead sense pickoff leaves the loop
   * "balanced" and its readout frozen, valid and wrong (selftest.h). */
  st.cont_on = v->selftest_continuous != 0u || v->sense_mode == 1u ? 1u : 0u;
  st.cont_amp_v = v->selftest_cont_amp_v;
  st.cont_fr_v2 = st.cont_on != 0u && v->sense_mode == 1u ? v->selftest_cont_fr_v2 : 0.0f;
  const double f_m = (double)v->selftest_cont_freq_hz;
  if (st.cont_on != 0u && !(f_m >= 1.5 * (double)v->rate_lpf_cutoff_hz && f_m <= block_hz / 4.0)) {
    return GYRO_DESIGN_CONT_FREQ;
  }
  st.cont_step = (uint32_t)(f_m / block_hz * 4294967296.0 + 0.5);
  st.cont_mu = (float)(2.0 / (GYRO_CONT_TAU_S * block_hz));
  st.cont_gain = 1.0f - 0.5f * st.cont_mu;
  st.cont_settle_blocks = (uint32_t)(5.0 * GYRO_CONT_TAU_S * block_hz);
  const double scale = fabs((double)v->rate_scale_dps);
  const double e = scale > 0.0 ? (double)v->selftest_cont_expect_dps * amp_k / scale : 0.0;
  const double tol = (double)v->selftest_tol_rel;
  /* (force rebalance: the expectation is the loop model's, design_fb) */
  if (st.cont_on != 0u && v->sense_mode != 1u && !(e > 0.0 && tol < 1.0))
    return GYRO_DESIGN_CONT_EXPECT;
  cont_band(&st, e, tol);
  t->selftest = st;
  return GYRO_DESIGN_OK;
}

/* Quadrature nulling (quad_null.h): updated once per RATE_P_DECIM ticks (the
 * thermometer's block, 500 Hz: the float integrator's dead band, quad_null.h), its
 * electrodes on the second converter, whose largest output is the limit's bound. */
static gyro_design_status_t design_quad_null(const param_values_t *v, gyro_design_t *t)
{
  const double v_dac_max = (double)(HAL_DAC_CODE_MAX - HAL_DAC_CODE_MID) *
                           (double)HAL_DAC_V_PER_CODE;
  const quad_null_cfg_t qc = {v->quad_bw_hz,
                              v->quad_v_max_v,
                              v->quad_settle_dps,
                              v->quad_settle_s,
                              v->quad_probe_v,
                              v->quad_probe_wait_s,
                              v->quad_probe_avg_s,
                              v->quad_min_step_dps,
                              (float)((double)RATE_P_DECIM / (double)v->sys_fs_hz)};
  if (!((double)v->quad_v_max_v <= v_dac_max) || quad_null_design(&qc, &t->quad) != 0) {
    return GYRO_DESIGN_QUAD_NULL;
  }
  t->quad_on = v->quad_null;
  return GYRO_DESIGN_OK;
}

/* The NCO at the drive frequency, below fs / 4: the 2 wc terms of the demodulation
 * (lmsd.h) then stay below fs / 2. */
static gyro_design_status_t design_nco(const param_values_t *v, gyro_design_t *t)
{
  const float fs_f = (float)v->sys_fs_hz;
  if (!(fs_f > 0.0f)) return GYRO_DESIGN_FS;
  if (!(v->drive_freq_hz < 0.25f * fs_f)) return GYRO_DESIGN_DRIVE_FREQ;
  const nco_cfg_t nc = {(double)v->drive_freq_hz, (double)v->sys_fs_hz, 0.0};
  nco_t probe;
  if (nco_init(&probe, &nc) != 0) return GYRO_DESIGN_DRIVE_FREQ;
  t->nco = nc;
  t->nco_half_step = probe.half_step;
  return GYRO_DESIGN_OK;
}

/* Both demodulators' step sizes: each must give the LMSD a bandwidth (lmsd.h). */
static gyro_design_status_t design_demod(const param_values_t *v, gyro_design_t *t)
{
  const double fs = (double)v->sys_fs_hz;
  if (!(lmsd_bandwidth_hz((double)v->demod_mu_drive, fs) > 0.0)) return GYRO_DESIGN_MU_DRIVE;
  if (!(lmsd_bandwidth_hz((double)v->demod_mu_sense, fs) > 0.0)) return GYRO_DESIGN_MU_SENSE;
  t->lmsd_drive.mu = v->demod_mu_drive;
  t->lmsd_sense.mu = v->demod_mu_sense;
  t->sweep_mu_sense = v->demod_mu_sense;
  return GYRO_DESIGN_OK;
}

/* The drive synthesis (scheme, bias, limit) and the force limit it gives the
 * amplitude loop. */
static gyro_design_status_t design_synth(const param_values_t *v, gyro_design_t *t)
{
  t->synth.scheme = v->drive_mode == 1u ? GYRO_DRIVE_DC_AC : GYRO_DRIVE_HALF_FREQ;
  t->synth.dc_bias_v = v->drive_dc_bias_v;
  t->synth.u_max_v = v->drive_u_max_v;
  drive_synth_t probe;
  if (drive_synth_init(&probe, &t->synth) != 0) return GYRO_DESIGN_DRIVE_VOLTAGES;
  t->drive.f_cmd_max_v2 = drive_synth_f_cmd_max(&probe);
  return GYRO_DESIGN_OK;
}

/* (6-12), (6-17): amplitude and phase of the drive vibration follow force amplitude
 * and phase as first-order lags of time constant 2 Q / wn. */
static double drive_tau_s(const param_values_t *v)
{
  return 2.0 * (double)v->drive_cal_q / (2.0 * FM_PI * (double)v->drive_cal_f0_hz);
}

/* Samples from a loop's measurement slot to the first DAC frame of its command: the
 * command goes to the synthesis on GYRO_SLOT_COMMAND and reaches the DAC frame one tick
 * later (the jobs run after their tick's frame). */
static double lag_samples(uint32_t slot)
{
  return (double)((GYRO_SLOT_COMMAND + GYRO_BLOCK - slot) % GYRO_BLOCK + 1u);
}

/* Half-width of the tracking drive's frequency window, relative to f0 (drive_track.h):
 * +-0.5 %, some 60 K of structure temperature at 40 ppm/K of Young's modulus either way. */
#define GYRO_TRACK_WINDOW_REL 0.005
/* The tracking loop's acquisition crossover, relative to the locked one (drive_track.h). */
#define GYRO_TRACK_ACQ_BW_FACTOR 3.0

/* The tracking drive (drive_track.h): a PLL on the NCO frequency, designed from the same
 * identified model and bandwidth (drive.phase_bw_hz) as the phase loop, in either mode
 * (status shows the design); the fixed drive's phase PI stops at GYRO_FIXED_Q_MAX. */
static gyro_design_status_t design_track(const param_values_t *v, double demod_bw,
                                         gyro_design_t *t)
{
  t->track = v->drive_track;
  /* The fixed-frequency drive's reach in Q (selfcal.h, where it is measured); the
   * tracking drive has none. */
  if (t->track == 0u && (double)v->drive_cal_q > SELFCAL_Q_FIXED_MAX)
    return GYRO_DESIGN_FIXED_Q;
  const double fs = (double)v->sys_fs_hz;
  const drive_track_design_in_t in = {(double)v->drive_cal_q, (double)v->drive_cal_f0_hz,
                                      (double)v->drive_phase_bw_hz, GYRO_TRACK_ACQ_BW_FACTOR,
                                      demod_bw, fs, (double)GYRO_BLOCK,
                                      /* the new step acts from the tick after its job */
                                      (double)(GYRO_SLOT_PHASE_PI - GYRO_SLOT_PHASE_MEAS + 1u),
                                      GYRO_TRACK_WINDOW_REL, (double)t->drive.p_init_rad, 0.1};
  if (drive_track_design(&in, &t->track_cfg, &t->track_design) != 0)
    return GYRO_DESIGN_PHASE_LOOP;
  t->hz_per_step = (float)(fs / 2147483648.0);
  t->f_cal_hz = (float)nco_freq_of(t->nco_half_step, fs);
  return GYRO_DESIGN_OK;
}

/* Both drive loops (drive_loop.h), once per block; nonzero manual gains override the
 * designed ones. */
static gyro_design_status_t design_drive_loops(const param_values_t *v, double tau_s,
                                               gyro_design_t *t)
{
  const double fs = (double)v->sys_fs_hz;
  const double demod_bw = lmsd_bandwidth_hz((double)v->demod_mu_drive, fs);
  const double blk = (double)GYRO_BLOCK;
  const drive_loop_design_in_t amp_in = {
      (double)v->drive_cal_gain_v_per_v2, tau_s, (double)v->drive_amp_bw_hz, demod_bw, fs, blk,
      /* the tracking drive's ripple notch delays the amplitude by a block (drive_track.h) */
      lag_samples(GYRO_SLOT_AMP) + (v->drive_track != 0u ? blk : 0.0)};
  const drive_loop_design_in_t ph_in = {1.0, tau_s, (double)v->drive_phase_bw_hz,     demod_bw,
                                        fs,  blk,   lag_samples(GYRO_SLOT_PHASE_MEAS)};
  if (drive_loop_design(&amp_in, &t->amp_design) != 0) return GYRO_DESIGN_AMP_LOOP;
  if (drive_loop_design(&ph_in, &t->phase_design) != 0) return GYRO_DESIGN_PHASE_LOOP;
  const float fs_f = (float)v->sys_fs_hz;
  t->drive.dt_s = (float)GYRO_BLOCK / fs_f; /* the loops run once per block */
  t->drive.amp_set_v = v->drive_amp_set_v;
  t->drive.phase_set_rad = v->drive_phase_set_deg * FM_RAD_PER_DEG_F;
  const int manual_amp = v->drive_amp_kp > 0.0f || v->drive_amp_ki > 0.0f;
  const int manual_ph = v->drive_phase_kp > 0.0f || v->drive_phase_ki > 0.0f;
  t->drive.amp_kp = manual_amp ? v->drive_amp_kp : (float)t->amp_design.kp;
  t->drive.amp_ki = manual_amp ? v->drive_amp_ki : (float)t->amp_design.ki;
  t->drive.phase_kp = manual_ph ? v->drive_phase_kp : (float)t->phase_design.kp;
  t->drive.phase_ki = manual_ph ? v->drive_phase_ki : (float)t->phase_design.ki;
  t->drive.p_init_rad = v->drive_p_init_deg * FM_RAD_PER_DEG_F;
  t->drive.amp_position = v->drive_track; /* drive_loop.h: the tracking drive's, any Q */
  drive_track_notch((double)v->drive_freq_hz, fs, blk, &t->drive.notch_c2, &t->drive.notch_g);
  /* The loops accept P's start value within one turn either way (drive_loop.c), the
   * parameter's range; within the parameters' ranges nothing else of theirs can fail. */
  drive_loop_cfg_t probe = t->drive;
  if (drive_loop_cfg_derive(&probe) != 0) return GYRO_DESIGN_P_INIT;
  return design_track(v, demod_bw, t);
}

/* The rate channel (rate_channel.h): output filter, reference, scale, compensation. */
static gyro_design_status_t design_rate(const param_values_t *v, double tau_s, gyro_design_t *t)
{
  const double fs = (double)v->sys_fs_hz;
  const int n = butter_design(BUTTER_LOWPASS, v->rate_lpf_order, (double)v->rate_lpf_cutoff_hz,
                              0.0, fs / RATE_DECIM, t->rate.lpf, BIQUAD_MAX_SECTIONS);
  if (n <= 0) return GYRO_DESIGN_RATE_LPF;
  /* Reference of the rate channel: the drive motion as the loops hold it (phase at
   * its setpoint, amplitude at its setpoint), turned by the demodulation phase. */
  const double psi = ((double)v->rate_demod_phase_deg + (double)v->drive_phase_set_deg) *
                     FM_PI / 180.0;
  t->rate.ref_re = (float)(cos(psi) / (double)v->drive_amp_set_v);
  t->rate.ref_im = (float)(sin(psi) / (double)v->drive_amp_set_v);
  t->rate.scale_dps = v->rate_scale_dps;
  t->rate.bias_c_dps[0] = v->rate_bias_c0_dps;
  t->rate.bias_c_dps[1] = v->rate_bias_c1_dps_per_deg;
  t->rate.bias_c_dps[2] = v->rate_bias_c2_dps_per_deg2;
  t->rate.bias_c_dps[3] = v->rate_bias_c3_dps_per_deg3;
  t->rate.sf_c[1] = v->rate_sf_c1_per_deg;
  t->rate.sf_c[2] = v->rate_sf_c2_per_deg2;
  t->rate.sf_c[3] = v->rate_sf_c3_per_deg3;
  t->rate.sf_c[4] = v->rate_sf_c4_per_deg4;
  t->rate.lin_c2_per_dps = v->rate_lin_c2_per_dps;
  t->rate.lin_c3_per_dps2 = v->rate_lin_c3_per_dps2;
  t->rate.p_ref_deg = v->drive_p_init_deg;
  t->rate.p_poly_off_deg = p_poly_off_deg(v);
  t->rate.grad_k_dps_per_deg = v->rate_bias_grad_dps_per_deg;
  t->rate.p_rate_deg_per_dps = v->rate_p_rate_deg_per_dps;
  t->rate.p_rate_c1_per_dps = v->rate_p_rate_c1_per_dps;
  t->rate.p_rate2_deg_per_dps2 = v->rate_p_rate2_deg_per_dps2;
  t->rate.turn_max_dps = RATE_TURN_MAX_FS * v->rate_full_scale_dps;
  t->rate.comp_a = v->rate_comp_tau_s > 0.0f
                       ? (float)(1.0 -
                                 exp(-(double)RATE_P_DECIM / (fs * (double)v->rate_comp_tau_s)))
                       : 1.0f;
  t->rate.comp_stages = v->rate_comp_stages;
  t->rate.comp_fast_a = v->rate_comp_fast_tau_s > 0.0f
                            ? (float)(1.0 - exp(-(double)RATE_P_DECIM /
                                                (fs * (double)v->rate_comp_fast_tau_s)))
                            : 0.0f;
  t->rate.grad_fast_k_dps_per_deg = v->rate_grad_fast_dps_per_deg;
  t->rate.blend_dps = v->rate_comp_blend_dps;
  t->rate.blend_inv_per_dps = 1.0f / v->rate_comp_blend_dps;
  t->rate.fast_hold_updates = (uint32_t)(3.0 *
                                         (double)(v->rate_comp_fast_tau_s + v->rate_grad_tau_s) *
                                         fs / (double)RATE_P_DECIM);
  t->rate.grad_a = (float)(1.0 - exp(-(double)RATE_P_DECIM / (fs * (double)v->rate_grad_tau_s)));
  /* First-order low-pass of P at the decimated rate fs / RATE_P_DECIM. */
  t->rate.p_lpf_alpha = (float)(1.0 - exp(-2.0 * FM_PI * (double)v->rate_p_lpf_hz *
                                          RATE_P_DECIM / fs));
  t->rate.p_mode_k = (float)(1.0 - exp(-(double)GYRO_BLOCK / (fs * tau_s))); /* per block */
  /* The reference's type-2 low-pass (rate_channel.h), per block: a PI tracker whose
   * closed loop is wn^2 + 2 zeta wn s over s^2 + 2 zeta wn s + wn^2. */
  const double ref_wn_t = 2.0 * FM_PI * RATE_REF_LP_HZ * (double)GYRO_BLOCK / fs;
  t->rate.ref_lp_kp = (float)(2.0 * RATE_REF_LP_ZETA * ref_wn_t);
  t->rate.ref_lp_ki = (float)(ref_wn_t * ref_wn_t);
  const double wide_wn_t = 2.0 * FM_PI * RATE_REF_WIDE_HZ * (double)GYRO_BLOCK / fs;
  t->rate.ref_wide_kp = (float)(2.0 * RATE_REF_LP_ZETA * wide_wn_t);
  t->rate.ref_wide_ki = (float)(wide_wn_t * wide_wn_t);
  const double blk_s = (double)GYRO_BLOCK / fs;
  t->rate.ref_wide_blocks = (uint32_t)(fmax(RATE_REF_WIDE_TAUS * tau_s, RATE_REF_WIDE_MIN_S) /
                                       blk_s);
  t->rate.ref_narrow_k = (float)pow(RATE_REF_LP_HZ / RATE_REF_WIDE_HZ,
                                    blk_s / RATE_REF_NARROW_S); /* per block */
  t->rate.lpf_sections = (uint32_t)n;
  t->rate.min_drive_v = 0.05f * v->drive_amp_set_v;
  t->rate_out_v_per_dps = v->rate_out_v_per_dps;
  return GYRO_DESIGN_OK;
}

/* The supervisor (supervisor.h), once per block. The lost-lock tolerances are at least
 * the lock ones (hysteresis), the over-amplitude trip above the lost-lock band, and the
 * setpoint below the absolute trip; the acquisition time-out needs the drive loops'
 * gains (design_drive_loops first). */
static gyro_design_status_t design_supervisor(const param_values_t *v, double tau_s,
                                              gyro_design_t *t)
{
  if (!(v->sup_lost_tol_rel >= v->sup_lock_tol_rel)) return GYRO_DESIGN_LOST_TOL;
  if (!(v->sup_amp_trip_rel > 1.0f + v->sup_lost_tol_rel)) return GYRO_DESIGN_AMP_TRIP;
  const float amp_max_v = GYRO_AMP_MAX_FRAC * HAL_ADC_FULL_SCALE_V;
  if (!(v->drive_amp_set_v > 0.0f && v->drive_amp_set_v < amp_max_v))
    return GYRO_DESIGN_AMP_SET;
  t->sup.dt_s = (float)GYRO_BLOCK / (float)v->sys_fs_hz;
  t->sup.lock_tol_rel = v->sup_lock_tol_rel;
  t->sup.lock_phase_tol_rad = v->sup_lock_phase_tol_deg * FM_RAD_PER_DEG_F;
  t->sup.lock_hold_s = v->sup_lock_hold_s;
  t->sup.lost_tol_rel = v->sup_lost_tol_rel;
  t->sup.lost_hold_s = v->sup_lost_hold_s;
  t->sup.amp_trip_rel = v->sup_amp_trip_rel;
  t->sup.sat_hold_s = v->sup_sat_hold_s;
  t->sup.retry_s = v->sup_retry_s;
  t->sup.clip_max_count = v->sup_clip_count;
  t->sup.lost_phase_tol_rad = (v->sup_lost_phase_tol_deg > v->sup_lock_phase_tol_deg
                                   ? v->sup_lost_phase_tol_deg
                                   : v->sup_lock_phase_tol_deg) *
                              FM_RAD_PER_DEG_F;
  t->sup.amp_set_v = v->drive_amp_set_v;
  t->sup.amp_max_v = amp_max_v;
  t->sup.acq_timeout_s = (float)acq_timeout_s(v, tau_s, t);
  return GYRO_DESIGN_OK;
}

/* Force rebalance (sense_fr.h): the feedback electrodes' synthesis and limit, and the
 * loop's design from the sense model (sense.f0_hz, sense.q, sense.fb_gain_v_per_v2) in the
 * rate channel's units: g = sense.fb_gain_v_per_v2 / drive.amp_set_v (R = S e^{-j psi} /
 * A_set). The lag it is designed against: the demodulator's pole (1 / (mu fs), mu =
 * sense.fr_mu) and the schedule's delay from the block mean's centre ((GYRO_BLOCK - 1) /
 * 2 ticks before the projection) to the force (synthesis on SENSE_FR_SYNTH_SLOT, the
 * waveform from the next tick, the DAC's latency of one) plus half the block the
 * command is held. */
static double fr_delay_ticks(void)
{
  const double centre = 0.5 * (double)(GYRO_BLOCK - 1u);
  const double to_force = (double)((SENSE_FR_SYNTH_SLOT + GYRO_BLOCK - GYRO_SLOT_PROJECT) %
                                   GYRO_BLOCK) +
                          2.0;
  return centre + to_force + 0.5 * (double)GYRO_BLOCK;
}

/* The lost-match monitor (sense_tune.h): the model's ratio of the continuous test's two
 * axes at its own pole, its slope per Hz of detuning (a central difference over
 * +-DISC_STEP_HZ, well inside its linear range: the ratio moved linearly over +-2.3 Hz,
 * measured), and the loop's tolerance. */
#define DISC_STEP_HZ 0.5
static int design_tune_disc(const param_values_t *v, const sense_fr_cfg_t *fc,
                            const sense_fr_lag_t *lag, sense_tune_disc_cfg_t *c)
{
  const double fs = (double)v->sys_fs_hz, fm = (double)v->selftest_cont_freq_hz;
  double c0[2], cp[2], cn[2];
  if (sense_fr_tone_cross(fc, lag, fs, fm, 0.0, c0) != 0 ||
      sense_fr_tone_cross(fc, lag, fs, fm, DISC_STEP_HZ, cp) != 0 ||
      sense_fr_tone_cross(fc, lag, fs, fm, -DISC_STEP_HZ, cn) != 0)
    return -1;
  c->c0_re = c0[0];
  c->c0_im = c0[1];
  c->u_re = (cp[0] - cn[0]) / (2.0 * DISC_STEP_HZ);
  c->u_im = (cp[1] - cn[1]) / (2.0 * DISC_STEP_HZ);
  c->tol_hz = sense_fr_detune_tol_hz(fc, SENSE_TUNE_LOST_ROOT_FRAC);
  c->zero_hz = (double)v->sense_tune_disc_zero_hz;
  c->window_ticks = (uint32_t)(SENSE_TUNE_DISC_WINDOW_S * fs + 0.5);
  c->k = 1.0 - exp(-SENSE_TUNE_DISC_WINDOW_S / SENSE_TUNE_DISC_TAU_S);
  if (!(c->u_re * c->u_re + c->u_im * c->u_im > 0.0) || !(c->tol_hz > 0.0)) return -1;
  c->on = 1u;
  return 0;
}

static gyro_design_status_t design_fb(const param_values_t *v, gyro_design_t *t)
{
  const double v_dac_max = (double)(HAL_DAC_CODE_MAX - HAL_DAC_CODE_MID) *
                           (double)HAL_DAC_V_PER_CODE;
  const int dc_ac = v->sense_fb_scheme == 1u;
  t->fb_synth.scheme = dc_ac ? GYRO_DRIVE_DC_AC : GYRO_DRIVE_HALF_FREQ;
  t->fb_synth.dc_bias_v = v->sense_fb_bias_v;
  t->fb_synth.u_max_v = v->sense_fb_v_max_v;
  t->fb_off_v = dc_ac ? v->sense_fb_bias_v : 0.0f;
  drive_synth_t probe;
  /* DC+AC: the converter carries the AC part only, at most v_max - Vb */
  if (!((double)v->sense_fb_v_max_v <= v_dac_max) || drive_synth_init(&probe, &t->fb_synth) != 0)
    return GYRO_DESIGN_SENSE_FB;
  t->fb_theta_rad = v->sense_fb_phase_deg * FM_RAD_PER_DEG_F;
  t->sense_mode = v->sense_mode;
  const double fs = (double)v->sys_fs_hz;
  const double scale = fabs((double)v->rate_scale_dps);
  const double g = (double)v->sense_fb_gain_v_per_v2 / (double)v->drive_amp_set_v;
  const sense_fr_cfg_t fc = {v->sense_fr_bw_hz,
                             v->sense_fr_zeta,
                             v->sense_f0_hz,
                             v->sense_q,
                             v->drive_freq_hz,
                             (float)g,
                             (float)(1.0 / ((double)v->sense_fr_mu * fs) + fr_delay_ticks() / fs),
                             drive_synth_f_cmd_max(&probe),
                             scale > 0.0 ? (float)((double)v->sense_fr_settle_dps / scale) : 0.0f,
                             v->sense_fr_settle_s,
                             (float)((double)GYRO_BLOCK / fs)};
  if (sense_fr_design(&fc, &t->fr) != 0) return GYRO_DESIGN_SENSE_FR;
  t->fr_scale_dps_per_v2 = (float)((double)v->rate_scale_dps * g);
  /* The continuous self-test with the loop closed: its expectation is the loop model's
   * (selftest.h), the open loop's calibrated selftest.cont_expect_dps does not apply. */
  if (v->sense_mode == 1u && t->selftest.cont_on != 0u) {
    const sense_fr_lag_t lag = {(double)v->sense_fr_mu * fs, fr_delay_ticks() / fs};
    const double e = sense_fr_tone_gain(&fc, &lag, (double)v->selftest_cont_freq_hz) *
                     (double)v->selftest_cont_fr_v2;
    const double tol = (double)v->selftest_tol_rel;
    if (!(e > 0.0) || !(tol < 1.0)) return GYRO_DESIGN_SENSE_SELFTEST;
    selftest_cfg_t *st = &t->selftest;
    /* The output filter (sense.fr_lpf_hz) passes the tone: not valid before the notch
     * has taken it out, three of its time constants (e^-3 of the tone left, 0.12 deg/s of
     * the default's 2.5). */
    st->cont_gate_bits = RATE_INVALID_SETTLING;
    st->cont_gate_blocks = (uint32_t)(3.0 * GYRO_CONT_TAU_S * fs / GYRO_BLOCK);
    cont_band(st, e, tol);
    if (v->sense_tune != SENSE_TUNE_OFF && design_tune_disc(v, &fc, &lag, &t->tune_disc) != 0)
      return GYRO_DESIGN_SENSE_TUNE;
  }
  /* The self-test's force would go onto the same electrodes, past the loop: the
   * continuous one goes into the loop's command (selftest.h), a small part of what the
   * electrodes can give; the on-demand one is refused by its command. */
  if (v->sense_mode == 1u &&
      !((double)v->selftest_cont_fr_v2 <= 0.25 * (double)drive_synth_f_cmd_max(&probe)))
    return GYRO_DESIGN_SENSE_SELFTEST;
  return GYRO_DESIGN_OK;
}

/* In force rebalance the demodulator sits inside the loop (sense.fr_mu) and the loop
 * sets the bandwidth: the output filter is a 2nd-order Butterworth at sense.fr_lpf_hz
 * instead of rate.lpf_* (sense_fr.h; open loop unchanged). */
static gyro_design_status_t design_fr_rate(const param_values_t *v, gyro_design_t *t)
{
  if (v->sense_mode != 1u) return GYRO_DESIGN_OK;
  const double fs = (double)v->sys_fs_hz;
  t->lmsd_sense.mu = v->sense_fr_mu;
  const int n = butter_design(BUTTER_LOWPASS, 2u, (double)v->sense_fr_lpf_hz, 0.0,
                              fs / RATE_DECIM, t->rate.lpf, BIQUAD_MAX_SECTIONS);
  if (n <= 0) return GYRO_DESIGN_SENSE_FR;
  t->rate.lpf_sections = (uint32_t)n;
  return GYRO_DESIGN_OK;
}

/* Mode tuning (sense_tune.h): matched only with the loop closed (open loop the rate's
 * band would be the sense mode's, f0 / 2Q: 0.08 Hz at Q 1e4); with a calibration, its
 * target reachable at the calibration's drive frequency. Not calibrated is allowed: the
 * rate is then not valid (TUNE) until a sweep tunes the part. */
static gyro_design_status_t design_tune(const param_values_t *v, gyro_design_t *t)
{
  const double v_dac_max = (double)(HAL_DAC_CODE_MAX - HAL_DAC_CODE_MID) *
                           (double)HAL_DAC_V_PER_CODE;
  sense_tune_cfg_t *c = &t->tune;
  c->mode = v->sense_tune;
  c->split_hz = (double)v->sense_tune_split_hz;
  c->v_max_v = (double)v->sense_tune_v_max_v;
  c->s0_hz = (double)v->sense_cal_s0_hz;
  c->ref_hz = (double)v->sense_cal_tune_ref_hz;
  c->ke_per_s2_per_v2 = (double)v->sense_cal_tune_ke_per_s2_per_v2;
  if (!(c->v_max_v <= v_dac_max)) return GYRO_DESIGN_SENSE_TUNE;
  if (c->mode == SENSE_TUNE_MATCHED && v->sense_mode != 1u) return GYRO_DESIGN_SENSE_TUNE;
  sense_tune_out_t o;
  sense_tune_at(c, c->ref_hz, &o);
  return o.state == SENSE_TUNE_BELOW || o.state == SENSE_TUNE_LIMIT ? GYRO_DESIGN_SENSE_TUNE
                                                                    : GYRO_DESIGN_OK;
}

/* The board thermometer (board_therm.h): every value the table accepts designs. */
static void design_board(const param_values_t *v, gyro_design_t *t)
{
  const float tz[2] = {v->board_tz1_s, v->board_tz2_s};
  const float tp[2] = {v->board_tp1_s, v->board_tp2_s};
  const float c[4] = {v->board_c0_dps, v->board_c1_dps_per_c, v->board_c2_dps_per_c2,
                      v->board_c3_dps_per_c3};
  board_therm_design(&t->board, v->board_fuse, tz, tp, v->board_ref_c, c, v->board_min_c,
                     v->board_max_c, v->board_crossover_s, v->board_start_s, v->board_fade_s,
                     v->board_stale_s, v->board_agree_dps);
}

/* Each part in turn; the first that fails names the reason. */
/* The demodulation phase, the scale and the compensation are measured at one drive
 * frequency: at another, the phase of the drive against its resonance, and with it P
 * and the sense phasor's angle, are another (2Q df/f rad, 2-33). */
/* The tuning voltage at the tuning's own reference (0 V untuned or not calibrated):
 * what cal.ref_tune_v records. Within 0.6 of a code: the same code. */
static int same_tuning(const param_values_t *v, const sense_tune_cfg_t *tune)
{
  sense_tune_out_t o;
  sense_tune_at(tune, tune->ref_hz, &o);
  return fabs(o.v_v - (double)v->cal_ref_tune_v) <= 0.6 * (double)HAL_DAC_V_PER_CODE;
}

static uint32_t cal_state(const param_values_t *v, const sense_tune_cfg_t *tune)
{
  const double ref = (double)v->cal_ref_freq_hz;
  if (!(ref > 0.0)) return GYRO_CAL_NONE;
  /* So is the phase setpoint: the loop holds the drive's phase there, so P is the set
   * point plus the lags at the part's temperature (a new set point moves the
   * thermometer by itself), and the drive's phase against the Coriolis force's moves. */
  const int same_phase = fabs((double)v->drive_phase_set_deg -
                              (double)v->cal_ref_phase_set_deg) <= GYRO_CAL_PHASE_DEG;
  /* And the drive mode: the tracking drive's thermometer is the tracked frequency (p_eq,
   * drive_track.h), with the part's Q in its scale, where the fixed drive's is P. */
  const int same_mode = v->drive_track == v->cal_ref_track;
  /* And the sense configuration: force rebalance's rate is the force's, nulling takes
   * away the quadrature that would leak into the rate as the thermometer moves. */
  const int same_sense = v->sense_mode == v->cal_ref_sense_mode &&
                         v->quad_null == v->cal_ref_quad_null;
  return same_phase && same_mode && same_sense && same_tuning(v, tune) &&
                 fabs((double)v->drive_freq_hz - ref) <= GYRO_CAL_FREQ_REL * ref
             ? GYRO_CAL_OK
             : GYRO_CAL_STALE;
}

const char *gyro_cal_state_name(uint32_t s)
{
  return s == GYRO_CAL_OK ? "yes" : s == GYRO_CAL_STALE ? "stale" : "no";
}

static gyro_design_status_t design_parts(const param_values_t *v, gyro_design_t *t)
{
  gyro_design_status_t s = design_nco(v, t);
  if (s == GYRO_DESIGN_OK) s = design_synth(v, t);
  if (s == GYRO_DESIGN_OK) s = design_demod(v, t);
  const double tau_s = drive_tau_s(v);
  if (s == GYRO_DESIGN_OK) s = design_drive_loops(v, tau_s, t);
  if (s == GYRO_DESIGN_OK) s = design_rate(v, tau_s, t);
  if (s == GYRO_DESIGN_OK) s = design_supervisor(v, tau_s, t);
  if (s == GYRO_DESIGN_OK) s = design_validity(v, t);
  if (s == GYRO_DESIGN_OK) s = design_selftest(v, t);
  if (s == GYRO_DESIGN_OK) s = design_quad_null(v, t);
  if (s == GYRO_DESIGN_OK) s = design_fb(v, t);
  if (s == GYRO_DESIGN_OK) s = design_fr_rate(v, t);
  if (s == GYRO_DESIGN_OK) s = design_tune(v, t);
  design_board(v, t);
  t->autostart = v->sys_autostart;
  t->cal_state = cal_state(v, &t->tune);
  t->track_uncal = v->drive_track != 0u && v->cal_ref_track == 0u ? 1u : 0u;
  return s;
}

int gyro_design_complete(gyro_design_t *d)
{
  if (d == NULL || drive_loop_cfg_derive(&d->drive) != 0 || supervisor_cfg_derive(&d->sup) != 0) {
    return -1;
  }
  selftest_cfg_derive(&d->selftest);
  d->rate_fault_code = gyro_volts_to_dac(d->rate_fault_out_v);
  /* What gyro_init_from_design checks, on scratch states. */
  nco_t nco;
  lmsd_t lmsd;
  drive_synth_t synth;
  return nco_init(&nco, &d->nco) == 0 && lmsd_init(&lmsd, &d->lmsd_drive) == 0 &&
                 lmsd_init(&lmsd, &d->lmsd_sense) == 0 &&
                 drive_synth_init(&synth, &d->synth) == 0 && rate_channel_cfg_ok(&d->rate) &&
                 rate_valid_cfg_ok(&d->valid)
             ? 0
             : -1;
}

gyro_design_status_t gyro_design(const param_values_t *v, gyro_design_t *d)
{
  if (v == NULL || d == NULL) return GYRO_DESIGN_NO_VALUES;
  gyro_design_t t;
  memset(&t, 0, sizeof t);
  const gyro_design_status_t s = design_parts(v, &t);
  if (s != GYRO_DESIGN_OK) return s;
  /* Every module must accept its part: a design that gyro_apply could not apply is
   * rejected here, in the background, where the error can be reported. The checks
   * above name the parameters; what is left for this one are values outside their
   * parameter's range (the parameter bank refuses those before a design). */
  if (gyro_design_complete(&t) != 0) return GYRO_DESIGN_MODULE;
  *d = t;
  return GYRO_DESIGN_OK;
}

static const char *const k_reasons[GYRO_DESIGN_STATUS_COUNT] = {
    [GYRO_DESIGN_OK] = "",
    [GYRO_DESIGN_NO_VALUES] = "no parameter values to design from",
    [GYRO_DESIGN_FS] = "sys.fs_hz must be above 0",
    [GYRO_DESIGN_DRIVE_FREQ] = "drive.freq_hz must lie between 0 and sys.fs_hz / 4",
    [GYRO_DESIGN_DRIVE_VOLTAGES] = "drive.u_max_v must be above 0, and drive.dc_bias_v between 0 "
                                   "and drive.u_max_v in DC+AC drive (drive.mode 1)",
    [GYRO_DESIGN_MU_DRIVE] = "demod.mu_drive must lie above 0 and at most 0.5",
    [GYRO_DESIGN_MU_SENSE] = "demod.mu_sense must lie above 0 and at most 0.5",
    [GYRO_DESIGN_AMP_LOOP] = "drive.cal_gain_v_per_v2, drive.cal_q, drive.cal_f0_hz and "
                             "drive.amp_bw_hz must be positive for the amplitude loop's design",
    [GYRO_DESIGN_PHASE_LOOP] = "drive.cal_q, drive.cal_f0_hz and drive.phase_bw_hz must be "
                               "positive for the phase loop's design",
    [GYRO_DESIGN_FIXED_Q] = "drive.cal_q above 5000 is beyond the fixed-frequency drive's reach: "
                            "select the tracking drive first (set drive.track 1, drive off)",
    [GYRO_DESIGN_P_INIT] = "drive.p_init_deg must lie within +-360 deg (one turn)",
    [GYRO_DESIGN_RATE_LPF] = "rate.lpf_cutoff_hz must be below half the block rate "
                             "(sys.fs_hz / 20), rate.lpf_order even and at most 8",
    [GYRO_DESIGN_AMP_SET] = "drive.amp_set_v must lie between 0 and 95 % of the ADC's range",
    [GYRO_DESIGN_LOST_TOL] = "sup.lost_tol_rel must not be below sup.lock_tol_rel",
    [GYRO_DESIGN_AMP_TRIP] = "sup.amp_trip_rel must be above 1 + sup.lost_tol_rel",
    [GYRO_DESIGN_FAULT_OUT] = "rate.fault_out_v must lie outside rate.full_scale_dps x "
                              "rate.out_v_per_dps plus 10 %",
    [GYRO_DESIGN_BIAS_SLOPE] = "rate.bias_c1_dps_per_deg .. rate.bias_c3_dps_per_deg3 must give a "
                               "finite bias slope over rate.p_range_deg",
    [GYRO_DESIGN_CONT_FREQ] = "selftest.cont_freq_hz must lie between 1.5 x rate.lpf_cutoff_hz and "
                              "a quarter of the block rate (sys.fs_hz / 40)",
    [GYRO_DESIGN_CONT_EXPECT] = "selftest.cont_expect_dps and rate.scale_dps must not be 0, and "
                                "selftest.tol_rel must be below 1",
    [GYRO_DESIGN_QUAD_NULL] = "quad.probe_v must not exceed quad.v_max_v, quad.v_max_v must lie "
                              "within the DAC's range (14.99 V), quad.bw_hz at most a tenth "
                              "of the 500 Hz update, quad.probe_avg_s at least one update (2 ms)",
    [GYRO_DESIGN_SENSE_FB] = "sense.fb_v_max_v must lie within the DAC's range (14.99 V), and "
                             "sense.fb_bias_v between 0 and sense.fb_v_max_v in DC+AC "
                             "(sense.fb_scheme 1)",
    [GYRO_DESIGN_SENSE_FR] = "the force-rebalance loop cannot be designed: sense.fb_gain_v_per_v2 "
                             "must not be 0, sense.fr_bw_hz at most a twentieth of the block "
                             "rate and 2 sense.fr_zeta sense.fr_bw_hz within the demodulator's "
                             "lag (sense.fr_mu), sense.fr_lpf_hz below half the block rate, "
                             "rate.scale_dps not 0",
    [GYRO_DESIGN_SENSE_SELFTEST] = "selftest.continuous 1 with force rebalance (sense.mode 1) "
                                   "needs selftest.cont_fr_v2 within a quarter of the "
                                   "feedback electrodes' force (sense.fb_v_max_v)",
    [GYRO_DESIGN_SENSE_TUNE] = "sense.tune 1 (matched) needs force rebalance (sense.mode 1); "
                               "sense.tune_v_max_v must lie within the DAC's range (14.99 V); "
                               "a tuned part's target (the drive's resonance, plus "
                               "sense.tune_split_hz with sense.tune 2) must lie below its "
                               "untuned sense resonance sense.cal_s0_hz (tuning only lowers "
                               "it) and within sense.tune_v_max_v",
    [GYRO_DESIGN_MODULE] = "a value outside its parameter's range: a module refused its part of "
                           "the design",
};

const char *gyro_design_reason(gyro_design_status_t s)
{
  const unsigned i = (unsigned)s;
  return i < (unsigned)GYRO_DESIGN_STATUS_COUNT ? k_reasons[i] : "";
}
