/* Top level of the plant: builds the modules from plant_cfg_t and runs one sample. */
#include "plant/plant.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include "plant/plant_const.h"

static const double kPi = PLANT_PI;
static const double kDeg = PLANT_RAD_PER_DEG;

__attribute__((format(printf, 2, 3))) static void set_err(plant_t *p, const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(p->err, sizeof p->err, fmt, ap);
  va_end(ap);
}

const char *plant_error(const plant_t *p) { return p->err; }

/* ---------------------------------------------------------- module configs ---- */

static void make_mech_cfg(const plant_cfg_t *c, mech_cfg_t *m)
{
  mech_default_cfg(m);
  m->f1_hz = c->f_drive_hz;
  m->q1 = c->q_drive;
  m->f2_hz = c->f_sense_hz;
  m->q2 = c->q_sense;
  m->temp_ref_k = c->temp_ref_k;
  m->ket_per_k = c->ket_per_k;
  /* equivalent rate of k_q y against 2 Omega y' at the drive frequency: k_q/(2 wc) */
  m->kq_per_s2 = 2.0 * (2.0 * kPi * c->f_drive_hz) * c->quad_dps * kDeg;
  m->dq_per_s = 2.0 * c->inphase_bias_dps * kDeg;
  m->mass_kg = c->mass_kg;
  m->fs_hz = c->fs_hz;
  m->refresh_eps = c->mech_refresh_eps;
  m->full_kinematics = c->full_kinematics ? 1 : 0;
  m->brownian = c->brownian ? 1 : 0;
  m->q_law = c->q_temp_law;
  m->k3_drive_per_m2 = c->k3_drive_per_m2;
  m->k3_sense_per_m2 = c->k3_sense_per_m2;
  m->nl_damp_drive_per_m2 = c->nl_damp_drive_per_m2;
  m->ke2_per_s2 = plant_fb_softening(c);
}

double plant_fb_pair_softening(const plant_cfg_t *c)
{
  /* (6-3) per electrode, 2 (Ks m) U^2 / d as in plant_fb_softening, on U3 and U4 */
  if (c->fb_mode != 3 || !(c->fb_gap_m > 0.0)) return 0.0;
  return 2.0 * c->ks_fb_mps2_per_v2 / c->fb_gap_m;
}

double plant_fb_rate_dps_per_v2(const plant_cfg_t *c, double f_drive_hz, double amp_m)
{
  if (!(f_drive_hz > 0.0) || !(amp_m > 0.0)) return 0.0;
  return c->ks_fb_mps2_per_v2 / (2.0 * amp_m * 2.0 * PLANT_PI * f_drive_hz) * PLANT_DEG_PER_RAD;
}

double plant_fb_softening(const plant_cfg_t *c)
{
  /* (6-3) per electrode: k_e = eps A V^2 / d^3 = 2 (Ks m) V^2 / d, with Ks m = eps A / (2 d^2)
   * the force constant of F = Ks V^2 at x = 0; both electrodes of the differential pair
   * sit at the DC bias Vb: k_e / m = 4 Ks Vb^2 / d. The single electrode has no DC. */
  if (c->fb_mode != 2 || !(c->fb_gap_m > 0.0)) return 0.0;
  return 4.0 * c->ks_fb_mps2_per_v2 * c->fb_bias_v * c->fb_bias_v / c->fb_gap_m;
}

static int thermal_every(const plant_cfg_t *c)
{
  const double n = floor(c->thermal_dt_s * c->fs_hz + 0.5);
  return n < 1.0 ? 1 : (int)n;
}

static void make_thermal_cfg(const plant_cfg_t *c, thermal_cfg_t *t)
{
  thermal_default_cfg(t);
  t->tau_s[THERMAL_STRUCT] = c->tau_struct_s;
  t->tau_s[THERMAL_CIRCUIT] = c->tau_circuit_s;
  t->tau_s[THERMAL_BOARD] = c->tau_board_s;
  t->couple_per_s[THERMAL_PAIR_SC] = c->couple_sc_per_s;
  t->couple_per_s[THERMAL_PAIR_SB] = c->couple_sb_per_s;
  t->couple_per_s[THERMAL_PAIR_CB] = c->couple_cb_per_s;
  t->rise_k[THERMAL_STRUCT] = c->rise_struct_k;
  t->rise_k[THERMAL_CIRCUIT] = c->rise_circuit_k;
  t->rise_k[THERMAL_BOARD] = c->rise_board_k;
  t->dt_s = thermal_every(c) / c->fs_hz;
}

/* The DAC channel of each electrode (plant_electrodes_t order). */
static const int kElecChannel[PLANT_ELECTRODES] = {HAL_DAC_SENSE_FB_U1, HAL_DAC_SENSE_FB_U2,
                                                   HAL_DAC_QUADNULL_V1, HAL_DAC_QUADNULL_V2,
                                                   HAL_DAC_TUNE};

/* Which electrodes the part has (plant_electrodes_t order), as the actuator decides
 * (actuator.h): the feedback pair in fb_mode 3, the nulling sets and the tuning electrodes
 * when their constants are non-zero. */
static void plant_electrodes_of(const plant_cfg_t *c, uint8_t has[PLANT_ELECTRODES])
{
  has[0] = has[1] = c->fb_mode == 3;
  has[2] = has[3] = c->quadnull_dps_per_v2 > 0.0;
  has[4] = c->tune_ke_per_s2_per_v2 > 0.0;
}

static void make_dac_cfg(const plant_cfg_t *c, dac_cfg_t *d)
{
  dac_default_cfg(d);
  d->inl.bow_lsb = c->dac_inl_bow_lsb;
  d->inl.code_lsb = c->dac_inl_code_lsb;
  d->inl_seed = (uint64_t)c->board_seed; /* the board's ladder, not the run's noise */
  d->fs_hz = c->fs_hz;
  d->recon_cutoff_hz = c->dac_recon_hz;
  d->recon_q = c->dac_recon_q;
  d->gain[HAL_DAC_DRIVE_U1] = c->dac_gain_u1;
  d->gain[HAL_DAC_DRIVE_U2] = c->dac_gain_u2;
  d->gain[HAL_DAC_RATE_OUT] = c->dac_gain_rate;
  d->gain[HAL_DAC_SPARE] = c->dac_gain_spare;
  d->offset_v[HAL_DAC_DRIVE_U1] = c->dac_offset_u1_v;
  d->offset_v[HAL_DAC_DRIVE_U2] = c->dac_offset_u2_v;
  d->offset_v[HAL_DAC_RATE_OUT] = c->dac_offset_rate_v;
  d->offset_v[HAL_DAC_SPARE] = c->dac_offset_spare_v;
  d->gain[HAL_DAC_SENSE_FB_U2] = c->dac_gain_fb_u2;
  d->gain[HAL_DAC_QUADNULL_V1] = c->dac_gain_quadnull_v1;
  d->gain[HAL_DAC_QUADNULL_V2] = c->dac_gain_quadnull_v2;
  d->gain[HAL_DAC_TUNE] = c->dac_gain_tune;
  d->offset_v[HAL_DAC_SENSE_FB_U2] = c->dac_offset_fb_u2_v;
  d->offset_v[HAL_DAC_QUADNULL_V1] = c->dac_offset_quadnull_v1_v;
  d->offset_v[HAL_DAC_QUADNULL_V2] = c->dac_offset_quadnull_v2_v;
  d->offset_v[HAL_DAC_TUNE] = c->dac_offset_tune_v;
  /* the second converter's channels load only the electrodes the part has (dac.h) */
  uint8_t has[PLANT_ELECTRODES];
  plant_electrodes_of(c, has);
  d->modelled[HAL_DAC_SENSE_FB_U2] = has[1];
  d->modelled[HAL_DAC_QUADNULL_V1] = has[2];
  d->modelled[HAL_DAC_QUADNULL_V2] = has[3];
  d->modelled[HAL_DAC_TUNE] = has[4];
}

static void make_actuator_cfg(const plant_cfg_t *c, actuator_cfg_t *a)
{
  actuator_default_cfg(a);
  a->fs_hz = c->fs_hz;
  a->ks_drive_mps2_per_v2 = c->ks_drive_mps2_per_v2;
  a->drive_noise.white_rthz = c->drive_noise_white_v_rthz;
  a->drive_noise.flicker_1hz_rthz = c->drive_noise_1hz_v_rthz;
  a->drive_noise.fmin_hz = c->drive_noise_fmin_hz;
  a->fb = (actuator_fb_t)c->fb_mode;
  a->ks_fb_mps2_per_v2 = c->ks_fb_mps2_per_v2;
  a->fb_bias_v = c->fb_bias_v;
  a->fb_noise.white_rthz = c->fb_noise_white_v_rthz;
  a->fb_noise.flicker_1hz_rthz = c->fb_noise_1hz_v_rthz;
  a->fb_noise.fmin_hz = c->fb_noise_fmin_hz;
  a->fb_ke_per_s2_per_v2 = plant_fb_pair_softening(c);
  /* c_q as an equivalent quadrature per V^2, scaled as quad_dps (make_mech_cfg) */
  a->quadnull_kyx_per_s2_per_v2 = 2.0 * (2.0 * kPi * c->f_drive_hz) * c->quadnull_dps_per_v2 *
                                  kDeg;
  a->quadnull_ke_per_s2_per_v2 = 2.0 * a->quadnull_kyx_per_s2_per_v2 *
                                 c->quadnull_overlap_per_gap;
  a->quadnull_noise.white_rthz = c->quadnull_noise_white_v_rthz;
  a->quadnull_noise.flicker_1hz_rthz = c->quadnull_noise_1hz_v_rthz;
  a->quadnull_noise.fmin_hz = c->quadnull_noise_fmin_hz;
  a->tune_ke_per_s2_per_v2 = c->tune_ke_per_s2_per_v2;
  a->tune_noise.white_rthz = c->tune_noise_white_v_rthz;
  a->tune_noise.flicker_1hz_rthz = c->tune_noise_1hz_v_rthz;
  a->tune_noise.fmin_hz = c->tune_noise_fmin_hz;
}

static void make_pickoff_cfg(const plant_cfg_t *c, int axis, pickoff_cfg_t *q)
{
  pickoff_default_cfg(q, axis == 0 ? PICKOFF_DRIVE : PICKOFF_SENSE);
  q->fs_hz = c->fs_hz;
  q->lag_ref_hz = c->pick_lag_ref_hz;
  q->temp_ref_k = c->temp_ref_k;
  q->phase_step_rad = c->pick_phase_step_rad;
  q->gain_v_per_m = PLANT_PICK(c, axis, gain_v_per_m);
  q->gain_tc_per_k = PLANT_PICK(c, axis, gain_tc_per_k);
  q->preamp_rail_v = PLANT_PICK(c, axis, rail_v);
  q->ft_u1 = PLANT_PICK(c, axis, ft_u1);
  q->ft_u2 = PLANT_PICK(c, axis, ft_u2);
  q->ft_spare = PLANT_PICK(c, axis, ft_spare);
  q->lag_kind = PLANT_PICK(c, axis, lag_allpass) ? PICKOFF_LAG_ALLPASS : PICKOFF_LAG_LOWPASS;
  q->phi0_rad = PLANT_PICK(c, axis, phi0_deg) * kDeg;
  q->phi1_rad_per_k = PLANT_PICK(c, axis, phi1_deg_per_k) * kDeg;
  q->phi2_rad_per_k2 = PLANT_PICK(c, axis, phi2_deg_per_k2) * kDeg;
  q->hp_hz = PLANT_PICK(c, axis, hp_hz);
  q->lp_hz = PLANT_PICK(c, axis, lp_hz);
  q->lp_q = PLANT_PICK(c, axis, lp_q);
  q->offset_v = PLANT_PICK(c, axis, offset_v);
  q->noise_v_rthz = PLANT_PICK(c, axis, noise_v_rthz);
  q->sample_delay_s = PLANT_PICK(c, axis, delay_s);
  q->jitter_rms_s = PLANT_PICK(c, axis, jitter_s);
  q->gap_m = PLANT_PICK(c, axis, gap_m);
  q->gap_asym = PLANT_PICK(c, axis, gap_asym);
  q->gain_flicker_1hz_rthz = PLANT_PICK(c, axis, gain_flicker_1hz_rthz);
  q->phase_flicker_1hz_rad_rthz = PLANT_PICK(c, axis, phase_flicker_1hz_deg_rthz) * kDeg;
  q->flicker_fmin_hz = c->pick_flicker_fmin_hz;
}

static void make_adc_cfg(const plant_cfg_t *c, uint64_t seed, adc_cfg_t *a)
{
  adc_default_cfg(a);
  a->full_scale_v = c->adc_full_scale_v;
  a->inl.bow_lsb = c->adc_inl_bow_lsb;
  a->inl.code_lsb = c->adc_inl_code_lsb;
  a->aperture_jitter_s = c->adc_aperture_jitter_s;
  a->seed = seed;
  a->inl_seed = (uint64_t)c->board_seed;
}

static void make_vref_cfg(const plant_cfg_t *c, vref_cfg_t *v)
{
  v->noise.white_rthz = c->vref_noise_white_rthz;
  v->noise.flicker_1hz_rthz = c->vref_noise_1hz_rthz;
  v->noise.fmin_hz = c->vref_noise_fmin_hz;
}

/* The two coupling drifts (drift.h), stepped at the thermal updates, in deg/s of
 * equivalent rate; with the scales to k_q and d_q of make_mech_cfg. */
static int init_drifts(plant_t *p, uint64_t seed)
{
  const plant_cfg_t *c = &p->cfg;
  const double dt = p->thermal_every * p->T;
  const drift_cfg_t dc[2] = {{c->quad_drift_dps, c->quad_drift_tau_s, dt},
                             {c->inphase_drift_dps, c->inphase_drift_tau_s, dt}};
  p->drift_kq_per_s2 = 2.0 * (2.0 * kPi * c->f_drive_hz) * kDeg;
  p->drift_dq_per_s = 2.0 * kDeg;
  p->drift_on = c->quad_drift_dps > 0.0 || c->inphase_drift_dps > 0.0;
  if (drift_init(&p->drift[0], &dc[0], seed, PLANT_RNG_STREAM_QUAD_DRIFT) != 0) return -1;
  return drift_init(&p->drift[1], &dc[1], seed, PLANT_RNG_STREAM_INPHASE_DRIFT);
}

static void make_accel_cfg(const plant_cfg_t *c, accel_cfg_t *a)
{
  accel_default_cfg(a);
  a->drive_mps2_per_g[ACCEL_AXIS_DRIVE] = c->gs_drive_from_drive_mps2_per_g;
  a->drive_mps2_per_g[ACCEL_AXIS_SENSE] = c->gs_drive_from_sense_mps2_per_g;
  a->drive_mps2_per_g[ACCEL_AXIS_NORMAL] = c->gs_drive_from_normal_mps2_per_g;
  a->sense_mps2_per_g[ACCEL_AXIS_DRIVE] = c->gs_sense_from_drive_mps2_per_g;
  a->sense_mps2_per_g[ACCEL_AXIS_SENSE] = c->gs_sense_from_sense_mps2_per_g;
  a->sense_mps2_per_g[ACCEL_AXIS_NORMAL] = c->gs_sense_from_normal_mps2_per_g;
}

static void make_board_sensor_cfg(const plant_cfg_t *c, board_sensor_cfg_t *b)
{
  b->kind = c->board_sensor;
  b->offset_c = c->board_sensor_offset_c;
  b->slope = c->board_sensor_slope;
  b->fault_s = c->board_sensor_fault_s;
}

static int pick_node(const plant_cfg_t *c, int axis) { return PLANT_PICK(c, axis, temp_node); }

/* ------------------------------------------------------------- warnings ------ */

static const char *const kLawNames[PLANT_LAWS] = {
    "pick_drive_phase", "pick_sense_phase", "pick_drive_gain", "pick_sense_gain",
    "resonance",        "ambient",          "q_temp",          "duffing_drive",
    "duffing_sense",    "pick_drive_gap",   "pick_sense_gap",  "sense_pull_in"};

const char *plant_law_name(int law)
{
  return (law >= 0 && law < PLANT_LAWS) ? kLawNames[law] : NULL;
}

const plant_warning_t *plant_warnings(const plant_t *p) { return p->warn; }

uint64_t plant_warning_total(const plant_t *p)
{
  uint64_t n = 0;
  for (int i = 0; i < PLANT_LAWS; i++) n += p->warn[i].count;
  return n;
}

/* One evaluation of a law outside its range, at the plant's time now. */
static void warn(plant_t *p, plant_law_t law)
{
  plant_warning_t *w = &p->warn[law];
  if (w->count == 0) w->first_t_s = (double)p->k * p->T;
  w->count++;
}

static void warn_pickoff(plant_t *p, int axis, int flags)
{
  if (flags <= 0) return;
  if ((unsigned)flags & PICKOFF_OUT_PHASE)
    warn(p, axis == 0 ? PLANT_LAW_PICK_DRIVE_PHASE : PLANT_LAW_PICK_SENSE_PHASE);
  if ((unsigned)flags & PICKOFF_OUT_GAIN)
    warn(p, axis == 0 ? PLANT_LAW_PICK_DRIVE_GAIN : PLANT_LAW_PICK_SENSE_GAIN);
  if ((unsigned)flags & PICKOFF_OUT_GAP)
    warn(p, axis == 0 ? PLANT_LAW_PICK_DRIVE_GAP : PLANT_LAW_PICK_SENSE_GAP);
}

/* The mechanics' laws (mech_laws_out) and the pickoffs' capacitive laws. */
static void warn_amplitude_laws(plant_t *p)
{
  const unsigned m = mech_laws_out(&p->mech);
  if (m & MECH_OUT_Q) warn(p, PLANT_LAW_Q_TEMP);
  if (m & MECH_OUT_DUFFING_DRIVE) warn(p, PLANT_LAW_DUFFING_DRIVE);
  if (m & MECH_OUT_DUFFING_SENSE) warn(p, PLANT_LAW_DUFFING_SENSE);
  if (m & MECH_OUT_PULL_IN) warn(p, PLANT_LAW_SENSE_PULL_IN);
  for (int i = 0; i < 2; i++) warn_pickoff(p, i, (int)pickoff_gap_out(&p->pick[i]));
}

/* ------------------------------------------------------------------ init ------ */

static void accel_flags(plant_t *p)
{
  const accel_profile_t *a = &p->prof.accel_g;
  p->accel_dynamic = a->n_shocks > 0;
  p->accel_any = 0;
  for (int i = 0; i < PROFILE_ACCEL_AXES; i++) {
    if (a->amp_g[i] != 0.0) p->accel_dynamic = 1;
    if (a->amp_g[i] != 0.0 || a->const_g[i] != 0.0) p->accel_any = 1;
  }
  p->vib_on = a->n_bands > 0;
  if (p->accel_dynamic || p->vib_on) p->accel_any = 1;
}

static void truth_temps(plant_t *p, double ambient_k)
{
  plant_truth_t *t = &p->truth;
  t->ambient_k = ambient_k;
  t->struct_k = thermal_temp(&p->thermal, THERMAL_STRUCT);
  t->circuit_k = thermal_temp(&p->thermal, THERMAL_CIRCUIT);
  t->board_k = thermal_temp(&p->thermal, THERMAL_BOARD);
  t->wn_drive_rad_s = mech_wn1(&p->mech);
  t->q_drive = mech_q1(&p->mech);
  t->wn_sense_rad_s = mech_wn2(&p->mech);
  t->q_sense = mech_q2(&p->mech);
}

/* The electrodes' part of the truth (plant_truth_t): the quadrature as an equivalent rate
 * at the drive frequency of the truth, the sense resonance with its softening. */
static void truth_sense(plant_t *p)
{
  plant_truth_t *t = &p->truth;
  const double wc = 2.0 * kPi * t->drive_freq_hz;
  t->quad_true_dps = mech_kyx_total(&p->mech) / (2.0 * wc) / kDeg;
  const double w2 = mech_wn2(&p->mech), w2e = mech_wn2_eff(&p->mech);
  t->sense_freq_hz = w2e / (2.0 * kPi);
  t->sense_shift_hz = (w2e - w2) / (2.0 * kPi);
}

/* The sample clock's error at time t_s (plant.h, clock_*): the mechanics see the sample
 * period of a clock fast by it. */
static void clock_update(plant_t *p, double t_s)
{
  const plant_cfg_t *c = &p->cfg;
  const double board_c = thermal_temp(&p->thermal, THERMAL_BOARD) - 298.15;
  const double e_ppm = c->clock_ppm + c->clock_tempco_ppm_per_k * board_c +
                       c->clock_ageing_ppm_per_day * t_s / 86400.0;
  p->truth.clock_ppm = e_ppm;
  (void)mech_set_clock(&p->mech, 1.0 / (1.0 + 1e-6 * e_ppm));
}

int plant_init(plant_t *p, const plant_cfg_t *cfg, uint64_t seed)
{
  if (p == NULL) return -1;
  char msg[sizeof p->err];
  if (plant_cfg_check(cfg, msg, sizeof msg) != 0) {
    memcpy(p->err, msg, sizeof msg);
    return -1;
  }
  /* Built in place (a scratch plant_t would be 28 kB of stack on the target): from
   * here on only a module rejecting a configuration that plant_cfg_check passed can
   * fail, and the plant is then left zeroed (see plant.h). cfg may be &p->cfg. */
  if (cfg != &p->cfg) p->cfg = *cfg;
  const plant_cfg_t *c = &p->cfg;
  memset(&p->prof, 0, offsetof(plant_t, err) - offsetof(plant_t, prof));
  p->T = 1.0 / c->fs_hz;
  p->thermal_every = thermal_every(c);
  const char *what = NULL;

  thermal_cfg_t thc;
  make_thermal_cfg(c, &thc);
  mech_cfg_t mc;
  make_mech_cfg(c, &mc);
  dac_cfg_t dc;
  make_dac_cfg(c, &dc);
  actuator_cfg_t ac;
  make_actuator_cfg(c, &ac);
  pickoff_cfg_t pc[2];
  make_pickoff_cfg(c, 0, &pc[0]);
  make_pickoff_cfg(c, 1, &pc[1]);
  adc_cfg_t adcc;
  make_adc_cfg(c, seed, &adcc);
  accel_cfg_t gc;
  make_accel_cfg(c, &gc);
  vref_cfg_t vc;
  make_vref_cfg(c, &vc);
  board_sensor_cfg_t bc;
  make_board_sensor_cfg(c, &bc);

  int out_mech = 0;
  /* cold_start: power-on after a long power-off, every node at the ambient (thermal.h) */
  const int th_rc = c->cold_start ? thermal_init_cold(&p->thermal, &thc, c->temp_k)
                                  : thermal_init(&p->thermal, &thc, c->temp_k);
  if (th_rc != 0) what = "thermal (tau_*, couple_*, rise_*)";
  else if (mech_init(&p->mech, &mc,
                     mech_temp_clamp(&mc, thermal_temp(&p->thermal, THERMAL_STRUCT), &out_mech),
                     seed) != 0)
    what = "mechanics (f_*_hz, q_*, ket_per_k, temp_k)";
  else if (dac_init(&p->dac, &dc) != 0) what = "DAC (dac_*)";
  else if (actuator_init(&p->act, &ac, seed) != 0) what = "actuator (ks_*, *_noise_*, fb_*)";
  else if (adc_init(&p->adc, &adcc) != 0) what = "ADC (adc_*)";
  else if (accel_init(&p->accel, &gc) != 0) what = "g-sensitivity (gs_*)";
  else if (vref_init(&p->vref, &vc, c->fs_hz, seed) != 0) what = "reference (vref_noise_*)";
  else if (init_drifts(p, seed) != 0) what = "coupling drift (*_drift_*)";
  else if (board_sensor_init(&p->board_sensor, &bc, seed) != 0)
    what = "board temperature sensor (board_sensor*)";
  for (int i = 0; what == NULL && i < 2; i++) {
    if (pickoff_init(&p->pick[i], &pc[i], thermal_temp(&p->thermal, pick_node(c, i)), seed) != 0)
      what = i == 0 ? "drive pickoff (pick_drive_*)" : "sense pickoff (pick_sense_*)";
  }
  if (what != NULL) {
    memset(p, 0, offsetof(plant_t, err));
    set_err(p, "plant_init: %s rejected the configuration", what);
    return -2;
  }

  plant_electrodes_of(c, p->elec_has);
  profile_const(&p->prof.rate_dps, c->rate_dps);
  profile_const(&p->prof.ambient_k, c->temp_k);
  accel_profile_zero(&p->prof.accel_g);
  accel_flags(p);
  p->seed = seed;

  /* truth at t = 0 */
  p->est_alpha = 1.0 - exp(-p->T / c->truth_tau_s);
  const double wt = 2.0 * kPi * c->f_drive_hz * p->T;
  p->est_num = 2.0 * cos(wt); /* prior: the nominal drive frequency, weight of one */
  p->est_den = 2.0;
  p->truth.drive_freq_hz = c->f_drive_hz;
  p->cw = cos(wt);
  p->sw = sin(wt);
  p->inv_sw = 1.0 / p->sw;
  p->thermal_countdown = 0; /* first update at the first sample */
  p->truth_countdown = c->truth_decim;
  p->fz_alpha = 1.0 - exp(-p->T / c->truth_force_tau_s);
  clock_update(p, 0.0);
  truth_temps(p, c->temp_k);
  truth_sense(p);
  p->truth.board_meas_c = NAN; /* no result before the sensor's first */
  if (out_mech) warn(p, PLANT_LAW_RESONANCE);
  for (int i = 0; i < 2; i++) warn_pickoff(p, i, p->pick[i].out_of_range);
  warn_amplitude_laws(p);
  p->err[0] = '\0';
  return 0;
}

/* 1 when the random vibration bands of a and b differ. */
static int bands_differ(const accel_profile_t *a, const accel_profile_t *b)
{
  if (a->n_bands != b->n_bands) return 1;
  for (int j = 0; j < a->n_bands; j++)
    if (a->band_axis[j] != b->band_axis[j] ||
        a->band_psd_g2_per_hz[j] != b->band_psd_g2_per_hz[j] ||
        a->band_f_lo_hz[j] != b->band_f_lo_hz[j] || a->band_f_hi_hz[j] != b->band_f_hi_hz[j])
      return 1;
  return 0;
}

int plant_set_profiles(plant_t *p, const plant_profiles_t *prof)
{
  if (p == NULL || prof == NULL) return -1;
  const char *key = NULL;
  if (profile_check(&prof->rate_dps, &key) != 0) {
    set_err(p, "rate profile: %s invalid", key);
    return -1;
  }
  if (profile_check(&prof->ambient_k, &key) != 0) {
    set_err(p, "ambient profile: %s invalid", key);
    return -1;
  }
  if (accel_profile_check(&prof->accel_g, &key) != 0 ||
      vib_check(&prof->accel_g, p->cfg.fs_hz, &key) != 0) {
    set_err(p, "acceleration profile: %s invalid", key);
    return -1;
  }
  /* the generators keep running unless the bands changed (vib.h: they start at rest) */
  if (bands_differ(&prof->accel_g, &p->prof.accel_g))
    (void)vib_init(&p->vib, &prof->accel_g, p->cfg.fs_hz, p->seed);
  p->prof = *prof;
  accel_flags(p);
  return 0;
}

double plant_input_now(const plant_t *p, plant_input_t which)
{
  const double t_s = (double)p->k * p->T;
  return profile_eval(which == PLANT_INPUT_RATE ? &p->prof.rate_dps : &p->prof.ambient_k, t_s,
                      NULL);
}

int plant_cold_soak(plant_t *p)
{
  const thermal_cfg_t cfg = p->thermal.cfg;
  return thermal_init_cold(&p->thermal, &cfg, plant_input_now(p, PLANT_INPUT_AMBIENT));
}

int plant_move_input(plant_t *p, plant_input_t which, double to, double edge_s)
{
  const int rate = which == PLANT_INPUT_RATE;
  const double lo = rate ? -1e4 : 150.0, hi = rate ? 1e4 : 450.0; /* plant.h rate_dps, temp_k */
  if (!(to >= lo && to <= hi) || !(edge_s > 0.0 && edge_s <= 1e5)) {
    set_err(p, "%s move to %g over %g s: the value within %g..%g, the edge within (0, 1e5] s",
            rate ? "rate" : "ambient", to, edge_s, lo, hi);
    return -1;
  }
  const double t_s = (double)p->k * p->T;
  const double from = plant_input_now(p, which);
  plant_profiles_t next = p->prof;
  profile_ramp(rate ? &next.rate_dps : &next.ambient_k, from, (to - from) / edge_s, t_s,
               t_s + edge_s);
  return plant_set_profiles(p, &next);
}

/* ------------------------------------------------------------------ step ------ */

/* Thermal update over [t0, t0 + dt): ambient at mid-interval (thermal.h). The new
 * node temperatures apply from this sample on (half an update period early, 0.5 ms
 * against time constants of minutes). */
static void thermal_update(plant_t *p, double t0)
{
  const double dt = p->thermal_every * p->T;
  double amb = profile_eval(&p->prof.ambient_k, t0 + 0.5 * dt, NULL);
  if (!(amb > 1.0 && amb < 2000.0)) {
    amb = p->truth.ambient_k; /* keep the last sane one */
    warn(p, PLANT_LAW_AMBIENT);
  }
  thermal_step(&p->thermal, amb);
  int out = 0;
  (void)mech_set_temp(
      &p->mech, mech_temp_clamp(&p->mech.cfg, thermal_temp(&p->thermal, THERMAL_STRUCT), &out));
  if (out) warn(p, PLANT_LAW_RESONANCE);
  if (p->act.elec) (void)mech_elec_rebase(&p->mech); /* the last update's mean stiffness */
  /* the gain follows at once; the phase re-discretises (microseconds) only when it moved
   * by pick_phase_step_rad. A law driven out of its range is held at its edge, counted. */
  for (int i = 0; i < 2; i++)
    warn_pickoff(
        p, i, pickoff_set_temp(&p->pick[i], thermal_temp(&p->thermal, pick_node(&p->cfg, i))));
  warn_amplitude_laws(p);
  if (p->drift_on)
    (void)mech_set_coupling_drift(&p->mech, p->drift_kq_per_s2 * drift_step(&p->drift[0]),
                                  p->drift_dq_per_s * drift_step(&p->drift[1]));
  clock_update(p, t0);
  truth_temps(p, amb);
}

/* Phasors at the drive frequency (plant.h, plant_truth_t): the frequency from the
 * force samples (a sampled sinusoid obeys F_k + F_k-2 = 2 cos(wT) F_k-1 exactly, so
 * the ratio of the two smoothed sums is exact for a steady tone), the force phasor
 * from its last two samples, the motion phasors from position and velocity. */
static void truth_phasors(plant_t *p)
{
  plant_truth_t *t = &p->truth;
  double c = p->est_den > 0.0 ? p->est_num / p->est_den : 2.0;
  if (!(c > -0.999999) || !(c < 0.999999)) c = cos(2.0 * kPi * p->cfg.f_drive_hz * p->T);
  const double s = sqrt(1.0 - c * c);
  p->cw = c;
  p->sw = s;
  p->inv_sw = 1.0 / s;
  const double w = atan2(s, c) / p->T;
  t->drive_freq_hz = w / (2.0 * kPi);
  /* motion: Z = v/w + j pos = amplitude e^{j theta} with pos = amplitude sin(theta) */
  const double yr = t->vy_mps / w, yi = t->y_m;
  const double amp = sqrt(yr * yr + yi * yi);
  t->drive_amp_m = amp;
  /* force phasor at mid-sample k, rotated by wT/2 to t_k+1 */
  const double ch = sqrt(0.5 * (1.0 + c)), sh = sqrt(0.5 * (1.0 - c));
  const double gr = p->fz_re * ch - p->fz_im * sh, gi = p->fz_re * sh + p->fz_im * ch;
  /* the samples carry sinc(wT/2) of the force; the hold multiplies by it once more */
  t->drive_force_mps2 = sqrt(gr * gr + gi * gi) * sh / (0.5 * w * p->T);
  if (t->drive_force_mps2 > 0.0 && amp > 0.0) {
    const double re = yr * gr + yi * gi, im = yi * gr - yr * gi; /* Zy conj(ZF) */
    t->drive_phase_rad = atan2(im, re);
  } else {
    t->drive_phase_rad = 0.0;
  }
  if (amp > 0.0) {
    const double xr = t->vx_mps / w, xi = t->x_m;
    t->sense_disp_m = (xr * yr + xi * yi) / amp; /* along sin(theta): with y */
    t->sense_vel_m = (xi * yr - xr * yi) / amp;  /* along cos(theta): with y' */
  } else {
    t->sense_disp_m = t->sense_vel_m = 0.0;
  }
  truth_sense(p);
}

/* Force phasor, every sample: the actuator gives per-sample means,
 * F_k = F0 sinc sin(theta(t_k + T/2)); with F_k-1 = F0 sinc sin(theta - wT) the phasor is
 * F0 sinc [ (F_k cos wT - F_k-1) / sin wT, F_k ]. The 14-bit DAC codes put ~1e-4 of
 * distortion on F, which the division by sin wT amplifies: the phasor is averaged over
 * truth_force_tau_s while being rotated along at w. */
static void truth_force(plant_t *p, double f)
{
  const double ir = (f * p->cw - p->f_prev[0]) * p->inv_sw, ii = f;
  const double rr = p->fz_re * p->cw - p->fz_im * p->sw;
  const double ri = p->fz_re * p->sw + p->fz_im * p->cw;
  p->fz_re = rr + p->fz_alpha * (ir - rr);
  p->fz_im = ri + p->fz_alpha * (ii - ri);
}

/* An electrode's voltage over the sample: its DAC channel's output in series with the held
 * level e (plant_set_electrodes), mean((v + e)^2) = mean(v^2) + e (2 mean(v) + e). */
static dac_chan_out_t in_series(const dac_chan_out_t *v, double e)
{
  const dac_chan_out_t c = {.held_v = v->held_v + e,
                            .mean_v = v->mean_v + e,
                            .mean_sq_v2 = v->mean_sq_v2 + e * (2.0 * v->mean_v + e),
                            .end_v = v->end_v + e,
                            .end_dvdt_v_per_s = v->end_dvdt_v_per_s};
  return c;
}

/* The electrodes' voltages over this sample from the DAC's outputs (p->dout) and the series
 * levels, for the actuator and the truth (plant_truth_t elec_mean_v, quadnull_v). */
static void elec_feed(plant_t *p)
{
  const plant_electrodes_t *e = &p->elec_series;
  const double series[PLANT_ELECTRODES] = {e->fb_u1_v, e->fb_u2_v, e->quadnull_v1_v,
                                           e->quadnull_v2_v, e->tune_v};
  dac_chan_out_t *const in[PLANT_ELECTRODES] = {&p->elec_in.fb[0], &p->elec_in.fb[1],
                                                &p->elec_in.quadnull[0],
                                                &p->elec_in.quadnull[1], &p->elec_in.tune};
  double mean[PLANT_ELECTRODES];
  for (int i = 0; i < PLANT_ELECTRODES; i++) {
    if (p->elec_has[i]) *in[i] = in_series(&p->dout.ch[kElecChannel[i]], series[i]);
    mean[i] = p->elec_has[i] ? in[i]->mean_v : 0.0;
  }
  plant_truth_t *t = &p->truth;
  t->elec_mean_v = (plant_electrodes_t){mean[0], mean[1], mean[2], mean[3], mean[4]};
  if (p->elec_has[2]) {
    const double d = p->elec_in.quadnull[0].mean_sq_v2 - p->elec_in.quadnull[1].mean_sq_v2;
    t->quadnull_v = d >= 0.0 ? sqrt(d) : -sqrt(-d);
  }
}

void plant_step(plant_t *p, const hal_dac_frame_t *dac, hal_adc_frame_t *adc_out)
{
  const double T = p->T;
  const double t0 = (double)p->k * T;
  plant_truth_t *t = &p->truth;
  if (p->thermal_countdown <= 0) {
    thermal_update(p, t0);
    p->thermal_countdown = p->thermal_every;
  }
  p->thermal_countdown--;
  /* the board sensor's conversions (board_sensor.h): due once or twice per 1 s result */
  if (board_sensor_due(&p->board_sensor, t0)) {
    board_sensor_step(&p->board_sensor, t0,
                      thermal_temp(&p->thermal, THERMAL_BOARD) - PLANT_K_AT_0_C);
    t->board_meas_c = board_sensor_reading_c(&p->board_sensor, t0);
  }

  /* The frame passed in is on the outputs during this interval (the host HAL applies
   * the board's latency), so it is latched now: dac_write validates it, then the
   * queued codes are moved to the held ones (dac.h's own one-sample queue would add a
   * second sample of latency). */
  if (dac != NULL) {
    if (dac_write(&p->dac, dac) == 0)
      memcpy(p->dac.latched, p->dac.pending, sizeof p->dac.latched);
    else t->dac_rejects++;
  }
  if (p->vref.active) {
    const double r = vref_step(&p->vref); /* one reference for both converters */
    dac_set_ref(&p->dac, r);
    adc_set_ref(&p->adc, r);
  }
  dac_out_t *const dout = &p->dout;
  dac_step(&p->dac, dout);
  actuator_out_t aout;
  if (p->act.elec) {
    elec_feed(p);
    actuator_step_elec(&p->act, dout, &p->elec_in, &aout);
    (void)mech_set_elec(&p->mech, aout.kyx_per_s2, aout.ke_per_s2); /* margin: mech flags */
  } else {
    actuator_step(&p->act, dout, &aout);
  }
  double fd = aout.f_drive_mps2, fsn = aout.f_sense_mps2;
  if (p->accel_any) {
    if (p->accel_dynamic) accel_profile_mean(&p->prof.accel_g, t0, t0 + T, t->accel_g);
    else memcpy(t->accel_g, p->prof.accel_g.const_g, sizeof t->accel_g);
    if (p->vib_on) vib_step(&p->vib, t->accel_g);
    accel_out_t gout;
    accel_step(&p->accel, t->accel_g, &gout);
    fd += gout.f_drive_mps2;
    fsn += gout.f_sense_mps2;
  }

  double slope_dps;
  const double rate_dps = profile_eval(&p->prof.rate_dps, t0 + 0.5 * T, &slope_dps);
  mech_step(&p->mech, fd, fsn, rate_dps * kDeg, slope_dps * kDeg);
  const mech_state_t s = mech_state(&p->mech);

  const double ta = adc_aperture_draw(&p->adc); /* common to both channels (adc.h) */
  const double vd = pickoff_step_at(&p->pick[0], s.y_m, s.vy_mps, dout, ta);
  const double vs = pickoff_step_at(&p->pick[1], s.x_m, s.vx_mps, dout, ta);
  adc_convert_frame(&p->adc, vd, vs, &t->adc);
  if (adc_out != NULL) *adc_out = t->adc;
  p->k++;

  /* truth: cheap fields every sample */
  t->sample = p->k;
  t->t_s = (double)p->k * T;
  t->rate_dps = rate_dps;
  t->y_m = s.y_m;
  t->vy_mps = s.vy_mps;
  t->x_m = s.x_m;
  t->vx_mps = s.vx_mps;
  t->f_drive_mps2 = fd;
  t->f_sense_mps2 = fsn;
  for (int i = 0; i < DAC_NCH; i++) t->dac_held_v[i] = dout->ch[i].held_v;
  t->adc_v[0] = vd;
  t->adc_v[1] = vs;
  for (int i = 0; i < 2; i++) t->adc_clip[i] = p->adc.clip_count[i];
  t->mech_refreshes = p->mech.refresh_count;

  /* drive-frequency estimate from the actuator's drive force (without accelerations) */
  const double f = aout.f_drive_mps2;
  const double a = p->est_alpha;
  p->est_num += a * ((f + p->f_prev[1]) * p->f_prev[0] - p->est_num);
  p->est_den += a * (2.0 * p->f_prev[0] * p->f_prev[0] - p->est_den);
  truth_force(p, f);
  if (--p->truth_countdown <= 0) {
    truth_phasors(p);
    p->truth_countdown = p->cfg.truth_decim;
  }
  p->f_prev[1] = p->f_prev[0];
  p->f_prev[0] = f;
}

int plant_set_electrodes(plant_t *p, const plant_electrodes_t *v)
{
  if (p == NULL || v == NULL) return -1;
  const struct {
    const char *key;
    double v;
  } e[5] = {{"fb_u1_v", v->fb_u1_v},
            {"fb_u2_v", v->fb_u2_v},
            {"quadnull_v1_v", v->quadnull_v1_v},
            {"quadnull_v2_v", v->quadnull_v2_v},
            {"tune_v", v->tune_v}};
  for (int i = 0; i < 5; i++)
    if (!(isfinite(e[i].v) && fabs(e[i].v) <= PLANT_ELECTRODE_MAX_V)) {
      set_err(p, "electrodes: %s must be finite and within +-%g V", e[i].key,
              PLANT_ELECTRODE_MAX_V);
      return -1;
    }
  p->truth.elec_v = *v;
  p->elec_series = *v;
  return 0;
}

void plant_step_hal(void *plant, const hal_dac_frame_t *dac, hal_adc_frame_t *adc)
{
  plant_step((plant_t *)plant, dac, adc);
}

hal_board_temp_event_t plant_board_temp_hal(void *plant, double t_s, int16_t *code,
                                            uint64_t *conversion)
{
  return board_sensor_read(&((const plant_t *)plant)->board_sensor, t_s, code, conversion);
}

const plant_truth_t *plant_truth(const plant_t *p) { return &p->truth; }
