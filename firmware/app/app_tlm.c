#include "app/app_tlm.h"

#include <string.h>

#include "app/app_tlm_fields.h"
#include "comm/numparse.h"
#include "hal/hal_uart.h"

static size_t uart_room(void *ctx)
{
  (void)ctx;
  const size_t free_b = hal_uart_tx_free();
  return (free_b > APP_TLM_TX_RESERVE) ? free_b - APP_TLM_TX_RESERVE : 0u;
}

static void uart_write(void *ctx, const uint8_t *data, size_t len)
{
  (void)ctx;
  (void)hal_uart_write(data, len); /* len <= room: all of it is taken */
}

/* stream with no arguments: the field table. */
static void list_fields(cli_t *cli)
{
  for (uint32_t i = 0; i < (uint32_t)TLM_FIELD_COUNT; i++) {
    const tlm_field_t *f = app_tlm_field(i);
    cli_putf(cli, "%s %s %s", f->name, (f->type == (uint8_t)TLM_T_F32) ? "f32" : "u32", f->unit);
    cli_emit_data(cli);
  }
  cli_putf(cli, "%u fields; usage: stream FIELD...|all [@RATE_HZ]", (uint32_t)TLM_FIELD_COUNT);
  cli_emit_ok(cli);
}

static void cmd_stream(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  app_tlm_t *t = ctx;
  if (argc == 1u) {
    list_fields(cli);
    return;
  }
  uint32_t mask = 0u;
  const char *rate_arg = NULL;
  for (uint32_t a = 1u; a < argc; a++) {
    const char *w = argv[a];
    if (w[0] == '@') {
      if (rate_arg != NULL) {
        cli_err(cli, "ARGS", "one @RATE_HZ only");
        return;
      }
      rate_arg = w;
      continue;
    }
    if (strcmp(w, "all") == 0) {
      mask |= TLM_FIELD_MASK_ALL;
      continue;
    }
    const uint32_t i = app_tlm_field_lookup(w, strlen(w));
    if (i >= (uint32_t)TLM_FIELD_COUNT) {
      cli->out_len = 0u;
      cli_putf(cli, "no field '%s'; `stream` alone lists them", w);
      cli_emit_err(cli, "NAME");
      return;
    }
    if ((mask >> i) & 1u) {
      cli->out_len = 0u;
      cli_putf(cli, "field '%s' given twice", w);
      cli_emit_err(cli, "ARGS");
      return;
    }
    mask |= 1u << i;
  }
  if (mask == 0u) {
    cli_err(cli, "ARGS", "usage: stream FIELD...|all [@RATE_HZ]");
    return;
  }
  const param_values_t *v = params_current(t->params);
  float rate_hz = (float)v->tlm_rate_hz;
  if (rate_arg != NULL &&
      numparse_f32(&rate_arg[1], strlen(&rate_arg[1]), &rate_hz) != NUMPARSE_OK) {
    cli_err(cli, "VALUE", "rate is not a number: @RATE_HZ, e.g. @1000");
    return;
  }
  tlm_plan_t plan;
  const tlm_status_t st = tlm_plan(&app_tlm_fields, t->stream.cfg.fs_hz, t->stream.cfg.baud,
                                   mask, rate_hz, &plan);
  if (st == TLM_ERR_RATE) {
    cli->out_len = 0u;
    cli_putf(cli, "rate must be > 0 and within [fs / %u, fs], fs = %u Hz", TLM_DECIM_MAX,
             t->stream.cfg.fs_hz);
    cli_emit_err(cli, "RANGE");
    return;
  }
  if (st == TLM_ERR_BANDWIDTH) {
    cli->out_len = 0u;
    cli_putf(cli,
             "%u fields at %f Hz need %u B/s, over %u%% of the link (%u of %u B/s); "
             "fewer fields or a lower rate",
             plan.n_fields, plan.rate_hz, plan.bytes_per_s, TLM_LINK_MAX_PCT,
             plan.link_bytes_per_s * TLM_LINK_MAX_PCT / 100u, plan.link_bytes_per_s);
    cli_emit_err(cli, "BANDWIDTH");
    return;
  }
  if (st != TLM_OK) {
    cli_err(cli, "ARGS", "usage: stream FIELD...|all [@RATE_HZ]");
    return;
  }
  tlm_start(&t->stream, &plan);
  tlm_stats_t s;
  tlm_stats(&t->stream, &s);
  const uint32_t link_pct = (uint32_t)(((uint64_t)plan.bytes_per_s * 100u +
                                        plan.link_bytes_per_s / 2u) /
                                       plan.link_bytes_per_s);
  cli->out_len = 0u;
  cli_putf(cli, "stream %u %f Hz decim %u fields %u per_frame %u link %u B/s %u%%", s.stream_id,
           plan.rate_hz, plan.decim, plan.n_fields, plan.rec_per_frame, plan.bytes_per_s,
           link_pct);
  if (plan.rate_hz != rate_hz) {
    cli_putf(cli, " rounded from %f", rate_hz);
  }
  cli_emit_ok(cli);
}

static void cmd_stop(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)argv;
  app_tlm_t *t = ctx;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: stop");
    return;
  }
  if (!t->stream.streaming) {
    cli_ok(cli, "not streaming");
    return;
  }
  tlm_stop(&t->stream);
  tlm_stats_t s;
  tlm_stats(&t->stream, &s);
  cli->out_len = 0u;
  cli_putf(cli, "stop %u records %u lost %u frames %u dropped %u", s.stream_id, s.records,
           s.lost, s.frames, s.dropped);
  cli_emit_ok(cli);
}

int app_tlm_init(app_tlm_t *t, cli_t *cli, const params_t *params)
{
  t->params = params;
  const tlm_cfg_t tc = {params_current(params)->sys_fs_hz,
                        APP_TLM_BAUD,
                        uart_room,
                        uart_write,
                        t,
                        &app_tlm_fields};
  if (tlm_init(&t->stream, &tc) != 0) {
    return -1;
  }
  const cli_cmd_t stream = {"stream", "[FIELD...|all [@RATE_HZ]]",
                            "start the telemetry stream (no argument: list the fields)",
                            cmd_stream, t};
  const cli_cmd_t stop = {"stop", "", "stop the telemetry stream", cmd_stop, t};
  t->cmds[0] = stream;
  t->cmds[1] = stop;
  for (uint32_t i = 0; i < 2u; i++) {
    if (cli_register(cli, &t->cmds[i]) != 0) {
      return -1;
    }
  }
  return 0;
}

void app_tlm_poll(app_tlm_t *t) { tlm_poll(&t->stream); }
