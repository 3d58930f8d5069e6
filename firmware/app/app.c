#include "app/app.h"

#include <stdatomic.h>
#include <stddef.h>
#include <string.h>

#include "hal/hal_adc.h"
#include "hal/hal_dac.h"
#include "hal/hal_flash.h"
#include "hal/hal_sample_timer.h"
#include "hal/hal_uart.h"
#include "app/app_cmds.h"
#include "app/app_selfcal.h"
#include "app/app_board.h"
#include "app/app_tune.h"
#include "comm/cli_builtin.h"
#include "dsp/ramfunc.h"

static int derive(void *ctx, const param_values_t *v, void *derived, const char **why)
{
  (void)ctx;
  gyro_design_t *d = derived;
  const gyro_design_status_t rc = gyro_design(v, d);
  if (rc != GYRO_DESIGN_OK) {
    if (why != NULL) {
      *why = gyro_design_reason(rc); /* names the parameters at fault */
    }
    return -(int)rc;
  }
  return 0;
}

/* Non-live parameters and flash saves need the drive off: an erase stalls every flash
 * fetch for hundreds of ms while the drive decays in a few (param_store.h). Off means
 * commanded off: a sweep excites the drive, a fault's wait ends in a restart by itself,
 * and a queued drive on is as good as done. */
static bool loop_safe(void *ctx)
{
  const app_t *a = ctx;
  return a->handing_over ||
         (app_mode_after_queue(a) == GYRO_MODE_OFF && !selfcal_running(&a->selfcal));
}

static void cli_write(void *ctx, const char *data, size_t len)
{
  (void)ctx;
  /* A line is only executed, and a console echo only written, with room for the
   * longest reply (feed_lines): all fits, and nothing cuts a telemetry frame. */
  (void)hal_uart_write((const uint8_t *)data, len);
}

static bool designable(app_t *a, const param_values_t *v, const char **why)
{
  return derive(a, v, &a->derived[0], why) == 0; /* derived[0]: scratch before params_init */
}

static void mark_dropped(app_t *a, unsigned i, bool on)
{
  const uint32_t bit = 1u << (i % 32u);
  a->store_dropped[i / 32u] = on ? (a->store_dropped[i / 32u] | bit)
                                 : (a->store_dropped[i / 32u] & ~bit);
}

/* A stored set whose values pass one by one but cannot be designed together: set stored
 * values back to their defaults, in table order, until the set designs; then take back
 * every one of them that designs with the rest. What stays dropped is in store_dropped. */
static void keep_designable(app_t *a, param_values_t *v)
{
  if (designable(a, v, &a->store_dropped_why)) return;
  const param_values_t stored = *v;
  unsigned end = 0u; /* one past the last value set back */
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if ((pi->flags & PF_PERSIST) == 0u ||
        param_value_equal((param_idx_t)i, param_get(v, (param_idx_t)i), pi->def)) {
      continue;
    }
    param_put(v, (param_idx_t)i, pi->def);
    mark_dropped(a, i, true);
    end = i + 1u;
    if (designable(a, v, NULL)) break;
  }
  for (unsigned i = 0; i < end; i++) {
    if (!app_store_dropped(a, (param_idx_t)i)) continue;
    param_values_t t = *v;
    param_put(&t, (param_idx_t)i, param_get(&stored, (param_idx_t)i));
    if (designable(a, &t, NULL)) {
      *v = t;
      mark_dropped(a, i, false);
    }
  }
}

int app_init_with(app_t *a, const param_values_t *values)
{
  memset(a, 0, sizeof *a);
  hal_dac_frame_midscale(&a->dac);
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
        keep_designable(a, &loaded);
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
    /* Values that cannot be designed even with the stored ones dropped: fall back to the
     * defaults, unless the caller insisted on its own. */
    if (values != NULL || params_init(&a->params, &pc, NULL, &err) != PARAM_OK) {
      return -1;
    }
  }
  const uint32_t gen = params_isr_ack(&a->params);
  const params_view_t view = params_isr_view(&a->params, gen);
  if (gyro_init_from_design(&a->gyro, view.derived) != 0) {
    return -2;
  }
  gyro_attach_lost_counter(&a->gyro, hal_sample_lost_counter());
  gyro_attach_dac_frame(&a->gyro, &a->dac);         /* the frame every tick writes */
  gyro_attach_adc_frame(&a->gyro, hal_adc_frame()); /* and the one it reads */
  a->applied = view.derived;
  a->applied_gen = gen;
  app_board_init(a);

  const cli_cfg_t cc = {&a->params, &a->store,        cli_write,
                        a,          cli_builtin_cmds, cli_builtin_count()};
  if (cli_init(&a->cli, &cc) != 0 || app_cmds_register(a) != 0 ||
      app_tlm_init(&a->tlm, &a->cli, &a->params) != 0 ||
      selfcal_init(&a->selfcal, &a->gyro.cal) != 0) {
    return -3;
  }
  return 0;
}

int app_init(app_t *a) { return app_init_with(a, NULL); }

/* ISR: one request at the tick boundary. */
static void take_request(app_t *a, uint32_t req)
{
  switch ((app_req_t)APP_REQ_KIND(req)) {
  case APP_REQ_DRIVE_ON:
    /* from a sweep or a fault's wait as well: the command takes the drive over now */
    if (!supervisor_drive_enabled(&a->gyro.sup)) gyro_stop(&a->gyro);
    gyro_start(&a->gyro);
    supervisor_clear_fault(&a->gyro.sup);
    break;
  case APP_REQ_SWEEP: gyro_sweep_begin(&a->gyro); break;
  case APP_REQ_SWEEP_HANDOVER:
    /* The design committed with the identified model was applied above. */
    (void)gyro_sweep_handover(&a->gyro, a->applied);
    break;
  case APP_REQ_SELFTEST: selftest_start(&a->gyro.selftest); break;
  case APP_REQ_CLEAR: supervisor_clear_fault(&a->gyro.sup); break;
  case APP_REQ_TUNE:
    gyro_set_tune(&a->gyro, APP_REQ_TUNE_CODE(req),
                  APP_REQ_TUNE_INVALID(req) ? RATE_INVALID_TUNE : 0u);
    break;
  case APP_REQ_BOARD:
    gyro_set_board(&a->gyro, APP_REQ_BOARD_INVALID(req) ? RATE_INVALID_BOARD_TEMP : 0u);
    break;
  case APP_REQ_DRIVE_OFF: gyro_stop(&a->gyro); break;
  case APP_REQ_NONE:
  default: break;
  }
}

/* ISR: what a tick takes on at its start besides the frame, rarely: a new design (the
 * bank's generation gen, published since the last tick), then one queued request. Out of
 * line, so that the tick's path keeps nothing but the application across its calls; in
 * flash, like gyro_apply and the requests' calls (linker/check_ramfunc.py, OFF_PATH). */
GYRO_NOINLINE static void take_changes(app_t *a, uint32_t gen)
{
  if (gen != a->applied_gen) {
    const params_view_t view = params_isr_view(&a->params, gen);
    gyro_apply(&a->gyro, view.derived);
    a->applied = view.derived;
    a->applied_gen = gen;
  }
  const uint32_t tail = a->req_tail;
  if (tail != a->req_head) {
    atomic_signal_fence(memory_order_acquire); /* the word was written before the head */
    take_request(a, a->req_word[tail % APP_REQ_QUEUE]);
    a->req_tail = tail + 1u;
  }
}

GYRO_RAMFUNC void app_sample_isr(void *ctx)
{
  app_t *a = ctx;

  const uint32_t gen = params_isr_ack(&a->params); /* this tick's parameters */
  /* Both tests in one branch (| rather than ||: the tick's path falls through). */
  if (GYRO_UNLIKELY((gen != a->applied_gen) | (a->req_tail != a->req_head))) {
    take_changes(a, gen);
  }

  gyro_tick(&a->gyro); /* the HAL's ADC frame in, a->dac out: attached at init */
  app_tlm_isr(&a->tlm, &a->gyro.out);
  /* Last, as a tail call: the frame is sent at the DAC's slots late in the period, and
   * what the telemetry takes of the tick does not touch it. Its ticks are the gyro's
   * (app_ticks), its cycles the HAL's, which measures the whole handler
   * (hal_sample_isr_cycles). */
  hal_dac_write_frame(&a->dac);
}

void app_cli_feed(app_t *a, const uint8_t *data, size_t len) { cli_feed(&a->cli, data, len); }

/* UART -> command line, one line at a time while the TX ring has room for the longest
 * reply; bytes not yet fed wait in rx_buf for the next pass. */
static void feed_lines(app_t *a)
{
  for (;;) {
    if (a->rx_pos == a->rx_len) {
      a->rx_pos = 0u;
      a->rx_len = (uint32_t)hal_uart_read(a->rx_buf, sizeof a->rx_buf);
      if (a->rx_len == 0u) {
        /* everything before a loss has been fed: the line in progress lost bytes */
        if (hal_uart_rx_lost()) cli_rx_lost(&a->cli);
        return;
      }
    }
    if (hal_uart_tx_free() < APP_TLM_TX_RESERVE) return;
    a->rx_pos += (uint32_t)cli_feed_line(&a->cli, &a->rx_buf[a->rx_pos], a->rx_len - a->rx_pos);
  }
}

void app_poll(app_t *a)
{
  feed_lines(a);
  app_tlm_poll(&a->tlm);
  app_selfcal_poll(a);
  app_tune_poll(a);
  app_board_poll(a);
}
