/* Telemetry frame primitives: CRC-16/CCITT-FALSE judged against Python's
 * binascii.crc_hqx (committed vectors, tools/gen_tlm_vectors.py) and the catalogued
 * check value; COBS judged against the published examples of the encoding and by
 * round trips; frame seal/open, and that damage is rejected. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "comm/tlm_frame.h"
#include "test_vectors.h"

static void test_crc_check_value(void **state)
{
  (void)state;
  /* CRC-16/CCITT-FALSE (a.k.a. CRC-16/IBM-3740) check value */
  assert_int_equal(tlm_crc16(TLM_CRC16_INIT, "123456789", 9u), 0x29B1u);
  assert_int_equal(tlm_crc16(TLM_CRC16_INIT, "", 0u), 0xFFFFu);
}

static void test_crc_matches_python(void **state)
{
  (void)state;
  size_t rows = 0, cols = 0;
  double *v = tv_load_csv("tlm_crc16.csv", &rows, &cols);
  assert_non_null(v);
  assert_int_equal(cols, 4u);
  assert_true(rows > 300u);
  uint8_t msg[600];
  for (size_t r = 0; r < rows; r++) {
    const size_t n = (size_t)v[4 * r];
    const unsigned start = (unsigned)v[4 * r + 1], step = (unsigned)v[4 * r + 2];
    assert_true(n <= sizeof msg);
    for (size_t i = 0; i < n; i++) {
      msg[i] = (uint8_t)((start + step * i) & 0xFFu);
    }
    assert_int_equal(tlm_crc16(TLM_CRC16_INIT, msg, n), (uint16_t)v[4 * r + 3]);
  }
  free(v);
}

static void test_crc_chaining(void **state)
{
  (void)state;
  const char *msg = "frames and text share one wire";
  const size_t n = strlen(msg);
  const uint16_t whole = tlm_crc16(TLM_CRC16_INIT, msg, n);
  for (size_t cut = 0; cut <= n; cut++) {
    assert_int_equal(tlm_crc16(tlm_crc16(TLM_CRC16_INIT, msg, cut), msg + cut, n - cut), whole);
  }
}

static void check_cobs(const uint8_t *in, size_t n, const uint8_t *want, size_t wn)
{
  uint8_t out[600], back[600];
  const size_t en = tlm_cobs_encode(in, n, out, sizeof out);
  assert_int_equal(en, wn);
  assert_memory_equal(out, want, wn);
  size_t dn = 9999u;
  assert_true(tlm_cobs_decode(out, en, back, sizeof back, &dn));
  assert_int_equal(dn, n);
  if (n > 0u) {
    assert_memory_equal(back, in, n);
  }
}

/* The worked examples of the COBS encoding (Cheshire & Baker; as listed in the
 * Wikipedia article), 254-byte runs included. */
static void test_cobs_examples(void **state)
{
  (void)state;
  check_cobs((const uint8_t *)"", 0u, (const uint8_t *)"\x01", 1u);
  check_cobs((const uint8_t *)"\x00", 1u, (const uint8_t *)"\x01\x01", 2u);
  check_cobs((const uint8_t *)"\x00\x00", 2u, (const uint8_t *)"\x01\x01\x01", 3u);
  check_cobs((const uint8_t *)"\x00\x11\x00", 3u, (const uint8_t *)"\x01\x02\x11\x01", 4u);
  check_cobs((const uint8_t *)"\x11\x22\x00\x33", 4u, (const uint8_t *)"\x03\x11\x22\x02\x33",
             5u);
  check_cobs((const uint8_t *)"\x11\x22\x33\x44", 4u, (const uint8_t *)"\x05\x11\x22\x33\x44",
             5u);
  check_cobs((const uint8_t *)"\x11\x00\x00\x00", 4u, (const uint8_t *)"\x02\x11\x01\x01\x01",
             5u);
  uint8_t in[256], want[260];
  /* 01 02 ... FE -> FF 01 02 ... FE */
  for (int i = 0; i < 254; i++) in[i] = (uint8_t)(i + 1);
  want[0] = 0xFF;
  memcpy(&want[1], in, 254);
  check_cobs(in, 254u, want, 255u);
  /* 00 01 ... FE -> 01 FF 01 ... FE */
  in[0] = 0;
  for (int i = 1; i < 255; i++) in[i] = (uint8_t)i;
  want[0] = 0x01;
  want[1] = 0xFF;
  memcpy(&want[2], &in[1], 254);
  check_cobs(in, 255u, want, 256u);
  /* 01 02 ... FF -> FF 01 ... FE 02 FF */
  for (int i = 0; i < 255; i++) in[i] = (uint8_t)(i + 1);
  want[0] = 0xFF;
  memcpy(&want[1], in, 254);
  want[255] = 0x02;
  want[256] = 0xFF;
  check_cobs(in, 255u, want, 257u);
  /* 02 03 ... FF 00 -> FF 02 ... FF 01 01 */
  for (int i = 0; i < 254; i++) in[i] = (uint8_t)(i + 2);
  in[254] = 0;
  want[0] = 0xFF;
  memcpy(&want[1], in, 254);
  want[255] = 0x01;
  want[256] = 0x01;
  check_cobs(in, 255u, want, 257u);
  /* 03 04 ... FF 00 01 -> FE 03 ... FF 02 01 */
  for (int i = 0; i < 253; i++) in[i] = (uint8_t)(i + 3);
  in[253] = 0;
  in[254] = 1;
  want[0] = 0xFE;
  memcpy(&want[1], in, 253);
  want[254] = 0x02;
  want[255] = 0x01;
  check_cobs(in, 255u, want, 256u);
}

static uint32_t lcg(uint32_t *s)
{
  *s = *s * 1664525u + 1013904223u;
  return *s >> 8;
}

/* Random buffers (dense, sparse and no zeros): no 0x00 in the encoding, length within
 * TLM_COBS_MAX, exact round trip. */
static void test_cobs_round_trip(void **state)
{
  (void)state;
  uint32_t s = 7u;
  uint8_t in[TLM_FRAME_MAX], enc[TLM_COBS_MAX(TLM_FRAME_MAX)], back[TLM_FRAME_MAX];
  for (size_t n = 0; n <= TLM_FRAME_MAX; n++) {
    for (int kind = 0; kind < 3; kind++) {
      for (size_t i = 0; i < n; i++) {
        uint8_t b = (uint8_t)lcg(&s);
        if (kind == 1) b = (lcg(&s) % 8u == 0u) ? 0u : b;
        if (kind == 2) b = (uint8_t)(b | 1u);
        in[i] = b;
      }
      const size_t en = tlm_cobs_encode(in, n, enc, sizeof enc);
      assert_true(en >= n + 1u && en <= TLM_COBS_MAX(n));
      assert_null(memchr(enc, 0, en));
      size_t dn = 0;
      assert_true(tlm_cobs_decode(enc, en, back, sizeof back, &dn));
      assert_int_equal(dn, n);
      assert_memory_equal(back, in, n);
    }
  }
  /* too small an output buffer is refused, not overrun */
  assert_int_equal(tlm_cobs_encode(in, 100u, enc, TLM_COBS_MAX(100u) - 1u), 0u);
}

static void test_cobs_decode_rejects(void **state)
{
  (void)state;
  uint8_t out[8];
  size_t n = 77u;
  assert_false(
      tlm_cobs_decode((const uint8_t *)"\x03\x11", 2u, out, sizeof out, &n)); /* short block */
  assert_false(tlm_cobs_decode((const uint8_t *)"\x03\x11\x00", 3u, out, sizeof out,
                               &n)); /* zero inside */
  assert_false(tlm_cobs_decode((const uint8_t *)"\x00", 1u, out, sizeof out, &n)); /* zero code */
  assert_false(
      tlm_cobs_decode((const uint8_t *)"\x05\x01\x02\x03\x04\x01", 6u, out, 4u, &n)); /* cap */
  assert_int_equal(n, 77u);
  assert_true(tlm_cobs_decode((const uint8_t *)"\x05\x01\x02\x03\x04", 5u, out, 4u, &n));
  assert_int_equal(n, 4u);
}

/* seal -> wire -> open gives back type, seq and payload; the wire form is
 * 00 01 ... 00 with no other zero; the CRC over a sealed frame is 0. */
static void test_frame_round_trip(void **state)
{
  (void)state;
  uint8_t raw[TLM_FRAME_MAX], wire[TLM_WIRE_MAX], back[TLM_FRAME_MAX];
  uint32_t s = 3u;
  for (size_t plen = 0; plen + TLM_FRAME_OVERHEAD <= TLM_FRAME_MAX; plen += 7u) {
    for (size_t i = 0; i < plen; i++) raw[TLM_FRAME_HEAD_BYTES + i] = (uint8_t)lcg(&s);
    const uint16_t seq = (uint16_t)lcg(&s);
    const size_t rn = tlm_frame_seal(raw, (uint8_t)TLM_FRAME_DATA, seq, plen);
    assert_int_equal(rn, plen + TLM_FRAME_OVERHEAD);
    assert_int_equal(tlm_crc16(TLM_CRC16_INIT, raw, rn), 0u);
    const size_t wn = tlm_frame_to_wire(raw, rn, wire, sizeof wire);
    assert_true(wn >= rn + 3u && wn <= tlm_wire_len_max((uint32_t)rn));
    assert_int_equal(wire[0], 0x00);
    assert_int_equal(wire[1], 0x01); /* the marker's COBS block: never a text byte */
    assert_int_equal(wire[wn - 1u], 0x00);
    assert_null(memchr(&wire[1], 0, wn - 2u));
    tlm_frame_view_t v;
    assert_int_equal(tlm_frame_open(&wire[1], wn - 2u, back, &v), TLM_FRAME_OK);
    assert_int_equal(v.type, TLM_FRAME_DATA);
    assert_int_equal(v.seq, seq);
    assert_int_equal(v.payload_len, plen);
    if (plen > 0u) assert_memory_equal(v.payload, &raw[TLM_FRAME_HEAD_BYTES], plen);
  }
}

/* Every single-bit error and every single-byte substitution of the wire bytes (between
 * the delimiters) is rejected: COBS structure, length, CRC or marker catches it. */
static void test_frame_damage_rejected(void **state)
{
  (void)state;
  uint8_t raw[TLM_FRAME_MAX], wire[TLM_WIRE_MAX], bad[TLM_WIRE_MAX], back[TLM_FRAME_MAX];
  uint32_t s = 11u;
  const size_t lens[] = {0u, 1u, 9u, 60u, 247u, 248u, 400u};
  for (size_t k = 0; k < sizeof lens / sizeof lens[0]; k++) {
    for (size_t i = 0; i < lens[k]; i++)
      raw[TLM_FRAME_HEAD_BYTES + i] = (uint8_t)(lcg(&s) % 3u);
    const size_t rn = tlm_frame_seal(raw, (uint8_t)TLM_FRAME_HEADER, (uint16_t)k, lens[k]);
    const size_t wn = tlm_frame_to_wire(raw, rn, wire, sizeof wire);
    const size_t cn = wn - 2u;
    tlm_frame_view_t v;
    for (size_t i = 0; i < cn; i++) {
      for (int b = 0; b < 8; b++) {
        memcpy(bad, &wire[1], cn);
        bad[i] ^= (uint8_t)(1u << b);
        assert_int_not_equal(tlm_frame_open(bad, cn, back, &v), TLM_FRAME_OK);
      }
      for (int x = 1; x < 256; x += 17) {
        memcpy(bad, &wire[1], cn);
        bad[i] = (uint8_t)(bad[i] ^ x);
        assert_int_not_equal(tlm_frame_open(bad, cn, back, &v), TLM_FRAME_OK);
      }
    }
    /* truncated anywhere */
    for (size_t cut = 0; cut < cn; cut++) {
      assert_int_not_equal(tlm_frame_open(&wire[1], cut, back, &v), TLM_FRAME_OK);
    }
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_crc_check_value),  cmocka_unit_test(test_crc_matches_python),
      cmocka_unit_test(test_crc_chaining),     cmocka_unit_test(test_cobs_examples),
      cmocka_unit_test(test_cobs_round_trip),  cmocka_unit_test(test_cobs_decode_rejects),
      cmocka_unit_test(test_frame_round_trip), cmocka_unit_test(test_frame_damage_rejected),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
