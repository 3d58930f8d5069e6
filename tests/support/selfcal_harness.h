/* Harness of the self-calibration closed-loop tests: the application and the host
 * plant through the host HAL, the `sweep` command, and the checks against the plant's
 * own parameters and motion. Header-only (static functions), one instance per test.
 * The parts are the ideal preset's (plant_ideal_cfg): the checks compare the identified
 * Q with the plant's linear q_drive, which the default part's stroke-dependent drive
 * damping lowers by 2-3 % at the sweep's amplitude; these tests are of the firmware's
 * identification, not of the part. */
#ifndef SELFCAL_HARNESS_H
#define SELFCAL_HARNESS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app_plant.h"

static inline void start(const plant_cfg_t *pc, const param_values_t *v)
{
  app_plant_start(pc, 23u, v);
}

/* Run with the background loop polled every millisecond. */
static inline void run_polled_s(double s)
{
  const uint64_t n = (uint64_t)(s * 1000.0 + 0.5);
  for (uint64_t i = 0; i < n; i++) {
    hal_host_run(50u);
    app_poll(&app);
  }
}

/* `sweep`, then run until the sequencer is done or failed (at most 150 s; a sweep takes
 * at most 60 s at any Q from 20 to 10^5, 23.5 s at Q = 10^5). Returns the
 * simulated length of the sweep in seconds. */
static inline double sweep_report(uint64_t t0);
/* Run until the sweep started by the caller is done or failed; its length from the
 * request (app.selfcal_t0_ticks). */
static inline double sweep_wait(void)
{
  return sweep_report(plant_truth(&plant)->sample - (app_ticks(&app) - app.selfcal_t0_ticks));
}

static inline double sweep(void)
{
  assert_true(strncmp(cmd("sweep\n"), "ok", 2) == 0);
  return sweep_report(plant_truth(&plant)->sample);
}

static inline double sweep_report(uint64_t t0)
{
  for (int i = 0;
       i < 150000 && (app.selfcal.state != SELFCAL_DONE && app.selfcal.state != SELFCAL_FAILED);
       i++) {
    run_polled_s(0.001);
  }
  const double t = (double)(plant_truth(&plant)->sample - t0) / 50000.0;
  printf("# sweep %s in %.2f s (%s): coarse %.2f Hz, ring-down %.3f Hz Q %.1f, fit %.4f Hz "
         "Q %.2f gain %.5g V/V^2 P %.2f deg rms %.2g delay %.2f samples\n",
         selfcal_state_name(app.selfcal.state), t, app.selfcal.why ? app.selfcal.why : "-",
         app.selfcal.f_coarse_hz, app.selfcal.rd_f_hz, app.selfcal.rd_q, app.selfcal.fit.f0_hz,
         app.selfcal.fit.q, app.selfcal.fit.gain_v_per_v2, app.selfcal.hold_p_rad * 180.0 / M_PI,
         app.selfcal.fit.rms_rel, app.selfcal.delay_s * 50000.0);
  return t;
}

/* The plant's undamped drive resonance now: (2-32) at the structure temperature. */
static inline double true_f0(const plant_cfg_t *pc)
{
  const double t = plant_truth(&plant)->struct_k;
  return pc->f_drive_hz * (1.0 - 0.5 * pc->ket_per_k * (t - pc->temp_ref_k));
}

static inline void check_identified(const plant_cfg_t *pc)
{
  const double f0 = true_f0(pc);
  const double bw = f0 / pc->q_drive;
  const selfcal_t *s = &app.selfcal;
  printf("# plant f0 %.4f Hz Q %.2f: error %.4f Hz (tolerance %.3f), Q %+.3f %%\n", f0,
         pc->q_drive, s->fit.f0_hz - f0, fmax(0.1, bw / 100.0),
         100.0 * (s->fit.q / pc->q_drive - 1.0));
  assert_true(fabs(s->fit.f0_hz - f0) <= fmax(0.1, bw / 100.0));
  assert_true(fabs(s->fit.q / pc->q_drive - 1.0) <= 0.02);
  const param_values_t *v = params_current(&app.params);
  assert_true(fabs((double)v->drive_cal_f0_hz - s->fit.f0_hz) < 1e-3);
  assert_true(fabs((double)v->drive_freq_hz - s->fit.f0_hz) < 1e-3);
  assert_true(fabs((double)v->drive_cal_q / s->fit.q - 1.0) < 1e-6);
}

/* `sweep points` after the sweep: the measured points as data lines
 *   - point K f_hz F amp_v A phase_deg P f_cmd_v2 C gain_v_per_v2 G stage S
 * then "ok N points". Checked: N is the sequencer's table (9 points per placement, both
 * placements kept), K counts up, the frequencies ascend and bracket the identified f0,
 * gain = amp / f_cmd, the largest gain lies within half a bandwidth of f0 and agrees
 * with the fitted |H(f0)|, and the printed points alone identify the plant again
 * (selfcal_fit_delay on them: f0 and Q within the tolerances of check_identified). */
static inline void check_points(const plant_cfg_t *pc)
{
  const char *r = cmd("sweep points\n");
  const selfcal_t *s = &app.selfcal;
  selfcal_point_t pts[SELFCAL_EXPORT_MAX];
  uint32_t n = 0u;
  double g_max = 0.0, f_at_max = 0.0;
  const char *line = r;
  while (strncmp(line, "- point ", 8) == 0) {
    unsigned k = 0u, stage = 0u;
    double f = 0.0, amp = 0.0, ph = 0.0, fc = 0.0, g = 0.0;
    assert_int_equal(sscanf(line,
                            "- point %u f_hz %lf amp_v %lf phase_deg %lf f_cmd_v2 %lf "
                            "gain_v_per_v2 %lf stage %u",
                            &k, &f, &amp, &ph, &fc, &g, &stage),
                     7);
    assert_true(n < SELFCAL_EXPORT_MAX);
    assert_int_equal(k, n);
    assert_true(stage == 1u || stage == 2u);
    assert_true(amp > 0.0 && fc > 0.0 && fabs(ph) <= 180.0);
    assert_true(fabs(g / (amp / fc) - 1.0) < 1e-5);
    if (n > 0u) assert_true(f >= pts[n - 1u].f_hz);
    if (g > g_max) {
      g_max = g;
      f_at_max = f;
    }
    pts[n].f_hz = f;
    /* phase_deg is the pickoff against the force: arg Z - 90 deg (gyro.h). */
    pts[n].h_re = g * cos((ph + 90.0) * M_PI / 180.0);
    pts[n].h_im = g * sin((ph + 90.0) * M_PI / 180.0);
    n++;
    line = strstr(line, "\r\n");
    assert_non_null(line);
    line += 2;
  }
  char ok[32];
  snprintf(ok, sizeof ok, "ok %u points\r\n", (unsigned)n);
  assert_string_equal(line, ok);
  assert_int_equal(n, s->n_pts);
  assert_true(n == 9u || n == 18u);
  const double f0 = s->fit.f0_hz, hb = f0 / (2.0 * s->fit.q);
  assert_true(pts[0].f_hz < f0 && pts[n - 1u].f_hz > f0);
  assert_true(fabs(f_at_max - f0) <= 0.6 * hb);
  assert_true(fabs(g_max / s->fit.gain_v_per_v2 - 1.0) < 0.1);
  selfcal_fit_t fit;
  double d = 0.0;
  assert_int_equal(
      selfcal_fit_delay(pts, n, s->cfg.delay_s, s->cfg.delay_s + 8.0 / s->cfg.fs_hz, &fit, &d),
      0);
  const double tf0 = true_f0(pc);
  printf("# sweep points: %u, %.3f..%.3f Hz, peak gain %.5g at %.3f Hz; refit on them: f0 "
         "%.4f Hz (plant %.4f) Q %.2f (plant %.2f) rms %.2g; reply %zu bytes\n",
         (unsigned)n, pts[0].f_hz, pts[n - 1u].f_hz, g_max, f_at_max, fit.f0_hz, tf0, fit.q,
         pc->q_drive, fit.rms_rel, strlen(r));
  assert_true(fabs(fit.f0_hz - tf0) <= fmax(0.1, tf0 / pc->q_drive / 100.0));
  assert_true(fabs(remainder(fit.phase_rad - s->fit.phase_rad, 2.0 * M_PI)) < 0.01);
  assert_true(fabs(fit.q / pc->q_drive - 1.0) <= 0.02);
}

/* True drive amplitude from the plant's position and velocity at the operating
 * frequency. (plant_truth()->drive_amp_m uses the frequency estimated from the force
 * samples, which the loops' response to the pickoff ripple at wc/2 phase-modulates at
 * high Q: that estimate then swings by 2 % while the motion does not.) */
static inline double amp_m(void)
{
  const plant_truth_t *t = plant_truth(&plant);
  const double w = 2.0 * M_PI * (double)params_current(&app.params)->drive_freq_hz;
  return hypot(t->y_m, t->vy_mps / w);
}

/* After the hand-over: the true drive amplitude within 1 % of its final value in 0.2 s
 * and staying there; locked, no fault. */
static inline void check_lock(void)
{
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  run_polled_s(0.2);
  const double a02 = amp_m();
  double amin = a02, amax = a02;
  for (int i = 0; i < 40; i++) {
    run_polled_s(0.02);
    const double a = amp_m();
    amin = fmin(amin, a);
    amax = fmax(amax, a);
  }
  const double a_end = amp_m();
  printf("# after hand-over: amplitude %.4f um at 0.2 s, %.4f..%.4f um to 1 s, mode %u faults %u (last 0x%x)\n",
         a02 * 1e6, amin * 1e6, amax * 1e6, (unsigned)app.gyro.sup.mode,
         (unsigned)app.gyro.sup.fault_count, (unsigned)app.gyro.sup.fault);
  assert_true(fabs(amin / a_end - 1.0) < 0.01 && fabs(amax / a_end - 1.0) < 0.01);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  /* The amplitude set point is the default 0.349 V = 10 um through the pickoff gain. */
  assert_true(fabs(a_end / 10.0e-6 - 1.0) < 0.02);
}

/* A +-1 Hz step of the drive resonance (the structure's thermal nodes stepped by the
 * temperature that moves it 1 Hz by (2-32)) with the loops the sweep designed: lock
 * holds, no fault, the true amplitude stays within 1 % of its setpoint. */
static inline void check_resonance_step(const plant_cfg_t *pc, double df_hz)
{
  const double dk = -df_hz / (0.5 * pc->ket_per_k * pc->f_drive_hz);
  double t[THERMAL_NODES];
  for (int i = 0; i < THERMAL_NODES; i++) t[i] = thermal_temp(&plant.thermal, i) + dk;
  thermal_set(&plant.thermal, t);
  double worst = 0.0;
  for (int i = 0; i < 50; i++) {
    run_polled_s(0.01);
    if (i >= 20) worst = fmax(worst, fabs(amp_m() / 10.0e-6 - 1.0));
  }
  printf("# resonance step %+.1f Hz: mode %u faults %u, amplitude within %.3f %% from 0.2 s\n",
         df_hz, (unsigned)app.gyro.sup.mode, (unsigned)app.gyro.sup.fault_count, 100.0 * worst);
  assert_int_equal(app.gyro.sup.fault_count, 0u);
  assert_int_equal(app.gyro.sup.mode, GYRO_MODE_LOCKED);
  assert_true(worst < 0.01);
}

static inline void values_no_autostart(param_values_t *v)
{
  param_values_defaults(v);
  v->sys_autostart = 0u;
}

static inline void random_plant_case(double f_hz, double q)
{
  plant_cfg_t pc;
  plant_ideal_cfg(&pc);
  pc.f_drive_hz = f_hz;
  pc.q_drive = q;
  param_values_t v;
  values_no_autostart(&v);
  start(&pc, &v);
  const double t = sweep();
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  assert_true(t <= 60.0);
  check_identified(&pc);
  check_points(&pc);
  check_lock();
  check_resonance_step(&pc, +1.0);
  check_resonance_step(&pc, -2.0);
}

/* The tolerances: the undamped resonance at the structure temperature within
 * max(0.01 Hz, f0 / (100 Q)), Q within 2 %, the sweep within 60 s. */
static inline void check_identified_strict(const plant_cfg_t *pc, double t_s)
{
  const double f0 = true_f0(pc);
  const double tol = fmax(0.01, f0 / pc->q_drive / 100.0);
  const selfcal_t *s = &app.selfcal;
  printf("# Q %.0f: %.2f s, %s; f0 %.5f Hz (plant %.5f) error %+.5f Hz (tolerance %.5f), Q %.1f "
         "error %+.3f %%\n",
         pc->q_drive, t_s, selfcal_state_name(s->state), s->fit.f0_hz, f0, s->fit.f0_hz - f0,
         tol, s->fit.q, 100.0 * (s->fit.q / pc->q_drive - 1.0));
  assert_true(t_s <= 60.0);
  assert_true(fabs(s->fit.f0_hz - f0) <= tol);
  assert_true(fabs(s->fit.q / pc->q_drive - 1.0) <= 0.02);
}

/* The part pc swept from the parameter defaults without autostart. Within the fixed-frequency drive's reach the sweep hands over and the
 * fixed drive's loops lock at the set point; beyond it the sweep identifies |H(wn)| by a
 * burst, commits drive.track 1 and hands over to the tracking drive, which locks. */
static inline void vacuum_part_case(const plant_cfg_t *pc)
{
  param_values_t v;
  values_no_autostart(&v);
  start(pc, &v);
  const double t = sweep();
  check_identified_strict(pc, t);
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  /* by the Q identified: a part of nominal Q 5000 may be found either side of the limit */
  const unsigned want_track = app.selfcal.fit.q > SELFCAL_Q_FIXED_MAX ? 1u : 0u;
  assert_int_equal(params_current(&app.params)->drive_track, want_track);
  check_lock();
  assert_int_equal(app.gyro.design->track, want_track); /* taken by the ISR by now */
  const char *r = cmd("status\n");
  assert_non_null(strstr(r, want_track ? "drive_track 1" : "drive_track 0"));
}

/* The same on the ideal preset's part of resonance f_hz and quality factor q, at an
 * ambient dtemp_k from the default. */
static inline void vacuum_case(double f_hz, double q, double dtemp_k)
{
  plant_cfg_t pc;
  plant_ideal_cfg(&pc);
  pc.f_drive_hz = f_hz;
  pc.q_drive = q;
  pc.temp_k += dtemp_k;
  vacuum_part_case(&pc);
}

/* The default part's resonance at the default ambient, quality factor q. */
static inline void high_q_case(double q)
{
  plant_cfg_t pc;
  plant_ideal_cfg(&pc);
  vacuum_case(pc.f_drive_hz, q, 0.0);
}

/* Negative control: the default (thesis part) loop design does not lock on the part. */
static inline int fixed_design_fails(double f_hz, double q)
{
  plant_cfg_t pc;
  plant_ideal_cfg(&pc);
  pc.f_drive_hz = f_hz;
  pc.q_drive = q;
  param_values_t v;
  default_part_values(&v);
  start(&pc, &v);
  run_polled_s(1.2);
  const double a = amp_m();
  printf("# fixed design on f %.1f Hz Q %.0f: mode %u faults %u amplitude %.3f um\n", f_hz, q,
         (unsigned)app.gyro.sup.mode, (unsigned)app.gyro.sup.fault_count, a * 1e6);
  return app.gyro.sup.mode != GYRO_MODE_LOCKED || fabs(a / 10.0e-6 - 1.0) > 0.01;
}

#endif /* SELFCAL_HARNESS_H */
