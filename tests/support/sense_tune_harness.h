/* The mode-tuning closed-loop tests' part and steps (test_cl_sense_tune.c, and the
 * lost-match study tests/slow/test_tune_disc_study.c): the sense identification's part
 * with tuning electrodes, its values, the plant's tuned resonance, the calibration flow's
 * steps on the tuned part, and the lost-match monitor's reading. Header-only (static),
 * one instance per test program. */
#ifndef SENSE_TUNE_HARNESS_H
#define SENSE_TUNE_HARNESS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "selfcal_harness.h"
#include "sense_mode_model.h"
#include "sense_step.h"

#define TUNE_KE 2.4e5 /* (1/s^2)/V^2: the 110 Hz split matched at 7.5 V */
#define BLOCK_S SENSE_STEP_BLOCK_S

static inline plant_cfg_t part(double f_sense_hz, double q_sense)
{
  plant_cfg_t pc;
  sense_test_part(&pc, q_sense);
  pc.f_sense_hz = f_sense_hz;
  pc.tune_ke_per_s2_per_v2 = TUNE_KE;
  return pc;
}

/* The default part's values, its rate calibration moved to the untuned sense mode, the
 * sense identification and force rebalance on, tuning `mode` (split_hz), no autostart. */
static inline void part_values(const plant_cfg_t *pc, uint32_t mode, double split_hz,
                               param_values_t *v)
{
  sense_test_fr_sweep_values(v, pc->f_sense_hz, pc->q_sense);
  v->sense_tune = mode;
  v->sense_tune_split_hz = (float)split_hz;
}

/* The plant's sense resonance now, with the tuning electrodes at the converter's held
 * voltage: ws^2 = ws(T)^2 - ke Vt^2. */
static inline double tuned_f_at(const plant_cfg_t *pc, double vt)
{
  plant_match_t m;
  assert_true(plant_sense_match(pc, plant_truth(&plant)->struct_k, 0.0, 0.0, &m) >= 0);
  const double ws = 2.0 * FM_PI * m.f_sense_hz;
  return sqrt(ws * ws - pc->tune_ke_per_s2_per_v2 * vt * vt) / (2.0 * FM_PI);
}

static inline double true_tuned_f(const plant_cfg_t *pc)
{
  return tuned_f_at(pc, plant_truth(&plant)->dac_held_v[HAL_DAC_TUNE]);
}

/* The calibration flow's part of the rate channel on the tuned part, from the plant's
 * truth (test_cl_sense_id.c's hand model at the tuned resonance f_tuned_hz). */
/* `set`, retried while the sample loop has not taken the previous change. */
static inline const char *set_line(const char *line)
{
  const char *r = cmd(line);
  for (int i = 0; i < 100 && strstr(r, "PENDING") != NULL; i++) {
    run_polled_s(0.001);
    r = cmd(line);
  }
  return r;
}

static inline void set_ok(const char *line)
{
  const char *r = set_line(line);
  if (strncmp(r, "ok", 2) != 0) fail_msg("%s -> %s", line, r);
}

static inline void calibrate_tuned(const plant_cfg_t *pc, double f_tuned_hz)
{
  const param_values_t *p = params_current(&app.params);
  param_values_t d;
  default_part_values(&d);
  d.drive_freq_hz = p->drive_freq_hz; /* the sweep's */
  sense_test_cal_moved(&d, f_tuned_hz, pc->q_sense);
  const double phi = (double)d.rate_demod_phase_deg;
  const double dphi = remainder(phi - (double)p->rate_demod_phase_deg, 360.0);
  char line[160];
  snprintf(line, sizeof line, "set rate.demod_phase_deg %.6f\n", remainder(phi, 360.0));
  set_ok(line);
  snprintf(line, sizeof line, "set sense.fb_phase_deg %.6f\n",
           remainder((double)p->sense_fb_phase_deg + dphi, 360.0));
  set_ok(line);
  snprintf(line, sizeof line, "set rate.scale_dps %.6f\n", (double)d.rate_scale_dps);
  set_ok(line);
  snprintf(line, sizeof line, "set cal.ref_freq_hz %.6f\n", (double)p->drive_freq_hz);
  set_ok(line);
  snprintf(line, sizeof line, "set cal.ref_tune_v %.6f\n", app.tune.v_v);
  set_ok(line);
}

/* The mean rate and quadrature over 0.1 s after 0.2 s at the input rate dps. */
static inline void held_mean(double dps, double *rate, double *quad)
{
  app_plant_hold_rate(dps);
  run_polled_s(0.2);
  *rate = *quad = 0.0;
  const int n = (int)(0.1 / BLOCK_S);
  for (int i = 0; i < n; i++) {
    hal_host_run(GYRO_BLOCK);
    *rate += (double)app.gyro.out.rate_dps / n;
    *quad += (double)app.gyro.out.quad_dps / n;
  }
}

/* The calibration flow's rate-table stage (tools/gyrotools/calflow.py rate_table,
 * demodcal.py) in two rates: the response vector's angle alpha turns the demodulation
 * phase and, with force rebalance, the feedback phase (the readout's frame); its length
 * the scale. */
static inline void flow_rate_table(void)
{
  double r1, q1, r2, q2;
  held_mean(100.0, &r1, &q1);
  held_mean(-100.0, &r2, &q2);
  app_plant_hold_rate(0.0);
  const double vr = (r1 - r2) / 200.0, vq = (q1 - q2) / 200.0;
  const double alpha = atan2(vq, vr) * FM_DEG_PER_RAD, gain = hypot(vr, vq);
  const param_values_t *p = params_current(&app.params);
  printf("# rate table: alpha %+.3f deg, gain %.4f\n", alpha, gain);
  char line[160];
  snprintf(line, sizeof line, "set rate.demod_phase_deg %.6f\n",
           remainder((double)p->rate_demod_phase_deg + alpha, 360.0));
  set_ok(line);
  snprintf(line, sizeof line, "set sense.fb_phase_deg %.6f\n",
           remainder((double)p->sense_fb_phase_deg + alpha, 360.0));
  set_ok(line);
  snprintf(line, sizeof line, "set rate.scale_dps %.6f\n", (double)p->rate_scale_dps / gain);
  set_ok(line);
}

/* The sweep tunes the part: S4 done, its resonance at the target within S4's tolerance
 * (a quarter of the half-bandwidth, or 0.6 of one code's move), the calibration staged. */
static inline void check_tuned(const plant_cfg_t *pc, double split_hz)
{
  const double t = sweep();
  const selfcal_sense_t *m = &app.selfcal.sense;
  printf("# sense %s, S4 %s (%s)\n", m->why != NULL ? m->why : "identified",
         m->match == SELFCAL_TUNE_OK ? "tuned" : "not tuned",
         m->match_why != NULL ? m->match_why : "-");
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  assert_int_equal(m->state, SELFCAL_SENSE_OK);
  assert_int_equal(m->match, SELFCAL_TUNE_OK);
  /* the plant with the sweep's voltage on (the tuning channel is the sweep's until the
   * hand-over; the test holds it there for the truth) */
  const param_values_t *p = params_current(&app.params);
  const double target = true_f0(pc) + split_hz;
  const double hb = pc->f_sense_hz / (2.0 * pc->q_sense);
  const double code_hz = m->match_ke * m->match_v * (double)HAL_DAC_V_PER_CODE /
                         (4.0 * FM_PI * FM_PI * target);
  printf("# sweep %.2f s (sense %.2f s): tuned in %u ring-downs at %.4f V: free %.4f Hz, "
         "target %.4f Hz (plant's drive %.4f + %.1f), code step %.4f Hz, half-band %.4f Hz; "
         "staged s0 %.4f Hz ref %.4f Hz ke %.5g\n",
         t, (double)m->ticks / 50000.0, m->match_passes, m->match_v, m->match_fd_hz,
         m->match_target_hz, true_f0(pc), split_hz, code_hz, hb, (double)p->sense_cal_s0_hz,
         (double)p->sense_cal_tune_ref_hz, (double)p->sense_cal_tune_ke_per_s2_per_v2);
  assert_true(fabs(m->match_fd_hz - m->match_target_hz) <= fmax(0.25 * hb, 0.6 * code_hz));
  assert_true(p->sense_cal_s0_hz > 0.0f && p->sense_cal_tune_ref_hz == p->drive_freq_hz);
  assert_float_equal(p->sense_f0_hz, (float)m->f0_hz, 1e-3f);
  assert_non_null(strstr(cmd("status\n"), "selfcal_match tuned"));
}

/* The lost-match monitor's reading in status (tune_detune_hz; 0 without one). */
static inline double status_detune_hz(void)
{
  const char *r = strstr(cmd("status\n"), "tune_detune_hz ");
  return r != NULL ? atof(r + strlen("tune_detune_hz ")) : 0.0;
}

/* The matched part tuned and calibrated as test_matched leaves it, running, its continuous
 * test's tone at cont_freq_hz (0: the default's). */
static inline void matched_tuned(const plant_cfg_t *pc, double cont_freq_hz)
{
  param_values_t v;
  part_values(pc, SENSE_TUNE_MATCHED, 0.0, &v);
  if (cont_freq_hz > 0.0) v.selftest_cont_freq_hz = (float)cont_freq_hz;
  start(pc, &v);
  check_tuned(pc, 0.0);
  run_polled_s(0.5);
  calibrate_tuned(pc, tuned_f_at(pc, app.selfcal.sense.match_v));
  flow_rate_table();
  flow_rate_table();
  app_plant_hold_rate(0.0);
  run_polled_s(1.0);
}

/* ... with the default tone, the rate valid. */
static inline void matched_running(const plant_cfg_t *pc)
{
  matched_tuned(pc, 0.0);
  assert_int_equal(app.gyro.out.rate_invalid, 0u);
}

#endif /* SENSE_TUNE_HARNESS_H */
