/* numparse/numfmt against glibc: an accepted token must be exactly what strtof reads;
 * a token strtof reads whole (in our character set) must not be a syntax error; every
 * value printed by numfmt must read back to the same bits. */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "comm/numfmt.h"
#include "comm/numparse.h"
#include "fuzz_check.h"

#define MAX_TOKEN 512

static uint32_t bits_of(float f)
{
  uint32_t u;
  memcpy(&u, &f, 4);
  return u;
}

static void check_format(float x)
{
  char buf[NUMFMT_F32_MAX];
  const size_t n = numfmt_f32(buf, sizeof buf, x);
  FUZZ_CHECK(n > 0 && n < sizeof buf && strlen(buf) == n);
  if (isnormal(x) || x == 0.0f) {
    float back = 0.0f;
    FUZZ_CHECK(numparse_f32(buf, n, &back) == NUMPARSE_OK);
    FUZZ_CHECK(bits_of(back) == bits_of(x));
    FUZZ_CHECK(bits_of(strtof(buf, NULL)) == bits_of(x));
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  if (size >= 4) {
    float x;
    memcpy(&x, data, 4);
    check_format(x);
  }
  if (size > MAX_TOKEN) {
    return 0;
  }
  char tok[MAX_TOKEN + 1];
  memcpy(tok, data, size);
  tok[size] = '\0';
  const char *s = (const char *)data;

  float v = 12345.0f;
  const numparse_status_t st = numparse_f32(s, size, &v);
  bool charset = size > 0;
  for (size_t i = 0; i < size; i++) {
    charset = charset && strchr("0123456789.eE+-", tok[i]) != NULL && tok[i] != '\0';
  }
  char *end = NULL;
  errno = 0;
  const float ref = strtof(tok, &end);
  const bool whole = size > 0 && end == tok + size;
  const bool ref_range = errno == ERANGE || isinf(ref) || (ref != 0.0f && fabsf(ref) < FLT_MIN);
  if (st == NUMPARSE_OK) {
    FUZZ_CHECK(whole && !ref_range);
    FUZZ_CHECK(bits_of(v) == bits_of(ref));
    check_format(v);
  } else {
    FUZZ_CHECK(bits_of(v) == bits_of(12345.0f)); /* untouched on error */
    if (charset && whole) {
      FUZZ_CHECK(st == NUMPARSE_ERR_RANGE);
      FUZZ_CHECK(ref_range || bits_of(ref) == 0x00800000u); /* below FLT_MIN, rounded up */
    }
  }

  uint32_t u = 7u;
  const numparse_status_t su = numparse_u32(s, size, &u);
  bool digits = size > 0;
  for (size_t i = 0; i < size; i++) {
    digits = digits && tok[i] >= '0' && tok[i] <= '9';
  }
  if (su == NUMPARSE_OK) {
    FUZZ_CHECK(digits);
    FUZZ_CHECK((unsigned long long)u == strtoull(tok, NULL, 10));
  } else {
    FUZZ_CHECK(u == 7u);
    if (digits) {
      FUZZ_CHECK(su == NUMPARSE_ERR_RANGE);
    }
  }
  return 0;
}
