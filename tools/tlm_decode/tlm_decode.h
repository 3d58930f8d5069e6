/* Receiver of the tuning UART for host tools and tests: separates command-line text from
 * telemetry frames and decodes the frames, following the rules in tlm_frame.h (the
 * TEXT / FRAME / SKIP machine). Robust to any input: every byte sequence leaves it in a
 * defined state, a frame is delivered only if its COBS, length, CRC, marker, type and
 * payload layout all check, and a damaged frame is counted, never misread.
 *
 * Delivered items (callbacks, any of them may be NULL):
 *   text   a line without its CR LF: only bytes 0x20-0x7E and TAB, at most
 *          TLM_DECODE_LINE_MAX bytes, NUL-terminated
 *   header the layout of a stream (every header frame, also the periodic repeats)
 *   data   the records of a data frame of the stream whose header was seen last
 * Accounting (tlm_decode_stats_t):
 *   lines_bad    text dropped: a byte outside the text set, a CR not before LF, too
 *                long, or cut short by 0x00 or a frame start
 *   corrupt      frames failing COBS, length, CRC or marker, or too long for a frame
 *   bad_format   frames with a good CRC but an unknown type or a malformed payload
 *                (a protocol mismatch, not line noise)
 *   no_layout    data frames for which no header of their stream has been seen
 *   seq_missing  frames of the current stream that were not delivered, from gaps in seq
 *                (lost on the wire, or rejected above)
 *   rec_missing  records of the current stream that never arrived, from gaps in
 *                first_rec (ring overruns in the firmware, or lost data frames)
 * A header with another stream_id starts a new stream: seq and record tracking restart.
 */
#ifndef TLM_DECODE_H
#define TLM_DECODE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "comm/tlm_frame.h"

#define TLM_DECODE_LINE_MAX 300u

typedef struct {
  uint32_t stream_id;
  uint32_t fs_hz;
  uint32_t decim;
  uint32_t lost;
  uint32_t dropped;
  uint16_t rec_per_frame;
  uint16_t seq;
  uint8_t n_fields;
  uint8_t type[TLM_FIELDS_MAX]; /* 0 f32, 1 u32 (tlm_type_t) */
  char name[TLM_FIELDS_MAX][TLM_NAME_MAX + 1u];
} tlm_layout_t;

typedef struct {
  const tlm_layout_t *layout;
  uint16_t seq;
  uint32_t first_rec;
  uint32_t n_rec;
  const uint8_t *rec; /* n_rec * n_fields little-endian 4-byte words */
} tlm_data_t;

static inline uint32_t tlm_data_u32(const tlm_data_t *d, uint32_t rec, uint32_t field)
{
  return tlm_get_u32(&d->rec[4u * (rec * d->layout->n_fields + field)]);
}
static inline float tlm_data_f32(const tlm_data_t *d, uint32_t rec, uint32_t field)
{
  const uint32_t w = tlm_data_u32(d, rec, field);
  float f;
  memcpy(&f, &w, sizeof f);
  return f;
}

typedef void (*tlm_text_fn)(void *ctx, const char *line, size_t len);
typedef void (*tlm_header_fn)(void *ctx, const tlm_layout_t *layout);
typedef void (*tlm_data_fn)(void *ctx, const tlm_data_t *data);

typedef struct {
  tlm_text_fn on_text;
  tlm_header_fn on_header;
  tlm_data_fn on_data;
  void *ctx;
} tlm_decode_cfg_t;

typedef struct {
  uint32_t lines, lines_bad;
  uint32_t headers, data;
  uint32_t corrupt, bad_format, no_layout;
  uint32_t seq_missing, rec_missing;
} tlm_decode_stats_t;

typedef struct {
  tlm_decode_cfg_t cfg;
  uint8_t state; /* TEXT, FRAME, SKIP */
  bool line_bad;
  bool line_cr; /* a CR was the last byte */
  uint32_t line_len;
  char line[TLM_DECODE_LINE_MAX + 1u];
  uint32_t buf_len;
  uint8_t buf[TLM_COBS_MAX(TLM_FRAME_MAX)];
  uint8_t raw[TLM_FRAME_MAX];
  tlm_layout_t layout;
  bool have_layout;
  uint16_t next_seq;
  bool have_rec;
  uint32_t next_rec;
  tlm_decode_stats_t st;
} tlm_decode_t;

/* cfg may be NULL (count only). */
void tlm_decode_init(tlm_decode_t *d, const tlm_decode_cfg_t *cfg);
/* Feed received bytes; callbacks run before it returns. */
void tlm_decode_feed(tlm_decode_t *d, const uint8_t *data, size_t len);
/* The layout of the current stream, or NULL before the first header. */
const tlm_layout_t *tlm_decode_layout(const tlm_decode_t *d);

#endif /* TLM_DECODE_H */
