/* CRC-32 judged against zlib's crc32() (an independent implementation of the same
 * IEEE 802.3 CRC) and the published check value. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>
#include <zlib.h>

#include "params/crc32.h"

static void test_check_value(void **state)
{
  (void)state;
  /* the catalogued check value of CRC-32/ISO-HDLC */
  assert_int_equal(crc32_update(0u, "123456789", 9u), 0xCBF43926u);
  assert_int_equal(crc32_update(0u, "", 0u), 0u);
}

static void test_matches_zlib(void **state)
{
  (void)state;
  static uint8_t buf[4096];
  uint32_t s = 1u;
  for (size_t i = 0; i < sizeof buf; i++) {
    s = s * 1103515245u + 12345u;
    buf[i] = (uint8_t)(s >> 16);
  }
  for (size_t len = 0; len <= 600u; len++) {
    const size_t off = (len * 7u) % 64u;
    assert_int_equal(crc32_update(0u, buf + off, len),
                     (uint32_t)crc32(0uL, buf + off, (uInt)len));
  }
  assert_int_equal(crc32_update(0u, buf, sizeof buf), (uint32_t)crc32(0uL, buf, sizeof buf));
  /* all-0xFF (erased flash) and all-zero runs */
  uint8_t ff[300], zero[300];
  memset(ff, 0xFF, sizeof ff);
  memset(zero, 0, sizeof zero);
  assert_int_equal(crc32_update(0u, ff, sizeof ff), (uint32_t)crc32(0uL, ff, sizeof ff));
  assert_int_equal(crc32_update(0u, zero, sizeof zero), (uint32_t)crc32(0uL, zero, sizeof zero));
}

/* Chaining over any split gives the CRC of the whole, as with zlib. */
static void test_chaining(void **state)
{
  (void)state;
  const char *msg = "the drive-mode phase is a thermometer of the structure itself";
  const size_t n = strlen(msg);
  const uint32_t whole = (uint32_t)crc32(0uL, (const Bytef *)msg, (uInt)n);
  for (size_t cut = 0; cut <= n; cut++) {
    const uint32_t c = crc32_update(crc32_update(0u, msg, cut), msg + cut, n - cut);
    assert_int_equal(c, whole);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_check_value),
      cmocka_unit_test(test_matches_zlib),
      cmocka_unit_test(test_chaining),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
