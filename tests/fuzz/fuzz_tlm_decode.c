/* The telemetry receiver fed arbitrary bytes, then one good header + data frame pair from
 * the real encoder. Byte 0 picks the chunk size the bytes arrive in (bits 0-5).
 * Invariants: every delivered line holds only text bytes; every delivered header is a
 * well-formed layout; every delivered data frame matches its layout's record size; the
 * counters never go back; and after any garbage the good frames that follow are decoded
 * exactly (the parser is back in step at the next frame's leading 0x00). */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "comm/tlm.h"
#include "comm/tlm_decode.h"
#include "fuzz_check.h"

typedef struct {
  uint32_t headers, data, records, good_records;
} seen_t;

static tlm_decode_t g_rx;
static seen_t g_seen;

static void on_text(void *ctx, const char *s, size_t n)
{
  (void)ctx;
  FUZZ_CHECK(n >= 1u && n <= TLM_DECODE_LINE_MAX && s[n] == '\0');
  for (size_t i = 0; i < n; i++) {
    FUZZ_CHECK((s[i] >= 0x20 && s[i] <= 0x7E) || s[i] == '\t');
  }
}

static void on_header(void *ctx, const tlm_layout_t *l)
{
  seen_t *s = ctx;
  FUZZ_CHECK(l == tlm_decode_layout(&g_rx));
  FUZZ_CHECK(l->n_fields >= 1u && l->n_fields <= TLM_FIELDS_MAX);
  FUZZ_CHECK(l->fs_hz >= 1u && l->decim >= 1u && l->rec_per_frame >= 1u);
  for (uint32_t i = 0; i < l->n_fields; i++) {
    const char *end = memchr(l->name[i], 0, TLM_NAME_MAX + 1u);
    FUZZ_CHECK(end != NULL && end != l->name[i] && l->type[i] <= 1u);
    for (uint32_t j = 0; j < i; j++) {
      FUZZ_CHECK(strcmp(l->name[i], l->name[j]) != 0);
    }
  }
  s->headers++;
}

static void on_data(void *ctx, const tlm_data_t *d)
{
  seen_t *s = ctx;
  FUZZ_CHECK(d->layout == tlm_decode_layout(&g_rx));
  FUZZ_CHECK(d->n_rec >= 1u && d->n_rec <= 255u);
  uint32_t acc = 0u;
  for (uint32_t r = 0; r < d->n_rec; r++) {
    for (uint32_t f = 0; f < d->layout->n_fields; f++) {
      acc ^= tlm_data_u32(d, r, f); /* every word readable (ASan) */
    }
  }
  (void)acc;
  /* The good pair (below) carries tick and rate_dps = tick / 4 */
  if (d->layout->n_fields == 2u && strcmp(d->layout->name[0], "rate_dps") == 0 &&
      strcmp(d->layout->name[1], "tick") == 0) {
    for (uint32_t r = 0; r < d->n_rec; r++) {
      if (tlm_data_f32(d, r, 0) == 0.25f * (float)tlm_data_u32(d, r, 1)) {
        s->good_records++;
      }
    }
  }
  s->data++;
  s->records += d->n_rec;
}

/* The encoder's first header frame and first data frame of a 1 kHz stream of
 * rate_dps and tick (built once). */
static uint8_t g_good[2u * TLM_WIRE_MAX];
static size_t g_good_len;
static uint32_t g_good_records;
static tlm_t g_tx;

static size_t room(void *ctx)
{
  (void)ctx;
  return (g_good_len == 0u || g_good_records == 0u) ? sizeof g_good - g_good_len : 0u;
}

static void take(void *ctx, const uint8_t *p, size_t n)
{
  (void)ctx;
  memcpy(&g_good[g_good_len], p, n);
  g_good_len += n;
  /* wire: 00, 01 (the marker's block), the next code byte, then the type */
  if (n > 3u && p[3] == (uint8_t)TLM_FRAME_DATA) {
    g_good_records = g_tx.plan.rec_per_frame;
  }
}

static void build_good(void)
{
  if (g_good_len != 0u) {
    return;
  }
  const tlm_cfg_t c = {50000u, 921600u, room, take, NULL};
  FUZZ_CHECK(tlm_init(&g_tx, &c) == 0);
  tlm_plan_t p;
  FUZZ_CHECK(tlm_plan(50000u, 921600u, (1u << TLM_FIELD_rate_dps) | (1u << TLM_FIELD_tick), 1000.0f, &p) ==
             TLM_OK);
  tlm_start(&g_tx, &p);
  gyro_out_t o;
  memset(&o, 0, sizeof o);
  for (uint32_t k = 1u; k <= 50u * p.rec_per_frame && g_good_records == 0u; k++) {
    o.tick = k;
    o.rate_dps = 0.25f * (float)k;
    tlm_isr_push(&g_tx, &o);
    tlm_poll(&g_tx);
  }
  FUZZ_CHECK(g_good_records > 0u && g_good[0] == 0u && g_good[1] == 0x01u);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  build_good();
  memset(&g_seen, 0, sizeof g_seen);
  const tlm_decode_cfg_t cfg = {on_text, on_header, on_data, &g_seen};
  tlm_decode_init(&g_rx, &cfg);
  const size_t chunk = (size > 0u) ? 1u + (size_t)(data[0] & 0x3Fu) * 7u : 1u;
  tlm_decode_stats_t prev = g_rx.st;
  for (size_t off = (size > 0u) ? 1u : 0u; off < size; off += chunk) {
    const size_t n = (size - off < chunk) ? size - off : chunk;
    tlm_decode_feed(&g_rx, data + off, n);
    const tlm_decode_stats_t *st = &g_rx.st;
    FUZZ_CHECK(st->lines >= prev.lines && st->lines_bad >= prev.lines_bad);
    FUZZ_CHECK(st->headers >= prev.headers && st->data >= prev.data);
    FUZZ_CHECK(st->corrupt >= prev.corrupt && st->bad_format >= prev.bad_format);
    FUZZ_CHECK(st->no_layout >= prev.no_layout);
    prev = *st;
  }
  FUZZ_CHECK(g_seen.headers == g_rx.st.headers && g_seen.data == g_rx.st.data);
  /* whatever came before: the good pair decodes exactly */
  const seen_t before = g_seen;
  tlm_decode_feed(&g_rx, g_good, g_good_len);
  FUZZ_CHECK(g_seen.headers == before.headers + 1u);
  FUZZ_CHECK(g_seen.data == before.data + 1u);
  FUZZ_CHECK(g_seen.good_records == before.good_records + g_good_records);
  return 0;
}
