#include "app/app_cmds.h"

#include <math.h>
#include <string.h>

#include "app/app_selfcal.h"
#include "dsp/fastmath.h"
#include "dsp/math_const.h"
#include "hal/hal_sample_timer.h"

static const char *mode_name(uint32_t m)
{
  switch ((gyro_mode_t)m) {
  case GYRO_MODE_OFF: return "OFF";
  case GYRO_MODE_SWEEP: return "SWEEP";
  case GYRO_MODE_ACQUIRE: return "ACQUIRE";
  case GYRO_MODE_LOCKED: return "LOCKED";
  case GYRO_MODE_FAULT: return "FAULT";
  }
  return "?";
}

static const struct {
  uint32_t bit;
  const char *name;
} k_fault_names[] = {
    {GYRO_FAULT_ADC_CLIP, "ADC_CLIP"},       {GYRO_FAULT_NAN, "NAN"},
    {GYRO_FAULT_LOST_LOCK, "LOST_LOCK"},     {GYRO_FAULT_DRIVE_SAT, "DRIVE_SAT"},
    {GYRO_FAULT_OVER_AMP, "OVER_AMP"},       {GYRO_FAULT_PHASE_LOST, "PHASE_LOST"},
    {GYRO_FAULT_ACQ_TIMEOUT, "ACQ_TIMEOUT"}, {GYRO_FAULT_LOST_SAMPLE, "LOST_SAMPLE"},
    {GYRO_FAULT_FREQ_WINDOW, "FREQ_WINDOW"}};
#define FAULT_NAMES (sizeof k_fault_names / sizeof k_fault_names[0])
_Static_assert(FAULT_NAMES == GYRO_FAULT_KINDS, "a name for every fault kind");

/* Name of fault kind i (bit i of gyro_fault_t): the table is in bit order. */
static const char *fault_kind_name(uint32_t i)
{
  return i < FAULT_NAMES && k_fault_names[i].bit == (1u << i) ? k_fault_names[i].name : "?";
}

/* The names of the bits set in `bits` (of n kinds), comma separated; "none" for none. */
static void put_bit_names(cli_t *cli, uint32_t bits, uint32_t n, const char *(*name)(uint32_t))
{
  if (bits == 0u) {
    cli_put(cli, "none");
    return;
  }
  int first = 1;
  for (uint32_t i = 0; i < n; i++) {
    if ((bits & (1u << i)) != 0u) {
      if (!first) cli_put(cli, ",");
      cli_put(cli, name(i));
      first = 0;
    }
  }
}

static void put_faults(cli_t *cli, uint32_t f)
{
  put_bit_names(cli, f, GYRO_FAULT_KINDS, fault_kind_name);
}

/* Output integrity (rate_valid.h, supervisor.h): the verdict with its reasons, then one
 * line per monitor that has ever fired, `NAME count N last_s T` (T: seconds since
 * power-on of its latest onset). */
static void put_reasons(cli_t *cli, uint32_t r)
{
  put_bit_names(cli, r, RATE_INVALID_KINDS, rate_valid_reason_name);
}

static void put_monitor(cli_t *cli, const char *kind, const char *name, uint32_t count, float t_s)
{
  cli_putf(cli, "%s%s count %u last_s %f", kind, name, count, t_s);
  cli_emit_data(cli);
}

static void put_integrity(cli_t *cli, app_t *a)
{
  const gyro_t *g = &a->gyro;
  const float block_s = (float)GYRO_BLOCK / (float)params_current(&a->params)->sys_fs_hz;
  cli_data_u32(cli, "rate_valid", g->out.rate_valid);
  cli_put(cli, "rate_invalid ");
  put_reasons(cli, g->out.rate_invalid);
  cli_emit_data(cli);
  cli_data_f32(cli, "rate_out_v", g->out.rate_out_v);
  for (uint32_t i = 0; i < RATE_INVALID_KINDS; i++) {
    if (g->valid_history.count[i] != 0u) {
      put_monitor(cli, "invalid_", rate_valid_reason_name(i), g->valid_history.count[i],
                  (float)g->valid_history.last_block[i] * block_s);
    }
  }
  for (uint32_t i = 0; i < GYRO_FAULT_KINDS; i++) {
    if (g->sup.kind_count[i] != 0u) {
      put_monitor(cli, "fault_", fault_kind_name(i), g->sup.kind_count[i],
                  (float)g->sup.kind_last_step[i] * block_s);
    }
  }
}

static const char *sense_id_name(selfcal_sense_state_t st)
{
  static const char *const names[] = {"off", "running", "f0", "identified", "failed"};
  const unsigned i = (unsigned)st;
  return i < sizeof names / sizeof names[0] ? names[i] : "?";
}

/* S4, mode tuning (sense.tune 1 or 2 with sense.cal 1): where the tuned resonance went
 * against its target, at which voltage and after how many ring-downs, or why not. */
static void put_selfcal_match(cli_t *cli, const selfcal_sense_t *m)
{
  if (m->match == SELFCAL_TUNE_OFF) return;
  cli_putf(cli, "selfcal_match %s", m->match == SELFCAL_TUNE_OK ? "tuned" : "failed");
  cli_emit_data(cli);
  if (m->match_why != NULL) {
    cli_putf(cli, "selfcal_match_why %s", m->match_why);
    cli_emit_data(cli);
  }
  cli_data_f32(cli, "selfcal_match_target_hz", (float)m->match_target_hz);
  cli_data_f32(cli, "selfcal_match_fd_hz", (float)m->match_fd_hz);
  cli_data_f32(cli, "selfcal_match_v", (float)m->match_v);
  cli_data_u32(cli, "selfcal_match_passes", m->match_passes);
}

/* The sense mode's identification (sense.cal 1, selfcal.h): its state and time beside
 * the drive's (selfcal_s is the whole sweep's, selfcal_drive_s the rest of it), what it
 * found, and why not. While its chain runs (selfcal_phase sense) the chain's lines above
 * are the sense mode's. */
static void put_selfcal_sense(cli_t *cli, app_t *a, uint32_t t)
{
  const selfcal_t *s = &a->selfcal;
  const selfcal_sense_t *m = &s->sense;
  if (m->state == SELFCAL_SENSE_OFF) return;
  const float fs = (float)params_current(&a->params)->sys_fs_hz;
  cli_putf(cli, "selfcal_phase %s", s->sense_phase != 0u ? "sense" : "drive");
  cli_emit_data(cli);
  cli_putf(cli, "selfcal_sense %s", sense_id_name(m->state));
  cli_emit_data(cli);
  if (m->why != NULL) {
    cli_putf(cli, "selfcal_sense_why %s", m->why);
    cli_emit_data(cli);
  }
  cli_data_f32(cli, "selfcal_sense_s", (float)m->ticks / fs);
  cli_data_f32(cli, "selfcal_drive_s", (float)(t - (t > m->ticks ? m->ticks : t)) / fs);
  if (m->state == SELFCAL_SENSE_F0 || m->state == SELFCAL_SENSE_OK) {
    cli_data_f32(cli, "selfcal_sense_f0_hz", (float)m->f0_hz);
    cli_data_f32(cli, "selfcal_sense_q", (float)m->q);
  }
  if (m->state == SELFCAL_SENSE_OK && m->fb_gain_v_per_v2 != 0.0) {
    cli_data_f32(cli, "selfcal_sense_fb_gain_v_per_v2", (float)m->fb_gain_v_per_v2);
    cli_data_f32(cli, "selfcal_sense_fb_phase_deg", (float)(m->fb_phase_rad * FM_DEG_PER_RAD));
  }
  if (m->tune == SELFCAL_TUNE_OK) {
    cli_data_f32(cli, "selfcal_tune_ke_per_s2_per_v2", (float)m->tune_ke_per_s2_per_v2);
  } else if (m->tune == SELFCAL_TUNE_FAILED && m->tune_why != NULL) {
    cli_putf(cli, "selfcal_tune_why %s", m->tune_why);
    cli_emit_data(cli);
  }
  put_selfcal_match(cli, m);
}

/* Self-calibration progress and result (the figures of the latest sweep). */
static void put_selfcal(cli_t *cli, app_t *a)
{
  const selfcal_t *s = &a->selfcal;
  cli_putf(cli, "selfcal %s", selfcal_state_name(s->state));
  cli_emit_data(cli);
  if (s->state == SELFCAL_IDLE) return;
  if (s->state == SELFCAL_FAILED && s->why != NULL) {
    cli_putf(cli, "selfcal_why %s", s->why);
    cli_emit_data(cli);
  }
  const uint32_t t = selfcal_running(s) ? app_ticks(a) - a->selfcal_t0_ticks : a->selfcal_ticks;
  cli_data_f32(cli, "selfcal_s", (float)t / (float)params_current(&a->params)->sys_fs_hz);
  if (s->f_coarse_hz > 0.0) cli_data_f32(cli, "selfcal_coarse_hz", (float)s->f_coarse_hz);
  if (s->rd_q > 0.0) {
    cli_data_f32(cli, "selfcal_ringdown_hz", (float)s->rd_f_hz);
    cli_data_f32(cli, "selfcal_ringdown_q", (float)s->rd_q);
  }
  if (s->fit.q > 0.0) {
    cli_data_f32(cli, "selfcal_f0_hz", (float)s->fit.f0_hz);
    cli_data_f32(cli, "selfcal_q", (float)s->fit.q);
    /* A high-Q sweep has no frequency-response fit, and one beyond the fixed drive's
     * reach measures no |H(f0)| and plans no hold: those lines are left out. */
    if (s->fit.gain_v_per_v2 > 0.0) {
      cli_data_f32(cli, "selfcal_gain_v_per_v2", (float)s->fit.gain_v_per_v2);
      cli_data_f32(cli, "selfcal_p_init_deg", (float)(s->hold_p_rad * FM_DEG_PER_RAD));
    }
    if (s->n_pts > 1u) cli_data_f32(cli, "selfcal_fit_rms_rel", (float)s->fit.rms_rel);
  }
  put_selfcal_sense(cli, a, t);
}

/* Stored values the boot set back to their defaults, each with the reason. */
static void put_store_dropped(cli_t *cli, app_t *a)
{
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    if (!app_store_dropped(a, (param_idx_t)i)) continue;
    cli_putf(cli, "store_dropped %s: cannot be designed with the other stored values (%s)",
             param_info((param_idx_t)i)->name, a->store_dropped_why);
    cli_emit_data(cli);
  }
}

/* The fault history: the latest fault, cleared or not, and when (seconds since start,
 * from the supervisor's step count; it steps once per block). */
static void put_last_fault(cli_t *cli, app_t *a)
{
  const supervisor_t *sv = &a->gyro.sup;
  cli_put(cli, "last_fault ");
  put_faults(cli, sv->last_fault);
  cli_emit_data(cli);
  if (sv->last_fault == GYRO_FAULT_NONE) return;
  const float step_s = (float)GYRO_BLOCK / (float)params_current(&a->params)->sys_fs_hz;
  cli_data_f32(cli, "last_fault_s", (float)sv->last_fault_step * step_s);
}

/* What the store holds now (the "store" line is what the boot found): the newest valid
 * image after any save since, read back without applying it. Background only. */
static void put_store_now(cli_t *cli, app_t *a)
{
  if (a->store_status == PARAM_STORE_ERR_CONFIG) {
    return; /* no usable store: the "store" line says so */
  }
  param_values_t scratch = *params_current(&a->params);
  param_store_report_t rep;
  const param_store_status_t st = param_store_load(&a->store, &scratch, &rep);
  if (st == PARAM_STORE_OK && rep.slot >= 0) {
    cli_putf(cli, "store_now slot %s seq %u", rep.slot == 0 ? "A" : "B", rep.seq);
  } else {
    cli_putf(cli, "store_now %s", param_store_status_str(st));
  }
  cli_emit_data(cli);
}

/* What the loop designer achieved for the values in use (drive_loop.h): each drive
 * loop's bandwidth and phase margin. Nonzero manual gains (drive.amp_kp ...) replace
 * the designed ones in the loops; these lines still report the design. */
static void put_design(cli_t *cli, app_t *a)
{
  const gyro_design_t *d = params_current_derived(&a->params);
  if (d == NULL) return;
  cli_data_f32(cli, "design_amp_bw_hz", (float)d->amp_design.bw_hz);
  cli_data_f32(cli, "design_amp_pm_deg", (float)d->amp_design.phase_margin_deg);
  cli_data_f32(cli, "design_phase_bw_hz", (float)d->phase_design.bw_hz);
  cli_data_f32(cli, "design_phase_pm_deg", (float)d->phase_design.phase_margin_deg);
  cli_data_f32(cli, "design_track_bw_hz", (float)d->track_design.bw_hz);
  cli_data_f32(cli, "design_track_acq_bw_hz", (float)d->track_design.acq_bw_hz);
  cli_data_f32(cli, "design_track_pm_deg", (float)d->track_design.phase_margin_deg);
}

/* ---- status: one table of rows, in the order of the reply ---- */

static void put_mode(cli_t *cli, app_t *a)
{
  cli_putf(cli, "mode %s", mode_name((uint32_t)a->gyro.sup.mode));
  cli_emit_data(cli);
}

static void put_fault(cli_t *cli, app_t *a)
{
  cli_put(cli, "fault ");
  put_faults(cli, a->gyro.sup.fault);
  cli_emit_data(cli);
}

static void put_rate(cli_t *cli, app_t *a)
{
  cli_data_f32(cli, "rate_dps", a->gyro.out.rate_dps);
  /* The temperature compensation taken off, and the fast thermometer's weight in it
   * (rate_channel_comp_refresh: 0 at rest, 1 in a transient the slow one lags). */
  cli_data_f32(cli, "comp_bias_dps", a->gyro.rate.comp_bias_dps);
  cli_data_f32(cli, "comp_fast_w", a->gyro.rate.comp_fast_w);
}

static void put_drive(cli_t *cli, app_t *a)
{
  const gyro_out_t *o = &a->gyro.out;
  cli_data_f32(cli, "quad_dps", o->quad_dps);
  cli_data_f32(cli, "drive_amp_v", o->drive_amp_v);
  cli_data_f32(cli, "drive_phase_deg", o->drive_phase_deg);
  cli_data_f32(cli, "p_deg", o->p_deg);
  cli_data_f32(cli, "p_f_deg", o->p_f_deg);
  cli_data_f32(cli, "f_cmd_v2", o->f_cmd_v2);
  /* The drive frequency (tracking: the tracked resonance), and its offset from the
   * calibrated one to the NCO's resolution (a float at 1.5 kHz resolves 1.2e-4 Hz only). */
  const gyro_design_t *d = a->gyro.design;
  cli_data_u32(cli, "drive_track", d->track);
  cli_data_f32(cli, "f_drive_hz", o->f_drive_hz);
  cli_data_f32(cli, "f_offset_hz", (float)a->gyro.track.off_steps * d->hz_per_step);
}

/* The calibration record (gyro_design.h): `calibrated yes|no|stale`; with a record,
 * the drive frequency it was made at, the part and the date. */
static void put_calibration(cli_t *cli, app_t *a)
{
  cli_putf(cli, "calibrated %s", gyro_cal_state_name(a->gyro.design->cal_state));
  cli_emit_data(cli);
  const param_values_t *v = params_current(&a->params);
  if (a->gyro.design->cal_state == GYRO_CAL_NONE) return;
  cli_data_f32(cli, "cal_ref_freq_hz", v->cal_ref_freq_hz);
  cli_data_u32(cli, "cal_part_id", v->cal_part_id);
  cli_data_u32(cli, "cal_date", v->cal_date);
}

/* Quadrature nulling (quad.null 1, quad_null.h): the loop's mode, its identified gain c
 * ((deg/s)/V^2, sign included; 0 before its probe), whether it has settled and is at its
 * limit, and the electrodes' voltages. */
static void put_quad_null(cli_t *cli, app_t *a)
{
  static const char *const names[] = {"off", "probe_base", "probe_step", "run", "failed"};
  const quad_null_t *q = &a->gyro.quad;
  const uint32_t m = (uint32_t)q->mode;
  cli_putf(cli, "quad_null %s", m < sizeof names / sizeof names[0] ? names[m] : "?");
  cli_emit_data(cli);
  cli_data_u32(cli, "quad_null_on", a->gyro.design->quad_on);
  cli_data_f32(cli, "quad_gain_dps_per_v2", q->gain_dps_per_v2);
  cli_data_u32(cli, "quad_settled", q->settled);
  cli_data_u32(cli, "quad_at_limit", q->at_limit);
  cli_data_f32(cli, "quad_v1_v", q->v1_v);
  cli_data_f32(cli, "quad_v2_v", q->v2_v);
}

/* Mode tuning (sense.tune, sense_tune.h): off, applied (ok), waiting for the lock, or
 * why the target is out of reach; the target, the untuned resonance the temperature hold
 * puts at the drive's frequency now, and the voltage. */
static void put_sense_tune(cli_t *cli, app_t *a)
{
  const sense_tune_out_t *o = &a->tune;
  const int waiting = o->state == SENSE_TUNE_OK && !a->tune_locked;
  cli_putf(cli, "sense_tune %s", waiting ? "waiting" : sense_tune_state_name(o->state));
  cli_emit_data(cli);
  if (o->state == SENSE_TUNE_IS_OFF || o->state == SENSE_TUNE_UNCALIBRATED) return;
  cli_data_f32(cli, "tune_target_hz", (float)o->target_hz);
  cli_data_f32(cli, "tune_s0_hz", (float)o->s0_hz);
  cli_data_f32(cli, "tune_v", (float)o->v_v);
  /* the lost-match monitor (force rebalance): the detuning it measures from the loop's
   * model, its tolerance, and tune_match 0 (no estimate yet), 1 (matched) or 2 (lost) */
  const sense_tune_disc_cfg_t *c = &a->gyro.design->tune_disc;
  if (c->on == 0u) return;
  const sense_tune_disc_t *m = &a->tune_disc;
  cli_data_f32(cli, "tune_detune_hz", (float)m->det_hz);
  cli_data_f32(cli, "tune_detune_tol_hz", (float)c->tol_hz);
  cli_data_u32(cli, "tune_match", !sense_tune_disc_settled(m) ? 0u : m->lost != 0u ? 2u : 1u);
}

/* The board thermometer (board.fuse, board_therm.h): its state (absent: the HAL says the
 * board has no sensor), the sensor's latest reading and its counts; fused, the model's
 * variable and bias, the hand-over's weight and the correction of the bias. */
static void put_board_temp(cli_t *cli, app_t *a)
{
  const board_therm_t *b = &a->board;
  cli_putf(cli, "board_temp %s",
           b->absent != 0u && b->readings == 0u ? "absent" : board_therm_state_name(b->state));
  cli_emit_data(cli);
  if (b->readings > 0u) cli_data_f32(cli, "board_c", b->x_c);
  cli_data_u32(cli, "board_readings", b->readings);
  cli_data_u32(cli, "board_faults", b->faults);
  if (a->gyro.design->board.on == 0u || b->have == 0u) return;
  cli_data_f32(cli, "board_y_c", b->y_c);
  cli_data_f32(cli, "board_model_dps", b->model_dps);
  cli_data_f32(cli, "board_w", b->w);
  cli_data_f32(cli, "board_corr_dps", b->corr_dps);
}

/* Force rebalance (sense.mode 1, sense_fr.h): whether it runs, balanced and at its
 * limit, the force command in the rate channel's frame (V^2: Coriolis, quadrature) and
 * the feedback pair's amplitude, its scale factor and the design's third root. */
static void put_sense_fr(cli_t *cli, app_t *a)
{
  const sense_fr_t *fr = &a->gyro.fr;
  const gyro_design_t *d = a->gyro.design;
  cli_putf(cli, "sense_fr %s",
           d->sense_mode == 0u ? "off"
           : fr->run == 0u     ? "open"
           : fr->settled       ? "balanced"
                               : "settling");
  cli_emit_data(cli);
  cli_data_u32(cli, "sense_mode", d->sense_mode);
  cli_data_u32(cli, "fr_settled", fr->settled);
  cli_data_u32(cli, "fr_at_limit", fr->at_limit);
  cli_data_f32(cli, "fr_force_i_v2", fr->f_re);
  cli_data_f32(cli, "fr_force_q_v2", fr->f_im);
  cli_data_f32(cli, "fr_force_v2", fm_sqrtf(fr->f_re * fr->f_re + fr->f_im * fr->f_im));
  cli_data_f32(cli, "fr_scale_dps_per_v2", d->fr_scale_dps_per_v2);
  cli_data_f32(cli, "fr_pole_c_re", d->fr.c_re);
}

static void put_store(cli_t *cli, app_t *a)
{
  cli_putf(cli, "store %s", param_store_status_str(a->store_status));
  cli_emit_data(cli);
}

static void put_selftest(cli_t *cli, app_t *a)
{
  cli_putf(cli, "selftest %s", selftest_state_name(a->gyro.selftest.state));
  cli_emit_data(cli);
  cli_data_f32(cli, "selftest_dps", a->gyro.selftest.result_dps);
  /* The continuous test's response on the rate axis, as it is judged (selftest.h): what
   * a calibration takes as selftest.cont_expect_dps. */
  if (a->gyro.design->selftest.cont_on != 0u) {
    const float *w = a->gyro.selftest.w_avg;
    const float scale = fm_absf(a->gyro.design->rate.scale_dps);
    cli_data_f32(cli, "selftest_cont_dps", fm_sqrtf(w[0] * w[0] + w[1] * w[1]) * scale);
    cli_data_f32(cli, "selftest_cont_expect_dps", a->gyro.design->selftest.cont_expect * scale);
  }
}

static void put_board(cli_t *cli, app_t *a)
{
  if (a->status_board != NULL) a->status_board(cli, NULL);
}

/* The health counters and the other one-number figures of status. */
static uint32_t fault_count(const app_t *a) { return a->gyro.sup.fault_count; }
static uint32_t ticks(const app_t *a) { return app_ticks(a); }
static uint32_t isr_cycles_last(const app_t *a)
{
  (void)a;
  uint32_t last;
  hal_sample_isr_cycles(&last, NULL);
  return last;
}
static uint32_t isr_cycles_max(const app_t *a)
{
  (void)a;
  uint32_t max;
  hal_sample_isr_cycles(NULL, &max);
  return max;
}
static uint32_t rx_overflows(const app_t *a) { return a->cli.rx_overflows; }
static uint32_t samples_lost(const app_t *a)
{
  (void)a;
  const volatile uint32_t *n = hal_sample_lost_counter();
  return (n != NULL) ? *n : 0u;
}
static uint32_t reply_lines_cut(const app_t *a) { return a->cli.truncated; }

/* A row is a counter ("- NAME N" from count) or a group of lines (lines); a new health
 * counter is one row here. Counters: fault_count (faults since power-on), ticks (sample
 * ISR runs), isr_cycles_last/max (hal_sample_isr_cycles), rx_overflows (command-line
 * input lost to a full receive ring), samples_lost (sample ticks the HAL lost: each also
 * raises LOST_SAMPLE), reply_lines_cut (reply lines cut at CLI_OUT_MAX: a bug if not 0). */
typedef struct {
  const char *name;
  uint32_t (*count)(const app_t *a);
  void (*lines)(cli_t *cli, app_t *a); /* the background's instance: put_store_now reads flash */
} status_row_t;

static const status_row_t k_status_rows[] = {
    {"mode", NULL, put_mode},
    {"fault", NULL, put_fault},
    {"fault_count", fault_count, NULL},
    {"last_fault", NULL, put_last_fault},
    {"rate_dps", NULL, put_rate},
    {"rate_valid", NULL, put_integrity},
    {"calibrated", NULL, put_calibration},
    {"drive", NULL, put_drive},
    {"quad_null", NULL, put_quad_null},
    {"sense_fr", NULL, put_sense_fr},
    {"sense_tune", NULL, put_sense_tune},
    {"board_temp", NULL, put_board_temp},
    {"design", NULL, put_design},
    {"ticks", ticks, NULL},
    {"isr_cycles_last", isr_cycles_last, NULL},
    {"isr_cycles_max", isr_cycles_max, NULL},
    {"rx_overflows", rx_overflows, NULL},
    {"samples_lost", samples_lost, NULL},
    {"reply_lines_cut", reply_lines_cut, NULL},
    {"store", NULL, put_store},
    {"store_dropped", NULL, put_store_dropped},
    {"store_now", NULL, put_store_now},
    {"selfcal", NULL, put_selfcal},
    {"selftest", NULL, put_selftest},
    {"board", NULL, put_board},
};

/* status: one data line per figure, then ok MODE. The snapshot is copied field by
 * field while the ISR may update it; each figure is one aligned word, so each line is a
 * consistent value (lines may come from adjacent ticks). */
static void cmd_status(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)argv;
  app_t *a = ctx;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: status");
    return;
  }
  for (size_t i = 0; i < sizeof k_status_rows / sizeof k_status_rows[0]; i++) {
    const status_row_t *r = &k_status_rows[i];
    if (r->count != NULL) {
      cli_data_u32(cli, r->name, r->count(a));
    } else {
      r->lines(cli, a);
    }
  }
  cli_ok(cli, mode_name((uint32_t)a->gyro.sup.mode));
}

/* Queue r; a full queue is answered err BUSY (false). */
static bool queue_or_refuse(cli_t *cli, app_t *a, app_req_t r)
{
  if (app_request(a, r) != 0) {
    cli_err(cli, "BUSY", "request queue full: retry");
    return false;
  }
  return true;
}

/* selftest: the built-in self-test runs in the ISR (0.5 s); status shows the result. */
static void cmd_selftest(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)argv;
  app_t *a = ctx;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: selftest");
    return;
  }
  const gyro_mode_t m = app_mode_after_queue(a);
  if (m == GYRO_MODE_OFF) {
    cli_err(cli, "STATE", "the drive is off: drive on first");
    return;
  }
  if (m != GYRO_MODE_LOCKED) {
    cli_err(cli, "BUSY", "the self-test needs the drive LOCKED");
    return;
  }
  if (a->gyro.design->sense_mode != 0u) {
    cli_err(cli, "STATE",
            "the self-test's force would go past the force-rebalance loop: "
            "sense.mode 0 first");
    return;
  }
  if (!queue_or_refuse(cli, a, APP_REQ_SELFTEST)) return;
  cli_ok(cli, "selftest started: see status in 0.5 s");
}

/* drive on|off: queued for the ISR. A command takes the drive over from a running
 * sweep, which is aborted; drive on also clears the shown fault. */
static void cmd_drive(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  app_t *a = ctx;
  if (argc != 2u || (strcmp(argv[1], "on") != 0 && strcmp(argv[1], "off") != 0)) {
    cli_err(cli, "ARGS", "usage: drive on|off");
    return;
  }
  const int on = strcmp(argv[1], "on") == 0;
  if (!queue_or_refuse(cli, a, on ? APP_REQ_DRIVE_ON : APP_REQ_DRIVE_OFF)) return;
  selfcal_abort(&a->selfcal, "sweep aborted by a drive command");
  a->sweep_owns_drive = false;
  cli_ok(cli, on ? "drive on" : "drive off");
}

/* clear: the shown fault goes; last_fault keeps it. */
static void cmd_clear(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)argv;
  app_t *a = ctx;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: clear");
    return;
  }
  if (!queue_or_refuse(cli, a, APP_REQ_CLEAR)) return;
  cli_ok(cli, "fault cleared");
}

/* sweep points: the measured points of the latest finished (or failed) sweep, one data
 * line each in ascending frequency: the force frequency, the mean drive pickoff phasor's
 * amplitude and phase against the force (force phase P = 0 during the steps; the
 * convention of gyro-sim's sweep CSV, not arg Z of gyro.h), the force command it had
 * and their ratio |H| (what a frequency-response fit reads), the placement it belongs to.
 * Background only: reads the sequencer's table. */
static void put_sweep_points(cli_t *cli, const app_t *a)
{
  const selfcal_t *s = &a->selfcal;
  const uint32_t n = selfcal_export_count(s);
  if (n == 0u) {
    cli_err(cli, "STATE",
            selfcal_running(s) ? "a sweep is in progress: wait for it to end"
                               : "no sweep has measured points yet: run sweep");
    return;
  }
  uint8_t order[SELFCAL_EXPORT_MAX] = {0};
  for (uint32_t i = 0; i < n; i++) {
    uint32_t k = i; /* insertion by frequency, stable */
    while (k > 0u && s->pts[order[k - 1u]].half_step > s->pts[i].half_step) {
      order[k] = order[k - 1u];
      k--;
    }
    order[k] = (uint8_t)i;
  }
  for (uint32_t k = 0; k < n; k++) {
    const selfcal_export_pt_t *p = &s->pts[order[k]];
    const double amp = hypot((double)p->z_re, (double)p->z_im);
    /* The pickoff v = Im{Z e^{j phi}} = |Z| cos(phi + arg Z - 90 deg) against the force
     * cos(phi) (gyro.h, drive_synth.h): its phase is arg Z - 90 deg, in (-180, 180]. */
    double ph = atan2((double)p->z_im, (double)p->z_re) * FM_DEG_PER_RAD - 90.0;
    if (ph <= -180.0) ph += 360.0;
    const float gain = p->f_cmd_v2 > 0.0f ? (float)(amp / (double)p->f_cmd_v2) : 0.0f;
    cli_putf(cli, "point %u f_hz %f amp_v %f phase_deg %f f_cmd_v2 %f gain_v_per_v2 %f stage %u",
             k, (float)selfcal_export_f_hz(s, order[k]), (float)amp, (float)ph, p->f_cmd_v2,
             gain, p->stage);
    cli_emit_data(cli);
  }
  cli_putf(cli, "%u points", n);
  cli_emit_ok(cli);
}

/* sweep: self-calibration; the drive goes SWEEP -> ACQUIRE with the identified model.
 * sweep points: the latest sweep's measured points (put_sweep_points). */
static void cmd_sweep(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  app_t *a = ctx;
  if (argc == 2u && strcmp(argv[1], "points") == 0) {
    put_sweep_points(cli, a);
    return;
  }
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: sweep [points]");
    return;
  }
  if (app_selfcal_start(a) != 0) {
    cli_err(cli, "BUSY", "a sweep is in progress, or the request queue is full");
    return;
  }
  cli_ok(cli, "sweep started");
}

int app_cmds_register(app_t *a)
{
  /* The CLI keeps the rows by pointer: they live in the application instance. */
  cli_cmd_t *cmds = a->cmds;
  const cli_cmd_t status = {"status", "", "mode, faults, drive and rate figures, ISR cycles",
                            cmd_status, a};
  const cli_cmd_t drive = {"drive", "on|off", "start or stop the drive (acquire / safe mode)",
                           cmd_drive, a};
  const cli_cmd_t sweep = {"sweep", "[points]",
                           "self-calibration: identify the drive mode, "
                           "redesign the loops, then acquire; points: the latest sweep's "
                           "measured points",
                           cmd_sweep, a};
  cmds[0] = status;
  cmds[1] = drive;
  const cli_cmd_t selftest = {"selftest", "",
                              "built-in self-test: a known force on the sense "
                              "mode, checked on the rate output",
                              cmd_selftest, a};
  const cli_cmd_t clear = {"clear", "", "clear the shown fault (status keeps it as last_fault)",
                           cmd_clear, a};
  cmds[2] = sweep;
  cmds[3] = selftest;
  cmds[4] = clear;
  for (size_t i = 0; i < 5u; i++) {
    if (cli_register(&a->cli, &cmds[i]) != 0) {
      return -1;
    }
  }
  return 0;
}
