#include "comm/tlm_frame.h"

#include <string.h>

/* Remainders of polynomial 0x1021 for each 4-bit value shifted in at the top: entry n is
 * n << 12 put through 4 steps of the bitwise MSB-first algorithm. */
static const uint16_t k_crc16_nibble[16] = {
    0x0000u, 0x1021u, 0x2042u, 0x3063u, 0x4084u, 0x50A5u, 0x60C6u, 0x70E7u,
    0x8108u, 0x9129u, 0xA14Au, 0xB16Bu, 0xC18Cu, 0xD1ADu, 0xE1CEu, 0xF1EFu};

uint16_t tlm_crc16(uint16_t crc, const void *data, size_t len)
{
  const uint8_t *p = (const uint8_t *)data;
  uint32_t c = crc;
  for (size_t i = 0; i < len; i++) {
    c = ((c << 4) & 0xFFFFu) ^ k_crc16_nibble[((c >> 12) ^ ((uint32_t)p[i] >> 4)) & 0x0Fu];
    c = ((c << 4) & 0xFFFFu) ^ k_crc16_nibble[((c >> 12) ^ (uint32_t)p[i]) & 0x0Fu];
  }
  return (uint16_t)c;
}

size_t tlm_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap)
{
  if (cap < TLM_COBS_MAX(n)) {
    return 0u;
  }
  size_t code_at = 0u; /* where the current block's code byte goes */
  size_t o = 1u;
  uint8_t code = 1u;
  for (size_t i = 0; i < n; i++) {
    if (in[i] == 0u) {
      out[code_at] = code;
      code_at = o++;
      code = 1u;
      continue;
    }
    out[o++] = in[i];
    code++;
    if (code == 0xFFu) {
      /* a full 254-byte block consumes no zero; a block follows only if bytes do */
      out[code_at] = code;
      code = 1u;
      if (i + 1u < n) {
        code_at = o++;
      } else {
        return o;
      }
    }
  }
  out[code_at] = code;
  return o;
}

bool tlm_cobs_decode(const uint8_t *in, size_t n, uint8_t *out, size_t cap, size_t *len)
{
  size_t i = 0u;
  size_t o = 0u;
  while (i < n) {
    const uint8_t code = in[i++];
    if (code == 0u) {
      return false;
    }
    const size_t k = (size_t)code - 1u;
    if (k > n - i || o + k > cap) {
      return false;
    }
    for (size_t j = 0; j < k; j++) {
      if (in[i + j] == 0u) {
        return false;
      }
      out[o + j] = in[i + j];
    }
    i += k;
    o += k;
    if (code != 0xFFu && i < n) {
      if (o >= cap) {
        return false;
      }
      out[o++] = 0u;
    }
  }
  *len = o;
  return true;
}

size_t tlm_frame_seal(uint8_t *raw, uint8_t type, uint16_t seq, size_t payload_len)
{
  raw[0] = (uint8_t)TLM_FRAME_MARKER;
  raw[1] = type;
  tlm_put_u16(&raw[2], seq);
  const size_t n = TLM_FRAME_HEAD_BYTES + payload_len;
  const uint16_t crc = tlm_crc16(TLM_CRC16_INIT, raw, n);
  raw[n] = (uint8_t)(crc >> 8);
  raw[n + 1u] = (uint8_t)(crc & 0xFFu);
  return n + TLM_FRAME_CRC_BYTES;
}

size_t tlm_frame_to_wire(const uint8_t *raw, size_t len, uint8_t *wire, size_t cap)
{
  if (cap < TLM_COBS_MAX(len) + 2u) {
    return 0u;
  }
  wire[0] = 0u;
  const size_t c = tlm_cobs_encode(raw, len, &wire[1], cap - 2u);
  wire[c + 1u] = 0u;
  return c + 2u;
}

tlm_frame_status_t tlm_frame_open(const uint8_t *cobs, size_t n, uint8_t *raw,
                                  tlm_frame_view_t *v)
{
  size_t len = 0u;
  if (!tlm_cobs_decode(cobs, n, raw, TLM_FRAME_MAX, &len)) {
    return TLM_FRAME_ERR_COBS;
  }
  if (len < TLM_FRAME_OVERHEAD) {
    return TLM_FRAME_ERR_SHORT;
  }
  /* MSB-first CRC appended: the CRC over the whole frame is 0 */
  if (tlm_crc16(TLM_CRC16_INIT, raw, len) != 0u) {
    return TLM_FRAME_ERR_CRC;
  }
  if (raw[0] != TLM_FRAME_MARKER) {
    return TLM_FRAME_ERR_MARKER;
  }
  v->type = raw[1];
  v->seq = tlm_get_u16(&raw[2]);
  v->payload = &raw[TLM_FRAME_HEAD_BYTES];
  v->payload_len = len - TLM_FRAME_OVERHEAD;
  return TLM_FRAME_OK;
}
