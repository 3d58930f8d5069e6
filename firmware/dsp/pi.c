#include "dsp/pi.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include "dsp/ramfunc.h"

static int finite_f(float x)
{
  return isfinite(x) != 0;
}

static float clampf(float x, float lo, float hi)
{
  return (x > hi) ? hi : ((x < lo) ? lo : x);
}

static int gains_valid(float kp, float ki, float dt_s)
{
  /* Ki T must be finite too (a huge Ki could overflow). */
  return finite_f(kp) && finite_f(ki) && finite_f(ki * dt_s);
}

static void set_coeffs(pi_t *pi, float kp, float ki)
{
  pi->kp = kp;
  pi->ki = ki;
  pi->ki_t = ki * pi->dt_s;
}

static int limits_valid(float u_min, float u_max)
{
  return finite_f(u_min) && finite_f(u_max) && u_min < u_max;
}

int pi_init(pi_t *pi, const pi_cfg_t *cfg)
{
  if (pi == NULL || cfg == NULL || !(cfg->dt_s > 0.0f && cfg->dt_s <= FLT_MAX) ||
      !gains_valid(cfg->kp, cfg->ki, cfg->dt_s) || !limits_valid(cfg->u_min, cfg->u_max) ||
      !(cfg->u_init >= cfg->u_min && cfg->u_init <= cfg->u_max)) {
    return -1;
  }
  pi->dt_s = cfg->dt_s;
  set_coeffs(pi, cfg->kp, cfg->ki);
  pi->u_min = cfg->u_min;
  pi->u_max = cfg->u_max;
  pi->u = cfg->u_init;
  pi->e_prev = 0.0f;
  return 0;
}

int pi_set_gains(pi_t *pi, float kp, float ki)
{
  if (pi == NULL || !gains_valid(kp, ki, pi->dt_s)) {
    return -1;
  }
  /* Velocity form: u(k-1) and e(k-1) stay, so nothing jumps. */
  set_coeffs(pi, kp, ki);
  return 0;
}

int pi_set_limits(pi_t *pi, float u_min, float u_max)
{
  if (pi == NULL || !limits_valid(u_min, u_max)) {
    return -1;
  }
  pi->u_min = u_min;
  pi->u_max = u_max;
  pi->u = clampf(pi->u, u_min, u_max);
  return 0;
}

GYRO_RAMFUNC int pi_reset(pi_t *pi, float u, float e_prev)
{
  if (pi == NULL || !finite_f(u) || !finite_f(e_prev)) {
    return -1;
  }
  pi->u = clampf(u, pi->u_min, pi->u_max);
  pi->e_prev = e_prev;
  return 0;
}
