/* Exact decimal expansion of the float (m 2^e = m 5^-e 10^e for e < 0: at most 113
 * digits), rounded half-even to 1, 2, ... 9 digits until numparse_f32 gives the same
 * bits back. Nine digits always round-trip a float. */
#include "comm/numfmt.h"

#include <stdbool.h>
#include <string.h>

#include "comm/bignum.h"
#include "comm/numparse.h"

#define MAX_EXACT_DIGITS 128u

static size_t finish(char *buf, size_t cap, const char *s, size_t n)
{
  if (cap == 0u) {
    return 0u;
  }
  if (n + 1u > cap) {
    buf[0] = '\0';
    return 0u;
  }
  memcpy(buf, s, n);
  buf[n] = '\0';
  return n;
}

/* Exact digits of the positive finite float with bits b: dig[0..*nd), value = 0.dig x
 * 10^(*point). */
static void exact_digits(uint32_t b, uint8_t *dig, uint32_t *nd, int32_t *point)
{
  const uint32_t expf = (b >> 23) & 0xFFu;
  const uint32_t frac = b & 0x7FFFFFu;
  const uint32_t m = (expf == 0u) ? frac : (frac | 0x800000u);
  const int32_t e = (expf == 0u) ? -149 : (int32_t)expf - 150;
  bignum_t n;
  bignum_set_u32(&n, m);
  int32_t e10 = 0;
  if (e >= 0) {
    bignum_shl(&n, (uint32_t)e);
  } else {
    bignum_mul_pow5(&n, (uint32_t)(-e));
    e10 = e;
  }
  uint8_t rev[MAX_EXACT_DIGITS + 9u] = {0};
  uint32_t cnt = 0u;
  while (!bignum_is_zero(&n) && cnt < MAX_EXACT_DIGITS) {
    uint32_t r = bignum_divmod_small(&n, 1000000000u);
    for (int k = 0; k < 9; k++) {
      rev[cnt++] = (uint8_t)(r % 10u);
      r /= 10u;
    }
  }
  while (cnt > 1u && rev[cnt - 1u] == 0u) {
    cnt--; /* leading zeros of the top chunk */
  }
  for (uint32_t i = 0; i < cnt; i++) {
    dig[i] = rev[cnt - 1u - i];
  }
  *nd = cnt;
  *point = (int32_t)cnt + e10;
}

/* Round dig[0..nd) to p digits (half-even) into r; returns the digits kept (trailing
 * zeros stripped, >= 1) and adjusts *point on a carry out of the first digit. */
static uint32_t round_digits(const uint8_t *dig, uint32_t nd, uint32_t p, uint8_t *r,
                             int32_t *point)
{
  uint32_t n = (nd < p) ? nd : p;
  memcpy(r, dig, n);
  if (nd > p) {
    bool up = false;
    if (dig[p] > 5u) {
      up = true;
    } else if (dig[p] == 5u) {
      bool rest = false;
      for (uint32_t i = p + 1u; i < nd; i++) {
        rest = rest || (dig[i] != 0u);
      }
      up = rest || ((dig[p - 1u] & 1u) != 0u);
    }
    if (up) {
      uint32_t i = p;
      while (i > 0u && r[i - 1u] == 9u) {
        r[i - 1u] = 0u;
        i--;
      }
      if (i == 0u) {
        r[0] = 1u; /* 9.99 -> 10.0 */
        (*point)++;
      } else {
        r[i - 1u]++;
      }
    }
  }
  while (n > 1u && r[n - 1u] == 0u) {
    n--;
  }
  return n;
}

static size_t emit(char *out, bool neg, const uint8_t *r, uint32_t n, int32_t k)
{
  size_t o = 0u;
  if (neg) {
    out[o++] = '-';
  }
  if (k >= -5 && k <= 9) {
    if (k >= 0) {
      for (int32_t i = 0; i <= k; i++) {
        out[o++] = (char)('0' + (((uint32_t)i < n) ? r[i] : 0u));
      }
      if (n > (uint32_t)k + 1u) {
        out[o++] = '.';
        for (uint32_t i = (uint32_t)k + 1u; i < n; i++) {
          out[o++] = (char)('0' + r[i]);
        }
      }
    } else {
      out[o++] = '0';
      out[o++] = '.';
      for (int32_t i = 0; i < -k - 1; i++) {
        out[o++] = '0';
      }
      for (uint32_t i = 0; i < n; i++) {
        out[o++] = (char)('0' + r[i]);
      }
    }
    return o;
  }
  out[o++] = (char)('0' + r[0]);
  if (n > 1u) {
    out[o++] = '.';
    for (uint32_t i = 1; i < n; i++) {
      out[o++] = (char)('0' + r[i]);
    }
  }
  out[o++] = 'e';
  uint32_t ek = (uint32_t)((k < 0) ? -k : k);
  if (k < 0) {
    out[o++] = '-';
  }
  if (ek >= 10u) {
    out[o++] = (char)('0' + ek / 10u);
  }
  out[o++] = (char)('0' + ek % 10u);
  return o;
}

size_t numfmt_f32(char *buf, size_t cap, float x)
{
  uint32_t b;
  memcpy(&b, &x, sizeof b);
  const bool neg = (b >> 31) != 0u;
  const uint32_t mag = b & 0x7FFFFFFFu;
  if (mag > 0x7F800000u) {
    return finish(buf, cap, "nan", 3u);
  }
  if (mag == 0x7F800000u) {
    return neg ? finish(buf, cap, "-inf", 4u) : finish(buf, cap, "inf", 3u);
  }
  if (mag == 0u) {
    return neg ? finish(buf, cap, "-0", 2u) : finish(buf, cap, "0", 1u);
  }
  uint8_t dig[MAX_EXACT_DIGITS + 9u];
  uint32_t nd = 0u;
  int32_t point = 0;
  exact_digits(mag, dig, &nd, &point);
  char tmp[NUMFMT_F32_MAX + 8u];
  size_t len = 0u;
  for (uint32_t p = 1u; p <= 9u; p++) {
    uint8_t r[10];
    int32_t pt = point;
    const uint32_t n = round_digits(dig, nd, p, r, &pt);
    len = emit(tmp, neg, r, n, pt - 1);
    float back = 0.0f;
    uint32_t bb = 0u;
    if (numparse_f32(tmp, len, &back) == NUMPARSE_OK) {
      memcpy(&bb, &back, sizeof bb);
      if (bb == b) {
        break;
      }
    }
  }
  return finish(buf, cap, tmp, len);
}

size_t numfmt_u32(char *buf, size_t cap, uint32_t x)
{
  char rev[NUMFMT_U32_MAX];
  size_t n = 0u;
  do {
    rev[n++] = (char)('0' + x % 10u);
    x /= 10u;
  } while (x != 0u);
  char tmp[NUMFMT_U32_MAX];
  for (size_t i = 0; i < n; i++) {
    tmp[i] = rev[n - 1u - i];
  }
  return finish(buf, cap, tmp, n);
}
