#include "app/app_board.h"

#include <math.h>
#include <stdatomic.h>

#include "board.h"
#include "gyro/rate_valid.h"
#include "hal/hal_board_temp.h"

/* Sample ticks per step of the fusion. */
#define BOARD_STEP_TICKS (BOARD_SAMPLE_RATE_HZ / BOARD_THERM_STEPS_PER_S)
/* A background stalled this many steps (a flash erase) catches up no further: the
 * filters' time is the sample clock's, a gap of the background's is not the part's. */
#define BOARD_CATCH_UP_STEPS 50u

_Static_assert(BOARD_SAMPLE_RATE_HZ % BOARD_THERM_STEPS_PER_S == 0u && BOARD_STEP_TICKS > 0u,
               "a step of the fusion is whole ticks");

/* What makes the compensation's bias in P not the part's yet: its disagreement with the
 * model is not to be low-passed (the fusion starts it again from the next good step). */
#define BOARD_BIAS_P_UNSETTLED \
  (RATE_INVALID_MODE | RATE_INVALID_SETTLING | RATE_INVALID_THERMO_RANGE | \
   RATE_INVALID_THERMO_SLEW | RATE_INVALID_THERMO_SETTLE)

void app_board_init(app_t *a)
{
  board_therm_init(&a->board);
  a->gyro.out.board_c = (float)NAN;
  a->board_tick = app_ticks(a);
  if (hal_board_temp_start() != 0) a->board.absent = 1u;
}

static void take_conversion(app_t *a)
{
  int16_t code = 0;
  switch (hal_board_temp_poll(&code)) {
  case HAL_BOARD_TEMP_NEW:
    board_therm_reading(&a->gyro.design->board, &a->board, (float)code * BOARD_TEMP_LSB_C);
    a->gyro.out.board_c = a->board.x_c;
    break;
  case HAL_BOARD_TEMP_FAULT: a->board.faults++; break;
  case HAL_BOARD_TEMP_ABSENT: a->board.absent = 1u; break;
  case HAL_BOARD_TEMP_NONE:
  default: break;
  }
}

/* The compensation in P as the sample path refreshed it: its bias less the correction it
 * added, its static part (the cubic in x = P_c - cal.ref_p_deg, rate_channel.h) and its
 * scale factor. A tick between the reads: read again (the interrupt takes a few per cent
 * of the reads' window, never two ticks running). */
static board_therm_bias_t bias_p(const app_t *a)
{
  const gyro_t *g = &a->gyro;
  const rate_channel_cfg_t *rc = &g->design->rate;
  const volatile uint32_t *tick = &g->out.tick;
  for (uint32_t k = 0u; k < 3u; k++) {
    const uint32_t t = *tick;
    atomic_signal_fence(memory_order_seq_cst);
    const float b = g->rate.comp_bias_dps - g->board_corr_applied_dps;
    const float x = rate_channel_comp_x_deg(rc, &g->rate);
    const float sf = g->rate.comp_sf;
    const uint32_t reasons = g->valid.reasons;
    atomic_signal_fence(memory_order_seq_cst);
    if (*tick == t)
      return (board_therm_bias_t){b, rate_channel_bias_static_dps(rc, x), sf,
                                  (reasons & BOARD_BIAS_P_UNSETTLED) == 0u ? 1u : 0u};
  }
  return (board_therm_bias_t){0.0f, 0.0f, 1.0f, BOARD_THERM_BIAS_HOLD};
}

void app_board_poll(app_t *a)
{
  take_conversion(a);
  const board_therm_cfg_t *c = &a->gyro.design->board;
  const uint32_t now = app_ticks(a);
  uint32_t n = 0u;
  while ((uint32_t)(now - a->board_tick) >= BOARD_STEP_TICKS) {
    if (++n > BOARD_CATCH_UP_STEPS) {
      a->board_tick = now;
      break;
    }
    a->board_tick += BOARD_STEP_TICKS;
    board_therm_step(c, &a->board, bias_p(a));
  }
  a->gyro.board_corr_dps = a->board.corr_dps;
  const bool invalid = board_therm_invalid(&a->board) != 0u;
  const bool was = (a->gyro.bg_bits & RATE_INVALID_BOARD_TEMP) != 0u;
  if (invalid != was && !app_requests_pending(a))
    (void)app_request_word(a, APP_REQ_BOARD_WORD(invalid)); /* the queue is empty */
}
