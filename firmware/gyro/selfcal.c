#include "gyro/selfcal.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "dsp/nco.h"
#include "gyro/gyro_dac.h" /* the tuning electrodes' code (S2, S4) */
#include "gyro/sense_tune.h"

#define SC_MIN_PEAK_V 0.02 /* chirp peak below this: not resolved from the noise */
#define SC_MAX_RETRIES 6u
#define SC_EXCITE_MAX_S 3.0 /* ring-down excitation, at most */
/* The decay is followed to 1/e or for this long, whichever comes first: beyond Q = pi f
 * 8 s (25,000 at 1 kHz) the log-amplitude slope over 8 s gives tau (6-12), at Q = 10^5
 * an amplitude ratio of e^-0.37 at 1490 Hz. */
#define SC_RING_MAX_S 8.0
/* Nine settled steps while tau <= 0.25 s (Q <= 980 at 1250 Hz, 1170 at 1490 Hz): with
 * the second placement they take at most 2 (8 + 8 x 7) tau + 1.6 s = 34 s. Beyond, the
 * ring-down's own f0 and Q are the result and one point at the resonance, settled for
 * SC_ONE_SETTLE_TAU, gives |H(wn)| and arg H(wn) for the hold. */
#define SC_STEPS_MAX_TAU_S 0.25
#define SC_ONE_SETTLE_TAU 6.0
/* The second decay (post_decay): nine means, the first after the demodulator has
 * settled on the new NCO frequency. */
#define SC_DECAY_PTS 9u
#define SC_DECAY_SETTLE_S 0.05
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

/* The search range and force of the mode the chain identifies now: the drive's, or the
 * sense mode's through the feedback pair (S1, selfcal.h). */
typedef struct {
  double f_lo_hz, f_hi_hz, f_cmd_max_v2; /* (the first force: each chain's start) */
} sc_range_t;

static sc_range_t rng(const selfcal_t *s)
{
  const selfcal_cfg_t *c = &s->cfg;
  const sc_range_t d = {c->f_lo_hz, c->f_hi_hz, c->f_cmd_max_v2};
  const sc_range_t m = {c->s_f_lo_hz, c->s_f_hi_hz, c->s_f_cmd_max_v2};
  return s->sense_phase != 0u ? m : d;
}

const char *selfcal_state_name(selfcal_state_t st)
{
  static const char *const names[] = {
      "IDLE",     "WAIT_SWEEP", "QUIET_UP",    "CHIRP_UP", "QUIET_DOWN", "CHIRP_DOWN",
      "RINGDOWN", "FINE",       "HOLD",        "READY",    "DONE",       "FAILED",
      "REBURST",  "SENSE_TUNE", "SENSE_QUIET", "SENSE_WC", "SENSE_MATCH"};
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
  if (c->sense != 0u && (!(c->s_f_lo_hz > 0.0) || !(c->s_f_hi_hz > c->s_f_lo_hz) ||
                         !(c->s_f_hi_hz < 0.25 * c->fs_hz) || !(c->s_f_cmd_start_v2 > 0.0) ||
                         !(c->s_f_cmd_max_v2 >= c->s_f_cmd_start_v2) ||
                         !(c->s_quiet_s >= 0.0) || !(c->tune_probe_v >= 0.0) ||
                         !isfinite(c->demod_phase_rad) || !(c->amp_clip_v >= c->amp_max_v))) {
    return -1;
  }
  if (c->tune_mode > SENSE_TUNE_SPLIT ||
      (c->tune_mode != SENSE_TUNE_OFF &&
       (!(c->tune_split_hz >= 0.0 && c->tune_split_hz < c->s_f_hi_hz) ||
        !(c->tune_v_max_v > 0.0 && c->tune_v_max_v <= 15.0)))) {
    return -1;
  }
  selfcal_exec_t *x = s->x;
  memset(s, 0, sizeof *s);
  s->x = x;
  s->cfg = *c;
  s->f_cmd_v2 = c->f_cmd_start_v2;
  s->match_code = (uint16_t)HAL_DAC_CODE_MID;
  s->state = SELFCAL_WAIT_SWEEP;
  s->watch_state = SELFCAL_IDLE; /* the first watch starts the clock of WAIT_SWEEP */
  return 0;
}

static void drive_begin(selfcal_t *s);

static void fail(selfcal_t *s, const char *why)
{
  if (s->sense_phase != 0u) {
    /* S1 or S2 could not identify the sense mode: its reason, nothing of it staged, and
     * the drive's identification goes on (selfcal.h). */
    s->sense.state = SELFCAL_SENSE_FAILED;
    s->sense.why = why;
    drive_begin(s);
    return;
  }
  s->why = why;
  s->state = SELFCAL_FAILED;
}

static void base_job(const selfcal_t *s, selfcal_job_t *j, selfcal_job_kind_t kind)
{
  memset(j, 0, sizeof *j);
  j->kind = (uint32_t)kind;
  j->amp_max_v = (float)s->cfg.amp_max_v;
  j->f_cmd_v2 = (float)s->f_cmd_v2;
  j->sense = s->sense_phase;
  j->tune_code = j->tune_ring_code = (uint16_t)HAL_DAC_CODE_MID;
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

static void post_quiet_for(selfcal_t *s, selfcal_state_t next, double t_s)
{
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_QUIET);
  j.f_cmd_v2 = 0.0f;
  j.half_step[0] = nco_half_step_of(rng(s).f_lo_hz, s->cfg.fs_hz);
  j.avg_ticks = ticks_of(t_s, s->cfg.fs_hz);
  post(s, &j, next);
}

static void post_quiet(selfcal_t *s, selfcal_state_t next)
{
  post_quiet_for(s, next, s->cfg.quiet_s);
}

static void post_chirp(selfcal_t *s, int up, selfcal_state_t next)
{
  const selfcal_cfg_t *c = &s->cfg;
  const sc_range_t m = rng(s);
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_CHIRP);
  const uint32_t lo = nco_half_step_of(m.f_lo_hz, c->fs_hz),
                 hi = nco_half_step_of(m.f_hi_hz, c->fs_hz);
  j.chirp_ticks = ticks_of((m.f_hi_hz - m.f_lo_hz) / c->chirp_hz_per_s, c->fs_hz);
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
  const double f_max = rng(s).f_cmd_max_v2;
  double f_cmd = c->amp_meas_v / gain;
  if (f_cmd > f_max) f_cmd = f_max;
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

/* One point at the ring-down's resonance (high Q), at a force that puts it at amp_meas. */
static void post_one(selfcal_t *s, double tau_s)
{
  const selfcal_cfg_t *c = &s->cfg;
  selfcal_job_t j;
  double f_cmd = c->amp_meas_v / s->rd_gain;
  if (f_cmd > c->f_cmd_max_v2) f_cmd = c->f_cmd_max_v2;
  s->f_cmd_v2 = f_cmd;
  base_job(s, &j, SELFCAL_JOB_STEPS);
  j.n_pts = 1u;
  j.half_step[0] = nco_half_step_of(s->fit.f0_hz, c->fs_hz);
  j.settle_ticks = j.step_settle_ticks = ticks_of(SC_ONE_SETTLE_TAU * tau_s, c->fs_hz);
  j.avg_ticks = ticks_of(SC_AVG_S, c->fs_hz);
  s->plan_f_hz = s->fit.f0_hz;
  s->plan_hb_hz = s->fit.f0_hz / (2.0 * s->fit.q);
  s->one_point = 1u;
  post(s, &j, SELFCAL_FINE);
}

/* High Q, the tracking drive: |H(wn)| and arg H(wn) from a burst at f0 instead of a
 * point settled for SC_ONE_SETTLE_TAU (128 s at Q = 10^5). From the decay's remains z0,
 * the force F makes Z(t) = z_inf + (z0 - z_inf) e^{-t/tau} with z_inf = H(wn) F (6-12);
 * SC_BURST_PTS means over SC_AVG_S after SC_DECAY_SETTLE_S give z_inf and z0 by least
 * squares (on_burst). F is chosen for a rise of about amp_meas / 2 over the burst from
 * the ring-down's gain. */
#define SC_BURST_PTS 4u
/* A burst over the ADC budget, or ending above amp_meas_v (the ring-down's gain under
 * the resonance's: on a Q 13345 part the budget was reached in 86 ms of the 0.45 s
 * planned): the drive off until the vibration has decayed by SC_REBURST_DECAY (tau ln of
 * it), then the burst again with SC_REBURST_FORCE of the force, within SC_MAX_RETRIES. */
#define SC_REBURST_DECAY 4.0
#define SC_REBURST_FORCE 0.125
static void post_burst_at(selfcal_t *s, double f_cmd);

static void post_burst(selfcal_t *s, double tau_s)
{
  const selfcal_cfg_t *c = &s->cfg;
  const double t_b = SC_DECAY_SETTLE_S + SC_BURST_PTS * SC_AVG_S;
  double f_cmd = 0.5 * c->amp_meas_v * tau_s / (t_b * s->rd_gain);
  post_burst_at(s, f_cmd);
}

static void post_reburst_wait(selfcal_t *s, double tau_s)
{
  if (++s->retries > SC_MAX_RETRIES) {
    fail(s, "no response at the resonance");
    return;
  }
  s->f_cmd_v2 *= SC_REBURST_FORCE;
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_QUIET);
  j.f_cmd_v2 = 0.0f;
  j.half_step[0] = nco_half_step_of(s->fit.f0_hz, s->cfg.fs_hz);
  j.avg_ticks = ticks_of(tau_s * log(SC_REBURST_DECAY), s->cfg.fs_hz);
  post(s, &j, SELFCAL_REBURST);
}

static void post_burst_at(selfcal_t *s, double f_cmd)
{
  const selfcal_cfg_t *c = &s->cfg;
  if (f_cmd > c->f_cmd_max_v2) f_cmd = c->f_cmd_max_v2;
  s->f_cmd_v2 = f_cmd;
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_STEPS);
  j.n_pts = SC_BURST_PTS;
  for (uint32_t i = 0; i < SC_BURST_PTS; i++)
    j.half_step[i] = nco_half_step_of(s->fit.f0_hz, c->fs_hz);
  j.settle_ticks = ticks_of(SC_DECAY_SETTLE_S, c->fs_hz);
  j.step_settle_ticks = 0u;
  j.avg_ticks = ticks_of(SC_AVG_S, c->fs_hz);
  s->plan_f_hz = s->fit.f0_hz;
  s->plan_hb_hz = s->fit.f0_hz / (2.0 * s->fit.q);
  s->one_point = 1u;
  s->burst = 1u;
  post(s, &j, SELFCAL_FINE);
}

static int more_force(selfcal_t *s, double peak_v)
{
  const double f_max = rng(s).f_cmd_max_v2;
  if (s->f_cmd_v2 >= f_max || ++s->retries > SC_MAX_RETRIES) return -1;
  double f = peak_v > 0.0 ? s->f_cmd_v2 * 4.0 * SC_MIN_PEAK_V / peak_v : s->f_cmd_v2 * 8.0;
  if (f < 2.0 * s->f_cmd_v2) f = 2.0 * s->f_cmd_v2;
  s->f_cmd_v2 = f > f_max ? f_max : f;
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
  const sc_range_t m = rng(s);
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
  if (!(s->f_coarse_hz > m.f_lo_hz && s->f_coarse_hz < m.f_hi_hz)) {
    fail(s, "resonance at the edge of the search range");
    return;
  }
  selfcal_job_t j;
  double f_cmd = s->f_cmd_v2 * c->amp_meas_v / s->chirp_peak_v;
  s->f_cmd_v2 = f_cmd > m.f_cmd_max_v2 ? m.f_cmd_max_v2 : f_cmd;
  base_job(s, &j, SELFCAL_JOB_RINGDOWN);
  j.half_step[0] = nco_half_step_of(s->f_coarse_hz, c->fs_hz);
  j.amp_target_v = (float)c->amp_meas_v;
  j.settle_ticks = ticks_of(SC_EXCITE_MAX_S, c->fs_hz);
  j.avg_ticks = ticks_of(SC_RING_MAX_S, c->fs_hz);
  post(s, &j, SELFCAL_RINGDOWN);
}

/* High Q: the decay excited at f_c, off the resonance by up to many bandwidths, was seen
 * by the demodulator at that offset and through single samples. It is followed again,
 * unexcited, with the NCO at the free frequency just found, as SC_DECAY_PTS means of Z
 * over one tau (at most SC_RING_MAX_S) from where the first decay ended (on_decay). */
static void post_decay(selfcal_t *s, double tau_s)
{
  const selfcal_cfg_t *c = &s->cfg;
  const double win_s = tau_s < SC_RING_MAX_S ? tau_s : SC_RING_MAX_S;
  const double gap_s = win_s / (double)(SC_DECAY_PTS - 1u);
  const double avg_s = SC_AVG_S < 0.5 * gap_s ? SC_AVG_S : 0.5 * gap_s;
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_STEPS);
  j.f_cmd_v2 = 0.0f;
  j.n_pts = SC_DECAY_PTS;
  for (uint32_t i = 0; i < SC_DECAY_PTS; i++)
    j.half_step[i] = nco_half_step_of(s->rd_f_hz, c->fs_hz);
  j.settle_ticks = ticks_of(SC_DECAY_SETTLE_S, c->fs_hz);
  j.avg_ticks = ticks_of(avg_s, c->fs_hz);
  j.step_settle_ticks = ticks_of(gap_s, c->fs_hz) - j.avg_ticks;
  s->rd_passes = 1u;
  post(s, &j, SELFCAL_RINGDOWN);
}

static void on_ringdown(selfcal_t *s, const selfcal_result_t *r)
{
  const selfcal_cfg_t *c = &s->cfg;
  /* |Z0| from its square here: the interrupt's tick that stops the excitation stays
   * without a square root. */
  const double amp0_v = sqrt((double)(r->rd_amp2_0_v2 > 0.0f ? r->rd_amp2_0_v2 : 0.0f));
  if (amp0_v < SC_MIN_PEAK_V || r->rd_ticks < 8u) {
    if (more_force(s, amp0_v) != 0) {
      fail(s, "ring-down too small to measure");
      return;
    }
    selfcal_job_t j = s->x->job;
    j.f_cmd_v2 = (float)s->f_cmd_v2;
    post(s, &j, SELFCAL_RINGDOWN);
    return;
  }
  /* Decay followed over t_ring from |Z0| to |Z_end|: tau = t_ring / ln(|Z0| / |Z_end|)
   * (6-12); the free (damped) frequency from the rotation of Z over t_ring. */
  const double t_ring = (double)r->rd_ticks / c->fs_hz;
  const double a0_2 = amp0_v * amp0_v;
  const double ln2 = (double)r->rd_amp2_end_v2 > 0.0 ? log(a0_2 / (double)r->rd_amp2_end_v2)
                                                     : 0.0;
  if (!(ln2 > 1e-3) || !isfinite(ln2)) {
    fail(s, "ring-down did not decay");
    return;
  }
  const double tau = 2.0 * t_ring / ln2;
  s->rd_f_hz = s->f_coarse_hz + (double)r->rd_phase_rad / (2.0 * FM_PI * t_ring);
  s->rd_q = FM_PI * s->rd_f_hz * tau;
  /* Steady-state gain at the peak from the excitation phase: the amplitude grew as
   * 1 - e^{-t/tau} towards |H(f_c)| f_cmd, and |H(f_c)| is below the peak by the
   * detuning factor of the first-order envelope model (6-12). */
  const double t_ex = (double)(r->ticks - r->rd_ticks) / c->fs_hz;
  const double grown = 1.0 - exp(-t_ex / tau);
  const double det = 2.0 * s->rd_q * (s->f_coarse_hz - s->rd_f_hz) / s->rd_f_hz;
  /* (The second, unexcited decay of high Q keeps the first's.) */
  if (r->rd_f_cmd_v2 > 0.0f)
    s->rd_gain = amp0_v / ((double)r->rd_f_cmd_v2 * (grown > 0.05 ? grown : 0.05)) *
                 sqrt(1.0 + det * det);
  if (!(s->rd_q > 0.5) || !(s->rd_f_hz > rng(s).f_lo_hz && s->rd_f_hz < rng(s).f_hi_hz) ||
      !isfinite(s->rd_gain)) {
    fail(s, "ring-down not consistent with a resonance");
    return;
  }
  if (tau <= SC_STEPS_MAX_TAU_S) {
    post_steps(s, s->rd_f_hz, s->rd_f_hz / (2.0 * s->rd_q), tau, s->rd_gain);
    return;
  }
  post_decay(s, tau);
}

/* What follows the drive's identification (resume): the hold, one point at f0, or a
 * burst; first S3 when the sense mode's f0 and Q are known (selfcal.h). */
enum { SC_RESUME_HOLD = 1u, SC_RESUME_ONE = 2u, SC_RESUME_BURST = 3u };
static void drive_next(selfcal_t *s, uint32_t resume);
static void sense_identified(selfcal_t *s);

/* High Q: the ring-down is the identification. The undamped resonance from the free
 * frequency, wd = wn sqrt(1 - 1/(4 Q^2)); a Q beyond the fixed drive's reach ends the
 * sweep with the reason, else one point at f0 for the hold. */
static void high_q_result(selfcal_t *s, double tau)
{
  s->fit.f0_hz = s->rd_f_hz / sqrt(1.0 - 0.25 / (s->rd_q * s->rd_q));
  s->fit.q = s->rd_q;
  s->fit.gain_v_per_v2 = 0.0; /* measured at f0 by post_one, within the reach */
  s->fit.rms_rel = 0.0;       /* no frequency-response fit */
  s->delay_s = s->cfg.delay_s;
  if (s->sense_phase != 0u) {
    sense_identified(s); /* (S1: the sense mode's gain at f0 is the ring-down's) */
    return;
  }
  (void)tau;
  /* Beyond the fixed drive's reach (the limit the design refuses beyond, whatever the
   * identification's scatter), or with the tracking drive selected, the tracking drive
   * takes over, and its point is a burst: it needs no settled vibration to start from. */
  s->track = s->cfg.track != 0u || s->rd_q > SELFCAL_Q_FIXED_MAX ? 1u : 0u;
  drive_next(s, s->track != 0u ? SC_RESUME_BURST : SC_RESUME_ONE);
}

/* The decay averaged at SC_DECAY_PTS times (the STEPS job, unexcited, at the free
 * frequency): the mean of Z over avg_ticks at each. ln|Z| and arg Z are straight lines in
 * t, of slopes -1/tau (6-12) and 2 pi (f_free - f_nco): least squares over the points.
 * Point i's mean is centred at settle + i (step_settle + avg) + avg / 2 ticks. */
static void on_decay(selfcal_t *s, const selfcal_result_t *r)
{
  const selfcal_job_t *j = &s->x->job;
  const double fs = s->cfg.fs_hz;
  double st = 0.0, sy = 0.0, sp = 0.0, stt = 0.0, sty = 0.0, stp = 0.0, ph = 0.0, ph_prev = 0.0;
  const double n = (double)j->n_pts;
  for (uint32_t i = 0; i < j->n_pts; i++) {
    const double zr = (double)r->z_re[i], zi = (double)r->z_im[i], m2 = zr * zr + zi * zi;
    if (!(m2 > 0.0) || !isfinite(m2)) {
      fail(s, "ring-down too small to measure");
      return;
    }
    const double p = atan2(zi, zr);
    ph = i == 0u ? p : ph + remainder(p - ph_prev, 2.0 * FM_PI);
    ph_prev = p;
    const double t = ((double)j->settle_ticks +
                      (double)i * (double)(j->step_settle_ticks + j->avg_ticks) +
                      0.5 * (double)j->avg_ticks) /
                     fs;
    const double y = 0.5 * log(m2);
    st += t;
    sy += y;
    sp += ph;
    stt += t * t;
    sty += t * y;
    stp += t * ph;
  }
  const double den = n * stt - st * st;
  const double slope_y = (n * sty - st * sy) / den, slope_p = (n * stp - st * sp) / den;
  if (r->backoffs != 0u || !(slope_y < 0.0) || !isfinite(slope_p)) {
    fail(s, "ring-down did not decay");
    return;
  }
  const double tau = -1.0 / slope_y;
  s->rd_f_hz = nco_freq_of(j->half_step[0], fs) + slope_p / (2.0 * FM_PI);
  s->rd_q = FM_PI * s->rd_f_hz * tau;
  high_q_result(s, tau);
}

/* Hold at the identified resonance s->fit, at the loop's set point, for SC_HOLD_TAU. */
static void sense_model(selfcal_t *s);

static void post_hold(selfcal_t *s)
{
  const selfcal_cfg_t *c = &s->cfg;
  sense_model(s); /* the drive's arg H(wn) is final here */
  const double tau = 2.0 * s->fit.q / (2.0 * FM_PI * s->fit.f0_hz);
  s->f0_hz_f = (float)s->fit.f0_hz;
  s->hold_f_cmd_v2 = c->amp_set_v / s->fit.gain_v_per_v2;
  s->hold_p_rad = remainder(c->phase_set_rad - s->fit.phase_rad, 2.0 * FM_PI);
  if (!(s->hold_f_cmd_v2 < c->f_cmd_max_v2)) {
    fail(s, "the amplitude set point needs more force than the drive has");
    return;
  }
  selfcal_job_t h;
  base_job(s, &h, SELFCAL_JOB_HOLD);
  h.f_cmd_v2 = (float)s->hold_f_cmd_v2;
  h.p_rad = (float)s->hold_p_rad;
  h.half_step[0] = nco_half_step_of((double)s->f0_hz_f, c->fs_hz);
  /* The burst left the vibration above the set point, and at high Q it would take tau
   * ln(A / A_set) to decay (seconds; force cannot pull, only push): brake it first with
   * half the drive's force in anti-phase, at K F / tau per second (6-12), to 90 % of the
   * set point, from where the amplitude loop brings it up. */
  const double a_end = s->burst_end_v, a_to = 0.9 * c->amp_set_v;
  if (s->track != 0u && s->braked == 0u && a_end > a_to) {
    const double f_b = 0.5 * c->f_cmd_max_v2;
    s->braked = 1u;
    h.f_cmd_v2 = (float)f_b;
    h.p_rad = (float)remainder(s->hold_p_rad + FM_PI, 2.0 * FM_PI);
    h.avg_ticks = ticks_of((a_end - a_to) * tau / (s->fit.gain_v_per_v2 * f_b), c->fs_hz);
    post(s, &h, SELFCAL_HOLD);
    return;
  }
  /* The tracking drive needs no settled vibration: its hold only hands the command over. */
  const double hold_s = s->track != 0u ? 0.02 : SC_HOLD_TAU * tau;
  h.avg_ticks = ticks_of(hold_s > 0.02 ? hold_s : 0.02, c->fs_hz);
  post(s, &h, SELFCAL_HOLD);
}

/* High Q, one point at f near wn with f0 and Q from the ring-down: H(wn) from H(f) by the
 * model of selfcal_fit.h, H(wn) / H(w) = (wn^2 - w^2 + j w wn / Q) / (j wn^2 / Q) (2-24). */
static void on_one_point(selfcal_t *s, const selfcal_point_t *p)
{
  const double wn = 2.0 * FM_PI * s->fit.f0_hz, w = 2.0 * FM_PI * p->f_hz, q = s->fit.q;
  /* (a + j b) / (j c) = (b - j a) / c */
  const double a = wn * wn - w * w, b = w * wn / q, cden = wn * wn / q;
  const double kr = b / cden, ki = -a / cden;
  const double hr = p->h_re * kr - p->h_im * ki, hi = p->h_re * ki + p->h_im * kr;
  s->fit.gain_v_per_v2 = hypot(hr, hi);
  s->fit.phase_rad = atan2(hi, hr);
  if (!(s->fit.gain_v_per_v2 > 0.0) || !isfinite(s->fit.gain_v_per_v2)) {
    fail(s, "no response at the resonance");
    return;
  }
  post_hold(s);
}

/* The burst's means (post_burst): z_mean_i = z_inf (1 - c_i) + z0 c_i, c_i the mean of
 * e^{-t/tau} over point i's window; least squares for z_inf and z0 (one real 2 x 2
 * system for both parts), then H(f) = z_inf / F and the point at f0 as on_one_point. */
static void on_burst(selfcal_t *s, const selfcal_result_t *r)
{
  const selfcal_job_t *j = &s->x->job;
  const double fs = s->cfg.fs_hz, tau = 2.0 * s->fit.q / (2.0 * FM_PI * s->fit.f0_hz);
  const double avg = (double)j->avg_ticks / fs;
  double saa = 0.0, sab = 0.0, sbb = 0.0, sar = 0.0, sbr = 0.0, sai = 0.0, sbi = 0.0;
  for (uint32_t i = 0; i < j->n_pts; i++) {
    const double t0 = (double)j->settle_ticks / fs + (double)i * avg;
    const double ci = tau * (exp(-t0 / tau) - exp(-(t0 + avg) / tau)) / avg;
    const double a = 1.0 - ci, b = ci;
    saa += a * a;
    sab += a * b;
    sbb += b * b;
    sar += a * (double)r->z_re[i];
    sbr += b * (double)r->z_re[i];
    sai += a * (double)r->z_im[i];
    sbi += b * (double)r->z_im[i];
  }
  const double det = saa * sbb - sab * sab;
  const double f = (double)r->f_cmd_v2[0];
  if (r->backoffs != 0u) {
    post_reburst_wait(s, tau);
    return;
  }
  if (!(fabs(det) > 1e-12) || !(f > 0.0)) {
    fail(s, "no response at the resonance");
    return;
  }
  selfcal_point_t p;
  p.f_hz = nco_freq_of(j->half_step[0], fs);
  p.h_re = (sbb * sar - sab * sbr) / det / f;
  p.h_im = (sbb * sai - sab * sbi) / det / f;
  /* Where the burst left the vibration (its end, t_b): the brake's start (post_hold). */
  const double t_b = ((double)j->settle_ticks + (double)j->n_pts * (double)j->avg_ticks) / fs;
  const double k = exp(-t_b / tau), zr = p.h_re * f, zi = p.h_im * f;
  const double z0r = (saa * sbr - sab * sar) / det;
  const double z0i = (saa * sbi - sab * sai) / det;
  s->burst_end_v = hypot(zr + (z0r - zr) * k, zi + (z0i - zi) * k);
  if (s->burst_end_v > s->cfg.amp_meas_v) {
    /* Under the budget but far over the rise planned: the hold could not brake that
     * vibration in time (the amplitude loop cannot pull). */
    post_reburst_wait(s, tau);
    return;
  }
  on_one_point(s, &p);
}

static void on_steps(selfcal_t *s, const selfcal_result_t *r)
{
  const selfcal_cfg_t *c = &s->cfg;
  const selfcal_job_t *j = &s->x->job;
  selfcal_point_t pts[SELFCAL_MAX_PTS];
  /* (`sweep points` exports the drive's: the sense mode's are not kept) */
  for (uint32_t i = 0; s->sense_phase == 0u && i < j->n_pts && s->n_pts < SELFCAL_EXPORT_MAX;
       i++) {
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
  if (s->burst != 0u) {
    on_burst(s, r);
    return;
  }
  if (s->one_point != 0u) {
    on_one_point(s, &pts[0]);
    return;
  }
  selfcal_fit_t fit;
  double delay_s = c->delay_s;
  /* The converter delay is known; what the analog chain adds (up to 8 samples) is
   * identified with the model (selfcal_fit_delay). */
  if (selfcal_fit_delay(pts, j->n_pts, c->delay_s, c->delay_s + 8.0 / c->fs_hz, &fit,
                        &delay_s) != 0 ||
      !(fit.rms_rel < 0.05) || !(fit.f0_hz > rng(s).f_lo_hz && fit.f0_hz < rng(s).f_hi_hz) ||
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
  if (s->sense_phase != 0u) {
    sense_identified(s);
    return;
  }
  drive_next(s, SC_RESUME_HOLD);
}

/* ---- The sense mode (selfcal.h: S1-S3) ---- */

/* S2: a tuning voltage's shift below this is no shift (no tuning electrodes): the free
 * frequency of a decay followed for tau (at least 64 samples) is resolved far finer, and
 * an electrode that can match a 110 Hz split moves it by tens of Hz at a few volts. */
#define SC_TUNE_MIN_SHIFT_HZ 0.01
#define SC_TUNE_MIN_RING_TICKS 64u
/* S3: the drive's ring-down before the points at wc, in its time constants: the drive's
 * steps left it at amp_meas (36 um on the thesis's part), whose 1500 deg/s quadrature is
 * 20 times the sense ADC's range on a part near its match; e^-10 of it is far inside.
 * And the sense mode's: the drive's chirps passed its resonance and the quadrature rang
 * it up (at Q 10^4 for seconds). At least 0.1 s, at most a few seconds (a drive of Q
 * 10^4 decays for 2 s per tau: what is left is a slow decay at wc, which the three means
 * cancel, and the sense mode's ring, which their whole beats cancel). */
#define SC_WC_QUIET_TAU 10.0
#define SC_WC_QUIET_SENSE_TAU 3.0
#define SC_WC_QUIET_MIN_S 0.1
#define SC_WC_QUIET_MAX_S 3.0
#define SC_WC_SETTLE_S 0.02
#define SC_WC_SETTLE_MAX_S 1.0 /* waiting out the sense mode's ring: up to Q 700 at 1.6 kHz */
#define SC_WC_PTS 3u
#define SC_WC_OFF_MASK 0x5u /* the first and the last unexcited */
_Static_assert(SC_WC_PTS <= SELFCAL_MAX_PTS, "the executive holds SELFCAL_MAX_PTS points");

/* Back to the drive's chain (after S1/S2, identified or not): its state from the start. */
static void drive_begin(selfcal_t *s)
{
  s->sense_phase = 0u;
  s->f_cmd_v2 = s->cfg.f_cmd_start_v2;
  s->f_up_hz = s->f_down_hz = s->f_coarse_hz = s->chirp_peak_v = 0.0;
  s->rd_f_hz = s->rd_q = s->rd_gain = 0.0;
  s->plan_f_hz = s->plan_hb_hz = 0.0;
  memset(&s->fit, 0, sizeof s->fit);
  s->delay_s = 0.0;
  s->retries = s->refits = s->rd_passes = s->one_point = s->burst = 0u;
  post_quiet(s, SELFCAL_QUIET_UP);
}

/* S2: a ring-down excited at the sense f0 (on resonance: the peak's force for amp_meas),
 * its decay with the tuning electrodes at 0 V (pass 0) or at the probe voltage (1). */
static void post_tune(selfcal_t *s)
{
  const selfcal_cfg_t *c = &s->cfg;
  selfcal_job_t j;
  double f_cmd = c->amp_meas_v / s->sense.gain_pk_v_per_v2;
  s->f_cmd_v2 = f_cmd > c->s_f_cmd_max_v2 ? c->s_f_cmd_max_v2 : f_cmd;
  base_job(s, &j, SELFCAL_JOB_RINGDOWN);
  j.half_step[0] = nco_half_step_of(s->sense.f0_hz, c->fs_hz);
  j.amp_target_v = (float)c->amp_meas_v;
  j.settle_ticks = ticks_of(SC_EXCITE_MAX_S, c->fs_hz);
  j.avg_ticks = ticks_of(SC_RING_MAX_S, c->fs_hz);
  if (s->tune_pass != 0u) j.tune_ring_code = gyro_volts_to_dac((float)c->tune_probe_v);
  post(s, &j, SELFCAL_SENSE_TUNE);
}

static void tune_done(selfcal_t *s, selfcal_tune_state_t st, const char *why)
{
  s->sense.tune = st;
  s->sense.tune_why = why;
  drive_begin(s);
}

/* The free frequency of a sense ring-down of S2 or S4 (its rotation against the NCO, as
 * on_ringdown), or -1 when the decay is too small or too short to show it. */
static double ring_free_hz(const selfcal_t *s, const selfcal_result_t *r)
{
  const double fs = s->cfg.fs_hz;
  const double amp0 = sqrt((double)(r->rd_amp2_0_v2 > 0.0f ? r->rd_amp2_0_v2 : 0.0f));
  if (amp0 < SC_MIN_PEAK_V || r->rd_ticks < SC_TUNE_MIN_RING_TICKS) return -1.0;
  const double t_ring = (double)r->rd_ticks / fs;
  return nco_freq_of(s->x->job.half_step[0], fs) +
         (double)r->rd_phase_rad / (2.0 * FM_PI * t_ring);
}

/* S2's result: the free frequency of each decay, then ke = (wd0^2 - wd1^2) / Vt^2. */
static void on_tune(selfcal_t *s, const selfcal_result_t *r)
{
  const double fd = ring_free_hz(s, r);
  if (!(fd > 0.0)) {
    tune_done(s, SELFCAL_TUNE_FAILED, "the sense ring-down too small or short to show a shift");
    return;
  }
  if (s->tune_pass == 0u) {
    s->sense.tune_fd0_hz = fd;
    s->tune_pass = 1u;
    post_tune(s);
    return;
  }
  s->sense.tune_fd1_hz = fd;
  const double w0 = 2.0 * FM_PI * s->sense.tune_fd0_hz, w1 = 2.0 * FM_PI * fd;
  const double vt = s->cfg.tune_probe_v, shift = s->sense.tune_fd0_hz - fd;
  s->sense.tune_ke_per_s2_per_v2 = 0.0;
  if (fabs(shift) < SC_TUNE_MIN_SHIFT_HZ) {
    tune_done(s, SELFCAL_TUNE_OK, NULL); /* no tuning electrodes: ke 0 */
    return;
  }
  if (!(shift > 0.0) || !isfinite(shift)) {
    tune_done(s, SELFCAL_TUNE_FAILED, "the tuning voltage raised the sense resonance");
    return;
  }
  s->sense.tune_ke_per_s2_per_v2 = (w0 * w0 - w1 * w1) / (vt * vt);
  tune_done(s, SELFCAL_TUNE_OK, NULL);
}

/* S1 done (f0, Q in s->fit): plausible, then S2 or the drive. */
static void sense_identified(selfcal_t *s)
{
  selfcal_sense_t *m = &s->sense;
  m->f0_hz = s->fit.f0_hz;
  m->q = s->fit.q;
  m->rms_rel = s->fit.rms_rel;
  m->gain_pk_v_per_v2 = s->fit.gain_v_per_v2 > 0.0 ? s->fit.gain_v_per_v2 : s->rd_gain;
  if (!(m->q >= 0.5 && m->q < 1.0e6) || !(m->gain_pk_v_per_v2 > 0.0) ||
      !isfinite(m->gain_pk_v_per_v2)) {
    fail(s, "sense resonance not consistent with a mode");
    return;
  }
  m->state = SELFCAL_SENSE_F0;
  if (s->cfg.tune_probe_v > 0.0) {
    s->tune_pass = 0u;
    post_tune(s);
    return;
  }
  drive_begin(s);
}

static void drive_resume(selfcal_t *s)
{
  const double tau = s->fit.q / (FM_PI * s->fit.f0_hz);
  switch (s->resume) {
  case SC_RESUME_ONE: post_one(s, tau); break;
  case SC_RESUME_BURST: post_burst(s, tau); break;
  default: post_hold(s); break;
  }
}

/* S3 first: the drive off until its vibration has decayed (the sense job's tick puts
 * the drive electrodes at 0 V), the NCO at wc. */
static void drive_next(selfcal_t *s, uint32_t resume)
{
  s->resume = resume;
  if (s->sense.state != SELFCAL_SENSE_F0) {
    drive_resume(s);
    return;
  }
  const double tau = s->fit.q / (FM_PI * s->fit.f0_hz);
  const double tau_s = s->sense.q / (FM_PI * s->sense.f0_hz);
  double t = SC_WC_QUIET_TAU * tau;
  if (t < SC_WC_QUIET_SENSE_TAU * tau_s) t = SC_WC_QUIET_SENSE_TAU * tau_s;
  t = t < SC_WC_QUIET_MIN_S ? SC_WC_QUIET_MIN_S : (t > SC_WC_QUIET_MAX_S ? SC_WC_QUIET_MAX_S : t);
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_QUIET);
  j.sense = 1u;
  j.f_cmd_v2 = 0.0f;
  j.half_step[0] = nco_half_step_of((double)(float)s->fit.f0_hz, s->cfg.fs_hz);
  j.avg_ticks = ticks_of(t, s->cfg.fs_hz);
  post(s, &j, SELFCAL_SENSE_QUIET);
}

/* S3's three means at wc (the drive's resonance as the parameter will hold it). Off
 * the sense resonance by more than a few half bandwidths, the switching's transient is
 * the sense mode's free ring at its beat against wc: short settling, means over whole
 * beats. Near it (a matched part) the response takes the sense mode's time to settle. */
static void post_wc(selfcal_t *s)
{
  const selfcal_cfg_t *c = &s->cfg;
  const selfcal_sense_t *m = &s->sense;
  const double f_wc = (double)(float)s->fit.f0_hz;
  const double hb = m->f0_hz / (2.0 * m->q), tau_s = m->q / (FM_PI * m->f0_hz);
  const double fd = m->f0_hz * sqrt(1.0 - 0.25 / (m->q * m->q)), beat = fabs(fd - f_wc);
  selfcal_job_t j;
  /* the force for a quarter of amp_meas from the peak gain and the detuning (6-12):
   * switching the force on or off starts the sense mode's free ring as large as the
   * forced response, which at high Q outlasts the means (the sum must stay under the
   * ADC budget, where a back-off would start another ring) */
  const double det = (f_wc - m->f0_hz) / hb;
  const double f_cmd = 0.25 * c->amp_meas_v * sqrt(1.0 + det * det) / m->gain_pk_v_per_v2;
  s->f_cmd_v2 = f_cmd > c->s_f_cmd_max_v2 ? c->s_f_cmd_max_v2 : f_cmd;
  base_job(s, &j, SELFCAL_JOB_STEPS);
  j.tune_code = j.tune_ring_code = s->match_code; /* S4's voltage, or 0 V */
  /* The back-off near the ADC's range only: what is left of the sense mode's ring
   * (above) may go over amp_max without the force's part, and a back-off would only
   * start another ring; the means cancel it as long as nothing clips. */
  j.amp_max_v = (float)c->amp_clip_v;
  j.sense = 1u;
  j.n_pts = SC_WC_PTS;
  j.off_mask = SC_WC_OFF_MASK;
  for (uint32_t i = 0; i < SC_WC_PTS; i++) j.half_step[i] = nco_half_step_of(f_wc, c->fs_hz);
  /* A ring that decays within the mean is not cancelled by its whole beats (at Q 300,
   * tau 60 ms, it turned the phase by 0.8 deg: 21 deg/s of the quadrature in the rate):
   * it is waited out, SC_SETTLE_TAU of the sense mode's tau, when that is short. */
  const int beats = beat > 4.0 * hb && SC_SETTLE_TAU * tau_s > SC_WC_SETTLE_MAX_S;
  const double settle_s = beats ? SC_WC_SETTLE_S : SC_SETTLE_TAU * tau_s;
  const double avg_s = beats ? ceil(SC_AVG_S * beat) / beat : SC_AVG_S;
  j.settle_ticks = j.step_settle_ticks = ticks_of(settle_s, c->fs_hz);
  j.avg_ticks = ticks_of(avg_s, c->fs_hz);
  post(s, &j, SELFCAL_SENSE_WC);
}

/* ---- S4: mode tuning (selfcal.h) ---- */

/* At most this many ring-downs at a tuning voltage: the secant on Vt^2 is exact for the
 * parallel-plate law, so the second lands within the ring-down's own resolution. */
#define SC_MATCH_PASSES 4u
/* Within this fraction of the sense half-bandwidth f0 / 2Q of the target: the sense
 * gain at wc within 3 % of the matched peak (1 / sqrt(1 + 0.25^2)). */
#define SC_MATCH_TOL_HB 0.25

static void match_done(selfcal_t *s, selfcal_tune_state_t st, const char *why)
{
  selfcal_sense_t *m = &s->sense;
  m->match = st;
  m->match_why = why;
  if (st != SELFCAL_TUNE_OK) {
    s->match_code = (uint16_t)HAL_DAC_CODE_MID;
  } else {
    /* From here on the model is the tuned mode's (S3 and the staged sense.f0_hz, sense.q):
     * the undamped resonance from the free one, the damping unchanged, so Q goes as f0. */
    const double f0 = m->match_fd_hz / sqrt(1.0 - 0.25 / (m->q * m->q));
    m->q *= f0 / m->f0_hz;
    m->f0_hz = f0;
  }
  post_wc(s);
}

/* A ring-down at the target with the tuning voltage v held through it. */
static void post_match(selfcal_t *s, double v)
{
  const selfcal_cfg_t *c = &s->cfg;
  selfcal_sense_t *m = &s->sense;
  if (!(v >= 0.0)) {
    match_done(s, SELFCAL_TUNE_FAILED,
               "the sense resonance is at or below the tuning target (tuning only lowers it)");
    return;
  }
  if (v > c->tune_v_max_v) {
    match_done(s, SELFCAL_TUNE_FAILED, "the tuning target needs more than sense.tune_v_max_v");
    return;
  }
  if (m->match_passes >= SC_MATCH_PASSES) {
    match_done(s, SELFCAL_TUNE_FAILED, "the tuned resonance did not converge on its target");
    return;
  }
  m->match_passes++;
  s->match_code = gyro_volts_to_dac((float)v);
  m->match_v = (double)((int32_t)s->match_code - (int32_t)HAL_DAC_CODE_MID) *
               (double)HAL_DAC_V_PER_CODE;
  const double f_cmd = c->amp_meas_v / m->gain_pk_v_per_v2;
  s->f_cmd_v2 = f_cmd > c->s_f_cmd_max_v2 ? c->s_f_cmd_max_v2 : f_cmd;
  selfcal_job_t j;
  base_job(s, &j, SELFCAL_JOB_RINGDOWN);
  j.sense = 1u;
  j.half_step[0] = nco_half_step_of(m->match_target_hz, c->fs_hz);
  j.amp_target_v = (float)c->amp_meas_v;
  j.settle_ticks = ticks_of(SC_EXCITE_MAX_S, c->fs_hz);
  j.avg_ticks = ticks_of(SC_RING_MAX_S, c->fs_hz);
  j.tune_code = j.tune_ring_code = s->match_code;
  post(s, &j, SELFCAL_SENSE_MATCH);
}

/* S4's start (S3's quiet is over): the voltage for the target from S2's slope. */
static void post_match_first(selfcal_t *s)
{
  selfcal_sense_t *m = &s->sense;
  m->match_target_hz = s->fit.f0_hz +
                       (s->cfg.tune_mode == SENSE_TUNE_SPLIT ? s->cfg.tune_split_hz : 0.0);
  m->match_ke = m->tune_ke_per_s2_per_v2;
  if (m->tune != SELFCAL_TUNE_OK || !(m->match_ke > 0.0)) {
    match_done(s, SELFCAL_TUNE_FAILED,
               m->tune == SELFCAL_TUNE_OK ? "no tuning electrodes (S2 saw no shift)"
                                          : "no tuning slope identified (S2)");
    return;
  }
  post_match(s, sense_tune_volts(m->tune_fd0_hz, m->match_target_hz, m->match_ke));
}

/* S4's ring-down: its free frequency, then done or the next voltage. */
static void on_match(selfcal_t *s, const selfcal_result_t *r)
{
  selfcal_sense_t *m = &s->sense;
  m->match_fd_hz = ring_free_hz(s, r);
  if (!(m->match_fd_hz > 0.0)) {
    match_done(s, SELFCAL_TUNE_FAILED, "the tuned sense ring-down too small or short");
    return;
  }
  const double w0 = 2.0 * FM_PI * m->tune_fd0_hz, w1 = 2.0 * FM_PI * m->match_fd_hz;
  const double v = m->match_v;
  /* one code's move of the resonance: d(ws^2) = -2 ke Vt dVt, so df = ke Vt dVt / (4 pi^2 f) */
  const double code_hz = m->match_ke * v * (double)HAL_DAC_V_PER_CODE /
                         (4.0 * FM_PI * FM_PI * m->match_target_hz);
  const double hb = m->f0_hz / (2.0 * m->q);
  double tol = SC_MATCH_TOL_HB * hb;
  if (tol < 0.6 * code_hz) tol = 0.6 * code_hz;
  const double ke = v > 0.0 ? (w0 * w0 - w1 * w1) / (v * v) : 0.0;
  if (!(ke > 0.0) || !isfinite(ke)) {
    match_done(s, SELFCAL_TUNE_FAILED, "the tuning voltage did not lower the sense resonance");
    return;
  }
  m->match_ke = ke;
  if (fabs(m->match_fd_hz - m->match_target_hz) <= tol) {
    match_done(s, SELFCAL_TUNE_OK, NULL);
    return;
  }
  post_match(s, sense_tune_volts(m->tune_fd0_hz, m->match_target_hz, ke));
}

double selfcal_match_s0_hz(const selfcal_sense_t *m)
{
  if (m->match != SELFCAL_TUNE_OK) return 0.0;
  const double ft = m->match_target_hz;
  return sqrt(ft * ft + m->match_ke * m->match_v * m->match_v / (4.0 * FM_PI * FM_PI));
}

/* S3's quiet is over: S4 first when tuning is asked for. */
static void after_wc_quiet(selfcal_t *s)
{
  if (s->cfg.tune_mode != SENSE_TUNE_OFF) {
    post_match_first(s);
    return;
  }
  post_wc(s);
}

static void sense_fail_wc(selfcal_t *s, const char *why)
{
  s->sense.state = SELFCAL_SENSE_FAILED;
  s->sense.why = why;
  drive_resume(s);
}

/* S3's result: H_s(wc) from the excited mean less the mean of the unexcited ones. */
static void on_wc(selfcal_t *s, const selfcal_result_t *r)
{
  const double a2 = s->cfg.amp_clip_v * s->cfg.amp_clip_v;
  const double z0r = (double)r->z_re[0], z0i = (double)r->z_im[0];
  const double z2r = (double)r->z_re[2], z2i = (double)r->z_im[2];
  const double f = (double)r->f_cmd_v2[1];
  if (z0r * z0r + z0i * z0i > a2 || z2r * z2r + z2i * z2i > a2 ||
      (r->backoffs != 0u && f == (double)s->x->job.f_cmd_v2)) {
    sense_fail_wc(s, "the drive's vibration over the sense pickoff's budget at wc");
    return;
  }
  const double dr = (double)r->z_re[1] - 0.5 * (z0r + z2r);
  const double di = (double)r->z_im[1] - 0.5 * (z0i + z2i);
  if (!(f > 0.0) || !(hypot(dr, di) >= SC_MIN_PEAK_V)) {
    sense_fail_wc(s, "no response of the sense pickoff to the feedback force at wc");
    return;
  }
  s->sense.h_re = dr / f;
  s->sense.h_im = di / f;
  s->sense.state = SELFCAL_SENSE_OK;
  drive_resume(s);
}

/* The force-rebalance model's gain and phase (selfcal.h: theta = phi_dm + arg H_d(wc) -
 * arg H_s(wc), within +-90 deg, the gain's sign the rest), once the drive's arg H is
 * final; a gain outside sense.fb_gain_v_per_v2's range is no model. */
static void sense_model(selfcal_t *s)
{
  selfcal_sense_t *m = &s->sense;
  if (m->state != SELFCAL_SENSE_OK) return;
  const double mag = hypot(m->h_re, m->h_im);
  double th = remainder(s->cfg.demod_phase_rad + s->fit.phase_rad - atan2(m->h_im, m->h_re),
                        2.0 * FM_PI);
  double g = mag;
  if (fabs(th) > 0.5 * FM_PI) {
    th -= th > 0.0 ? FM_PI : -FM_PI;
    g = -g;
  }
  if (!(mag >= 1.0e-6 && mag <= 1.0e5) || !isfinite(th)) {
    m->state = SELFCAL_SENSE_FAILED;
    m->why = "feedback gain at wc outside sense.fb_gain_v_per_v2's range";
    return;
  }
  m->fb_gain_v_per_v2 = g;
  m->fb_phase_rad = th;
}

selfcal_state_t selfcal_background(selfcal_t *s, int sweeping)
{
  if (s == NULL) return SELFCAL_FAILED;
  if (!selfcal_running(s)) return s->state;
  if (s->state == SELFCAL_WAIT_SWEEP) {
    if (sweeping && s->cfg.sense != 0u) {
      /* S1 first, after the drive's ring-down (selfcal.h) */
      s->sense_phase = 1u;
      s->sense.state = SELFCAL_SENSE_RUN;
      s->f_cmd_v2 = s->cfg.s_f_cmd_start_v2;
      post_quiet_for(s, SELFCAL_QUIET_UP, s->cfg.s_quiet_s);
    } else if (sweeping) {
      post_quiet(s, SELFCAL_QUIET_UP);
    }
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
  if (s->x->job.sense != 0u) s->sense.ticks += r.ticks;
  switch (s->state) {
  case SELFCAL_QUIET_UP: post_chirp(s, 1, SELFCAL_CHIRP_UP); break;
  case SELFCAL_QUIET_DOWN: post_chirp(s, 0, SELFCAL_CHIRP_DOWN); break;
  case SELFCAL_CHIRP_UP: on_chirp(s, &r, 1); break;
  case SELFCAL_CHIRP_DOWN: on_chirp(s, &r, 0); break;
  case SELFCAL_RINGDOWN:
    if (s->rd_passes != 0u) on_decay(s, &r);
    else on_ringdown(s, &r);
    break;
  case SELFCAL_FINE: on_steps(s, &r); break;
  case SELFCAL_REBURST: post_burst_at(s, s->f_cmd_v2); break;
  case SELFCAL_SENSE_TUNE: on_tune(s, &r); break;
  case SELFCAL_SENSE_QUIET: after_wc_quiet(s); break;
  case SELFCAL_SENSE_WC: on_wc(s, &r); break;
  case SELFCAL_SENSE_MATCH: on_match(s, &r); break;
  case SELFCAL_HOLD:
    if (s->braked == 1u) {
      s->braked = 2u;
      post_hold(s);
    } else {
      s->state = SELFCAL_READY;
    }
    break;
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
