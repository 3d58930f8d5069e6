/* The telemetry receiver fed arbitrary bytes, then one good header + data frame pair from
 * the real encoder. Byte 0 picks the mode: bit 6 clear, the rest is fed as it is, in
 * chunks of a size chosen by bits 0-5; bit 6 set ("sealed"), the rest is a sequence of
 * [length][type, seq, payload...] records that the harness turns into frames with a
 * correct CRC and COBS, so the fuzzer reaches the header and data payload checks that
 * random bytes almost never get past the CRC to.
 * Invariants: every delivered line holds only text bytes; every delivered header is a
 * well-formed layout; every delivered data frame matches its layout's record size; the
 * counters never go back; and after any garbage the good frames that follow are decoded
 * exactly (the parser is back in step at the next 0x00). */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "app/app_tlm_fields.h"
#include "comm/tlm.h"
#include "gyro/gyro.h"
#include "tlm_decode.h"
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
  const tlm_cfg_t c = {50000u, 921600u, room, take, NULL, &app_tlm_fields};
  FUZZ_CHECK(tlm_init(&g_tx, &c) == 0);
  tlm_plan_t p;
  FUZZ_CHECK(tlm_plan(&app_tlm_fields, 50000u, 921600u,
                      (1u << TLM_FIELD_rate_dps) | (1u << TLM_FIELD_tick), 1000.0f, &p) == TLM_OK);
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

/* Sealed mode: [len][body...] -> 00 COBS(00 body CRC) 00, body = type, seq, payload. */
static void feed_sealed(const uint8_t *data, size_t size)
{
  static uint8_t raw[TLM_FRAME_MAX], wire[TLM_WIRE_MAX];
  size_t off = 0u;
  while (off < size) {
    size_t len = data[off++];
    if (len > size - off) len = size - off;
    if (len > TLM_FRAME_MAX - TLM_FRAME_OVERHEAD + 3u)
      len = TLM_FRAME_MAX - TLM_FRAME_OVERHEAD + 3u;
    raw[0] = 0u;
    memset(&raw[1], 0, 3u);
    memcpy(&raw[1], data + off, len);
    off += len;
    const size_t body = (len < 3u) ? 3u : len; /* type and seq, zero if missing */
    const uint16_t crc = tlm_crc16(TLM_CRC16_INIT, raw, 1u + body);
    raw[1u + body] = (uint8_t)(crc >> 8);
    raw[2u + body] = (uint8_t)(crc & 0xFFu);
    const size_t wn = tlm_frame_to_wire(raw, 3u + body, wire, sizeof wire);
    FUZZ_CHECK(wn > 0u);
    tlm_decode_feed(&g_rx, wire, wn);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  build_good();
  memset(&g_seen, 0, sizeof g_seen);
  const tlm_decode_cfg_t cfg = {on_text, on_header, on_data, &g_seen};
  tlm_decode_init(&g_rx, &cfg);
  const bool sealed = size > 0u && (data[0] & 0x40u) != 0u;
  const size_t chunk = (size > 0u) ? 1u + (size_t)(data[0] & 0x3Fu) * 7u : 1u;
  tlm_decode_stats_t prev = g_rx.st;
  if (sealed) {
    feed_sealed(data + 1, size - 1u);
    FUZZ_CHECK(g_rx.st.corrupt == 0u); /* every sealed frame passes COBS and CRC */
  }
  for (size_t off = (size > 0u) ? 1u : 0u; !sealed && off < size; off += chunk) {
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
  /* whatever came before: after a delimiter (the input may end with a complete frame
   * that only lacks its closing 0x00), the good pair decodes exactly */
  tlm_decode_feed(&g_rx, (const uint8_t *)"", 1u);
  const seen_t before = g_seen;
  tlm_decode_feed(&g_rx, g_good, g_good_len);
  FUZZ_CHECK(g_seen.headers == before.headers + 1u);
  FUZZ_CHECK(g_seen.data == before.data + 1u);
  FUZZ_CHECK(g_seen.good_records == before.good_records + g_good_records);
  return 0;
}
