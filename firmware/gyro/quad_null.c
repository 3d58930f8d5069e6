#include "gyro/quad_null.h"

#include <math.h>
#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/math_const.h"
#include "dsp/ramfunc.h"

static int pos_finite(float x) { return isfinite(x) && x > 0.0f; }

/* updates in t_s at dt_s, or -1 if it does not fit a counter */
static int64_t updates(float t_s, float dt_s)
{
  const float n = t_s / dt_s;
  return (isfinite(n) && n >= 0.0f && n < 4.0e9f) ? (int64_t)n : -1;
}

static int cfg_ok(const quad_null_cfg_t *c)
{
  return pos_finite(c->bw_hz) && pos_finite(c->v_max_v) && pos_finite(c->settle_dps) &&
         isfinite(c->settle_s) && c->settle_s >= 0.0f && pos_finite(c->probe_v) &&
         c->probe_v <= c->v_max_v && isfinite(c->probe_wait_s) && c->probe_wait_s >= 0.0f &&
         isfinite(c->probe_avg_s) && c->probe_avg_s >= c->dt_s && pos_finite(c->min_step_dps) &&
         pos_finite(c->dt_s) && c->bw_hz * c->dt_s <= 0.1f; /* first order: f_c << rate */
}

int quad_null_design(const quad_null_cfg_t *cfg, quad_null_design_t *d)
{
  if (cfg == NULL || d == NULL || !cfg_ok(cfg)) return -1;
  const int64_t settle = updates(cfg->settle_s, cfg->dt_s);
  const int64_t wait = updates(cfg->probe_wait_s, cfg->dt_s);
  const int64_t avg = updates(cfg->probe_avg_s, cfg->dt_s);
  if (settle < 0 || wait < 0 || avg < 1) return -1;
  d->wc_dt = FM_TWO_PI_F * cfg->bw_hz * cfg->dt_s;
  d->u_max_v2 = cfg->v_max_v * cfg->v_max_v;
  d->u_probe_v2 = cfg->probe_v * cfg->probe_v;
  d->settle_dps = cfg->settle_dps;
  d->min_step_dps = cfg->min_step_dps;
  d->settle_updates = (uint32_t)settle;
  d->wait_updates = (uint32_t)wait;
  d->avg_updates = (uint32_t)avg;
  /* the probe's two divides, here: the sample interrupt's block carries at most one */
  d->inv_avg = 1.0f / (float)avg;
  d->inv_u_probe_v2 = 1.0f / d->u_probe_v2;
  return 0;
}

void quad_null_stop(quad_null_t *q)
{
  quad_null_clear_a(q);
  quad_null_clear_b(q);
  quad_null_clear_c(q);
}

GYRO_RAMFUNC void quad_null_halt(quad_null_t *q)
{
  q->mode = QUAD_NULL_OFF;
  q->u_cmd_v2 = 0.0f;
  q->root_v = 0.0f;
  q->v1_v = 0.0f;
  q->v2_v = 0.0f;
  q->settled = 0u;
  q->at_limit = 0u;
  q->close_due = 0u;
}

void quad_null_start(const quad_null_design_t *d, quad_null_t *q)
{
  (void)d;
  quad_null_stop(q);
  q->mode = QUAD_NULL_PROBE_BASE;
}

/* The loop's integrator for the gain c (deg/s per V^2, sign included): e = -q and
 * q = q0 + c u, so Ki T = 2 pi f_c T / c puts the crossover at f_c (what pi_design makes
 * for Kp = 0). Returns Ki T, or NaN for a c that gives none. */
static inline float ki_t_for(const quad_null_design_t *d, float c_dps_per_v2)
{
  if (!(fm_isfinite(c_dps_per_v2) && c_dps_per_v2 != 0.0f)) return NAN;
  return d->wc_dt / c_dps_per_v2;
}

/* The loop closed with Ki T on the gain c, from u (within the limits). */
static inline void close_loop(const quad_null_design_t *d, quad_null_t *q, float ki_t, float u)
{
  q->pi.kp = 0.0f;
  q->pi.ki_t = ki_t;
  q->pi.u_min = -d->u_max_v2;
  q->pi.u_max = d->u_max_v2;
  q->pi_state.u = u;
  q->pi_state.e_prev = 0.0f;
  q->integ_v2 = u;
  q->mode = QUAD_NULL_RUN;
  quad_null_command(q, u, d->u_max_v2);
}

int quad_null_start_with_gain(const quad_null_design_t *d, quad_null_t *q, float c_dps_per_v2)
{
  quad_null_stop(q);
  const float ki_t = ki_t_for(d, c_dps_per_v2);
  if (!fm_isfinite(ki_t)) return -1;
  close_loop(d, q, ki_t, 0.0f);
  q->gain_dps_per_v2 = c_dps_per_v2;
  return 0;
}

void quad_null_update(const quad_null_design_t *d, quad_null_t *q, float quad_dps)
{
  quad_null_take(q, quad_dps);
  if (q->skip != 0u) return; /* no measurement: the voltages hold */
  if (q->mode == QUAD_NULL_PROBE_BASE || q->mode == QUAD_NULL_PROBE_STEP) {
    quad_null_accumulate(d, q);
    if (q->mean_due == 0u) return; /* the command has not changed */
    quad_null_mean(d, q);
    const int step_mean = q->mode == QUAD_NULL_PROBE_STEP;
    quad_null_verdict(d, q);
    if (step_mean) {
      quad_null_judge(d, q);
      if (q->close_due == 0u) { /* FAILED: both electrodes at 0 V */
        quad_null_fail_a(q);
        quad_null_fail_b(q);
        return;
      }
      quad_null_gain(d, q);
      quad_null_close(d, q);
      quad_null_engage(d, q); /* on the probe's command: the voltages stay */
      return;
    }
  } else if (q->mode == QUAD_NULL_RUN) {
    quad_null_integrate(q);
    quad_null_limit(d, q);
    quad_null_settle(d, q);
  } else {
    return; /* OFF, FAILED: both electrodes stay at 0 V */
  }
  quad_null_root(q);
  quad_null_sign(q);
}
