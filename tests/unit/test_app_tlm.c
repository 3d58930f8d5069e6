/* The stream/stop commands of the application, end to end through the host UART stub:
 * the real app (ISR glue, background loop, command line), the TX bytes split by the
 * receiver (tools/tlm_decode) into reply lines and frames. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "app/app.h"
#include "app/app_tlm_fields.h"
#include "tlm_decode.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"

static void quiet_plant(void *p, const hal_dac_frame_t *dac, hal_adc_frame_t *adc)
{
  (void)p;
  (void)dac;
  adc->drive = 0;
  adc->sense = 0;
}

static app_t app;
static tlm_decode_t rx;

typedef struct {
  uint32_t lines;
  char line[64][TLM_DECODE_LINE_MAX + 1u];
  uint32_t headers, records, bad_ticks;
  uint32_t bad_valid; /* rate_valid words other than 0 or 1 */
  uint32_t last_tick;
  tlm_layout_t layout;
} sink_t;
static sink_t got;

static void on_text(void *ctx, const char *s, size_t n)
{
  sink_t *g = ctx;
  if (g->lines < 64u) memcpy(g->line[g->lines], s, n + 1u);
  g->lines++;
}

static void on_header(void *ctx, const tlm_layout_t *l)
{
  sink_t *g = ctx;
  g->headers++;
  g->layout = *l;
}

/* Records carry the gyro's own tick counter: consecutive records are decim ticks apart. */
static void on_data(void *ctx, const tlm_data_t *d)
{
  sink_t *g = ctx;
  uint32_t f_tick = 99u, f_valid = 99u;
  for (uint32_t f = 0; f < d->layout->n_fields; f++) {
    if (strcmp(d->layout->name[f], "tick") == 0) f_tick = f;
    if (strcmp(d->layout->name[f], "rate_valid") == 0) f_valid = f;
  }
  for (uint32_t r = 0; r < d->n_rec; r++) {
    if (f_valid != 99u && tlm_data_u32(d, r, f_valid) > 1u) g->bad_valid++;
    if (f_tick != 99u) {
      const uint32_t t = tlm_data_u32(d, r, f_tick);
      if (g->records > 0u && t != g->last_tick + d->layout->decim) g->bad_ticks++;
      g->last_tick = t;
    }
    g->records++;
  }
}

static int setup(void **state)
{
  (void)state;
  const hal_flash_host_cfg_t fc = {2u, 16384u, NULL, 250000u, 16u, 0u};
  assert_int_equal(hal_flash_host_configure(&fc), 0);
  hal_uart_host_reset();
  hal_host_attach(quiet_plant, NULL);
  assert_int_equal(app_init(&app), 0);
  assert_int_equal(hal_sample_timer_start(50000u, app_sample_isr, &app), 0);
  memset(&got, 0, sizeof got);
  const tlm_decode_cfg_t dc = {on_text, on_header, on_data, &got};
  tlm_decode_init(&rx, &dc);
  return 0;
}

static void drain(void)
{
  uint8_t buf[4096];
  size_t n;
  while ((n = hal_uart_host_tx_pop(buf, sizeof buf)) > 0u) {
    tlm_decode_feed(&rx, buf, n);
  }
}

/* Send a line; the reply is the last text line received. */
static const char *cmd(const char *line)
{
  hal_uart_host_rx_push((const uint8_t *)line, strlen(line));
  app_poll(&app);
  drain();
  assert_true(got.lines > 0u);
  return got.line[(got.lines - 1u) % 64u];
}

/* Run the tick and the background loop (every 50 ticks, 1 ms) for ms milliseconds. */
static void run_ms(uint32_t ms)
{
  for (uint32_t i = 0; i < ms; i++) {
    hal_host_run(50u);
    app_poll(&app);
    drain();
  }
}

static void test_list_fields(void **state)
{
  (void)state;
  const uint32_t before = got.lines;
  assert_string_equal(cmd("stream\n"), "ok 19 fields; usage: stream FIELD...|all [@RATE_HZ]");
  assert_int_equal(got.lines - before, 20u);
  assert_string_equal(got.line[before], "- rate_dps f32 deg/s");
  assert_string_equal(got.line[before + 12u], "- mode u32 -");
  assert_string_equal(got.line[before + 15u], "- tick u32 -");
  assert_string_equal(got.line[before + 16u], "- rate_valid u32 -");
  assert_string_equal(got.line[before + 17u], "- f_drive_hz f32 Hz");
  assert_string_equal(got.line[before + 18u], "- rate_invalid u32 -");
}

/* Every bad request is refused with a clear err and starts nothing. */
static void test_errors_change_nothing(void **state)
{
  (void)state;
  const struct {
    const char *line, *prefix;
  } bad[] = {
      {"stream bogus_dps\n", "err NAME no field 'bogus_dps'"},
      {"stream rate_dps rate_dps\n", "err ARGS field 'rate_dps' given twice"},
      {"stream @100\n", "err ARGS usage"},
      {"stream rate_dps @100 @200\n", "err ARGS one @RATE_HZ"},
      {"stream rate_dps @abc\n", "err VALUE"},
      {"stream rate_dps @nan\n", "err VALUE"},
      {"stream rate_dps @1e999\n", "err VALUE"},
      {"stream rate_dps @\n", "err VALUE"},
      {"stream rate_dps @0\n", "err RANGE"},
      {"stream rate_dps @-5\n", "err RANGE"},
      {"stream rate_dps @50001\n", "err RANGE"},
      {"stream rate_dps @0.5\n", "err RANGE"},
      {"stream all @1000\n",
       "err BANDWIDTH 19 fields at 1000 Hz need 81555 B/s, over 70% of the link (64512 of 92160 B/s)"},
      {"stream tick @50000\n", "err BANDWIDTH"},
      {"stop now\n", "err ARGS"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    const char *r = cmd(bad[i].line);
    if (strncmp(r, bad[i].prefix, strlen(bad[i].prefix)) != 0) {
      fail_msg("%s-> %s (want %s)", bad[i].line, r, bad[i].prefix);
    }
  }
  run_ms(50u);
  assert_int_equal(rx.st.headers + rx.st.data, 0u);
  assert_false(app.tlm.stream.streaming);
  assert_string_equal(cmd("stop\n"), "ok not streaming");
}

/* A stream at 1 kHz for 1 s with replies in between; stop reports what the host got. */
static void test_stream_and_stop(void **state)
{
  (void)state;
  /* N = 240 / 12 = 20 records, raw 253, wire 256 B, 50 frames/s; header raw
   * 30 + (2+8) + (2+8) + (2+4) = 56, wire 59 B once a second: 12859 B/s of 92160 */
  assert_string_equal(cmd("stream tick rate_dps quad_dps @1000\n"),
                      "ok stream 1 1000 Hz decim 50 fields 3 per_frame 20 link 12859 B/s 14%");
  run_ms(300u);
  /* a command while streaming: its reply comes through whole */
  const char *r = cmd("get sys.fs_hz\n");
  assert_string_equal(r, "ok sys.fs_hz 50000 Hz");
  run_ms(710u); /* 1010 records: the last frame of 20 is partial when stop comes */
  char want[128];
  const uint32_t before = got.records;
  r = cmd("stop\n");
  tlm_stats_t st;
  tlm_stats(&app.tlm.stream, &st);
  snprintf(want, sizeof want, "ok stop 1 records %u lost 0 frames %u dropped 0",
           (unsigned)st.records, (unsigned)st.frames);
  assert_string_equal(r, want);
  assert_true(got.records > before); /* stop sent the last frames before its reply */
  assert_int_equal(got.records, st.records);
  assert_true(st.records >= 1010u && st.records <= 1011u);
  assert_int_equal(got.bad_ticks, 0u);
  assert_int_equal(got.layout.n_fields, 3u);
  assert_string_equal(got.layout.name[0], "rate_dps"); /* table order, not argument order */
  assert_string_equal(got.layout.name[2], "tick");
  assert_int_equal(rx.st.corrupt + rx.st.bad_format + rx.st.no_layout + rx.st.lines_bad, 0u);
  assert_int_equal(rx.st.seq_missing + rx.st.rec_missing, 0u);
  /* nothing after stop */
  const uint32_t frames = rx.st.headers + rx.st.data;
  run_ms(100u);
  assert_int_equal(rx.st.headers + rx.st.data, frames);
}

/* The rate is rounded to fs / integer and said so; without @, tlm.rate_hz applies. */
static void test_rate_rounding_and_default(void **state)
{
  (void)state;
  const char *r = cmd("stream tick @3000\n");
  assert_true(strncmp(r, "ok stream 1 2941.1765 Hz decim 17 ", 34u) == 0);
  assert_non_null(strstr(r, " rounded from 3000"));
  r = cmd("stream tick\n");
  assert_true(strncmp(r, "ok stream 2 100 Hz decim 500 ", 29u) == 0);
  assert_null(strstr(r, "rounded"));
  assert_true(strncmp(cmd("set tlm.rate_hz 250\n"), "ok", 2u) == 0);
  r = cmd("stream all\n");
  assert_true(strncmp(r, "ok stream 3 250 Hz decim 200 fields 19 ", 39u) == 0);
  run_ms(100u);
  assert_string_equal(got.layout.name[15], "tick");
  assert_string_equal(got.layout.name[16], "rate_valid");
  assert_true(strncmp(cmd("stop\n"), "ok stop 3 records ", 18u) == 0);
  assert_int_equal(got.bad_ticks, 0u);
}

/* A field past the 16th (rate_valid, row 16) selected with a low one: the command takes
 * it, and the host receives both in table order, each in its place (the gyro's tick
 * counter advances by decim; rate_valid is 0 or 1). */
static void test_stream_field_past_16(void **state)
{
  (void)state;
  assert_int_equal(app_tlm_field_lookup("rate_valid", 10u), 16u);
  const char *want = "ok stream 1 1000 Hz decim 50 fields 2 ";
  assert_true(strncmp(cmd("stream rate_valid tick @1000\n"), want, strlen(want)) == 0);
  run_ms(200u);
  assert_true(strncmp(cmd("stop\n"), "ok stop 1 records ", 18u) == 0);
  assert_int_equal(got.layout.n_fields, 2u);
  assert_string_equal(got.layout.name[0], "tick");
  assert_string_equal(got.layout.name[1], "rate_valid");
  assert_int_equal(got.layout.type[1], (uint8_t)TLM_T_U32);
  assert_true(got.records >= 200u);
  assert_int_equal(got.bad_ticks + got.bad_valid, 0u);
  assert_int_equal(rx.st.corrupt + rx.st.bad_format + rx.st.no_layout, 0u);
  assert_int_equal(rx.st.seq_missing + rx.st.rec_missing, 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_list_fields, setup),
      cmocka_unit_test_setup(test_errors_change_nothing, setup),
      cmocka_unit_test_setup(test_stream_and_stop, setup),
      cmocka_unit_test_setup(test_rate_rounding_and_default, setup),
      cmocka_unit_test_setup(test_stream_field_past_16, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
