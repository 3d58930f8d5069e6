#include "gyro/board_therm.h"

#include <math.h>

#include "dsp/fastmath.h"

static float step_a(double tau_s)
{
  return (float)(1.0 - exp(-(double)BOARD_THERM_STEP_S / tau_s));
}

static uint32_t to_steps(float t_s)
{
  const double n = (double)t_s / (double)BOARD_THERM_STEP_S;
  return n >= 4.0e9 ? 4000000000u : (uint32_t)(n + 0.5);
}

void board_therm_design(board_therm_cfg_t *c, uint32_t on, const float tz_s[2],
                        const float tp_s[2], float ref_c, const float c_dps[4], float min_c,
                        float max_c, float crossover_s, float start_s, float fade_s,
                        float stale_s, float agree_dps)
{
  c->agree_dps = agree_dps;
  c->on = on;
  for (uint32_t k = 0u; k < 2u; k++) {
    /* (1 + s tz) / (1 + s tp) = r + (1 - r) / (1 + s tp), r = tz / tp */
    c->r[k] = (float)((double)tz_s[k] / (double)tp_s[k]);
    c->a[k] = step_a((double)tp_s[k]);
  }
  c->ref_c = ref_c;
  for (uint32_t k = 0u; k < 4u; k++) c->c[k] = c_dps[k];
  c->min_c = min_c;
  c->max_c = max_c;
  c->lp_a = step_a((double)crossover_s);
  c->start_steps = to_steps(start_s);
  c->fade_steps = to_steps(fade_s);
  c->stale_steps = to_steps(stale_s);
}

void board_therm_init(board_therm_t *s)
{
  *s = (board_therm_t){0};
  s->state = BOARD_THERM_WAIT;
}

void board_therm_reading(const board_therm_cfg_t *c, board_therm_t *s, float x_c)
{
  if (!fm_isfinite(x_c)) return;
  s->x_c = x_c;
  s->age_steps = 0u;
  s->readings++;
  if (s->have == 0u) {
    /* the lead-lag in its steady state at the first reading */
    const float u = x_c - c->ref_c;
    s->in[0] = s->in[1] = u;
    s->e[0] = s->e[1] = 0.0f;
    s->y_c = x_c;
  }
}

/* One section in its lag form: e = in - LP(in) moves by in's step, then decays by (1 - a);
 * the output r in + (1 - r) LP(in) = in - (1 - r) e. */
static float section(const board_therm_cfg_t *c, board_therm_t *s, uint32_t k, float in)
{
  s->e[k] = (1.0f - c->a[k]) * (s->e[k] + (in - s->in[k]));
  s->in[k] = in;
  return in - (1.0f - c->r[k]) * s->e[k];
}

static float model_dps(const board_therm_cfg_t *c, float y_c)
{
  const float u = y_c - c->ref_c;
  return c->c[0] + u * (c->c[1] + u * (c->c[2] + u * c->c[3]));
}

static float weight(const board_therm_cfg_t *c, uint32_t steps)
{
  if (steps < c->start_steps) return 0.0f;
  if (c->fade_steps == 0u) return 1.0f;
  return fm_clampf((float)(steps - c->start_steps) / (float)c->fade_steps, 0.0f, 1.0f);
}

static board_therm_state_t judge(const board_therm_cfg_t *c, const board_therm_t *s)
{
  if (c->on == 0u) return BOARD_THERM_OFF;
  if (s->have == 0u) return BOARD_THERM_WAIT;
  if (s->age_steps > c->stale_steps) return BOARD_THERM_STALE;
  if (!(s->y_c >= c->min_c && s->y_c <= c->max_c)) return BOARD_THERM_RANGE;
  if (s->d_on != 0u && !(fm_absf(s->d_dps) <= c->agree_dps)) return BOARD_THERM_DISAGREE;
  return BOARD_THERM_OK;
}

/* The lead-lag on the held reading, then the model. */
static void model_step(const board_therm_cfg_t *c, board_therm_t *s)
{
  const float v1 = section(c, s, 0u, s->x_c - c->ref_c);
  s->y_c = section(c, s, 1u, v1) + c->ref_c;
  s->model_dps = model_dps(c, s->y_c);
  s->have = 1u;
}

/* The crossover's low-pass of B_s - sf M: it starts at the disagreement of its first
 * settled step (the fused bias is then the model's), and again after an unsettled one.
 * Returns whether it took this step. */
static int cross_step(const board_therm_cfg_t *c, board_therm_t *s, board_therm_bias_t b)
{
  if (b.settled == BOARD_THERM_BIAS_HOLD || s->have == 0u) return 0;
  if (b.settled == 0u || !fm_isfinite(b.dps) || !fm_isfinite(b.static_dps) || !fm_isfinite(b.sf)) {
    s->d_on = 0u;
    return 0;
  }
  const float dis = b.static_dps - b.sf * s->model_dps;
  s->d_dps = s->d_on == 0u ? dis : s->d_dps + c->lp_a * (dis - s->d_dps);
  s->d_on = 1u;
  return 1;
}

void board_therm_step(const board_therm_cfg_t *c, board_therm_t *s, board_therm_bias_t b)
{
  if (s->steps < 4000000000u) s->steps++;
  if (s->age_steps < 4000000000u) s->age_steps++;
  if (c->on == 0u) {
    s->w = 0.0f;
    s->corr_dps = 0.0f;
    s->state = BOARD_THERM_OFF;
    return;
  }
  if (s->readings > 0u) model_step(c, s);
  const int took = cross_step(c, s, b);
  s->w = weight(c, s->steps);
  s->state = judge(c, s);
  /* B - B_P = (B_s - d) - B_P. Not trusted, or nothing new to take it from: the
   * correction holds its last value (the rate is not valid then, or the step is the
   * one the interrupt fell into). */
  if (s->w == 0.0f) s->corr_dps = 0.0f;
  else if (took && s->state == BOARD_THERM_OK)
    s->corr_dps = s->w * ((b.static_dps - s->d_dps) - b.dps);
}

const char *board_therm_state_name(board_therm_state_t st)
{
  static const char *const names[] = {"off", "wait", "ok", "stale", "range", "disagree"};
  return (uint32_t)st < sizeof names / sizeof names[0] ? names[st] : "?";
}
