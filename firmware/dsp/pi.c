#include "dsp/pi.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include "dsp/ramfunc.h"

static int finite_f(float x) { return isfinite(x) != 0; }

static float clampf(float x, float lo, float hi) { return (x > hi) ? hi : ((x < lo) ? lo : x); }

static int gains_valid(float kp, float ki, float dt_s)
{
  /* Ki T must be finite too (a huge Ki could overflow). */
  return finite_f(kp) && finite_f(ki) && finite_f(ki * dt_s);
}

static int limits_valid(float u_min, float u_max)
{
  return finite_f(u_min) && finite_f(u_max) && u_min < u_max;
}

int pi_design(const pi_cfg_t *cfg, pi_coeffs_t *c)
{
  if (c == NULL || cfg == NULL || !(cfg->dt_s > 0.0f && cfg->dt_s <= FLT_MAX) ||
      !gains_valid(cfg->kp, cfg->ki, cfg->dt_s) || !limits_valid(cfg->u_min, cfg->u_max) ||
      !(cfg->u_init >= cfg->u_min && cfg->u_init <= cfg->u_max)) {
    return -1;
  }
  c->kp = cfg->kp;
  c->ki_t = cfg->ki * cfg->dt_s;
  c->u_min = cfg->u_min;
  c->u_max = cfg->u_max;
  return 0;
}

int pi_init(const pi_cfg_t *cfg, pi_coeffs_t *c, pi_t *pi)
{
  if (pi == NULL || pi_design(cfg, c) != 0) {
    return -1;
  }
  pi->u = cfg->u_init;
  pi->e_prev = 0.0f;
  return 0;
}

void pi_limit(const pi_coeffs_t *c, pi_t *pi) { pi->u = clampf(pi->u, c->u_min, c->u_max); }

GYRO_RAMFUNC int pi_reset(const pi_coeffs_t *restrict c, pi_t *restrict pi, float u, float e_prev)
{
  if (pi == NULL || !finite_f(u) || !finite_f(e_prev)) {
    return -1;
  }
  pi->u = clampf(u, c->u_min, c->u_max);
  pi->e_prev = e_prev;
  return 0;
}
