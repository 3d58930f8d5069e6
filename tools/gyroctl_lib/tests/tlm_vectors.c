/* tlm-vectors: reference streams from the firmware's telemetry encoder (comm/tlm), for
 * the Python decoder's tests (tools/gyroctl_lib/tests/test_frames.py).
 *
 *   tlm-vectors make DIR     write DIR/stream.bin (command-line lines and frames of three
 *                            streams, as the firmware puts them on the UART) and
 *                            DIR/expected.json (the lines, and for each stream its layout
 *                            and every record as the 32-bit words of the snapshot the ISR
 *                            was given: the truth, not a decode)
 *   tlm-vectors decode FILE  run the C receiver (tools/tlm_decode) over FILE and print its
 *                            counters and a digest of what it delivered as JSON, so the
 *                            Python receiver can be compared on damaged input.
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/app_tlm_fields.h"
#include "comm/tlm.h"
#include "gyro/gyro.h"
#include "tlm_decode.h"

#define FS 50000u
static uint8_t wire[4u << 20];
static size_t wire_len;
static size_t room_limit = (size_t)-1;

static size_t room(void *ctx)
{
  (void)ctx;
  const size_t left = sizeof wire - wire_len;
  return left < room_limit ? left : room_limit;
}

static void put(void *ctx, const uint8_t *p, size_t n)
{
  (void)ctx;
  memcpy(&wire[wire_len], p, n);
  wire_len += n;
}

static void text(FILE *js, const char *line, int *first)
{
  put(NULL, (const uint8_t *)line, strlen(line));
  put(NULL, (const uint8_t *)"\r\n", 2u);
  fprintf(js, "%s\"%s\"", *first ? "" : ", ", line);
  *first = 0;
}

/* The snapshot of tick k: every member a distinct function of k. */
static void snap(gyro_out_t *o, uint32_t k)
{
  const float x = (float)k;
  o->tick = k;
  o->rate_dps = 0.001f * x - 3.0f;
  o->rate_unc_dps = -x;
  o->quad_dps = x * 1e-6f;
  o->drive_amp_v = 1.8f + 1e-5f * x;
  o->drive_phase_deg = -45.5f;
  o->p_deg = 2.0f * x;
  o->p_f_deg = 3.0f * x;
  o->f_cmd_v2 = -4.0f * x;
  o->u1_v = 5.0f * x;
  o->u2_v = -6.0f * x;
  o->sense_i_v = 7.0f * x;
  o->sense_q_v = -8.0f * x;
  o->mode = k % 5u;
  o->fault = k * 3u;
  o->flags = k & 0xFu;
  o->rate_valid = (k >> 4) & 1u;
}

static tlm_t tx;

/* One stream: start, `ticks` ticks with the background loop every `poll` ticks except
 * between stall_from and stall_to (ticks), stop. Records go to js as words. */
static void stream(FILE *js, uint32_t *tick, uint32_t mask, float rate, uint32_t ticks,
                   uint32_t poll, uint32_t stall_from, uint32_t stall_to, int first)
{
  tlm_plan_t p;
  if (tlm_plan(&app_tlm_fields, FS, 921600u, mask, rate, &p) != TLM_OK) {
    fprintf(stderr, "plan refused\n");
    exit(1);
  }
  tlm_start(&tx, &p);
  fprintf(js,
          "%s{\"stream_id\": %" PRIu32 ", \"fs_hz\": %u, \"decim\": %" PRIu32 ", \"fields\": [",
          first ? "" : ", ", tx.stream_id, FS, p.decim);
  int f1 = 1;
  for (uint32_t i = 0; i < (uint32_t)TLM_FIELD_COUNT; i++) {
    if ((mask >> i) & 1u) {
      fprintf(js, "%s[\"%s\", %u]", f1 ? "" : ", ", app_tlm_field(i)->name,
              app_tlm_field(i)->type);
      f1 = 0;
    }
  }
  fprintf(js, "], \"records\": [");
  gyro_out_t o;
  uint32_t count = 0u, rec = 0u;
  int r1 = 1;
  for (uint32_t k = 0; k < ticks; k++) {
    snap(&o, *tick);
    tlm_isr_push(&tx, &o);
    if (count == 0u) {
      /* the record this tick produced (pushed or lost to an overrun) */
      fprintf(js, "%s[%" PRIu32, r1 ? "" : ", ", rec++);
      for (uint32_t i = 0; i < (uint32_t)TLM_FIELD_COUNT; i++) {
        if ((mask >> i) & 1u) {
          uint32_t w;
          memcpy(&w, (const uint8_t *)&o + app_tlm_field(i)->offset, 4u);
          fprintf(js, ", %" PRIu32, w);
        }
      }
      fprintf(js, "]");
      r1 = 0;
    }
    count = (count + 1u) % p.decim;
    (*tick)++;
    if (poll != 0u && k % poll == poll - 1u && !(k >= stall_from && k < stall_to)) {
      tlm_poll(&tx);
    }
  }
  tlm_stop(&tx);
  tlm_stats_t st;
  tlm_stats(&tx, &st);
  fprintf(js, "], \"taken\": %" PRIu32 ", \"lost\": %" PRIu32 ", \"frames\": %" PRIu32 "}",
          st.records, st.lost, st.frames);
}

static int make(const char *dir)
{
  char path[1024];
  snprintf(path, sizeof path, "%s/expected.json", dir);
  FILE *js = fopen(path, "w");
  if (js == NULL) {
    perror(path);
    return 1;
  }
  const tlm_cfg_t c = {FS, 921600u, room, put, NULL, &app_tlm_fields};
  if (tlm_init(&tx, &c) != 0) return 1;
  uint32_t tick = 12345u;
  fprintf(js, "{\"lines\": [");
  int first = 1;
  text(js, "ok drive.amp_set_v 1.8 V", &first);
  text(js, "ok stream 1 1000 Hz decim 50", &first);
  fprintf(js, "], \"streams\": [");
  /* 1: five fields at 1 kHz, 0.5 s */
  const uint32_t m1 = (1u << TLM_FIELD_rate_dps) | (1u << TLM_FIELD_quad_dps) |
                      (1u << TLM_FIELD_mode) | (1u << TLM_FIELD_flags) | (1u << TLM_FIELD_tick);
  stream(js, &tick, m1, 1000.0f, 25000u, 50u, 0u, 0u, 1);
  /* 2: all fields at 250 Hz, 2.1 s (three headers) */
  stream(js, &tick, TLM_FIELD_MASK_ALL, 250.0f, 105000u, 100u, 0u, 0u, 0);
  /* 3: two fields at 5 kHz (rounded from 4900), with the background loop stalled for
   * 0.2 s: the ring overflows and records are lost */
  stream(js, &tick, (1u << TLM_FIELD_drive_amp_v) | (1u << TLM_FIELD_tick), 4900.0f, 50000u,
         25u, 10000u, 20000u, 0);
  fprintf(js, "], \"trailer\": [");
  first = 1;
  text(js, "ok stop 3 records 5000", &first);
  fprintf(js, "]}\n");
  fclose(js);
  snprintf(path, sizeof path, "%s/stream.bin", dir);
  FILE *f = fopen(path, "wb");
  if (f == NULL || fwrite(wire, 1, wire_len, f) != wire_len) {
    perror(path);
    return 1;
  }
  fclose(f);
  return 0;
}

/* ---- decode ---- */

typedef struct {
  uint32_t records;
  uint64_t digest; /* FNV-1a over (stream_id, index, words) of every record delivered */
  uint32_t line_chars;
} sum_t;

static void fnv(uint64_t *h, uint32_t w)
{
  for (int i = 0; i < 4; i++) {
    *h ^= (w >> (8 * i)) & 0xFFu;
    *h *= 1099511628211ull;
  }
}

static void on_data(void *ctx, const tlm_data_t *d)
{
  sum_t *s = ctx;
  for (uint32_t r = 0; r < d->n_rec; r++) {
    fnv(&s->digest, d->layout->stream_id);
    fnv(&s->digest, d->first_rec + r);
    for (uint32_t f = 0; f < d->layout->n_fields; f++) fnv(&s->digest, tlm_data_u32(d, r, f));
    s->records++;
  }
}

static void on_text(void *ctx, const char *line, size_t n)
{
  (void)line;
  ((sum_t *)ctx)->line_chars += (uint32_t)n;
}

static int decode(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL) {
    perror(path);
    return 1;
  }
  wire_len = fread(wire, 1, sizeof wire, f);
  fclose(f);
  static tlm_decode_t rx;
  sum_t s = {0u, 1469598103934665603ull, 0u};
  const tlm_decode_cfg_t c = {on_text, NULL, on_data, &s};
  tlm_decode_init(&rx, &c);
  tlm_decode_feed(&rx, wire, wire_len);
  const tlm_decode_stats_t *st = &rx.st;
  printf("{\"lines\": %" PRIu32 ", \"lines_bad\": %" PRIu32 ", \"headers\": %" PRIu32
         ", \"data\": %" PRIu32 ", \"corrupt\": %" PRIu32 ", \"bad_format\": %" PRIu32
         ", \"no_layout\": %" PRIu32 ", \"seq_missing\": %" PRIu32 ", \"rec_missing\": %" PRIu32
         ", \"records\": %" PRIu32 ", \"digest\": %" PRIu64 ", \"line_chars\": %" PRIu32 "}\n",
         st->lines, st->lines_bad, st->headers, st->data, st->corrupt, st->bad_format,
         st->no_layout, st->seq_missing, st->rec_missing, s.records, s.digest, s.line_chars);
  return 0;
}

int main(int argc, char **argv)
{
  if (argc == 3 && strcmp(argv[1], "make") == 0) return make(argv[2]);
  if (argc == 3 && strcmp(argv[1], "decode") == 0) return decode(argv[2]);
  fprintf(stderr, "usage: tlm-vectors make DIR | tlm-vectors decode FILE\n");
  return 2;
}
