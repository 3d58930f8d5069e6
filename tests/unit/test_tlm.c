/* The telemetry stream (comm/tlm): plan and link budget against hand-computed figures
 * and against the bytes the encoder really emits; records through the ISR ring, frames
 * and the receiver (tools/tlm_decode) back to the values of the snapshot at the tick
 * each record claims; overruns, a blocked link, stop and restart accounted exactly. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "app/app_tlm_fields.h"
#include "comm/tlm.h"
#include "gyro/gyro.h"
#include "tlm_decode.h"
#include "tlm_test_link.h"

#define FS 50000u
#define BAUD 921600u

static tlm_t tx;
static tlm_decode_t rx;
static tlm_test_link_t link_;
static uint8_t link_buf[TLM_TEST_LINK_MAX];

/* ---- the truth: snapshot of tick k, written member by member (not via the table) ---- */

static void snap(gyro_out_t *o, uint32_t k)
{
  memset(o, 0, sizeof *o);
  const float x = (float)k;
  o->tick = k;
  o->rate_dps = 0.5f * x;
  o->rate_unc_dps = -x;
  o->quad_dps = x + 0.25f;
  o->drive_amp_v = 1.0f + x * 1e-3f;
  o->drive_phase_deg = -90.0f + x;
  o->p_deg = 2.0f * x;
  o->p_f_deg = 3.0f * x;
  o->f_cmd_v2 = -4.0f * x;
  o->u1_v = 5.0f * x;
  o->u2_v = -6.0f * x;
  o->sense_i_v = 7.0f * x;
  o->sense_q_v = -8.0f * x;
  o->mode = k % 5u;
  o->fault = k * 3u;
  o->flags = k ^ 0xA5u;
  o->rate_valid = (k / 3u) & 1u;
}

static uint32_t f2w(float f)
{
  uint32_t w;
  memcpy(&w, &f, 4);
  return w;
}

/* The word a field of that name must carry for tick k, and its type. */
static int truth(const char *name, uint32_t k, uint32_t *w)
{
  gyro_out_t o;
  snap(&o, k);
  static const struct {
    const char *name;
    size_t off;
    int type;
  } m[] = {{"rate_dps", offsetof(gyro_out_t, rate_dps), 0},
           {"rate_unc_dps", offsetof(gyro_out_t, rate_unc_dps), 0},
           {"quad_dps", offsetof(gyro_out_t, quad_dps), 0},
           {"drive_amp_v", offsetof(gyro_out_t, drive_amp_v), 0},
           {"drive_phase_deg", offsetof(gyro_out_t, drive_phase_deg), 0},
           {"p_deg", offsetof(gyro_out_t, p_deg), 0},
           {"p_f_deg", offsetof(gyro_out_t, p_f_deg), 0},
           {"f_cmd_v2", offsetof(gyro_out_t, f_cmd_v2), 0},
           {"u1_v", offsetof(gyro_out_t, u1_v), 0},
           {"u2_v", offsetof(gyro_out_t, u2_v), 0},
           {"sense_i_v", offsetof(gyro_out_t, sense_i_v), 0},
           {"sense_q_v", offsetof(gyro_out_t, sense_q_v), 0},
           {"mode", offsetof(gyro_out_t, mode), 1},
           {"fault", offsetof(gyro_out_t, fault), 1},
           {"flags", offsetof(gyro_out_t, flags), 1},
           {"tick", offsetof(gyro_out_t, tick), 1},
           {"rate_valid", offsetof(gyro_out_t, rate_valid), 1},
           {"f_drive_hz", offsetof(gyro_out_t, f_drive_hz), 0},
           {"rate_invalid", offsetof(gyro_out_t, rate_invalid), 1}};
  for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) {
    if (strcmp(m[i].name, name) == 0) {
      const uint8_t *b = (const uint8_t *)&o;
      if (m[i].type == 0) {
        float f;
        memcpy(&f, b + m[i].off, 4);
        *w = f2w(f);
      } else {
        memcpy(w, b + m[i].off, 4);
      }
      return m[i].type;
    }
  }
  fail_msg("unknown field %s", name);
  return -1;
}

/* ---- receiver side ---- */

typedef struct {
  uint32_t t0; /* tick of record 0 of the current stream */
  uint32_t records;
  uint32_t next_index; /* expected first_rec if nothing is missing */
  uint32_t headers;
  uint32_t mismatches; /* a delivered value that is not the truth: must stay 0 */
  tlm_layout_t last;
  uint32_t lines;
  char line[64][64];
} rx_t;
static rx_t got;

static void on_header(void *ctx, const tlm_layout_t *l)
{
  rx_t *g = ctx;
  g->headers++;
  g->last = *l;
}

static void on_data(void *ctx, const tlm_data_t *d)
{
  rx_t *g = ctx;
  for (uint32_t r = 0; r < d->n_rec; r++) {
    const uint32_t k = g->t0 + (d->first_rec + r) * d->layout->decim;
    for (uint32_t f = 0; f < d->layout->n_fields; f++) {
      uint32_t want;
      const int type = truth(d->layout->name[f], k, &want);
      if (type != d->layout->type[f] || tlm_data_u32(d, r, f) != want) {
        g->mismatches++;
      }
    }
    g->records++;
  }
  g->next_index = d->first_rec + d->n_rec;
}

static void on_text(void *ctx, const char *line, size_t len)
{
  rx_t *g = ctx;
  assert_true(len < 64u && g->lines < 64u);
  memcpy(g->line[g->lines++], line, len + 1u);
}

static void setup_all(void)
{
  memset(&link_, 0, sizeof link_);
  link_.buf = link_buf;
  link_.room = (size_t)-1;
  const tlm_cfg_t cfg = {FS, BAUD, tlm_test_room, tlm_test_write, &link_, &app_tlm_fields};
  assert_int_equal(tlm_init(&tx, &cfg), 0);
  memset(&got, 0, sizeof got);
  const tlm_decode_cfg_t dc = {on_text, on_header, on_data, &got};
  tlm_decode_init(&rx, &dc);
}

static uint32_t tick_now;

/* n ticks of the ISR, the background loop every poll_every ticks (0: never). */
static void run(uint32_t n, uint32_t poll_every)
{
  gyro_out_t o;
  for (uint32_t i = 0; i < n; i++) {
    snap(&o, tick_now);
    tlm_isr_push(&tx, &o);
    tick_now++;
    if (poll_every != 0u && tick_now % poll_every == 0u) {
      tlm_poll(&tx);
    }
  }
}

static void receive_all(void) { tlm_decode_feed(&rx, link_.buf, link_.len); }

static uint32_t mask_of(const char *const *names, size_t n)
{
  uint32_t m = 0u;
  for (size_t i = 0; i < n; i++) {
    const uint32_t k = app_tlm_field_lookup(names[i], strlen(names[i]));
    assert_true(k < (uint32_t)TLM_FIELD_COUNT);
    m |= 1u << k;
  }
  return m;
}

static const char *const four[] = {"rate_dps", "quad_dps", "drive_amp_v", "p_deg"};

/* ---- plan ---- */

static void test_plan_rate_rounding(void **state)
{
  (void)state;
  tlm_plan_t p;
  const uint32_t m = mask_of(four, 4);
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, m, 1000.0f, &p), TLM_OK);
  assert_int_equal(p.decim, 50u);
  assert_true(p.rate_hz == 1000.0f);
  /* 50000 / 3000 = 16.67 -> 17 ticks -> 2941.18 Hz */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, m, 3000.0f, &p), TLM_OK);
  assert_int_equal(p.decim, 17u);
  assert_float_equal(p.rate_hz, 50000.0f / 17.0f, 1e-3f);
  /* 50000 / 0.763 = 65531 ticks: the slowest rate still in 16 bits */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, m, 0.763f, &p), TLM_OK);
  assert_int_equal(p.decim, 65531u);
  assert_int_equal(p.rec_per_frame, 1u);
  const float bad[] = {0.0f, -1.0f, 0.5f, 50001.0f, NAN, INFINITY, -INFINITY};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, m, bad[i], &p), TLM_ERR_RATE);
  }
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, 0u, 100.0f, &p), TLM_ERR_FIELDS);
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD,
                            (uint32_t)((uint64_t)1u << TLM_FIELD_COUNT), 100.0f, &p),
                   TLM_ERR_FIELDS);
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, 1u << 31, 100.0f, &p), TLM_ERR_FIELDS);
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, 1u << TLM_FIELD_rate_valid, 100.0f, &p),
                   TLM_OK);
  /* one u32 at the full tick rate is far beyond the link */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, 1u, 50000.0f, &p), TLM_ERR_BANDWIDTH);
}

/* The worked examples of tlm.h, by hand:
 *   data frame raw = 13 + 4 N F, wire = raw + 1 + raw/254 + 2
 *   header raw = 30 + sum(2 + name length), same wire rule, once per second. */
static void test_link_budget_by_hand(void **state)
{
  (void)state;
  tlm_plan_t p;
  /* 4 f32 at 1 kHz: N = min(20, 240/16) = 15, raw 253, wire 256, 1000/15 frames/s =
   * 17066.7 -> 17067 B/s; header 30 + 10+10+13+7 = 70 -> 73 B */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, mask_of(four, 4), 1000.0f, &p), TLM_OK);
  assert_int_equal(p.rec_per_frame, 15u);
  assert_int_equal(p.bytes_per_s, 17067u + 73u);
  /* 4 f32 at 200 Hz: N = 4, raw 77, wire 80, 50 frames/s */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, mask_of(four, 4), 200.0f, &p), TLM_OK);
  assert_int_equal(p.rec_per_frame, 4u);
  assert_int_equal(p.bytes_per_s, 50u * 80u + 73u);
  assert_int_equal(p.link_bytes_per_s, 92160u);
  /* all 19 at 1 kHz: N = min(20, 240/76) = 3, raw 13 + 12 * 19 = 241, wire 244,
   * 1000/3 frames = 81333.3 -> 81334; header names 150 bytes + 38 + 30 = 218 -> 221 B:
   * 81555 B/s > 70 % of 92160 = 64512 */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, TLM_FIELD_MASK_ALL, 1000.0f, &p),
                   TLM_ERR_BANDWIDTH);
  assert_int_equal(p.rec_per_frame, 3u);
  assert_int_equal(p.bytes_per_s, 81334u + 221u);
  /* all 19 at 500 Hz: 40666.7 -> 40667 + 221 */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, TLM_FIELD_MASK_ALL, 500.0f, &p), TLM_OK);
  assert_int_equal(p.bytes_per_s, 40667u + 221u);
  /* 12 f32 (the twelve floats) at 1 kHz: N = 5, raw 253, wire 256, 200 frames/s */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, 0x0FFFu, 1000.0f, &p), TLM_OK);
  assert_int_equal(p.rec_per_frame, 5u);
  assert_true(p.bytes_per_s > 51200u && p.bytes_per_s < 51200u + 200u);
  /* 8 f32 at 1 kHz: N = 7, raw 237, wire 240, 1000/7 frames/s */
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, 0x00FFu, 1000.0f, &p), TLM_OK);
  assert_int_equal(p.rec_per_frame, 7u);
  assert_true(p.bytes_per_s >= 34286u && p.bytes_per_s < 34286u + 200u);
}

/* The budget is what the encoder really sends: 10 s of stream, bytes counted. */
static void test_link_budget_matches_encoder(void **state)
{
  (void)state;
  const struct {
    uint32_t mask;
    float rate;
  } cases[] = {{0x000Fu, 1000.0f},
               {0x00FFu, 1000.0f},
               {0x0FFFu, 1000.0f},
               {TLM_FIELD_MASK_ALL, 500.0f},
               {0x8001u, 100.0f},
               {0x0001u, 10000.0f},
               {(1u << TLM_FIELD_rate_valid) | 0x8001u, 1000.0f}};
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    setup_all();
    tlm_plan_t p;
    assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, cases[c].mask, cases[c].rate, &p),
                     TLM_OK);
    tlm_start(&tx, &p);
    tick_now = 0u;
    run(10u * FS, 50u);
    const double measured = (double)link_.len / 10.0;
    assert_true(measured <= (double)p.bytes_per_s);
    assert_true(measured >= 0.98 * (double)p.bytes_per_s);
    assert_int_equal(link_.oversize, 0u);
  }
}

/* ---- round trip ---- */

static void start(uint32_t mask, float rate)
{
  tlm_plan_t p;
  assert_int_equal(tlm_plan(&app_tlm_fields, FS, BAUD, mask, rate, &p), TLM_OK);
  tlm_start(&tx, &p);
  got.t0 = tick_now; /* a new stream takes its first record at the next tick */
}

static void test_round_trip(void **state)
{
  (void)state;
  /* the last two select the field past the 16th (rate_valid), alone and between others */
  const uint32_t masks[] = {
      mask_of(four, 4), TLM_FIELD_MASK_ALL,         0x8000u,
      0x7001u,          1u << TLM_FIELD_rate_valid, (1u << TLM_FIELD_rate_valid) | 0x9001u};
  const float rates[] = {1000.0f, 250.0f, 5000.0f, 3000.0f, 2000.0f, 1000.0f};
  for (size_t c = 0; c < sizeof masks / sizeof masks[0]; c++) {
    setup_all();
    tick_now = 1000u * (uint32_t)c;
    start(masks[c], rates[c]);
    /* the background loop at irregular intervals */
    uint32_t s = 5u;
    for (int i = 0; i < 400; i++) {
      s = s * 1664525u + 1013904223u;
      run(1u + (s >> 20) % 200u, 0u);
      tlm_poll(&tx);
    }
    tlm_stop(&tx);
    run(5000u, 7u); /* after stop: nothing more */
    receive_all();
    tlm_stats_t st;
    tlm_stats(&tx, &st);
    assert_int_equal(got.mismatches, 0u);
    assert_int_equal(got.records, st.records);
    assert_true(st.records > 100u);
    assert_int_equal(st.lost, 0u);
    assert_int_equal(st.dropped, 0u);
    assert_int_equal(rx.st.rec_missing, 0u);
    assert_int_equal(rx.st.seq_missing, 0u);
    assert_int_equal(rx.st.corrupt + rx.st.bad_format + rx.st.no_layout, 0u);
    assert_int_equal(rx.st.headers + rx.st.data, st.frames);
    assert_int_equal(got.last.stream_id, st.stream_id);
    assert_int_equal(got.last.fs_hz, FS);
    /* one header at the start, then one per second of records */
    const uint32_t per_s = (uint32_t)lroundf(tx.plan.rate_hz);
    assert_int_equal(got.headers, 1u + (st.records - 1u) / per_s);
  }
}

/* The background loop stalls (a flash erase): the ring overflows, the ISR counts the
 * records it could not keep, the receiver sees exactly that many missing, and every
 * record that does arrive is the right one. */
static void test_overrun_counted(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  start(TLM_FIELD_MASK_ALL, 500.0f);
  run(20000u, 50u);  /* 0.4 s normal */
  run(50000u, 0u);   /* 1 s without the background loop: 500 records, the ring holds 120 */
  run(100000u, 50u); /* 2 s normal: later headers report the loss */
  tlm_stop(&tx);
  receive_all();
  tlm_stats_t st;
  tlm_stats(&tx, &st);
  assert_true(st.lost > 300u);
  assert_int_equal(rx.st.rec_missing, st.lost);
  assert_int_equal(got.records + st.lost, st.records + st.lost);
  assert_int_equal(got.records, st.records);
  assert_int_equal(got.last.lost, st.lost);
  assert_int_equal(got.mismatches, 0u);
  assert_int_equal(rx.st.seq_missing, 0u); /* no frame was lost, only records */
}

/* The link takes nothing for a while: frames wait, nothing is written past the room,
 * the ring absorbs what it can and the rest is counted, then the stream resumes. */
static void test_link_blocked(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  start(mask_of(four, 4), 1000.0f);
  run(10000u, 50u);
  link_.room = 100u; /* less than a frame */
  run(10000u, 50u);  /* 200 ms: 200 records x 5 words fit the ring */
  link_.room = (size_t)-1;
  run(10000u, 50u);
  tlm_stop(&tx);
  receive_all();
  tlm_stats_t st;
  tlm_stats(&tx, &st);
  assert_int_equal(link_.oversize, 0u);
  assert_int_equal(st.lost, 0u);
  assert_int_equal(st.dropped, 0u);
  assert_int_equal(got.records, st.records);
  assert_int_equal(rx.st.rec_missing, 0u);
  assert_int_equal(got.mismatches, 0u);
  /* blocked long enough to overflow: counted as lost records, never as bad data */
  setup_all();
  start(mask_of(four, 4), 1000.0f);
  run(1000u, 50u);
  link_.room = 0u;
  run(50000u, 50u);
  link_.room = (size_t)-1;
  run(50000u, 50u);
  tlm_stop(&tx);
  receive_all();
  tlm_stats(&tx, &st);
  assert_true(st.lost > 500u);
  assert_int_equal(rx.st.rec_missing, st.lost);
  assert_int_equal(got.mismatches, 0u);
}

/* stop at a link that cannot take the last frames: they are dropped and counted. */
static void test_stop_drops_what_does_not_fit(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  start(mask_of(four, 4), 1000.0f);
  run(5000u, 50u);
  link_.room = 0u;
  run(5000u, 50u);
  tlm_stop(&tx);
  tlm_stats_t st;
  tlm_stats(&tx, &st);
  assert_false(st.streaming);
  assert_true(st.dropped >= 5u);
  assert_int_equal(link_.oversize, 0u);
  link_.room = (size_t)-1;
  const size_t before = link_.len;
  run(5000u, 10u);
  tlm_poll(&tx);
  assert_int_equal(link_.len, before); /* nothing after stop */
}

/* A new stream replaces the running one: new stream id, its own layout, records from 0;
 * no record of the old stream is read with the new layout. */
static void test_restart(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  start(mask_of(four, 4), 1000.0f);
  run(3000u, 50u);
  /* host-side: the old stream's bytes, then the new one's */
  receive_all();
  const uint32_t first_records = got.records;
  const uint32_t first_id = got.last.stream_id;
  link_.len = 0u;
  start(0x8000u | 0x4000u, 200.0f); /* flags, tick at 200 Hz */
  run(30000u, 50u);
  tlm_stop(&tx);
  receive_all();
  assert_int_equal(got.last.stream_id, first_id + 1u);
  assert_int_equal(got.last.n_fields, 2u);
  assert_string_equal(got.last.name[0], "flags");
  assert_string_equal(got.last.name[1], "tick");
  assert_int_equal(got.last.decim, 250u);
  assert_int_equal(got.records - first_records, 30000u / 250u);
  assert_int_equal(got.mismatches, 0u);
  assert_int_equal(rx.st.seq_missing + rx.st.rec_missing, 0u);
}

/* ISR cost when not streaming: one load and a compare (checked as behaviour: nothing is
 * pushed, the decimation state is untouched). */
static void test_idle_isr_does_nothing(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  run(1000u, 0u);
  assert_int_equal(tlm_ring_used(&tx.ring), 0u);
  assert_int_equal(atomic_load(&tx.isr_rec), 0u);
  tlm_poll(&tx);
  assert_int_equal(link_.len, 0u);
}

/* ---- selection handoff (tlm.h: configuration handoff) ---- */

/* The ISR's next n records, straight from the ring: each must hold exactly the fields of
 * mask for ticks k0, k0 + decim, ...: a record with one selection's mask and another's
 * decim (a torn selection) fails either the length or the tick spacing. */
static void expect_records(uint32_t mask, uint32_t decim, uint32_t k0, uint32_t n)
{
  uint32_t nf = 0u;
  for (uint32_t m = mask; m != 0u; m &= m - 1u) {
    nf++;
  }
  assert_int_equal(tlm_ring_used(&tx.ring), n * (1u + nf));
  for (uint32_t r = 0; r < n; r++) {
    uint32_t rec[1u + TLM_FIELDS_MAX];
    assert_true(tlm_ring_peek(&tx.ring, rec, 1u + nf));
    uint32_t j = 1u;
    for (uint32_t i = 0; i < (uint32_t)TLM_FIELD_COUNT; i++) {
      if ((mask >> i) & 1u) {
        uint32_t want;
        (void)truth(app_tlm_field(i)->name, k0 + r * decim, &want);
        assert_int_equal(rec[j++], want);
      }
    }
    tlm_ring_consume(&tx.ring, 1u + nf);
  }
}

static uint32_t named_slot(void) { return atomic_load(&tx.isr_gen) & 1u; }

/* The background prepares a new selection while a stream runs, and the ISR ticks between
 * every step: until the publication every record is whole and of the old selection,
 * from the first tick after it whole and of the new one. */
static void test_selection_never_torn(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  const uint32_t a = mask_of(four, 4) | (1u << TLM_FIELD_tick);
  const uint32_t b = (1u << TLM_FIELD_flags) | (1u << TLM_FIELD_tick) |
                     (1u << TLM_FIELD_rate_valid);
  start(a, 1000.0f); /* decim 50 */
  run(100u, 0u);
  expect_records(a, 50u, 0u, 2u);
  const tlm_isr_sel_t live = tx.isr_sel[named_slot()];
  /* steps 1-2: the slot written is not the one the ISR reads, which stays as it was */
  const uint32_t g = tlm_sel_write(&tx, b, 7u);
  assert_int_not_equal(g & 1u, named_slot());
  assert_memory_equal(&tx.isr_sel[named_slot()], &live, sizeof live);
  run(100u, 0u);
  expect_records(a, 50u, 100u, 2u);
  /* the background interrupted half way through rewriting that slot (mask stored, decim
   * not yet): the ISR still reads only the slot it is given */
  tx.isr_sel[g & 1u].mask = 1u << TLM_FIELD_mode;
  run(100u, 0u);
  expect_records(a, 50u, 200u, 2u);
  /* written again before a publication: the same unnamed slot, whole again */
  assert_int_equal(tlm_sel_write(&tx, b, 7u), g);
  run(100u, 0u);
  expect_records(a, 50u, 300u, 2u);
  /* step 3: the next tick takes the new selection's first record at once */
  tlm_sel_publish(&tx, g);
  run(70u, 0u);
  expect_records(b, 7u, 400u, 10u);
}

/* Two publications between ticks reuse the first slot; the generation, not the slot,
 * tells the ISR that a new stream began, also across the generation counter's wrap. */
static void test_selection_slot_reuse(void **state)
{
  (void)state;
  setup_all();
  tick_now = 0u;
  tx.sel_gen = 0xFFFFFFFDu;
  const uint32_t a = mask_of(four, 4);
  start(a, 1000.0f); /* generation 0xFFFFFFFE */
  run(60u, 0u);
  expect_records(a, 50u, 0u, 2u);
  const uint32_t slot_a = named_slot();
  const uint32_t gb = tlm_sel_write(&tx, 1u << TLM_FIELD_tick, 3u);
  tlm_sel_publish(&tx, gb);
  assert_int_equal(gb, 0xFFFFFFFFu);
  /* the same selection as before, in the same slot, as a new generation (2: 0 is off) */
  const uint32_t gc = tlm_sel_write(&tx, a, 50u);
  assert_int_equal(gc, 2u);
  assert_int_equal(gc & 1u, slot_a);
  tlm_sel_publish(&tx, gc);
  run(100u, 0u); /* a new stream: its first record at once, not at tick 100 */
  expect_records(a, 50u, 60u, 2u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plan_rate_rounding),
      cmocka_unit_test(test_link_budget_by_hand),
      cmocka_unit_test(test_link_budget_matches_encoder),
      cmocka_unit_test(test_round_trip),
      cmocka_unit_test(test_overrun_counted),
      cmocka_unit_test(test_link_blocked),
      cmocka_unit_test(test_stop_drops_what_does_not_fit),
      cmocka_unit_test(test_restart),
      cmocka_unit_test(test_idle_isr_does_nothing),
      cmocka_unit_test(test_selection_never_torn),
      cmocka_unit_test(test_selection_slot_reuse),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
