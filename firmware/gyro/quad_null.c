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

/* u -> the electrode pair: one electrode carries sqrt(|u|), the other nothing */
GYRO_RAMFUNC static void electrodes(quad_null_t *q, float u, float u_max)
{
  q->at_limit = (u >= u_max || u <= -u_max) ? 1u : 0u;
  q->v1_v = u > 0.0f ? fm_sqrtf(u) : 0.0f;
  q->v2_v = u < 0.0f ? fm_sqrtf(-u) : 0.0f;
}

/* Field by field rather than memset: the sample interrupt stops and starts the loop, and
 * the library's memset lies in flash (linker/check_ramfunc.py). */
GYRO_RAMFUNC void quad_null_stop(quad_null_t *q)
{
  q->mode = QUAD_NULL_OFF;
  q->count = 0u;
  q->sum_dps = 0.0f;
  q->base_dps = 0.0f;
  q->gain_dps_per_v2 = 0.0f;
  q->pi.kp = 0.0f;
  q->pi.ki_t = 0.0f;
  q->pi.u_min = 0.0f;
  q->pi.u_max = 0.0f;
  q->pi_state.u = 0.0f;
  q->pi_state.e_prev = 0.0f;
  q->integ_v2 = 0.0f;
  q->in_band = 0u;
  q->settled = 0u;
  q->at_limit = 0u;
  q->v1_v = 0.0f;
  q->v2_v = 0.0f;
}

GYRO_RAMFUNC void quad_null_start(const quad_null_design_t *d, quad_null_t *q)
{
  (void)d;
  quad_null_stop(q);
  q->mode = QUAD_NULL_PROBE_BASE;
}

GYRO_RAMFUNC int quad_null_start_with_gain(const quad_null_design_t *d, quad_null_t *q,
                                           float c_dps_per_v2)
{
  quad_null_stop(q);
  if (!(fm_isfinite(c_dps_per_v2) && c_dps_per_v2 != 0.0f)) return -1;
  /* e = -q and q = q0 + c u: Ki T = 2 pi f_c T / c puts the crossover at f_c (the
   * coefficients pi_design would make for Kp = 0, without its call: it is background
   * code; the one divide of the probe's last update) */
  const float ki_t = d->wc_dt / c_dps_per_v2;
  if (!fm_isfinite(ki_t)) return -1;
  q->pi.kp = 0.0f;
  q->pi.ki_t = ki_t;
  q->pi.u_min = -d->u_max_v2;
  q->pi.u_max = d->u_max_v2;
  q->gain_dps_per_v2 = c_dps_per_v2;
  q->mode = QUAD_NULL_RUN;
  return 0;
}

/* The probe's phases: wait, then average; returns 1 when the mean is complete. */
GYRO_RAMFUNC static int probe_mean(const quad_null_design_t *d, quad_null_t *q, float quad_dps,
                                   float *mean)
{
  q->count++;
  if (q->count <= d->wait_updates) return 0;
  q->sum_dps += quad_dps;
  if (q->count < d->wait_updates + d->avg_updates) return 0;
  *mean = q->sum_dps * d->inv_avg;
  q->count = 0u;
  q->sum_dps = 0.0f;
  return 1;
}

GYRO_RAMFUNC static void probe(const quad_null_design_t *d, quad_null_t *q, float quad_dps)
{
  float mean;
  if (!probe_mean(d, q, quad_dps, &mean)) return;
  if (q->mode == QUAD_NULL_PROBE_BASE) {
    q->base_dps = mean;
    q->mode = QUAD_NULL_PROBE_STEP;
    electrodes(q, d->u_probe_v2, d->u_max_v2);
    return;
  }
  const float step = mean - q->base_dps;
  if (!((step < 0.0f ? -step : step) >= d->min_step_dps) ||
      quad_null_start_with_gain(d, q, step * d->inv_u_probe_v2) != 0) {
    quad_null_stop(q);
    q->mode = QUAD_NULL_FAILED;
    return;
  }
  /* bumpless: the loop takes over from the probe's voltage */
  (void)pi_reset(&q->pi, &q->pi_state, d->u_probe_v2, 0.0f);
  q->integ_v2 = q->pi_state.u;
  electrodes(q, q->integ_v2, d->u_max_v2);
}

GYRO_RAMFUNC static void run(const quad_null_design_t *d, quad_null_t *q, float quad_dps)
{
  const float u = pi_step_position(&q->pi, &q->pi_state, &q->integ_v2, -quad_dps);
  electrodes(q, u, d->u_max_v2);
  const float a = quad_dps < 0.0f ? -quad_dps : quad_dps;
  if (a <= d->settle_dps && !q->at_limit) {
    if (q->in_band < d->settle_updates) q->in_band++;
  } else {
    q->in_band = 0u;
  }
  q->settled = q->in_band >= d->settle_updates ? 1u : 0u;
}

GYRO_RAMFUNC void quad_null_update(const quad_null_design_t *d, quad_null_t *q, float quad_dps)
{
  if (!fm_isfinite(quad_dps)) { /* no measurement: hold, and a probe mean starts again */
    q->in_band = 0u;
    q->settled = 0u;
    q->count = 0u;
    q->sum_dps = 0.0f;
    return;
  }
  switch (q->mode) {
  case QUAD_NULL_PROBE_BASE:
  case QUAD_NULL_PROBE_STEP: probe(d, q, quad_dps); break;
  case QUAD_NULL_RUN: run(d, q, quad_dps); break;
  case QUAD_NULL_OFF:
  case QUAD_NULL_FAILED:
  default: break;
  }
}
