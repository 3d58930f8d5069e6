/* The receiver (tools/tlm_decode): text and frames interleaved on one wire, header layout
 * parsing and its rejections, and damage of every kind (bit errors, lost and inserted
 * bytes, cut frames, garbage) detected and counted, never delivered as data. Frames come
 * from the real encoder (comm/tlm) or are built by hand with the documented byte layout. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "app/app_tlm_fields.h"
#include "comm/tlm.h"
#include "gyro/gyro.h"
#include "tlm_decode.h"
#include "tlm_test_link.h"

static tlm_decode_t rx;
static uint8_t link_buf[TLM_TEST_LINK_MAX];
static uint8_t damaged[TLM_TEST_LINK_MAX + 4096u];

typedef struct {
  uint32_t lines;
  char line[16][TLM_DECODE_LINE_MAX + 1u];
  uint32_t headers, data, records, mismatches;
  tlm_layout_t last;
  uint32_t first_words[TLM_FIELDS_MAX]; /* record 0 of the last data frame */
} sink_t;
static sink_t got;

static void on_text(void *ctx, const char *s, size_t n)
{
  sink_t *g = ctx;
  assert_int_equal(strlen(s), n);
  for (size_t i = 0; i < n; i++) {
    assert_true((s[i] >= 0x20 && s[i] <= 0x7E) || s[i] == '\t');
  }
  if (g->lines < 16u) {
    memcpy(g->line[g->lines], s, n + 1u);
  }
  g->lines++;
}

static void on_header(void *ctx, const tlm_layout_t *l)
{
  sink_t *g = ctx;
  g->headers++;
  g->last = *l;
}

/* Streams in these tests carry `tick` (u32) and `rate_dps` = tick / 8: a record is right
 * iff its two words agree with each other and with its index. */
static uint32_t t0;
static void on_data(void *ctx, const tlm_data_t *d)
{
  sink_t *g = ctx;
  g->data++;
  for (uint32_t f = 0; f < d->layout->n_fields; f++) {
    g->first_words[f] = tlm_data_u32(d, 0u, f);
  }
  for (uint32_t r = 0; r < d->n_rec; r++) {
    const uint32_t tick = t0 + (d->first_rec + r) * d->layout->decim;
    for (uint32_t f = 0; f < d->layout->n_fields; f++) {
      if (strcmp(d->layout->name[f], "tick") == 0) {
        g->mismatches += tlm_data_u32(d, r, f) != tick;
      } else if (strcmp(d->layout->name[f], "rate_dps") == 0) {
        g->mismatches += tlm_data_f32(d, r, f) != (float)tick * 0.125f;
      }
    }
    g->records++;
  }
}

static void reset_rx(void)
{
  memset(&got, 0, sizeof got);
  const tlm_decode_cfg_t c = {on_text, on_header, on_data, &got};
  tlm_decode_init(&rx, &c);
}

static void feed(const void *p, size_t n) { tlm_decode_feed(&rx, (const uint8_t *)p, n); }
static void feed_s(const char *s) { feed(s, strlen(s)); }

/* ---- an encoder stream with command-line lines between frames ---- */

static tlm_t tx;
static tlm_test_link_t link_;
typedef struct {
  size_t len;
  uint32_t frames, records, lines;
} stream_t;

static void text_line(const char *s) { tlm_test_write(&link_, (const uint8_t *)s, strlen(s)); }

/* seconds of a 1 kHz stream of tick + rate_dps; a reply line after every 7th poll */
static stream_t make_stream(uint32_t seconds)
{
  memset(&link_, 0, sizeof link_);
  link_.buf = link_buf;
  link_.room = (size_t)-1;
  const tlm_cfg_t cfg = {50000u,         921600u, tlm_test_room,
                         tlm_test_write, &link_,  &app_tlm_fields};
  assert_int_equal(tlm_init(&tx, &cfg), 0);
  tlm_plan_t p;
  const uint32_t mask = (1u << TLM_FIELD_tick) | (1u << TLM_FIELD_rate_dps);
  assert_int_equal(tlm_plan(&app_tlm_fields, 50000u, 921600u, mask, 1000.0f, &p), TLM_OK);
  text_line("ok stream 1 1000 Hz\r\n");
  tlm_start(&tx, &p);
  t0 = 0u;
  gyro_out_t o;
  memset(&o, 0, sizeof o);
  stream_t s = {0u, 0u, 0u, 1u};
  for (uint32_t k = 0; k < seconds * 50000u; k++) {
    o.tick = k;
    o.rate_dps = (float)k * 0.125f;
    tlm_isr_push(&tx, &o);
    if (k % 500u == 499u) {
      tlm_poll(&tx);
      if ((k / 500u) % 7u == 0u) {
        text_line("- rate_dps 0.125\r\n");
        s.lines++;
      }
    }
  }
  tlm_stop(&tx);
  text_line("ok stop\r\n");
  s.lines++;
  tlm_stats_t st;
  tlm_stats(&tx, &st);
  s.len = link_.len;
  s.frames = st.frames;
  s.records = st.records;
  return s;
}

static void test_text_and_frames_interleaved(void **state)
{
  (void)state;
  const stream_t s = make_stream(2u);
  reset_rx();
  feed(link_buf, s.len);
  assert_int_equal(got.lines, s.lines);
  assert_string_equal(got.line[0], "ok stream 1 1000 Hz");
  assert_string_equal(got.line[1], "- rate_dps 0.125");
  assert_int_equal(got.records, s.records);
  assert_int_equal(got.records, 2000u);
  assert_int_equal(got.headers + got.data, s.frames);
  assert_int_equal(got.mismatches, 0u);
  assert_int_equal(rx.st.lines_bad + rx.st.corrupt + rx.st.bad_format + rx.st.no_layout, 0u);
  assert_int_equal(rx.st.seq_missing + rx.st.rec_missing, 0u);
  /* byte by byte gives the same */
  reset_rx();
  for (size_t i = 0; i < s.len; i++) feed(&link_buf[i], 1u);
  assert_int_equal(got.records, 2000u);
  assert_int_equal(got.lines, s.lines);
}

static uint32_t lcg(uint32_t *x)
{
  *x = *x * 1664525u + 1013904223u;
  return *x >> 8;
}

/* Damage anywhere after the first header and before the last frames: bit flips, lost
 * bytes, inserted random bytes and runs of garbage. Every delivered record is right;
 * every frame is either delivered or counted missing. */
static void test_damage_detected_never_misread(void **state)
{
  (void)state;
  const stream_t s = make_stream(10u);
  uint32_t x = 99u;
  for (int trial = 0; trial < 6; trial++) {
    size_t o = 0u;
    const size_t keep_head = 300u, keep_tail = s.len - 1200u;
    uint32_t damage = 0u;
    for (size_t i = 0; i < s.len; i++) {
      uint8_t b = link_buf[i];
      if (i > keep_head && i < keep_tail && lcg(&x) % 500u == 0u) {
        damage++;
        switch (lcg(&x) % 4u) {
        case 0: b ^= (uint8_t)(1u << (lcg(&x) % 8u)); break; /* bit error */
        case 1: continue;                                    /* lost byte */
        case 2: damaged[o++] = (uint8_t)lcg(&x); break;      /* inserted byte */
        default:                                             /* burst of garbage */
          for (uint32_t j = lcg(&x) % 40u; j > 0u; j--) damaged[o++] = (uint8_t)lcg(&x);
          break;
        }
      }
      damaged[o++] = b;
    }
    reset_rx();
    feed(damaged, o);
    assert_true(damage > 100u);
    assert_int_equal(got.mismatches, 0u);
    assert_true(rx.st.corrupt > 50u);
    assert_true(got.records > s.records / 2u);
    assert_int_equal(got.headers + got.data + rx.st.seq_missing, s.frames);
    assert_int_equal(got.records + rx.st.rec_missing, s.records);
    assert_int_equal(rx.st.no_layout, 0u);
  }
}

/* Whatever garbage came before, the parser is in step at the next frame. */
static void test_resync_after_any_garbage(void **state)
{
  (void)state;
  const stream_t s = make_stream(1u);
  /* the first header frame and the first data frame of the stream, with the leading
   * text line skipped: find the frame boundaries */
  size_t start = 0u;
  while (link_buf[start] != 0u) start++;
  size_t end = start + 1u;
  int zeros = 0;
  while (zeros < 3) { /* 00 H 00 00 D 00: stop after the data frame's closing zero */
    if (link_buf[end] == 0u) zeros++;
    end++;
  }
  uint32_t x = 5u;
  uint8_t junk[700];
  for (int trial = 0; trial < 500; trial++) {
    const size_t n = lcg(&x) % sizeof junk;
    for (size_t i = 0; i < n; i++) {
      junk[i] = (uint8_t)lcg(&x);
      if (trial % 3 == 0 && junk[i] == 0u) junk[i] = 1u; /* no zero at all: stay in FRAME */
    }
    reset_rx();
    feed(junk, n);
    const uint32_t before = got.records;
    feed(&link_buf[start], end - start);
    assert_int_equal(got.headers, 1u);
    assert_int_equal(got.records - before, 1u * tx.plan.rec_per_frame);
    assert_int_equal(got.mismatches, 0u);
  }
  (void)s;
}

static void test_text_rules(void **state)
{
  (void)state;
  reset_rx();
  feed_s("ok 1489.9 Hz\r\n");
  feed_s("\n\r\n\n"); /* empty lines: nothing */
  feed_s("- a\tb\n"); /* TAB kept, bare LF accepted */
  assert_int_equal(got.lines, 2u);
  assert_string_equal(got.line[0], "ok 1489.9 Hz");
  assert_string_equal(got.line[1], "- a\tb");
  feed_s("x\x7fy\r\n");     /* DEL */
  feed_s("x\r\ry\r\n");     /* CR CR */
  feed_s("x\ry\r\n");       /* CR not before LF */
  feed("ab\x00", 3u);       /* cut by a delimiter */
  feed_s("cd\x01\x01\x01"); /* cut by a frame start (that frame is then 01 01 01 ...) */
  feed("\x00", 1u);         /* ... which ends here as a corrupt frame */
  char longline[TLM_DECODE_LINE_MAX + 10u];
  memset(longline, 'a', sizeof longline);
  feed(longline, sizeof longline);
  feed_s("\r\n");
  assert_int_equal(got.lines, 2u);
  assert_int_equal(rx.st.lines_bad, 6u);
  assert_int_equal(rx.st.corrupt, 1u);
  /* a line of exactly the limit is fine */
  feed(longline, TLM_DECODE_LINE_MAX);
  feed_s("\r\nok\r\n");
  assert_int_equal(got.lines, 4u);
  assert_string_equal(got.line[3], "ok");
}

/* ---- hand-built frames ---- */

static uint8_t raw[TLM_FRAME_MAX], wire[TLM_WIRE_MAX];
static uint16_t seq;

static void send_frame(uint8_t type, const uint8_t *payload, size_t n)
{
  memcpy(&raw[TLM_FRAME_HEAD_BYTES], payload, n);
  const size_t rn = tlm_frame_seal(raw, type, seq++, n);
  const size_t wn = tlm_frame_to_wire(raw, rn, wire, sizeof wire);
  feed(wire, wn);
}

typedef struct {
  uint8_t b[TLM_FRAME_MAX];
  size_t n;
} buf_t;

static void put8(buf_t *b, uint8_t v) { b->b[b->n++] = v; }
static void put16(buf_t *b, uint16_t v)
{
  put8(b, (uint8_t)v);
  put8(b, (uint8_t)(v >> 8));
}
static void put32(buf_t *b, uint32_t v)
{
  put16(b, (uint16_t)v);
  put16(b, (uint16_t)(v >> 16));
}
static void putname(buf_t *b, uint8_t type, const char *s)
{
  put8(b, type);
  put8(b, (uint8_t)strlen(s));
  memcpy(&b->b[b->n], s, strlen(s));
  b->n += strlen(s);
}

/* A header as the format says: version, stream id 7, fs 50000, decim 50, 10 per frame,
 * lost 3, dropped 1, fields tick (u32), rate_dps (f32), x.y_z9 (f32). */
static buf_t good_header(void)
{
  buf_t b = {{0}, 0u};
  put8(&b, 1u);
  put32(&b, 7u);
  put32(&b, 50000u);
  put32(&b, 50u);
  put16(&b, 10u);
  put32(&b, 3u);
  put32(&b, 1u);
  put8(&b, 3u);
  putname(&b, 1u, "tick");
  putname(&b, 0u, "rate_dps");
  putname(&b, 0u, "x.y_z9");
  return b;
}

static void test_header_layout(void **state)
{
  (void)state;
  reset_rx();
  seq = 0u;
  const buf_t h = good_header();
  send_frame((uint8_t)TLM_FRAME_HEADER, h.b, h.n);
  assert_int_equal(got.headers, 1u);
  const tlm_layout_t *l = tlm_decode_layout(&rx);
  assert_non_null(l);
  assert_int_equal(l->stream_id, 7u);
  assert_int_equal(l->fs_hz, 50000u);
  assert_int_equal(l->decim, 50u);
  assert_int_equal(l->rec_per_frame, 10u);
  assert_int_equal(l->lost, 3u);
  assert_int_equal(l->dropped, 1u);
  assert_int_equal(l->n_fields, 3u);
  assert_int_equal(l->type[0], 1u);
  assert_int_equal(l->type[1], 0u);
  assert_string_equal(l->name[0], "tick");
  assert_string_equal(l->name[1], "rate_dps");
  assert_string_equal(l->name[2], "x.y_z9");
  /* a data frame of 2 records for it */
  buf_t d = {{0}, 0u};
  put16(&d, 7u);
  put32(&d, 0u);
  put8(&d, 2u);
  t0 = 0u;
  put32(&d, 0u);
  put32(&d, 0u);          /* 0.0f */
  put32(&d, 0x3F800000u); /* 1.0f */
  put32(&d, 50u);
  put32(&d, 0x40C80000u); /* 6.25f = 50 / 8 */
  put32(&d, 0xBF800000u); /* -1.0f */
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n);
  assert_int_equal(got.data, 1u);
  assert_int_equal(got.records, 2u);
  assert_int_equal(got.mismatches, 0u);
}

static void test_header_rejections(void **state)
{
  (void)state;
  const buf_t good = good_header();
  /* byte offset and replacement value of each corruption of the good header */
  const struct {
    size_t off;
    uint8_t val;
  } edits[] = {
      {0u, 2u},            /* version */
      {5u, 0u},            /* fs_hz = 0 (all four bytes, below) */
      {9u, 0u},            /* decim = 0 */
      {13u, 0u},           /* rec_per_frame = 0 */
      {23u, 0u},           /* n_fields = 0 */
      {23u, 33u},          /* n_fields > 32 */
      {23u, 4u},           /* more fields than given */
      {23u, 2u},           /* fewer fields than given: trailing bytes */
      {24u, 2u},           /* type 2 */
      {25u, 0u},           /* empty name */
      {25u, 32u},          /* name longer than 31 */
      {26u, (uint8_t)'-'}, /* character outside the name set */
  };
  for (size_t i = 0; i < sizeof edits / sizeof edits[0]; i++) {
    buf_t b = good;
    if (edits[i].off == 5u) {
      b.b[5] = b.b[6] = b.b[7] = b.b[8] = 0u;
    } else {
      b.b[edits[i].off] = edits[i].val;
    }
    reset_rx();
    seq = 0u;
    send_frame((uint8_t)TLM_FRAME_HEADER, b.b, b.n);
    assert_int_equal(got.headers, 0u);
    assert_int_equal(rx.st.bad_format, 1u);
    assert_null(tlm_decode_layout(&rx));
  }
  /* duplicate names */
  buf_t b = {{0}, 0u};
  memcpy(b.b, good.b, 24u);
  b.n = 24u;
  b.b[23] = 2u;
  putname(&b, 0u, "rate_dps");
  putname(&b, 1u, "rate_dps");
  reset_rx();
  send_frame((uint8_t)TLM_FRAME_HEADER, b.b, b.n);
  assert_int_equal(rx.st.bad_format, 1u);
  /* one byte short, one byte long */
  reset_rx();
  send_frame((uint8_t)TLM_FRAME_HEADER, good.b, good.n - 1u);
  send_frame((uint8_t)TLM_FRAME_HEADER, good.b, good.n + 1u);
  send_frame((uint8_t)TLM_FRAME_HEADER, good.b, 10u);
  assert_int_equal(rx.st.bad_format, 3u);
  /* an unknown type with a good CRC */
  send_frame((uint8_t)'X', good.b, good.n);
  assert_int_equal(rx.st.bad_format, 4u);
  assert_int_equal(got.headers, 0u);
}

static void test_data_needs_its_header(void **state)
{
  (void)state;
  reset_rx();
  seq = 0u;
  buf_t d = {{0}, 0u};
  put16(&d, 7u);
  put32(&d, 0u);
  put8(&d, 1u);
  put32(&d, 0u);
  put32(&d, 0u);
  put32(&d, 0u);
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n); /* before any header */
  assert_int_equal(rx.st.no_layout, 1u);
  const buf_t h = good_header();
  send_frame((uint8_t)TLM_FRAME_HEADER, h.b, h.n);
  d.b[0] = 8u; /* another stream */
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n);
  assert_int_equal(rx.st.no_layout, 2u);
  d.b[0] = 7u;
  d.b[6] = 2u; /* says 2 records, holds 1 */
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n);
  d.b[6] = 0u; /* no record */
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, 7u);
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, 5u); /* shorter than the fixed part */
  assert_int_equal(rx.st.bad_format, 3u);
  assert_int_equal(got.data, 0u);
  d.b[6] = 1u;
  t0 = 0u;
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n);
  assert_int_equal(got.data, 1u);
  /* seq: frames 0..6 were sent; after the header (seq 1), 2..5 were not delivered */
  assert_int_equal(rx.st.seq_missing, 4u);
  /* a gap in first_rec counts the records in between */
  tlm_put_u32(&d.b[2], 10u);
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n);
  assert_int_equal(rx.st.rec_missing, 9u);
}

/* The widest header the format allows, 32 fields with 31-byte names (a raw frame of
 * exactly TLM_FRAME_MAX bytes), and a record of 32 words: fields past the 16th decode in
 * place. 33 fields are refused. */
static void test_header_32_fields(void **state)
{
  (void)state;
  reset_rx();
  seq = 0u;
  buf_t h = good_header();
  h.n = TLM_HEADER_FIXED;
  h.b[23] = (uint8_t)TLM_FIELDS_MAX;
  char name[TLM_NAME_MAX + 1u];
  memset(name, 'x', TLM_NAME_MAX);
  name[TLM_NAME_MAX] = '\0';
  for (uint32_t i = 0; i < TLM_FIELDS_MAX; i++) {
    name[0] = (char)('a' + i / 10u);
    name[1] = (char)('0' + i % 10u);
    putname(&h, (uint8_t)(i & 1u), name);
  }
  assert_int_equal(TLM_FRAME_OVERHEAD + h.n, TLM_FRAME_MAX);
  send_frame((uint8_t)TLM_FRAME_HEADER, h.b, h.n);
  assert_int_equal(got.headers, 1u);
  assert_int_equal(got.last.n_fields, TLM_FIELDS_MAX);
  assert_int_equal(got.last.type[31], 1u);
  assert_string_equal(got.last.name[31], "d1xxxxxxxxxxxxxxxxxxxxxxxxxxxxx");
  buf_t d = {{0}, 0u};
  put16(&d, 7u);
  put32(&d, 0u);
  put8(&d, 1u);
  for (uint32_t i = 0; i < TLM_FIELDS_MAX; i++) {
    put32(&d, 0xA5000000u | i);
  }
  send_frame((uint8_t)TLM_FRAME_DATA, d.b, d.n);
  assert_int_equal(got.data, 1u);
  for (uint32_t i = 0; i < TLM_FIELDS_MAX; i++) {
    assert_int_equal(got.first_words[i], 0xA5000000u | i);
  }
  /* one field more than the format allows */
  reset_rx();
  h.n = TLM_HEADER_FIXED;
  h.b[23] = (uint8_t)(TLM_FIELDS_MAX + 1u);
  for (uint32_t i = 0; i <= TLM_FIELDS_MAX; i++) {
    const char n2[3] = {(char)('a' + i / 10u), (char)('0' + i % 10u), '\0'};
    putname(&h, 0u, n2);
  }
  send_frame((uint8_t)TLM_FRAME_HEADER, h.b, h.n);
  assert_int_equal(got.headers, 0u);
  assert_int_equal(rx.st.bad_format, 1u);
}

/* A frame longer than any valid one, then a good one. */
static void test_oversize_then_good(void **state)
{
  (void)state;
  reset_rx();
  uint8_t big[TLM_WIRE_MAX + 100u];
  memset(big, 0x55, sizeof big);
  big[0] = 0x01;
  feed(big, sizeof big);
  feed("\x00", 1u);
  assert_int_equal(rx.st.corrupt, 1u);
  seq = 0u;
  const buf_t h = good_header();
  send_frame((uint8_t)TLM_FRAME_HEADER, h.b, h.n);
  assert_int_equal(got.headers, 1u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_text_and_frames_interleaved),
      cmocka_unit_test(test_damage_detected_never_misread),
      cmocka_unit_test(test_resync_after_any_garbage),
      cmocka_unit_test(test_text_rules),
      cmocka_unit_test(test_header_layout),
      cmocka_unit_test(test_header_rejections),
      cmocka_unit_test(test_data_needs_its_header),
      cmocka_unit_test(test_oversize_then_good),
      cmocka_unit_test(test_header_32_fields),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
