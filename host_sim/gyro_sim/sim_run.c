/* The simulation loops: closed loop (plant + firmware application through the host HAL)
 * and open loop (the plant driven by a fixed or stepped half-frequency drive). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "dsp/butter.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"
#include "sim.h"
#include "sim_out.h"
#include "slip.h"
#include "sim/uart_pty.h"
#include "sim_bench.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include "plant/plant_const.h"

/* SIGINT/SIGTERM end a paced (pty) run cleanly; a flag is all a handler may touch. */
static volatile sig_atomic_t stop_requested;
static void on_signal(int sig)
{
  (void)sig;
  stop_requested = 1;
}

static double wall_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU time of this process: the real-time factor on one core, independent of what
 * else the machine is doing (the wall-clock factor is reported too). */
static double cpu_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
  int enabled;
  double t0_wall, last_wall;
  double total_s;
} progress_t;

static void progress_update(progress_t *pr, double sim_s, int final)
{
  if (!pr->enabled) return;
  const double now = wall_now();
  if (!final && now - pr->last_wall < 0.25) return;
  pr->last_wall = now;
  const double frac = pr->total_s > 0.0 ? sim_s / pr->total_s : 1.0;
  const int width = 30, fill = (int)(frac * width + 0.5);
  const double el = now - pr->t0_wall;
  const double eta = frac > 1e-6 ? el * (1.0 - frac) / frac : 0.0;
  fprintf(stderr, "\r[%.*s%*s] %5.1f%%  sim %.1f/%.1f s  %.0fx real time  eta %.0f s ", fill,
          "##############################", width - fill, "", 100.0 * frac, sim_s, pr->total_s,
          el > 0.0 ? sim_s / el : 0.0, eta);
  if (final) fputc('\n', stderr);
  fflush(stderr);
}

/* RMS of x[i0..n) after removing its linear trend (the 0.1 Hz lower band edge of the
 * drive figures is approximated by the detrend over a window of a few seconds) and a
 * 100 Hz low-pass (the upper band edge), at sample rate fs. */
static double band_rms(const double *x, size_t i0, size_t n, double fs)
{
  if (n <= i0 + 16) return NAN;
  const size_t m = n - i0;
  double st = 0, sx = 0, stt = 0, stx = 0;
  for (size_t i = 0; i < m; i++) {
    const double t = (double)i;
    st += t;
    sx += x[i0 + i];
    stt += t * t;
    stx += t * x[i0 + i];
  }
  const double den = (double)m * stt - st * st;
  const double b = den != 0.0 ? ((double)m * stx - st * sx) / den : 0.0;
  const double a = (sx - b * st) / (double)m;
  butter_sos_f64_t sos[2];
  const int ns = butter_design_f64(BUTTER_LOWPASS, 2u, 100.0, 0.0, fs, sos, 2u);
  double s1 = 0, s2 = 0, acc = 0;
  size_t cnt = 0;
  const size_t skip = (size_t)(0.02 * fs); /* the low-pass's own start-up */
  for (size_t i = 0; i < m; i++) {
    double v = x[i0 + i] - (a + b * (double)i);
    if (ns == 1) {
      const double y = sos[0].b0 * v + s1;
      s1 = sos[0].b1 * v - sos[0].a1 * y + s2;
      s2 = sos[0].b2 * v - sos[0].a2 * y;
      v = y;
    }
    if (i >= skip) {
      acc += v * v;
      cnt++;
    }
  }
  return cnt ? sqrt(acc / (double)cnt) : NAN;
}

static void startup_figures(const double *amp, const double *ph, const double *rerr, size_t n,
                            double fs, sim_startup_t *st)
{
  memset(st, 0, sizeof *st);
  if (n < 100) return;
  const size_t tail = n / 10;
  double af = 0.0;
  for (size_t i = n - tail; i < n; i++) af += amp[i];
  af /= (double)tail;
  double peak = 0.0;
  size_t last_out = 0;
  for (size_t i = 0; i < n; i++) {
    if (amp[i] > peak) peak = amp[i];
    if (fabs(amp[i] / af - 1.0) > 0.01) last_out = i + 1;
  }
  st->final_amp_m = af;
  st->lock_time_s = (double)last_out / fs;
  st->overshoot_pct = peak > af ? 100.0 * (peak / af - 1.0) : 0.0;
  /* Loop figures from 0.1 s after lock (the last of the acquisition transient). */
  const size_t i0 = last_out + (size_t)(0.1 * fs);
  st->amp_err_rms_pct = 100.0 * band_rms(amp, i0, n, fs) / af;
  st->phase_err_rms_deg = band_rms(ph, i0, n, fs) * 180.0 / PLANT_PI;
  /* Turn-on of the rate output: from here on its error stays within 0.5 deg/s of the
   * error it ends with (bias, filter and P-compensation transients settled). */
  double ef = 0.0;
  for (size_t i = n - tail; i < n; i++) ef += rerr[i];
  ef /= (double)tail;
  size_t last_rate_out = 0;
  for (size_t i = 0; i < n; i++) {
    if (!(fabs(rerr[i] - ef) <= 0.5)) last_rate_out = i + 1;
  }
  st->rate_settle_s = (double)last_rate_out / fs;
}

/* The drive's true motion at 1 kHz for the start-up figures, in the firmware's NCO frame. */
typedef struct {
  size_t decim;            /* ticks per truth sample */
  size_t cap, n;           /* samples allocated, taken */
  double *amp, *ph, *rerr; /* |Z| (m), unwrapped arg Z (rad), rate error (deg/s) */
  double ph_prev, ph_unwrap;
  double w_fw; /* the firmware's drive frequency, rad/s */
} cl_truth_t;

static void truth_sample(cl_truth_t *t, const app_t *app, const plant_truth_t *tr)
{
  /* The true drive phasor in the firmware's NCO frame: y = Im{Z e^{j phi}}, so
   * Z = (y'/w + j y) e^{-j phi} with phi the NCO phase of the next tick. */
  const uint32_t phase_u = app->gyro.nco.half_phase << 1;
  const double phi = 2.0 * PLANT_PI * (double)phase_u / 4294967296.0;
  const double re = tr->vy_mps / t->w_fw, im = tr->y_m;
  const double c = cos(phi), s = sin(phi);
  const double zr = re * c + im * s, zi = im * c - re * s;
  t->amp[t->n] = hypot(zr, zi);
  const double p = atan2(zi, zr);
  double d = p - t->ph_prev;
  d -= 2.0 * PLANT_PI * floor((d + PLANT_PI) / (2.0 * PLANT_PI));
  t->ph_unwrap += d;
  t->ph_prev = p;
  t->ph[t->n] = t->ph_unwrap;
  t->rerr[t->n] = (double)app->gyro.out.rate_dps - tr->rate_dps;
  t->n++;
}

/* Phase slips (slip.h), judged on the truth's samples. */
static void slip_take(slip_t *s, const app_t *app, const plant_truth_t *tr)
{
  const gyro_mode_t m = app->gyro.sup.mode;
  slip_sample(s, m == GYRO_MODE_LOCKED || m == GYRO_MODE_ACQUIRE, m == GYRO_MODE_LOCKED,
              tr->drive_phase_rad, tr->drive_force_mps2);
}

/* Running sums of a closed-loop run for its figures. */
typedef struct {
  slip_t slip;
  double fw_lock_s, first_valid_s; /* -1: not yet */
  uint64_t valid_ticks;
  double sum_struct_k, sum_drive_freq_hz, sum_drive_amp_m;
  uint64_t n_mean;
} cl_stats_t;

/* What a closed-loop run owns; released by cl_release. */
typedef struct {
  plant_t *plant;
  app_t *app;
  sim_csv_t csv;
  uart_pty_t pty;
  cl_truth_t truth;
  sim_bench_t bench; /* the pty session's `emu` command */
} cl_run_t;

static void cl_release(cl_run_t *r)
{
  if (r->pty.master_fd >= 0) uart_pty_close(&r->pty);
  sim_csv_close(&r->csv);
  hal_sample_timer_stop();
  hal_host_attach_board_temp(NULL, NULL); /* before its plant goes */
  free(r->truth.amp);
  free(r->truth.ph);
  free(r->truth.rerr);
  free(r->plant);
  free(r->app);
}

/* Opens the tuning UART's pty for a paced run and prints its path. */
static int cl_open_pty(cl_run_t *r, const sim_opts_t *opt, char *err, size_t err_len)
{
  char path[UART_PTY_PATH_MAX];
  if (uart_pty_open(&r->pty, path, sizeof path) != 0 ||
      (opt->uart_pty_link != NULL && uart_pty_link(&r->pty, opt->uart_pty_link) != 0)) {
    snprintf(err, err_len, "--uart-pty: %s", strerror(errno));
    return -1;
  }
  if (sim_bench_register(&r->bench, &r->app->cli, r->plant, opt->pace) != 0) {
    snprintf(err, err_len, "--uart-pty: the bench command could not be registered");
    return -1;
  }
  stop_requested = 0;
  signal(SIGINT, on_signal);
  signal(SIGTERM, on_signal);
  printf("pty %s\n", opt->uart_pty_link != NULL ? opt->uart_pty_link : path);
  fflush(stdout);
  return 0;
}

/* What a timeline after a self-calibration starts from: the structure's, circuit's and
 * board's temperatures as the sweep left them (the mechanics start at rest). */
typedef struct {
  double t_k[THERMAL_NODES];
} sim_warm_t;

static int params_equal(const param_values_t *a, const param_values_t *b)
{
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_value_t x = param_get(a, (param_idx_t)i), y = param_get(b, (param_idx_t)i);
    if (param_info((param_idx_t)i)->type == PARAM_T_F32 ? x.f != y.f : x.u != y.u) return 0;
  }
  return 1;
}

/* Allocates and starts the plant, the firmware behind the host HAL, the trace and the
 * pty. Returns 0, or -1 with err set (cl_release frees what was made). */
static int cl_start(cl_run_t *r, const sim_scenario_t *sc, const sim_opts_t *opt,
                    const plant_cfg_t *pc, const plant_profiles_t *prof, const param_values_t *fw,
                    const sim_warm_t *warm, uint64_t n_ticks, char *err, size_t err_len)
{
  memset(r, 0, sizeof *r);
  r->pty.master_fd = -1;
  r->plant = calloc(1, sizeof *r->plant);
  r->app = calloc(1, sizeof *r->app);
  cl_truth_t *t = &r->truth;
  t->decim = (size_t)llround(pc->fs_hz / 1000.0); /* truth samples at 1 kHz */
  t->w_fw = 2.0 * PLANT_PI * (double)fw->drive_freq_hz;
  if ((sc->analyses & SIM_AN_STARTUP) != 0u) {
    t->cap = (size_t)(n_ticks / t->decim) + 1u;
    t->amp = calloc(t->cap, sizeof *t->amp);
    t->ph = calloc(t->cap, sizeof *t->ph);
    t->rerr = calloc(t->cap, sizeof *t->rerr);
    if (t->amp == NULL || t->ph == NULL || t->rerr == NULL) t->cap = 0;
  }
  if (r->plant == NULL || r->app == NULL ||
      ((sc->analyses & SIM_AN_STARTUP) != 0u && t->cap == 0)) {
    snprintf(err, err_len, "out of memory");
    return -1;
  }
  if (plant_init(r->plant, pc, sc->seed) != 0 || plant_set_profiles(r->plant, prof) != 0) {
    snprintf(err, err_len, "plant: %s", plant_error(r->plant));
    return -1;
  }
  if (warm != NULL) thermal_set(&r->plant->thermal, warm->t_k);
  /* After a self-calibration the flash keeps what it saved: power-on loads it. */
  if (warm == NULL) (void)hal_flash_host_configure(NULL);
  hal_uart_host_reset();
  hal_host_attach(plant_step_hal, r->plant);
  hal_host_attach_board_temp(plant_board_temp_hal, r->plant); /* the board's TMP117 */
  if ((warm != NULL ? app_init(r->app) : app_init_with(r->app, fw)) != 0 ||
      hal_sample_timer_start(fw->sys_fs_hz, app_sample_isr, r->app) != 0) {
    snprintf(err, err_len, "firmware: application did not start");
    return -1;
  }
  if (warm != NULL && !params_equal(params_current(&r->app->params), fw)) {
    snprintf(err, err_len, "firmware: power-on did not load the values the sweep saved");
    return -1;
  }
  if (opt->csv_path != NULL && sim_csv_open(&r->csv, opt->csv_path, err, err_len) != 0)
    return -1;
  if (opt->uart_pty && cl_open_pty(r, opt, err, err_len) != 0) return -1;
  return 0;
}

/* Paced run: the firmware meets a person or a tool in real time (pace 1), or a tool
 * faster (pace times real time; 0: as fast as it runs). Sleeps on the pty until the wall
 * clock has caught up with the simulated time t_sim_s / pace. Returns 1 when a signal
 * asked to stop. */
static int cl_pace(cl_run_t *r, double t_sim_s, double t_wall0, double pace)
{
  uart_pty_pump(&r->pty);
  const double ahead = pace > 0.0 ? t_sim_s / pace - (wall_now() - t_wall0) : 0.0;
  if (ahead > 0.0) {
    struct pollfd pfd = {uart_pty_fd(&r->pty), POLLIN, 0};
    (void)poll(&pfd, 1, (int)(ahead * 1000.0));
    uart_pty_pump(&r->pty);
    app_poll(r->app);
    uart_pty_pump(&r->pty);
  }
  return stop_requested != 0;
}

/* The figures of a finished closed-loop run of n_ticks. */
static void cl_results(const cl_run_t *r, const cl_stats_t *st, const plant_cfg_t *pc,
                       uint64_t n_ticks, sim_result_t *res)
{
  if (r->truth.cap > 0) {
    startup_figures(r->truth.amp, r->truth.ph, r->truth.rerr, r->truth.n, 1000.0, &res->startup);
    res->startup.fw_lock_time_s = st->fw_lock_s;
  }
  const plant_truth_t *tr = plant_truth(r->plant);
  res->adc_clips[0] = tr->adc_clip[0];
  res->adc_clips[1] = tr->adc_clip[1];
  memcpy(res->plant_warnings, plant_warnings(r->plant), sizeof res->plant_warnings);
  res->dac_rejects = plant_truth(r->plant)->dac_rejects;
  (void)plant_adc_fraction(pc, res->adc_fraction);
  res->faults = r->app->gyro.sup.fault_count;
  res->rate_valid_fraction = n_ticks > 0u ? (double)st->valid_ticks / (double)n_ticks : 0.0;
  res->rate_first_valid_s = st->first_valid_s;
  res->phase_slips = st->slip.count;
  res->final_mode = (uint32_t)r->app->gyro.sup.mode;
  res->final_params = *params_current(&r->app->params);
  const double n = (double)st->n_mean;
  res->mean_struct_k = st->n_mean ? st->sum_struct_k / n : NAN;
  res->mean_drive_freq_hz = st->n_mean ? st->sum_drive_freq_hz / n : NAN;
  res->mean_drive_amp_m = st->n_mean ? st->sum_drive_amp_m / n : NAN;
}

/* ------------------------------------------------------------ self-calibration -- */

/* The longest sweep gyro-sim waits for (simulated): the sequencer's own timeouts end a
 * stuck sweep long before (selfcal_watch); this only bounds a run that keeps going. */
#define SELFCAL_MAX_S 600.0

/* One command line into the application over its UART, the background loop run once,
 * the reply out (as a user at the command line, or gyroctl, would send it). */
static const char *sc_cmd(app_t *a, const char *line, char *reply, size_t n)
{
  hal_uart_host_rx_push((const uint8_t *)line, strlen(line));
  app_poll(a);
  const size_t got = hal_uart_host_tx_pop((uint8_t *)reply, n - 1u);
  reply[got] = '\0';
  return reply;
}

/* The scenario's "commands" due by t_s, typed in order between two ticks, each reply kept
 * whole (a line end added: the command line reads lines). */
static void cl_commands(app_t *a, const sim_scenario_t *sc, double t_s, sim_result_t *res)
{
  while (res->n_cmds_run < sc->n_cmds && sc->cmds[res->n_cmds_run].t_s <= t_s) {
    char line[SIM_CMD_LINE_MAX + 2];
    snprintf(line, sizeof line, "%s\n", sc->cmds[res->n_cmds_run].line);
    (void)sc_cmd(a, line, res->cmd_reply[res->n_cmds_run], SIM_CMD_REPLY_MAX);
    res->n_cmds_run++;
  }
}

/* The scenario's inputs held at their values of t = 0: the initial conditions. */
static void initial_profiles(const plant_profiles_t *prof, plant_profiles_t *held)
{
  memset(held, 0, sizeof *held);
  profile_const(&held->rate_dps, profile_eval(&prof->rate_dps, 0.0, NULL));
  profile_const(&held->ambient_k, profile_eval(&prof->ambient_k, 0.0, NULL));
  double a_g[PROFILE_ACCEL_AXES];
  accel_profile_eval(&prof->accel_g, 0.0, a_g);
  accel_profile_zero(&held->accel_g);
  for (int i = 0; i < PROFILE_ACCEL_AXES; i++) held->accel_g.const_g[i] = a_g[i];
}

/* The reply's first line without its line end, for a message. */
static void first_line(const char *reply, char *out, size_t n)
{
  snprintf(out, n, "%.*s", (int)strcspn(reply, "\r\n"), reply);
}

/* The sense mode's identification (sense.cal 1) against the plant: what was identified
 * or why not, its time; the truth of the feedback gain and phase as the closed-loop tests
 * model them (test_cl_sense_fr.c): they hold when the firmware's rate.scale_dps and
 * rate.demod_phase_deg are the part's. */
static void selfcal_sense_result(const app_t *a, const plant_t *p, double fs, sim_selfcal_t *out)
{
  const selfcal_sense_t *m = &a->selfcal.sense;
  const param_values_t *v = params_current(&a->params);
  const plant_cfg_t *pc = &p->cfg;
  out->sense_ran = m->state != SELFCAL_SENSE_OFF;
  out->sense_ok = m->state == SELFCAL_SENSE_OK;
  snprintf(out->sense_why, sizeof out->sense_why, "%s",
           m->why != NULL  ? m->why
           : out->sense_ok ? ""
                           : "not finished");
  const int f0 = m->state == SELFCAL_SENSE_F0 || out->sense_ok;
  out->sense_f0_hz = f0 ? m->f0_hz : NAN;
  out->sense_q = f0 ? m->q : NAN;
  out->sense_fb_gain_v_per_v2 = out->sense_ok ? m->fb_gain_v_per_v2 : NAN;
  out->sense_fb_phase_deg = out->sense_ok ? m->fb_phase_rad * PLANT_DEG_PER_RAD : NAN;
  out->tune_ok = m->tune == SELFCAL_TUNE_OK;
  snprintf(out->tune_why, sizeof out->tune_why, "%s",
           m->tune_why != NULL ? m->tune_why
           : out->tune_ok      ? ""
                               : "not probed");
  out->sense_tune_ke_per_s2_per_v2 = out->tune_ok ? m->tune_ke_per_s2_per_v2 : NAN;
  out->sense_s = (double)m->ticks / fs;
  const double k_dps_per_v2 = plant_fb_rate_dps_per_v2(pc, out->true_f0_hz, pc->drive_amp_m);
  out->true_sense_fb_gain_v_per_v2 = k_dps_per_v2 / (double)v->rate_scale_dps *
                                     (double)v->drive_amp_set_v;
  out->true_sense_fb_phase_deg = 0.0;
  out->true_tune_ke_per_s2_per_v2 = pc->tune_ke_per_s2_per_v2 * pc->dac_gain_tune;
}

/* `sweep` on the running application, then the background loop polled every
 * millisecond until the sequencer is done or failed. Sums the plant's true drive
 * resonance and Q (both at the structure temperature) over the sweep. Returns 0 when it
 * finished (DONE), else -1 with out->why. */
static int selfcal_sweep(app_t *a, const plant_t *p, double fs, sim_selfcal_t *out)
{
  char reply[1024];
  sc_cmd(a, "sweep\n", reply, sizeof reply);
  if (strncmp(reply, "ok", 2) != 0) {
    first_line(reply, out->why, sizeof out->why);
    return -1;
  }
  const uint64_t poll = (uint64_t)llround(fs / 1000.0);
  const uint64_t cap = (uint64_t)llround(SELFCAL_MAX_S * fs);
  /* the Q as its first value plus the mean deviation: exactly the plant's Q when its
   * law keeps it constant */
  const double q0 = plant_truth(p)->q_drive, qs0 = plant_truth(p)->q_sense;
  double sum_wn = 0.0, sum_dq = 0.0, sum_wn2 = 0.0, sum_dqs = 0.0;
  uint64_t n = 0u;
  const selfcal_t *s = &a->selfcal;
  for (uint64_t k = 0; k < cap && s->state != SELFCAL_DONE && s->state != SELFCAL_FAILED;
       k += poll) {
    hal_host_run(poll);
    app_poll(a);
    sum_wn += plant_truth(p)->wn_drive_rad_s;
    sum_dq += plant_truth(p)->q_drive - q0;
    sum_wn2 += plant_truth(p)->wn_sense_rad_s;
    sum_dqs += plant_truth(p)->q_sense - qs0;
    n++;
  }
  out->true_sense_f0_hz = n ? sum_wn2 / (double)n / (2.0 * PLANT_PI) : NAN;
  out->true_sense_q = n ? qs0 + sum_dqs / (double)n : NAN;
  out->true_f0_hz = n ? sum_wn / (double)n / (2.0 * PLANT_PI) : NAN;
  /* the drive Q at the structure temperature (its law, plant.q_temp_law), mean over the
   * sweep */
  out->true_q = n ? q0 + sum_dq / (double)n : NAN;
  out->f0_hz = s->fit.q > 0.0 ? s->fit.f0_hz : NAN;
  out->q = s->fit.q > 0.0 ? s->fit.q : NAN;
  out->s = (double)(s->state == SELFCAL_DONE ? a->selfcal_ticks
                                             : app_ticks(a) - a->selfcal_t0_ticks) /
           fs;
  selfcal_sense_result(a, p, fs, out);
  if (s->state == SELFCAL_DONE) return 0;
  if (s->state == SELFCAL_FAILED)
    snprintf(out->why, sizeof out->why, "%s", s->why != NULL ? s->why : "failed");
  else snprintf(out->why, sizeof out->why, "still running after %g s", SELFCAL_MAX_S);
  return -1;
}

/* Keeps what the sweep identified as a user would: `drive off`, `save` (the parameter
 * store in the host flash, read back at the timeline's power-on). */
static int selfcal_save(app_t *a, sim_selfcal_t *out)
{
  char reply[1024];
  sc_cmd(a, "drive off\nsave\n", reply, sizeof reply);
  const char *sv = strstr(reply, "\r\n");
  if (strncmp(reply, "ok", 2) != 0 || sv == NULL ||
      (strncmp(sv + 2, "ok saved", 8) != 0 && strncmp(sv + 2, "ok unchanged", 12) != 0)) {
    char line[128];
    first_line(sv != NULL && strncmp(reply, "ok", 2) == 0 ? sv + 2 : reply, line, sizeof line);
    snprintf(out->why, sizeof out->why, "saving the identified values: %s", line);
    return -1;
  }
  out->saved = *params_current(&a->params);
  return 0;
}

/* The scenario's self-calibration: a plant at the initial conditions (inputs held at
 * their t = 0 values), the application from the scenario's parameters with an empty
 * store, `sweep`, then `drive off` and `save`. warm receives the temperatures it left.
 * Returns 0, -1 with err (could not run), -2 (the sweep failed: out->why). */
static int selfcal_run(const sim_scenario_t *sc, const plant_cfg_t *pc,
                       const plant_profiles_t *prof, const param_values_t *fw,
                       sim_selfcal_t *out, sim_warm_t *warm, char *err, size_t err_len)
{
  out->ran = 1;
  out->f0_hz = out->q = out->s = out->true_f0_hz = out->true_q = NAN;
  out->true_sense_f0_hz = out->true_sense_q = NAN;
  plant_profiles_t held;
  initial_profiles(prof, &held);
  plant_t *p = calloc(1, sizeof *p);
  app_t *a = calloc(1, sizeof *a);
  int rc = -1;
  if (p == NULL || a == NULL) {
    snprintf(err, err_len, "out of memory");
  } else if (plant_init(p, pc, sc->seed ^ 0x5eedca1u) != 0 ||
             /* noise of its own */ plant_set_profiles(p, &held) != 0) {
    snprintf(err, err_len, "plant: %s", plant_error(p));
  } else {
    (void)hal_flash_host_configure(NULL);
    hal_uart_host_reset();
    hal_host_attach(plant_step_hal, p);
    hal_host_attach_board_temp(plant_board_temp_hal, p);
    if (app_init_with(a, fw) != 0 ||
        hal_sample_timer_start(fw->sys_fs_hz, app_sample_isr, a) != 0) {
      snprintf(err, err_len, "firmware: application did not start");
    } else {
      rc = (selfcal_sweep(a, p, pc->fs_hz, out) == 0 && selfcal_save(a, out) == 0) ? 0 : -2;
      out->ok = rc == 0;
      for (int i = 0; i < THERMAL_NODES; i++) warm->t_k[i] = thermal_temp(&p->thermal, i);
    }
    hal_sample_timer_stop();
    hal_host_attach_board_temp(NULL, NULL); /* before p goes */
  }
  if (rc == -2) snprintf(err, err_len, "self-calibration failed: %s", out->why);
  free(p);
  free(a);
  return rc;
}

int sim_run_closed_loop(const sim_scenario_t *sc, const sim_opts_t *opt, sim_result_t *res,
                        char *err, size_t err_len)
{
  memset(res, 0, sizeof *res);
  plant_cfg_t pc;
  plant_profiles_t prof;
  param_values_t fw;
  if (sim_plant_cfg(sc, &pc, &prof, err, err_len) != 0) return -1;
  if (sim_fw_params(sc, &fw, err, err_len) != 0) return -1;
  if (fabs(pc.fs_hz - (double)fw.sys_fs_hz) > 1e-9) {
    snprintf(err, err_len, "plant.fs_hz %g differs from the firmware's sys.fs_hz %u", pc.fs_hz,
             fw.sys_fs_hz);
    return -1;
  }
  sim_warm_t warm;
  if (sc->selfcal) {
    const int sc_rc = selfcal_run(sc, &pc, &prof, &fw, &res->selfcal, &warm, err, err_len);
    if (sc_rc != 0) return sc_rc;
    fw = res->selfcal.saved;
  }
  const double fs = pc.fs_hz;
  uint64_t n_ticks = (uint64_t)llround(sc->duration_s * fs);
  cl_run_t r;
  if (cl_start(&r, sc, opt, &pc, &prof, &fw, sc->selfcal ? &warm : NULL, n_ticks, err,
               err_len) != 0) {
    cl_release(&r);
    return -1;
  }
  const app_t *app = r.app;
  const uint64_t csv_every = (uint64_t)fmax(1.0, llround(fs / opt->csv_rate_hz));
  progress_t pr = {opt->progress && !opt->uart_pty, wall_now(), 0.0, sc->duration_s};
  const double t_wall0 = wall_now(), t_cpu0 = cpu_now();
  cl_stats_t st = {.fw_lock_s = -1.0, .first_valid_s = -1.0};
  slip_init(&st.slip, (double)r.truth.decim / fs);
  res->n_cmds_run = 0;
  for (uint64_t k = 0; k < n_ticks; k++) {
    hal_host_run(1u);
    cl_commands(r.app, sc, (double)(k + 1u) / fs, res);
    const plant_truth_t *tr = plant_truth(r.plant);
    if (st.fw_lock_s < 0.0 && app->gyro.sup.mode == GYRO_MODE_LOCKED)
      st.fw_lock_s = (double)(k + 1u) / fs;
    if (app->gyro.out.rate_valid != 0u) {
      st.valid_ticks++;
      if (st.first_valid_s < 0.0) st.first_valid_s = (double)(k + 1u) / fs;
    }
    if ((k + 1u) % r.truth.decim == 0u) {
      if (r.truth.n < r.truth.cap) truth_sample(&r.truth, app, tr);
      slip_take(&st.slip, app, tr);
    }
    if (k % csv_every == 0u) {
      if (r.csv.f != NULL)
        sim_csv_row(&r.csv, tr, &app->gyro.out, nco_freq_of(app->gyro.nco.half_step, fs));
      st.sum_struct_k += tr->struct_k;
      st.sum_drive_freq_hz += tr->drive_freq_hz;
      st.sum_drive_amp_m += tr->drive_amp_m;
      st.n_mean++;
    }
    if ((k & 1023u) == 0u) {
      app_poll(r.app);
      progress_update(&pr, (double)k / fs, 0);
      if (opt->uart_pty && cl_pace(&r, (double)(k + 1u) / fs, t_wall0, opt->pace)) {
        n_ticks = k + 1u;
        break;
      }
    }
  }
  progress_update(&pr, sc->duration_s, 1);
  res->wall_s = wall_now() - t_wall0;
  res->cpu_s = cpu_now() - t_cpu0;
  res->sim_s = (double)n_ticks / fs;
  res->realtime_factor = res->wall_s > 0.0 ? res->sim_s / res->wall_s : 0.0;
  res->realtime_factor_cpu = res->cpu_s > 0.0 ? res->sim_s / res->cpu_s : 0.0;
  cl_results(&r, &st, &pc, n_ticks, res);
  cl_release(&r);
  return 0;
}

/* ------------------------------------------------------------------ open loop -- */

typedef struct {
  double psi, dpsi; /* half-frequency voltage phase and its advance per tick */
  double u_amp_v;
  int measuring;
  double acc_i, acc_q, acc_am;
  uint64_t acc_n;
  double v_per_code;
} ol_t;

/* The open-loop "firmware": half-frequency drive U1 = A cos(psi), U2 = A sin(psi), so
 * the force is Ks A^2 cos(2 psi) (6-18, 6-19); the drive pickoff is demodulated against
 * the same phase as a firmware sweep would (through the board's DAC latency). */
static void ol_isr(void *ctx)
{
  ol_t *o = ctx;
  const double phi = 2.0 * o->psi;
  if (o->measuring) {
    const double v = (double)hal_adc_frame()->drive * o->v_per_code;
    o->acc_i += v * cos(phi);
    o->acc_q += v * sin(phi);
    o->acc_n++;
  }
  hal_dac_frame_t dac;
  hal_dac_frame_midscale(&dac); /* every channel: the sense electrodes' at 0 V */
  dac.code[HAL_DAC_DRIVE_U1] = dac_v_to_code(o->u_amp_v * cos(o->psi));
  dac.code[HAL_DAC_DRIVE_U2] = dac_v_to_code(o->u_amp_v * sin(o->psi));
  hal_dac_write_frame(&dac);
  o->psi += o->dpsi;
  if (o->psi > 2.0 * PLANT_PI) o->psi -= 2.0 * PLANT_PI;
}

/* Drive at f_hz with amplitude u for dwell_s; measure over the whole cycles after
 * settle_s. Returns amplitude (V at the ADC) and phase against the force. */
static void ol_point(ol_t *o, plant_t *plant, double fs, double f_hz, double u, double settle_s,
                     double dwell_s, double *amp_v, double *phase_deg, double *amp_m,
                     sim_csv_t *csv, uint64_t *k, uint64_t csv_every)
{
  o->dpsi = PLANT_PI * f_hz / fs;
  o->u_amp_v = u;
  const uint64_t n_settle = (uint64_t)llround(settle_s * fs);
  const double cycles = floor((dwell_s - settle_s) * f_hz);
  const uint64_t n_meas = (uint64_t)llround(fmax(cycles, 1.0) * fs / f_hz);
  o->measuring = 0;
  o->acc_i = o->acc_q = 0.0;
  o->acc_n = 0;
  double sum_am = 0.0;
  for (uint64_t i = 0; i < n_settle + n_meas; i++) {
    if (i == n_settle) o->measuring = 1;
    hal_host_run(1u);
    if (o->measuring) sum_am += plant_truth(plant)->drive_amp_m;
    if (csv->f != NULL && (*k)++ % csv_every == 0u)
      sim_csv_row(csv, plant_truth(plant), NULL, plant_truth(plant)->drive_freq_hz);
  }
  const double n = (double)o->acc_n;
  *amp_v = 2.0 * hypot(o->acc_i, o->acc_q) / n;
  *phase_deg = atan2(-o->acc_q, o->acc_i) * 180.0 / PLANT_PI;
  *amp_m = sum_am / n;
}

int sim_run_open_loop(const sim_scenario_t *sc, const sim_opts_t *opt, sim_result_t *res,
                      sim_sweep_t *sweep, sim_square_t *sq, char *err, size_t err_len)
{
  memset(res, 0, sizeof *res);
  sweep->n = 0;
  sq->n = 0;
  plant_cfg_t pc;
  plant_profiles_t prof;
  if (sim_plant_cfg(sc, &pc, &prof, err, err_len) != 0) return -1;
  plant_t *plant = calloc(1, sizeof *plant);
  if (plant == NULL) {
    snprintf(err, err_len, "out of memory");
    return -1;
  }
  if (plant_init(plant, &pc, sc->seed) != 0 || plant_set_profiles(plant, &prof) != 0) {
    snprintf(err, err_len, "plant: %s", plant_error(plant));
    free(plant);
    return -1;
  }
  const double fs = pc.fs_hz;
  ol_t o;
  memset(&o, 0, sizeof o);
  o.v_per_code = pc.adc_full_scale_v / 32768.0;
  hal_host_attach(plant_step_hal, plant);
  (void)hal_sample_timer_start((uint32_t)llround(fs), ol_isr, &o);
  sim_csv_t csv;
  memset(&csv, 0, sizeof csv);
  if (opt->csv_path != NULL && sim_csv_open(&csv, opt->csv_path, err, err_len) != 0) {
    free(plant);
    return -1;
  }
  const uint64_t csv_every = (uint64_t)fmax(1.0, llround(fs / opt->csv_rate_hz));
  uint64_t k = 0;
  const double t_wall0 = wall_now(), t_cpu0 = cpu_now();
  progress_t pr = {opt->progress, t_wall0, 0.0, 0.0};
  double am;
  if (sc->loop == SIM_OPEN_LOOP_SWEEP) {
    const int np = sc->ol.points > 10000 ? 10000 : sc->ol.points;
    pr.total_s = np * sc->ol.dwell_s;
    for (int i = 0; i < np; i++) {
      const double f = sc->ol.f_start_hz + (sc->ol.f_stop_hz - sc->ol.f_start_hz) * i / (np - 1);
      ol_point(&o, plant, fs, f, sc->ol.u_amp_v, sc->ol.settle_s, sc->ol.dwell_s,
               &sweep->amp_v[i], &sweep->phase_deg[i], &am, &csv, &k, csv_every);
      sweep->f_hz[i] = f;
      sweep->n = i + 1;
      progress_update(&pr, (double)hal_host_ticks() / fs, 0);
    }
  } else {
    const int na = sc->ol.n_amps > 0 ? sc->ol.n_amps : 1;
    pr.total_s = na * sc->ol.dwell_s;
    for (int i = 0; i < na; i++) {
      const double u = sc->ol.n_amps > 0 ? sc->ol.amps_v[i] : sc->ol.u_amp_v;
      double ph;
      ol_point(&o, plant, fs, sc->ol.freq_hz, u, sc->ol.settle_s, sc->ol.dwell_s, &sq->amp_v[i],
               &ph, &sq->amp_m[i], &csv, &k, csv_every);
      sq->u_v[i] = u;
      sq->n = i + 1;
      progress_update(&pr, (double)hal_host_ticks() / fs, 0);
    }
  }
  progress_update(&pr, (double)hal_host_ticks() / fs, 1);
  res->wall_s = wall_now() - t_wall0;
  res->cpu_s = cpu_now() - t_cpu0;
  res->sim_s = (double)hal_host_ticks() / fs;
  res->realtime_factor = res->wall_s > 0.0 ? res->sim_s / res->wall_s : 0.0;
  res->realtime_factor_cpu = res->cpu_s > 0.0 ? res->sim_s / res->cpu_s : 0.0;
  res->adc_clips[0] = plant_truth(plant)->adc_clip[0];
  res->adc_clips[1] = plant_truth(plant)->adc_clip[1];
  memcpy(res->plant_warnings, plant_warnings(plant), sizeof res->plant_warnings);
  res->dac_rejects = plant_truth(plant)->dac_rejects;
  (void)plant_adc_fraction(&pc, res->adc_fraction);
  sim_csv_close(&csv);
  hal_sample_timer_stop();
  free(plant);
  return 0;
}
