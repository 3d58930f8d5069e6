/* Telemetry stream: selected fields of the application's per-tick snapshot, decimated in
 * the sample ISR, framed in the background loop, sent on the tuning UART next to the
 * command line (frame format and the text/frame rule: tlm_frame.h; the field table the
 * application registers: tlm_fields.h).
 *
 *   ISR (50 kHz)   tlm_isr_push(): one 32-bit load and a compare while not streaming;
 *                  otherwise a decimation counter, and every decim-th tick (two more
 *                  loads: the selection, see below) one record
 *                  {record index, selected words} into the SPSC ring (tlm_ring.h). A full
 *                  ring drops the record and counts it; the ISR never waits.
 *   background     tlm_poll(): records -> data frames of rec_per_frame records, a header
 *                  frame at the start and once per second, each frame handed to the
 *                  link only when the link takes all of it; otherwise it waits in
 *                  `pending` and the ring absorbs the delay.
 *
 * Configuration handoff. A selection is two words, {mask, decim} (tlm_isr_sel_t): with
 * up to 32 fields the mask alone fills a word, so the ISR cannot read a selection with
 * one load. The background, the only writer, keeps two slots isr_sel[2] and names the
 * current one with a single 32-bit word, the generation isr_gen: 0 = off, otherwise g,
 * whose selection is isr_sel[g & 1]. To publish a selection the background
 *   1. takes g = the last generation it published + 1 (skipping 0), so g's slot is not
 *      the one isr_gen names (or isr_gen is 0 and names none);
 *   2. writes mask and decim into isr_sel[g & 1];
 *   3. a release signal fence, then one store isr_gen = g.
 * The ISR loads isr_gen once per tick and, on a tick that takes a record, an acquire
 * signal fence and then the slot g names, in that same activation.
 * Why the ISR never pairs the mask of one selection with the decim of another: on the
 * single core the background never runs while an ISR activation does (the ISR preempts
 * it, never the reverse), so an activation reads the generation and its slot at one
 * point between the background's steps. Before step 3 it reads the old generation,
 * whose slot was complete when that generation was published and is not the slot being
 * written; after step 3 it reads the new slot, complete because the fence keeps step
 * 2's stores before step 3's store. The slot a generation names is written again only
 * after a later publication has moved the ISR to the other slot; as the ISR holds no
 * slot from one tick to the next (it re-reads isr_gen every tick), that publication is
 * its acknowledgement, and the background never waits. (A reader on another core, or
 * one the writer could preempt, would have to report the generation it moved to before
 * its old slot could be reused.) The ISR compares the generation, not the slot index,
 * with the one it acted on last: two publications between two ticks reuse one slot,
 * and the new number still tells it that a new stream began.
 * A stream starts with isr_gen = 0 already in place (stop), the ring emptied and the
 * ISR's record counter noted as the stream's base while nothing produces, then the
 * publication of its selection: every record the background reads afterwards belongs
 * to the new stream, with no lock.
 *
 * Link budget (the command's bandwidth check, tlm_plan). 8N1 at 921600 baud carries
 * 92160 bytes/s. A data frame of N records of F fields is raw = 13 + 4 N F bytes
 * (marker 1, type 1, seq 2, stream 2, first_rec 4, n_rec 1, CRC 2) and costs at most
 * raw + 1 + floor(raw / 254) + 2 bytes on the wire (COBS, two delimiters).
 *   N = min(max(1, floor(rate / 50)), floor(240 / 4F)): about 50 frames/s (20 ms of
 *   latency) and raw <= 253, so COBS adds 2 bytes and a damaged frame costs few records.
 * Wire load = rate / N * wire(N, F) + one header frame per second
 * (30 + sum(2 + name length) bytes raw). Worked examples (tests/unit/test_tlm.c checks
 * these against the bytes the encoder actually emits):
 *   4 f32 at 200 Hz   N = 4,  raw 77,  wire 80,  50 frames/s    ->  4.1 kB/s =  4 %
 *   4 f32 at 1 kHz    N = 15, raw 253, wire 256, 66.7 frames/s  -> 17.1 kB/s = 19 %
 *   8 f32 at 1 kHz    N = 7,  raw 237, wire 240, 142.9 frames/s -> 34.4 kB/s = 37 %
 *   12 f32 at 1 kHz   N = 5,  raw 253, wire 256, 200 frames/s -> 51.4 kB/s = 56 %
 *   all 17 at 1 kHz   N = 3,  raw 217, wire 220, 333 frames/s -> 73.5 kB/s = 80 %: refused
 *   all 17 at 500 Hz  N = 3                                  -> 36.9 kB/s = 40 %
 * A stream may use at most TLM_LINK_MAX_PCT = 70 % of the link: command replies share
 * it, and the UART's byte timing and the background loop's latency need slack.
 */
#ifndef TLM_H
#define TLM_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "comm/tlm_fields.h"
#include "comm/tlm_frame.h"
#include "comm/tlm_ring.h"

#define TLM_LINK_MAX_PCT 70u
#define TLM_FRAMES_PER_S 50u
/* Slowest stream fs / 65535 (0.76 Hz at 50 kHz): the range the `stream` command offers
 * (app_tlm.h); the selection slot itself holds 32 bits. */
#define TLM_DECIM_MAX 65535u

/* Bytes the link takes now without blocking (0: try again later). */
typedef size_t (*tlm_room_fn)(void *ctx);
/* Queue len bytes; called only with len <= room(). */
typedef void (*tlm_write_fn)(void *ctx, const uint8_t *data, size_t len);

typedef struct {
  uint32_t fs_hz; /* tick rate */
  uint32_t baud;  /* UART line rate, 8N1 (10 bits per byte) */
  tlm_room_fn room;
  tlm_write_fn write;
  void *ctx;
  const tlm_fields_t *fields; /* the snapshot's field table, kept by pointer */
} tlm_cfg_t;

/* A checked stream selection (tlm_plan). */
typedef struct {
  uint32_t mask; /* bit i: row i of the field table */
  uint32_t n_fields;
  uint32_t decim; /* ticks per record */
  float rate_hz;  /* fs / decim, what the stream delivers */
  uint32_t rec_per_frame;
  uint32_t bytes_per_s;      /* worst-case wire load, headers included */
  uint32_t link_bytes_per_s; /* what the line carries: baud / 10 */
} tlm_plan_t;

typedef enum {
  TLM_OK = 0,
  TLM_ERR_FIELDS,   /* empty or unknown selection */
  TLM_ERR_RATE,     /* rate not finite, <= 0, above fs, or decim > TLM_DECIM_MAX */
  TLM_ERR_BANDWIDTH /* over TLM_LINK_MAX_PCT of the link */
} tlm_status_t;

typedef struct {
  bool streaming;
  uint32_t stream_id;
  uint32_t records; /* records read from the ring this stream */
  uint32_t lost;    /* records of this stream lost to ring overruns */
  uint32_t frames;  /* frames handed to the link this stream */
  uint32_t dropped; /* frames of this stream the link could not take (at stop) */
} tlm_stats_t;

/* A selection as the ISR reads it (configuration handoff above). */
typedef struct {
  uint32_t mask;  /* bit i: row i of the field table */
  uint32_t decim; /* ticks per record, >= 1 */
} tlm_isr_sel_t;

typedef struct {
  /* ISR side, first: the sample ISR loads isr_gen every tick, at a small offset from
   * whatever holds the stream (the ring, 8 KB, follows). */
  _Atomic uint32_t isr_gen; /* 0 = off, else g: selection isr_sel[g & 1]; background */
  const tlm_field_t *rows;  /* cfg.fields->row: one load fewer per record */
  tlm_isr_sel_t isr_sel[2]; /* written by the background, never the slot isr_gen names */
  uint32_t isr_seen;        /* last isr_gen the ISR acted on */
  uint32_t isr_count;       /* ticks to wait before the next record */
  _Atomic uint32_t isr_rec; /* records taken (pushed or lost), written by the ISR */
  tlm_ring_t ring;
  /* background side */
  tlm_cfg_t cfg;
  tlm_plan_t plan;
  bool streaming;
  bool header_due;
  uint32_t stream_id;
  uint32_t sel_gen;     /* the last non-zero generation published */
  uint32_t rec_base;    /* isr_rec when the stream started */
  uint32_t lost_base;   /* ring overruns when the stream started */
  uint32_t next_header; /* record index that triggers the next periodic header */
  uint32_t rec_per_s;
  uint16_t seq;
  uint32_t acc_n; /* records collected for the next data frame */
  uint32_t acc_first;
  uint32_t records, frames, dropped;
  size_t pending_len; /* wire bytes of a frame waiting for room */
  uint8_t raw[TLM_FRAME_MAX];
  uint8_t wire[TLM_WIRE_MAX];
} tlm_t;

/* Returns 0, or -1 for a missing callback, fs_hz == 0, baud == 0, or a field table
 * that is missing, empty, longer than TLM_FIELDS_MAX, or has a row with a name longer
 * than TLM_NAME_MAX or an offset that is not a multiple of 4. */
int tlm_init(tlm_t *t, const tlm_cfg_t *cfg);

/* Check a selection and choose decim = round(fs / rate_hz) (>= 1), the frame size and the
 * wire load. Pure; *plan is filled on TLM_OK and on TLM_ERR_BANDWIDTH (for the message). */
tlm_status_t tlm_plan(const tlm_fields_t *fields, uint32_t fs_hz, uint32_t baud, uint32_t mask,
                      float rate_hz, tlm_plan_t *plan);
/* Wire bytes per second of a plan: data frames at their worst-case size plus headers. */
uint32_t tlm_plan_bytes_per_s(const tlm_fields_t *fields, uint32_t fs_hz, uint32_t mask,
                              uint32_t decim, uint32_t rec_per_frame);

/* Stop any running stream (as tlm_stop) and start plan (from tlm_plan with this t's
 * fs and baud). Background only. */
void tlm_start(tlm_t *t, const tlm_plan_t *plan);
/* Stop the stream: no more records, the remaining ones framed and handed to the link
 * now (frames that do not fit are dropped and counted). Background only. */
void tlm_stop(tlm_t *t);
/* Move records to frames to the link; never blocks. Background only. */
void tlm_poll(tlm_t *t);
void tlm_stats(const tlm_t *t, tlm_stats_t *st);

/* The selection handoff's steps (configuration handoff above), background only;
 * tlm_start runs them back to back, tests run the ISR between them.
 * Steps 1-2: write {mask, decim} into the slot of the generation after the last one
 * published (the slot isr_gen does not name) and return that generation.
 * Step 3: publish gen, the value tlm_sel_write returned. */
uint32_t tlm_sel_write(tlm_t *t, uint32_t mask, uint32_t decim);
void tlm_sel_publish(tlm_t *t, uint32_t gen);

/* ISR, streaming: gen is the isr_gen this tick loaded (non-zero). */
void tlm_isr_record(tlm_t *t, const void *snapshot, uint32_t gen);

/* ISR: call once per tick with the tick's snapshot, the object the field table's
 * offsets are taken in. */
static inline void tlm_isr_push(tlm_t *t, const void *snapshot)
{
  const uint32_t gen = atomic_load_explicit(&t->isr_gen, memory_order_relaxed);
  if (gen != 0u) {
    tlm_isr_record(t, snapshot, gen);
  }
}

#endif /* TLM_H */
