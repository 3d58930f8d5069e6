#include "gyro/selfcal.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "dsp/nco.h"

#define SC_MIN_PEAK_V 0.02 /* chirp peak below this: not resolved from the noise */
#define SC_MAX_RETRIES 6u
#define SC_EXCITE_MAX_S 1.5 /* ring-down excitation, at most */
#define SC_RING_MAX_S 2.0   /* Q up to pi f 2 s */
#define SC_AVG_S 0.1
#define SC_SETTLE_TAU 7.0
#define SC_HOLD_TAU 6.0

/* Nine points: the fit needs four unknowns, an exported sweep (`sweep points`) needs at
 * least eight for gyro-freqresp's five; the flanks at +-1.5 half bandwidths are where a
 * wrong Q shows most. */
#define SC_STEP_PTS 9u
static const double k_offsets[SC_STEP_PTS] = {-2.0, -1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0};
_Static_assert(SC_STEP_PTS <= SELFCAL_MAX_PTS, "the executive holds SELFCAL_MAX_PTS points");

static uint32_t ticks_of(double t_s, double fs_hz)
{
  const double n = t_s * fs_hz;
  return n < 1.0 ? 1u : (n > 4.0e9 ? 4000000000u : (uint32_t)n);
}

const char *selfcal_state_name(selfcal_state_t st)
{
  static const char *const names[] = {"IDLE",       "WAIT_SWEEP", "QUIET_UP", "CHIRP_UP",
                                      "QUIET_DOWN", "CHIRP_DOWN", "RINGDOWN", "FINE",
                                      "HOLD",       "READY",      "DONE",     "FAILED"};
  const unsigned i = (unsigned)st;
  return i < sizeof names / sizeof names[0] ? names[i] : "?";
}

int selfcal_init(selfcal_t *s, selfcal_exec_t *x)
{
  if (s == NULL || x == NULL) return -1;
  memset(s, 0, sizeof *s);
  s->x = x;
  s->state = SELFCAL_IDLE;
  return 0;
}

int selfcal_running(const selfcal_t *s)
{
  return s->state != SELFCAL_IDLE && s->state != SELFCAL_DONE && s->state != SELFCAL_FAILED;
}

int selfcal_start(selfcal_t *s, const selfcal_cfg_t *c)
{
  if (s == NULL || c == NULL || s->x == NULL || selfcal_running(s)) return -1;
  if (!(c->fs_hz > 0.0) || !(c->f_lo_hz > 0.0) || !(c->f_hi_hz > c->f_lo_hz) ||
      !(c->f_hi_hz < 0.25 * c->fs_hz) || !(c->chirp_hz_per_s > 0.0) || !(c->quiet_s >= 0.0) ||
      !(c->amp_max_v > 0.0) || !(c->amp_meas_v > 0.0 && c->amp_meas_v < c->amp_max_v) ||
      !(c->f_cmd_start_v2 > 0.0) || !(c->f_cmd_max_v2 >= c->f_cmd_start_v2) ||
      !(c->amp_set_v > 0.0 && c->amp_set_v < c->amp_max_v) || !isfinite(c->phase_set_rad) ||
      !(c->delay_s >= 0.0)) {
    return -1;
  }
  selfcal_exec_t *x = s->x;
  memset(s, 0, sizeof *s);
  s->x = x;
  s->cfg = *c;
  s->f_cmd_v2 = c->f_cmd_start_v2;
  s->state = SELFCAL_WAIT_SWEEP;
  s->watch_state = SELFCAL_IDLE; /* the first watch starts the clock of WAIT_SWEEP */
  return 0;
}

static void fail(selfcal_t *s, const char *why)
{
  s->why = why;
  s->state = SELFCAL_FAILED;
}

static void base_job(const selfcal_t *s, selfcal_job_t *j, selfcal_job_kind_t kind)
{
  memset(j, 0, sizeof *j);
  j->kind = (uint32_t)kind;
  j->amp_max_v = (float)s->cfg.amp_max_v;
  j->f_cmd_v2 = (float)s->f_cmd_v2;
}

/* The longest a job can run, samples: every phase it may have, each at its longest (a
 * ring-down is an excitation and a decay of avg_ticks each). */
static uint32_t job_bound_ticks(const selfcal_job_t *j)
{
  const uint64_t per_pt = (uint64_t)j->step_settle_ticks + j->avg_ticks;
  const uint64_t n = (uint64_t)j->chirp_ticks + j->settle_ticks +
                     ((uint64_t)j->n_pts + 2u) * per_pt;
  return n > 1000000000u ? 1000000000u : (uint32_t)n;
}

static void post(selfcal_t *s, const selfcal_job_t *j, selfcal_state_t next)
{
  if (selfcal_exec_post(s->x, j) != 0) {
    fail(s, "measurement job refused");
    return;
  }
  s->job_bound_ticks = job_bound_ticks(j);
  s->watch_state = SELFCAL_IDLE; /* a new job: selfcal_watch restarts its clock */
  s->state = next;
}

static void post_quiet(selfcal_t *s, selfcal_state_t next)
{
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_QUIET);
  j.f_cmd_v2 = 0.0f;
  j.half_step[0] = nco_half_step_of(s->cfg.f_lo_hz, s->cfg.fs_hz);
  j.avg_ticks = ticks_of(s->cfg.quiet_s, s->cfg.fs_hz);
  post(s, &j, next);
}

static void post_chirp(selfcal_t *s, int up, selfcal_state_t next)
{
  const selfcal_cfg_t *c = &s->cfg;
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_CHIRP);
  const uint32_t lo = nco_half_step_of(c->f_lo_hz, c->fs_hz),
                 hi = nco_half_step_of(c->f_hi_hz, c->fs_hz);
  j.chirp_ticks = ticks_of((c->f_hi_hz - c->f_lo_hz) / c->chirp_hz_per_s, c->fs_hz);
  const int32_t d = (int32_t)((hi - lo) / j.chirp_ticks);
  j.chirp_delta = up ? d : -d;
  j.half_step[0] = up ? lo : hi;
  post(s, &j, next);
}

/* Steps around (centre, half bandwidth hb) at a force that puts the peak at amp_meas. */
static void post_steps(selfcal_t *s, double f_c, double hb, double tau_s, double gain)
{
  const selfcal_cfg_t *c = &s->cfg;
  /* The plan spans f_c +- 2 hb = f_c (1 +- 1/Q): below Q = 2 its lowest point would lie
   * under half the centre (at or below 0 Hz for Q <= 1), which no drive part has. */
  if (!(f_c - 2.0 * hb >= 0.5 * f_c) || !(f_c + 2.0 * hb < 0.25 * c->fs_hz)) {
    fail(s, "Q below 2: no stepped plan around the resonance");
    return;
  }
  selfcal_job_t j;
  double f_cmd = c->amp_meas_v / gain;
  if (f_cmd > c->f_cmd_max_v2) f_cmd = c->f_cmd_max_v2;
  s->f_cmd_v2 = f_cmd;
  base_job(s, &j, SELFCAL_JOB_STEPS);
  j.n_pts = SC_STEP_PTS;
  for (uint32_t i = 0; i < SC_STEP_PTS; i++) {
    j.half_step[i] = nco_half_step_of(f_c + k_offsets[i] * hb, c->fs_hz);
  }
  j.settle_ticks = ticks_of((SC_SETTLE_TAU + 1.0) * tau_s, c->fs_hz);
  j.step_settle_ticks = ticks_of(SC_SETTLE_TAU * tau_s, c->fs_hz);
  if (j.step_settle_ticks < 256u) j.step_settle_ticks = 256u;
  if (j.settle_ticks < 256u) j.settle_ticks = 256u;
  j.avg_ticks = ticks_of(SC_AVG_S, c->fs_hz);
  s->plan_f_hz = f_c;
  s->plan_hb_hz = hb;
  post(s, &j, SELFCAL_FINE);
}

static int more_force(selfcal_t *s, double peak_v)
{
  if (s->f_cmd_v2 >= s->cfg.f_cmd_max_v2 || ++s->retries > SC_MAX_RETRIES) return -1;
  double f = peak_v > 0.0 ? s->f_cmd_v2 * 4.0 * SC_MIN_PEAK_V / peak_v : s->f_cmd_v2 * 8.0;
  if (f < 2.0 * s->f_cmd_v2) f = 2.0 * s->f_cmd_v2;
  s->f_cmd_v2 = f > s->cfg.f_cmd_max_v2 ? s->cfg.f_cmd_max_v2 : f;
  return 0;
}

static int less_force(selfcal_t *s)
{
  if (++s->retries > SC_MAX_RETRIES) return -1;
  s->f_cmd_v2 *= 0.25;
  return 0;
}

static void on_chirp(selfcal_t *s, const selfcal_result_t *r, int up)
{
  const selfcal_cfg_t *c = &s->cfg;
  if (r->aborted != 0u) {
    if (less_force(s) != 0) fail(s, "amplitude over the ADC budget at the smallest force");
    else post_quiet(s, up ? SELFCAL_QUIET_UP : SELFCAL_QUIET_DOWN);
    return;
  }
  if ((double)r->peak_amp_v < SC_MIN_PEAK_V) {
    if (more_force(s, (double)r->peak_amp_v) != 0)
      fail(s, "no resonance found in the search range");
    else post_quiet(s, up ? SELFCAL_QUIET_UP : SELFCAL_QUIET_DOWN);
    return;
  }
  const double f = nco_freq_of(r->peak_half_step, c->fs_hz);
  if (up) {
    s->f_up_hz = f;
    s->chirp_peak_v = (double)r->peak_amp_v;
    post_quiet(s, SELFCAL_QUIET_DOWN);
    return;
  }
  s->f_down_hz = f;
  if ((double)r->peak_amp_v > s->chirp_peak_v) s->chirp_peak_v = (double)r->peak_amp_v;
  s->f_coarse_hz = 0.5 * (s->f_up_hz + s->f_down_hz);
  if (!(s->f_coarse_hz > c->f_lo_hz && s->f_coarse_hz < c->f_hi_hz)) {
    fail(s, "resonance at the edge of the search range");
    return;
  }
  selfcal_job_t j;
  double f_cmd = s->f_cmd_v2 * c->amp_meas_v / s->chirp_peak_v;
  s->f_cmd_v2 = f_cmd > c->f_cmd_max_v2 ? c->f_cmd_max_v2 : f_cmd;
  base_job(s, &j, SELFCAL_JOB_RINGDOWN);
  j.half_step[0] = nco_half_step_of(s->f_coarse_hz, c->fs_hz);
  j.amp_target_v = (float)c->amp_meas_v;
  j.avg_ticks = ticks_of(SC_EXCITE_MAX_S > SC_RING_MAX_S ? SC_EXCITE_MAX_S : SC_RING_MAX_S,
                         c->fs_hz);
  post(s, &j, SELFCAL_RINGDOWN);
}

static void on_ringdown(selfcal_t *s, const selfcal_result_t *r)
{
  const selfcal_cfg_t *c = &s->cfg;
  if ((double)r->rd_amp0_v < SC_MIN_PEAK_V || r->rd_ticks < 8u) {
    if (more_force(s, (double)r->rd_amp0_v) != 0) {
      fail(s, "ring-down too small to measure");
      return;
    }
    selfcal_job_t j = s->x->job;
    j.f_cmd_v2 = (float)s->f_cmd_v2;
    post(s, &j, SELFCAL_RINGDOWN);
    return;
  }
  const double tau = (double)r->rd_ticks / c->fs_hz;
  s->rd_f_hz = s->f_coarse_hz + (double)r->rd_phase_rad / (2.0 * FM_PI * tau);
  s->rd_q = FM_PI * s->rd_f_hz * tau;
  /* Steady-state gain at the peak from the excitation phase: the amplitude grew as
   * 1 - e^{-t/tau} towards |H(f_c)| f_cmd, and |H(f_c)| is below the peak by the
   * detuning factor of the first-order envelope model (6-12). */
  const double t_ex = (double)(r->ticks - r->rd_ticks) / c->fs_hz;
  const double grown = 1.0 - exp(-t_ex / tau);
  const double det = 2.0 * s->rd_q * (s->f_coarse_hz - s->rd_f_hz) / s->rd_f_hz;
  s->rd_gain = (double)r->rd_amp0_v / ((double)r->rd_f_cmd_v2 * (grown > 0.05 ? grown : 0.05)) *
               sqrt(1.0 + det * det);
  if (!(s->rd_q > 0.5) || !(s->rd_f_hz > c->f_lo_hz && s->rd_f_hz < c->f_hi_hz) ||
      !isfinite(s->rd_gain)) {
    fail(s, "ring-down not consistent with a resonance");
    return;
  }
  post_steps(s, s->rd_f_hz, s->rd_f_hz / (2.0 * s->rd_q), tau, s->rd_gain);
}

static void on_steps(selfcal_t *s, const selfcal_result_t *r)
{
  const selfcal_cfg_t *c = &s->cfg;
  const selfcal_job_t *j = &s->x->job;
  selfcal_point_t pts[SELFCAL_MAX_PTS];
  for (uint32_t i = 0; i < j->n_pts && s->n_pts < SELFCAL_EXPORT_MAX; i++) {
    selfcal_export_pt_t *e = &s->pts[s->n_pts++];
    e->half_step = j->half_step[i];
    e->z_re = r->z_re[i];
    e->z_im = r->z_im[i];
    e->f_cmd_v2 = r->f_cmd_v2[i];
    e->stage = s->refits + 1u;
  }
  for (uint32_t i = 0; i < j->n_pts; i++) {
    /* P = 0 during the steps: H = Z / f_cmd. */
    const double f = (double)r->f_cmd_v2[i];
    pts[i].f_hz = nco_freq_of(j->half_step[i], c->fs_hz);
    pts[i].h_re = (double)r->z_re[i] / f;
    pts[i].h_im = (double)r->z_im[i] / f;
  }
  selfcal_fit_t fit;
  double delay_s = c->delay_s;
  /* The converter delay is known; what the analog chain adds (up to 8 samples) is
   * identified with the model (selfcal_fit_delay). */
  if (selfcal_fit_delay(pts, j->n_pts, c->delay_s, c->delay_s + 8.0 / c->fs_hz, &fit,
                        &delay_s) != 0 ||
      !(fit.rms_rel < 0.05) || !(fit.f0_hz > c->f_lo_hz && fit.f0_hz < c->f_hi_hz) ||
      !(fit.q >= 1.0 && fit.q < 1.0e6)) {
    fail(s, "frequency response does not fit a resonance");
    return;
  }
  s->fit = fit;
  s->delay_s = delay_s;
  const double hb = fit.f0_hz / (2.0 * fit.q);
  const double tau = 2.0 * fit.q / (2.0 * FM_PI * fit.f0_hz);
  if ((fabs(fit.f0_hz - s->plan_f_hz) > 0.25 * hb || fabs(hb / s->plan_hb_hz - 1.0) > 0.2) &&
      s->refits < 1u) {
    s->refits++;
    post_steps(s, fit.f0_hz, hb, tau, fit.gain_v_per_v2);
    return;
  }
  /* Hold at the identified resonance, at the loop's set point. */
  s->f0_hz_f = (float)fit.f0_hz;
  s->hold_f_cmd_v2 = c->amp_set_v / fit.gain_v_per_v2;
  s->hold_p_rad = remainder(c->phase_set_rad - fit.phase_rad, 2.0 * FM_PI);
  if (!(s->hold_f_cmd_v2 < c->f_cmd_max_v2)) {
    fail(s, "the amplitude set point needs more force than the drive has");
    return;
  }
  selfcal_job_t h;
  base_job(s, &h, SELFCAL_JOB_HOLD);
  h.f_cmd_v2 = (float)s->hold_f_cmd_v2;
  h.p_rad = (float)s->hold_p_rad;
  h.half_step[0] = nco_half_step_of((double)s->f0_hz_f, c->fs_hz);
  h.avg_ticks = ticks_of(SC_HOLD_TAU * tau > 0.02 ? SC_HOLD_TAU * tau : 0.02, c->fs_hz);
  post(s, &h, SELFCAL_HOLD);
}

selfcal_state_t selfcal_background(selfcal_t *s, int sweeping)
{
  if (s == NULL) return SELFCAL_FAILED;
  if (!selfcal_running(s)) return s->state;
  if (s->state == SELFCAL_WAIT_SWEEP) {
    if (sweeping) post_quiet(s, SELFCAL_QUIET_UP);
    return s->state;
  }
  if (!sweeping) {
    fail(s, "sweep interrupted (fault or drive command)");
    return s->state;
  }
  if (s->state == SELFCAL_READY) return s->state;
  selfcal_result_t r;
  if (!selfcal_exec_poll(s->x, &r)) return s->state;
  s->ticks += r.ticks;
  switch (s->state) {
  case SELFCAL_QUIET_UP: post_chirp(s, 1, SELFCAL_CHIRP_UP); break;
  case SELFCAL_QUIET_DOWN: post_chirp(s, 0, SELFCAL_CHIRP_DOWN); break;
  case SELFCAL_CHIRP_UP: on_chirp(s, &r, 1); break;
  case SELFCAL_CHIRP_DOWN: on_chirp(s, &r, 0); break;
  case SELFCAL_RINGDOWN: on_ringdown(s, &r); break;
  case SELFCAL_FINE: on_steps(s, &r); break;
  case SELFCAL_HOLD: s->state = SELFCAL_READY; break;
  case SELFCAL_IDLE:
  case SELFCAL_WAIT_SWEEP:
  case SELFCAL_READY:
  case SELFCAL_DONE:
  case SELFCAL_FAILED: break;
  }
  return s->state;
}

void selfcal_finish(selfcal_t *s, int ok, const char *why)
{
  if (s == NULL || s->state != SELFCAL_READY) return;
  if (ok) {
    s->state = SELFCAL_DONE;
  } else {
    fail(s, why != NULL ? why : "parameters refused");
  }
}

void selfcal_abort(selfcal_t *s, const char *why)
{
  if (s != NULL && selfcal_running(s)) fail(s, why);
}

uint32_t selfcal_export_count(const selfcal_t *s)
{
  return s == NULL || selfcal_running(s) ? 0u : s->n_pts;
}

double selfcal_export_f_hz(const selfcal_t *s, uint32_t i)
{
  return s == NULL || i >= s->n_pts ? 0.0 : nco_freq_of(s->pts[i].half_step, s->cfg.fs_hz);
}

void selfcal_watch(selfcal_t *s, uint32_t now_ticks)
{
  if (s == NULL || !selfcal_running(s)) return;
  if (s->state != s->watch_state) {
    s->watch_state = s->state;
    s->watch_t0 = now_ticks;
    return;
  }
  const double fs = s->cfg.fs_hz;
  double limit_s = 1.0;
  if (s->state == SELFCAL_WAIT_SWEEP) {
    limit_s = 0.1;
  } else if (s->state != SELFCAL_READY) {
    limit_s = 2.0 * (double)s->job_bound_ticks / fs + 1.0;
  }
  if ((double)(uint32_t)(now_ticks - s->watch_t0) > limit_s * fs) {
    fail(s, s->state == SELFCAL_WAIT_SWEEP ? "the drive never entered SWEEP"
                                           : "sweep step timed out");
  }
}
