#include "app/app_tune.h"

#include <stdatomic.h>

#include "gyro/gyro_dac.h"
#include "gyro/rate_valid.h"

/* The lost-match monitor's pass (sense_tune.h), on the weights the continuous test's LMS
 * keeps (the sample path does nothing more for it): fed while LOCKED with the notch
 * converged, started again otherwise. True while the rate must wait for it or the match
 * is lost. */
static bool disc_invalid(app_t *a, bool locked)
{
  const gyro_t *g = &a->gyro;
  const sense_tune_disc_cfg_t *c = &g->design->tune_disc;
  if (c->on == 0u) return false;
  const uint32_t now = app_ticks(a);
  /* A new design (another model, tone or loop) has another c0 and u: what the low-pass
   * holds was measured against the old ones. */
  const bool redesigned = a->tune_disc_design != (const void *)g->design;
  a->tune_disc_design = g->design;
  if (redesigned || !locked || g->selftest.cont_blocks < g->design->selftest.cont_settle_blocks) {
    sense_tune_disc_reset(&a->tune_disc, now);
    return true;
  }
  /* The weights with the modulation's phase they go with: a sample the interrupt may
   * have changed while it was read (a tick between the two reads of the tick count) is
   * left out. */
  const volatile uint32_t *tick = &g->out.tick;
  const uint32_t t = *tick;
  atomic_signal_fence(memory_order_seq_cst);
  const uint32_t phase = g->selftest.cont_phase;
  const float w[4] = {g->selftest.w[0], g->selftest.w[1], g->selftest.w[2], g->selftest.w[3]};
  atomic_signal_fence(memory_order_seq_cst);
  if (*tick == t) sense_tune_disc_feed(c, &a->tune_disc, w, phase, now);
  return !sense_tune_disc_settled(&a->tune_disc) || a->tune_disc.lost != 0u;
}

void app_tune_poll(app_t *a)
{
  const gyro_t *g = &a->gyro;
  if (g->sup.mode == GYRO_MODE_SWEEP || selfcal_running(&a->selfcal) || a->sweep_owns_drive ||
      app_requests_pending(a))
    return;
  const sense_tune_cfg_t *c = &g->design->tune;
  sense_tune_at(c, (double)g->out.f_drive_hz, &a->tune);
  a->tune_locked = g->sup.mode == GYRO_MODE_LOCKED;
  uint16_t code = (uint16_t)HAL_DAC_CODE_MID;
  bool invalid = false;
  if (c->mode != SENSE_TUNE_OFF) {
    const bool reach = a->tune.state == SENSE_TUNE_OK || a->tune.state == SENSE_TUNE_LIMIT;
    if (a->tune_locked && reach) code = gyro_volts_to_dac((float)a->tune.v_v);
    invalid = !a->tune_locked || a->tune.state != SENSE_TUNE_OK;
  }
  if (disc_invalid(a, a->tune_locked)) invalid = true;
  const bool was_invalid = (g->bg_bits & RATE_INVALID_TUNE) != 0u;
  if (code != a->dac.code[HAL_DAC_TUNE] || invalid != was_invalid)
    (void)app_request_word(a, APP_REQ_TUNE_WORD(code, invalid)); /* the queue is empty */
}
