/* The board's TMP117 temperature sensor (board_sensor.h). */
#include "plant/board_sensor.h"

#include <math.h>
#include <stddef.h>

#include "board.h"

int board_sensor_check(const board_sensor_cfg_t *c)
{
  if (c == NULL) return -1;
  if (c->kind != BOARD_SENSOR_NONE && c->kind != BOARD_SENSOR_TMP117) return -1;
  if (!isfinite(c->offset_c) || !isfinite(c->slope) || isnan(c->fault_s)) return -1;
  return 0;
}

int board_sensor_init(board_sensor_t *s, const board_sensor_cfg_t *c, uint64_t seed)
{
  if (s == NULL || board_sensor_check(c) != 0) return -1;
  s->cfg = *c;
  /* the board's facts (board.h): 2^-7 degC and 1 s, exact in float and in double */
  s->lsb_c = (double)BOARD_TEMP_LSB_C;
  s->cycle_s = (double)BOARD_TEMP_CYCLE_S;
  s->half_active_s = 0.5 * BOARD_SENSOR_AVERAGES * BOARD_SENSOR_CONVERSION_S;
  s->sigma_lsb = BOARD_SENSOR_SIGMA_LSB / sqrt((double)BOARD_SENSOR_AVERAGES);
  s->made = s->done = 0u;
  s->pending = 0;
  s->pend_code = s->code = 0;
  s->end_s = 0.0;
  rng_seed(&s->rng, seed, BOARD_SENSOR_RNG_STREAM);
  if (c->kind == BOARD_SENSOR_NONE) {
    s->first_mid_s = s->mid_s = s->due_s = INFINITY;
    return 0;
  }
  /* The sensor powers up with the board and converts from then on: its first result is
   * ready somewhere within the first cycle, as the study draws it. */
  const double phase_s = rng_uniform(&s->rng) * s->cycle_s;
  s->first_mid_s = s->mid_s = s->due_s = phase_s - s->half_active_s;
  return 0;
}

int16_t board_sensor_round(double lsb)
{
  const double r = nearbyint(lsb); /* the default rounding mode: half to even */
  if (!(r < (double)INT16_MAX)) return INT16_MAX;
  if (r <= (double)INT16_MIN) return INT16_MIN;
  return (int16_t)r;
}

/* One result of the node at node_c: the accuracy error and the averaged noise on it,
 * rounded to the register's LSB. */
static int16_t convert(board_sensor_t *s, double node_c)
{
  const double err_c = s->cfg.offset_c + s->cfg.slope * (node_c - 25.0);
  return board_sensor_round((node_c + err_c) / s->lsb_c + s->sigma_lsb * rng_gauss(&s->rng));
}

void board_sensor_step(board_sensor_t *s, double t_s, double node_c)
{
  if (s->pending && t_s >= s->end_s) {
    s->code = s->pend_code;
    s->done++;
    s->pending = 0;
  }
  if (t_s >= s->mid_s) {
    s->pend_code = convert(s, node_c);
    s->end_s = s->mid_s + s->half_active_s;
    s->pending = 1;
    s->made++;
    s->mid_s = s->first_mid_s + (double)s->made * s->cycle_s; /* no accumulated rounding */
  }
  s->due_s = s->pending ? fmin(s->end_s, s->mid_s) : s->mid_s;
  /* the reading turns to NaN at the fault: a step there updates whoever copies it */
  if (s->cfg.fault_s >= 0.0 && s->cfg.fault_s > t_s) s->due_s = fmin(s->due_s, s->cfg.fault_s);
}

hal_board_temp_event_t board_sensor_read(const board_sensor_t *s, double t_s, int16_t *code,
                                         uint64_t *conversion)
{
  if (s->cfg.kind == BOARD_SENSOR_NONE) return HAL_BOARD_TEMP_ABSENT;
  const int ready = s->pending && t_s >= s->end_s; /* finished since the last step */
  const uint64_t n = s->done + (ready ? 1u : 0u);
  if (conversion != NULL) *conversion = n;
  if (s->cfg.fault_s >= 0.0 && t_s >= s->cfg.fault_s) return HAL_BOARD_TEMP_FAULT;
  if (n == 0u) return HAL_BOARD_TEMP_NONE;
  if (code != NULL) *code = ready ? s->pend_code : s->code;
  return HAL_BOARD_TEMP_NEW;
}

double board_sensor_reading_c(const board_sensor_t *s, double t_s)
{
  int16_t code = 0;
  if (board_sensor_read(s, t_s, &code, NULL) != HAL_BOARD_TEMP_NEW) return NAN;
  return (double)code * s->lsb_c;
}
