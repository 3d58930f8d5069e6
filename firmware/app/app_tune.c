#include "app/app_tune.h"

#include "gyro/gyro_dac.h"
#include "gyro/rate_valid.h"

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
  const bool was_invalid = g->tune_bits != 0u;
  if (code != a->dac.code[HAL_DAC_TUNE] || invalid != was_invalid)
    (void)app_request_word(a, APP_REQ_TUNE_WORD(code, invalid)); /* the queue is empty */
}
