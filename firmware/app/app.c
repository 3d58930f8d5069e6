#include "app/app.h"

#include <stddef.h>
#include <string.h>

#include "hal/hal_adc.h"
#include "hal/hal_dac.h"
#include "hal/hal_flash.h"
#include "hal/hal_sample_timer.h"
#include "hal/hal_uart.h"
#include "app/app_cmds.h"
#include "app/app_selfcal.h"

static int derive(void *ctx, const param_values_t *v, void *derived, const char **why)
{
  (void)ctx;
  gyro_design_t *d = derived;
  const int rc = gyro_design(v, d);
  if (rc != 0) {
    if (why != NULL) {
      *why = "the drive or output filter cannot be designed from these values";
    }
    return rc;
  }
  return 0;
}

/* Non-live parameters and flash saves need the drive off: an erase stalls every flash
 * fetch for hundreds of ms while the drive decays in a few (param_store.h). */
static bool loop_safe(void *ctx)
{
  const app_t *a = ctx;
  return !supervisor_drive_enabled(&a->gyro.sup);
}

static void cli_write(void *ctx, const char *data, size_t len)
{
  (void)ctx;
  const uint8_t *p = (const uint8_t *)data;
  /* The TX ring is sized for the longest reply; what does not fit is lost rather than
   * blocking the background loop. */
  (void)hal_uart_write(p, len);
}

int app_init_with(app_t *a, const param_values_t *values)
{
  memset(a, 0, sizeof *a);
  param_values_t initial;
  param_values_defaults(&initial);

  hal_flash_geometry_t geo;
  hal_flash_geometry(&geo);
  const param_store_cfg_t sc = {0u, 1u};
  a->store_status = PARAM_STORE_ERR_CONFIG;
  if (geo.num_sectors >= 2u && param_store_init(&a->store, &sc) == PARAM_STORE_OK) {
    if (values != NULL) {
      a->store_status = PARAM_STORE_NONE; /* given values: the store is not read */
    } else {
      param_values_t loaded = initial; /* non-persistent values come from here */
      param_store_report_t rep;
      a->store_status = param_store_load(&a->store, &loaded, &rep);
      if (a->store_status == PARAM_STORE_OK) {
        initial = loaded;
      }
    }
  }
  if (values != NULL) {
    initial = *values;
  }

  const params_cfg_t pc = {derive, {&a->derived[0], &a->derived[1]}, loop_safe, a};
  params_err_t err;
  if (params_init(&a->params, &pc, &initial, &err) != PARAM_OK) {
    /* Values that load but cannot be designed: fall back to the defaults, unless the
     * caller insisted on its own. */
    if (values != NULL || params_init(&a->params, &pc, NULL, &err) != PARAM_OK) {
      return -1;
    }
  }
  const params_view_t view = params_isr_acquire(&a->params);
  if (gyro_init_from_design(&a->gyro, view.derived) != 0) {
    return -2;
  }
  gyro_attach_lost_counter(&a->gyro, hal_sample_lost_counter());
  a->applied = view.derived;

  const cli_cfg_t cc = {&a->params, &a->store, cli_write, a};
  if (cli_init(&a->cli, &cc) != 0 || app_cmds_register(a) != 0 ||
      app_tlm_init(&a->tlm, &a->cli, &a->params) != 0 ||
      selfcal_init(&a->selfcal, &a->gyro.cal) != 0) {
    return -3;
  }
  return 0;
}

int app_init(app_t *a) { return app_init_with(a, NULL); }

void app_sample_isr(void *ctx)
{
  app_t *a = ctx;

  const params_view_t view = params_isr_acquire(&a->params);
  if (view.derived != a->applied) {
    gyro_apply(&a->gyro, view.derived);
    a->applied = view.derived;
  }
  const uint32_t req = a->request;
  if (req != APP_REQ_NONE) {
    if (req == APP_REQ_DRIVE_ON) {
      gyro_start(&a->gyro);
    } else if (req == APP_REQ_SWEEP) {
      gyro_sweep_begin(&a->gyro);
    } else if (req == APP_REQ_SWEEP_HANDOVER) {
      /* The design committed with the identified model was applied above. */
      (void)gyro_sweep_handover(&a->gyro, a->applied);
    } else if (req == APP_REQ_SELFTEST) {
      selftest_start(&a->gyro.selftest);
    } else {
      gyro_stop(&a->gyro);
    }
    a->request = APP_REQ_NONE;
  }

  hal_adc_frame_t adc;
  hal_dac_frame_t dac;
  hal_adc_read_frame(&adc);
  gyro_tick(&a->gyro, &adc, &dac);
  hal_dac_write_frame(&dac);
  app_tlm_isr(&a->tlm, &a->gyro.out);

  a->isr_ticks++; /* its cycles: the HAL measures the whole handler (hal_sample_isr_cycles) */
}

void app_cli_feed(app_t *a, const uint8_t *data, size_t len) { cli_feed(&a->cli, data, len); }

void app_poll(app_t *a)
{
  uint8_t buf[64];
  size_t n;
  while ((n = hal_uart_read(buf, sizeof buf)) > 0u) {
    cli_feed(&a->cli, buf, n);
  }
  app_tlm_poll(&a->tlm);
  app_selfcal_poll(a);
}
