#include "gyro/quad_null.h"

#include <math.h>
#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/math_const.h"

static int pos_finite(float x) { return isfinite(x) && x > 0.0f; }

int quad_null_design(const quad_null_cfg_t *cfg, quad_null_design_t *d)
{
  if (cfg == NULL || d == NULL) return -1;
  const float c = cfg->gain_dps_per_v2;
  if (!(isfinite(c) && c != 0.0f) || !pos_finite(cfg->bw_hz) || !pos_finite(cfg->v_max_v) ||
      !pos_finite(cfg->settle_dps) || !(isfinite(cfg->settle_s) && cfg->settle_s >= 0.0f) ||
      !pos_finite(cfg->dt_s))
    return -1;
  /* a first-order loop needs its crossover well under the update rate */
  if (cfg->bw_hz * cfg->dt_s > 0.1f) return -1;
  const float updates = cfg->settle_s / cfg->dt_s;
  if (!(updates < 4.0e9f)) return -1;
  const float u_max = cfg->v_max_v * cfg->v_max_v;
  /* e = -q and q = q0 + c u: Ki = 2 pi f_c / c gives the crossover f_c */
  const pi_cfg_t pc = {0.0f, FM_TWO_PI_F * cfg->bw_hz / c, cfg->dt_s, -u_max, u_max, 0.0f};
  quad_null_design_t t;
  if (pi_design(&pc, &t.pi) != 0) return -1;
  t.settle_dps = cfg->settle_dps;
  t.settle_updates = (uint32_t)updates;
  *d = t;
  return 0;
}

/* u -> the electrode pair: one electrode carries sqrt(|u|), the other nothing */
static void electrodes(const quad_null_design_t *d, quad_null_t *q, float u)
{
  q->at_limit = (u >= d->pi.u_max || u <= d->pi.u_min) ? 1u : 0u;
  q->v1_v = u > 0.0f ? fm_sqrtf(u) : 0.0f;
  q->v2_v = u < 0.0f ? fm_sqrtf(-u) : 0.0f;
}

void quad_null_reset(const quad_null_design_t *d, quad_null_t *q, float u_v2)
{
  const float u = isfinite(u_v2) ? u_v2 : 0.0f;
  (void)pi_reset(&d->pi, &q->pi, u, 0.0f);
  q->integ_v2 = q->pi.u;
  q->in_band = 0u;
  q->settled = 0u;
  electrodes(d, q, q->pi.u);
}

void quad_null_update(const quad_null_design_t *d, quad_null_t *q, float quad_dps)
{
  if (!isfinite(quad_dps)) { /* no measurement: hold the voltages, not settled */
    q->in_band = 0u;
    q->settled = 0u;
    return;
  }
  const float u = pi_step_position(&d->pi, &q->pi, &q->integ_v2, -quad_dps);
  electrodes(d, q, u);
  const float a = quad_dps < 0.0f ? -quad_dps : quad_dps;
  if (a <= d->settle_dps && !q->at_limit) {
    if (q->in_band < d->settle_updates) q->in_band++;
  } else {
    q->in_band = 0u;
  }
  q->settled = q->in_band >= d->settle_updates ? 1u : 0u;
}
