/* Telemetry frames on the tuning UART: byte layout, CRC-16, COBS, and the rule by which
 * a host tells frames from command-line text sharing the wire.
 *
 * On the wire a frame is  0x00, COBS(raw frame), 0x00.
 * COBS (consistent overhead byte stuffing, Cheshire & Baker 1999) rewrites the raw frame
 * without any 0x00 byte, so 0x00 delimits frames unambiguously and a receiver resyncs at
 * the next 0x00 after any damage. Encoding: split the raw frame (with a virtual 0x00
 * appended) into blocks of k <= 254 non-zero bytes that end at a zero or at 254 bytes;
 * each block is sent as the code byte k+1 followed by its k bytes, except that a full
 * 254-byte block is sent as 0xFF + 254 bytes and consumes no zero; the virtual trailing
 * zero is not reproduced by the decoder (the Wikipedia variant: 254 non-zero bytes
 * encode as FF + the bytes, no trailing 01). Cost: at most 1 + floor(n / 254) bytes.
 *
 * Raw frame (multi-byte fields little-endian, except the CRC):
 *   offset size  field
 *   0      1     0x00 marker. COBS turns it into the code byte 0x01, so the first byte
 *                after a frame's leading 0x00 is always 0x01 - a byte text never holds
 *   1      1     type: 'H' (0x48) header frame, 'D' (0x44) data frame
 *   2      2     seq: frame counter of the stream, +1 per frame of either type, from 0
 *                at the stream's first header, wraps at 2^16
 *   4      n     payload
 *   4+n    2     CRC-16/CCITT-FALSE of bytes 0 .. 3+n, most significant byte first (so
 *                the CRC over a whole good frame is 0): polynomial 0x1021, initial
 *                0xFFFF, no reflection, no final XOR; check value 0x29B1 for "123456789";
 *                Python: binascii.crc_hqx(data, 0xFFFF).
 *
 * Header payload ('H'): sent first when a stream starts, then once per second of
 * stream (every round(rate) records), so a host that joins late learns the layout.
 *   0   1  version = 1
 *   1   4  stream_id: `stream` commands since boot; data frames carry its low 16 bits
 *   5   4  fs_hz: tick rate
 *   9   4  decim: ticks per record; the record rate is fs_hz / decim
 *   13  2  rec_per_frame: records in a full data frame
 *   15  4  lost: records of this stream lost to ring overruns so far (the ISR side)
 *   19  4  dropped: frames of this stream the UART could not take so far
 *   23  1  n_fields, 1 .. 32 (1 .. 16 before the field table grew past 16 rows: such
 *          a receiver rejects a wider header as malformed or oversize and reads none of
 *          that stream's data, it never misreads it; the layout itself is unchanged, so
 *          the version stays 1)
 *   24  .. n_fields times: type (0 = f32, 1 = u32), name length L (1 .. 31), then L
 *          name bytes from [A-Za-z0-9_.]; names are unique
 * Data payload ('D'):
 *   0   2  stream: low 16 bits of stream_id (a data frame is read only with the header
 *          of its own stream)
 *   2   4  first_rec: index of its first record since the stream started; record k
 *          was taken k * decim ticks after the first, t_k = k * decim / fs_hz
 *   6   1  n_rec, 1 .. 255
 *   7   .. n_rec records, each n_fields 4-byte values in header order (IEEE-754
 *          binary32 or uint32, little-endian); payload length = 7 + 4 n_rec n_fields
 * Records of one data frame are consecutive; a gap in first_rec means records were lost.
 *
 * Text and frames on one wire. The firmware guarantees:
 *   T1 command-line text holds only the bytes 0x20-0x7E, CR and LF (cli.h);
 *   F1 a frame is 0x00 0x01 <COBS bytes, never 0x00> 0x00;
 *   F2 lines and frames are each written whole by the background loop: a frame is queued
 *      only when the TX ring takes all of it, so neither is ever split by the other;
 *   F3 frames flow only between the `ok stream ...` reply that starts a stream and the
 *      `ok stop ...` reply (or the next `stream` reply) that ends it: `stop` sends the
 *      last frames before its reply.
 * A host parser (tools/tlm_decode/tlm_decode.h, and gyroctl's frames.py, which follows
 * it) is a three-state machine, starting in TEXT:
 *   TEXT   0x01 starts a frame (-> FRAME, the 0x01 is its first COBS byte; a partial
 *          line is dropped as garbage); LF ends a line (one trailing CR is removed, an
 *          empty line is ignored); 0x20-0x7E, TAB and CR extend the line; 0x00 drops a
 *          partial line as garbage; any other byte marks the line as garbage, dropped and
 *          counted at its LF; a line longer than the parser's limit is garbage too.
 *   FRAME  0x00 ends the frame: COBS-decode, check marker, length, CRC and format; a frame
 *          failing any check is counted and never delivered. -> TEXT. A frame longer than
 *          TLM_WIRE_MAX is counted as oversize -> SKIP.
 *   SKIP   bytes are ignored until 0x00 -> TEXT.
 * Every frame begins with 0x00, which ends FRAME and SKIP and is harmless in TEXT, so
 * after any damage (a lost or corrupted byte, a reply cut short by a full TX ring) the
 * parser is back in step at the next frame.
 */
#ifndef TLM_FRAME_H
#define TLM_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define TLM_FRAME_MARKER 0x00u
#define TLM_FRAME_HEADER 0x48u  /* 'H' */
#define TLM_FRAME_DATA 0x44u    /* 'D' */
#define TLM_FRAME_HEAD_BYTES 4u /* marker, type, seq */
#define TLM_FRAME_CRC_BYTES 2u
#define TLM_FRAME_OVERHEAD (TLM_FRAME_HEAD_BYTES + TLM_FRAME_CRC_BYTES)
/* Largest raw frame either side handles (a header of 32 fields with 31-byte names). */
#define TLM_FRAME_MAX 1086u
#define TLM_COBS_MAX(n) ((n) + 1u + (n) / 254u)
/* Largest frame on the wire, both delimiters included. */
#define TLM_WIRE_MAX (TLM_COBS_MAX(TLM_FRAME_MAX) + 2u)

#define TLM_HEADER_VERSION 1u
#define TLM_HEADER_FIXED 24u /* header payload before the field list */
#define TLM_DATA_FIXED 7u    /* data payload before the records */
#define TLM_FIELDS_MAX 32u
#define TLM_NAME_MAX 31u
/* Record bytes in one data frame: with the fixed part the raw frame stays <= 253 bytes,
 * so COBS adds 2 bytes (the marker's block and one more). */
#define TLM_DATA_RECORD_BYTES_MAX 240u

_Static_assert(TLM_FRAME_OVERHEAD + TLM_HEADER_FIXED + TLM_FIELDS_MAX * (2u + TLM_NAME_MAX) <=
                   TLM_FRAME_MAX,
               "the largest header fits");

#define TLM_CRC16_INIT 0xFFFFu

/* CRC-16/CCITT-FALSE; chain like binascii.crc_hqx: crc = tlm_crc16(TLM_CRC16_INIT, ...). */
uint16_t tlm_crc16(uint16_t crc, const void *data, size_t len);

/* COBS-encode n bytes into out (cap bytes). Returns the encoded length, or 0 if cap is
 * smaller than TLM_COBS_MAX(n). in and out must not overlap. */
size_t tlm_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap);
/* Decode n COBS bytes (no delimiters) into out (cap bytes). Returns true and the length
 * in *len, or false for a 0x00 byte, a block running past the end, or output > cap. */
bool tlm_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *len);

/* Seal a raw frame whose payload (payload_len bytes) is already at raw + 4: write marker,
 * type and seq before it and the CRC after it. Returns the raw length. raw must hold
 * TLM_FRAME_OVERHEAD + payload_len bytes. */
size_t tlm_frame_seal(uint8_t *raw, uint8_t type, uint16_t seq, size_t payload_len);
/* Raw frame -> wire bytes 0x00 COBS 0x00. Returns the wire length, 0 if cap is short. */
size_t tlm_frame_to_wire(const uint8_t *raw, size_t len, uint8_t *wire, size_t cap);

typedef enum {
  TLM_FRAME_OK = 0,
  TLM_FRAME_ERR_COBS,  /* not valid COBS, or longer than TLM_FRAME_MAX */
  TLM_FRAME_ERR_SHORT, /* shorter than marker + type + seq + CRC */
  TLM_FRAME_ERR_CRC,   /* CRC mismatch */
  TLM_FRAME_ERR_MARKER /* byte 0 is not the marker */
} tlm_frame_status_t;

typedef struct {
  uint8_t type;
  uint16_t seq;
  const uint8_t *payload; /* into the caller's raw buffer */
  size_t payload_len;
} tlm_frame_view_t;

/* The COBS bytes between two delimiters -> checked raw frame in raw (TLM_FRAME_MAX bytes)
 * and a view of it. On error *v is unspecified. */
tlm_frame_status_t tlm_frame_open(const uint8_t *cobs, size_t n, uint8_t *raw,
                                  tlm_frame_view_t *v);

/* Worst-case wire bytes of a raw frame of raw_len bytes, delimiters included. */
static inline uint32_t tlm_wire_len_max(uint32_t raw_len) { return TLM_COBS_MAX(raw_len) + 2u; }

static inline void tlm_put_u16(uint8_t *p, uint16_t v)
{
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}
static inline void tlm_put_u32(uint8_t *p, uint32_t v)
{
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)((v >> 8) & 0xFFu);
  p[2] = (uint8_t)((v >> 16) & 0xFFu);
  p[3] = (uint8_t)(v >> 24);
}
static inline uint16_t tlm_get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static inline uint32_t tlm_get_u32(const uint8_t *p)
{
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

#endif /* TLM_FRAME_H */
