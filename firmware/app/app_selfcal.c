#include "app/app_selfcal.h"

#include <stddef.h>

#include "dsp/fastmath.h"
#include "board.h"

/* Search range of the drive resonance: the part family's 1.3-2.0 kHz with margin. */
#define SC_F_LO_HZ 1250.0
#define SC_F_HI_HZ 2050.0
/* Chirp rate: 2.7 s per direction over the range; the resulting envelope-peak lag
 * (~15 Hz at Q = 600) cancels between the up and down chirps. */
#define SC_CHIRP_HZ_PER_S 300.0
/* Quiet time before a chirp: 7 time constants at Q = 600, 1.3 kHz. */
#define SC_QUIET_S 1.0
/* First chirp force: 8 Ks*V^2 stays inside the ADC budget at Q = 600 with the default
 * actuator and pickoff gains; weaker responses raise it. */
#define SC_F_CMD_START_V2 8.0
/* The sense mode's search range (selfcal.h, S1): the family's drive range and the
 * thesis's sense mode 510 Hz above its drive (2 kHz), with margin; a part's mode is
 * matched or split by tens to hundreds of Hz from its drive. */
#define SC_S_F_LO_HZ 1250.0
#define SC_S_F_HI_HZ 2550.0
/* First chirp force on the feedback pair: the sense pickoff is far more sensitive than
 * the drive's (6.2e7 against 3.5e4 V/m on the thesis's part) and its Q spans 3..10^4, so
 * the chain starts low and raises it (a response at the sense pickoff 2000 times the
 * drive's per V^2 at Q 10^4 would clip at once at the drive's 8 V^2). */
#define SC_S_F_CMD_START_V2 0.05
/* The drive's ring-down before S1: five of its time constants from the stored model
 * (drive.cal_*), at least SC_QUIET_S, at most this. */
#define SC_S_QUIET_MAX_S 3.0

int app_selfcal_start(app_t *a)
{
  if (selfcal_running(&a->selfcal) || a->req_head - a->req_tail >= APP_REQ_QUEUE) return -1;
  const param_values_t *v = params_current(&a->params);
  selfcal_cfg_t c;
  c.fs_hz = (double)v->sys_fs_hz;
  c.f_lo_hz = SC_F_LO_HZ;
  c.f_hi_hz = SC_F_HI_HZ;
  c.chirp_hz_per_s = SC_CHIRP_HZ_PER_S;
  c.quiet_s = SC_QUIET_S;
  c.amp_max_v = 0.5 * (double)HAL_ADC_FULL_SCALE_V;
  c.amp_meas_v = 0.25 * (double)HAL_ADC_FULL_SCALE_V;
  c.f_cmd_start_v2 = SC_F_CMD_START_V2;
  c.f_cmd_max_v2 = (double)a->gyro.design->drive.f_cmd_max_v2;
  c.amp_set_v = (double)v->drive_amp_set_v;
  c.phase_set_rad = (double)v->drive_phase_set_deg * FM_PI / 180.0;
  c.track = v->drive_track;
  /* One sample of DAC latency plus half a sample of zero-order hold. */
  c.delay_s = 1.5 / c.fs_hz;
  c.sense = v->sense_cal;
  c.s_f_lo_hz = SC_S_F_LO_HZ;
  c.s_f_hi_hz = SC_S_F_HI_HZ;
  c.s_f_cmd_start_v2 = SC_S_F_CMD_START_V2;
  c.s_f_cmd_max_v2 = (double)a->gyro.design->fr.f_max_v2;
  const double tau_d = (double)v->drive_cal_q / (FM_PI * (double)v->drive_cal_f0_hz);
  const double quiet = 5.0 * tau_d < SC_QUIET_S ? SC_QUIET_S : 5.0 * tau_d;
  c.s_quiet_s = quiet > SC_S_QUIET_MAX_S ? SC_S_QUIET_MAX_S : quiet;
  c.tune_probe_v = (double)v->sense_cal_tune_probe_v;
  c.demod_phase_rad = (double)v->rate_demod_phase_deg * FM_PI / 180.0;
  /* S4 with the sense identification only: without it the drive's sweep keeps the stored
   * tuning, whose temperature hold scales from its own reference (sense_tune.h) */
  c.tune_mode = v->sense_cal != 0u ? v->sense_tune : 0u;
  c.tune_split_hz = (double)v->sense_tune_split_hz;
  c.tune_v_max_v = (double)v->sense_tune_v_max_v;
  c.amp_clip_v = 0.95 * (double)HAL_ADC_FULL_SCALE_V;
  if (selfcal_start(&a->selfcal, &c) != 0) return -1;
  (void)app_request(a, APP_REQ_SWEEP); /* room checked above */
  a->selfcal_t0_ticks = app_ticks(a);
  a->selfcal_ticks = 0u;
  a->sweep_owns_drive = true;
  return 0;
}

static param_status_t stage_f(app_t *a, param_idx_t i, double v)
{
  param_value_t pv;
  pv.f = (float)v;
  return params_stage(&a->params, i, pv);
}

/* Mode tuning's calibration (S4, sense_tune.h): the untuned resonance (the one that
 * gives back S4's voltage, selfcal_match_s0_hz) and the drive's it was measured against; a tuning asked for and not achieved clears it, since the
 * force-rebalance model staged with it was measured untuned (the rate then stays not
 * valid, TUNE, and status gives S4's reason). */
static param_status_t stage_match(app_t *a)
{
  const selfcal_sense_t *m = &a->selfcal.sense;
  const int ok = m->match == SELFCAL_TUNE_OK && m->state == SELFCAL_SENSE_OK;
  param_status_t st = stage_f(a, PARAM_sense_cal_s0_hz, ok ? selfcal_match_s0_hz(m) : 0.0);
  if (st == PARAM_OK)
    st = stage_f(a, PARAM_sense_cal_tune_ref_hz, ok ? (double)a->selfcal.f0_hz_f : 0.0);
  return st;
}

/* The sense mode's model (selfcal.h): all four values or none (the reason stays in
 * status), the tuning slope on its own. */
static param_status_t stage_sense(app_t *a)
{
  const selfcal_sense_t *m = &a->selfcal.sense;
  param_status_t st = PARAM_OK;
  if (m->state == SELFCAL_SENSE_OK) {
    st = stage_f(a, PARAM_sense_f0_hz, m->f0_hz);
    if (st == PARAM_OK) st = stage_f(a, PARAM_sense_q, m->q);
    if (st == PARAM_OK) st = stage_f(a, PARAM_sense_fb_gain_v_per_v2, m->fb_gain_v_per_v2);
    if (st == PARAM_OK)
      st = stage_f(a, PARAM_sense_fb_phase_deg, m->fb_phase_rad * 180.0 / FM_PI);
  }
  if (st == PARAM_OK && m->tune == SELFCAL_TUNE_OK)
    st = stage_f(a, PARAM_sense_cal_tune_ke_per_s2_per_v2,
                 m->match == SELFCAL_TUNE_OK ? m->match_ke : m->tune_ke_per_s2_per_v2);
  if (st == PARAM_OK && a->selfcal.cfg.tune_mode != 0u) st = stage_match(a);
  return st;
}

/* READY: stage and commit the identified model, then hand the drive to the loops. */
static void hand_over(app_t *a)
{
  selfcal_t *s = &a->selfcal;
  param_status_t st = stage_sense(a);
  if (st == PARAM_OK) st = stage_f(a, PARAM_drive_freq_hz, (double)s->f0_hz_f);
  if (st == PARAM_OK) st = stage_f(a, PARAM_drive_cal_f0_hz, (double)s->f0_hz_f);
  if (st == PARAM_OK) st = stage_f(a, PARAM_drive_cal_q, s->fit.q);
  if (st == PARAM_OK) st = stage_f(a, PARAM_drive_cal_gain_v_per_v2, s->fit.gain_v_per_v2);
  if (st == PARAM_OK) st = stage_f(a, PARAM_drive_p_init_deg, s->hold_p_rad * 180.0 / FM_PI);
  if (st == PARAM_OK) {
    /* A Q beyond the fixed drive's reach: the tracking drive (selfcal.h); a tracking
     * drive selected before the sweep stays selected at any Q. */
    param_value_t tr;
    tr.u = s->track != 0u || s->cfg.track != 0u ? 1u : 0u;
    st = params_stage(&a->params, PARAM_drive_track, tr);
  }
  if (st != PARAM_OK) {
    params_discard(&a->params);
    selfcal_finish(s, 0, param_status_str(st));
    return;
  }
  params_err_t err;
  a->handing_over = true;
  st = params_commit(&a->params, &err);
  a->handing_over = false;
  if (st == PARAM_ERR_PENDING) return; /* the ISR has not taken the last change: retry */
  if (st != PARAM_OK) {
    selfcal_finish(s, 0, err.why != NULL ? err.why : param_status_str(st));
    return;
  }
  selfcal_finish(s, 1, NULL);
  a->selfcal_ticks = app_ticks(a) - a->selfcal_t0_ticks;
  /* The design is published before the request (app_request's fence), and the ISR
   * applies a new block at the start of a tick before it takes a request. */
  a->sweep_owns_drive = false;
  (void)app_request(a, APP_REQ_SWEEP_HANDOVER); /* the queue is empty (app_selfcal_poll) */
}

void app_selfcal_poll(app_t *a)
{
  selfcal_t *s = &a->selfcal;
  selfcal_watch(s, app_ticks(a));
  /* The drive is judged once the ISR has taken every request, the sweep's own included;
   * then the queue is empty and the sequencer's request always fits. */
  if (app_requests_pending(a)) return;
  if (selfcal_running(s)) {
    const int sweeping = a->gyro.sup.mode == GYRO_MODE_SWEEP;
    if (selfcal_background(s, sweeping) == SELFCAL_READY) hand_over(a);
  }
  if (!selfcal_running(s) && a->sweep_owns_drive) {
    /* A failed sweep leaves the electrodes off (safe mode); status says why and how long
     * it ran (selfcal_s). */
    a->selfcal_ticks = app_ticks(a) - a->selfcal_t0_ticks;
    a->sweep_owns_drive = false;
    (void)app_request(a, APP_REQ_DRIVE_OFF);
  }
}
