/* Decimal to float, correctly rounded, in two steps:
 *   1. an approximation from the first 19 significant digits in double (within a few
 *      double ulps, so within one float ulp);
 *   2. exact correction: compare the decimal value D * 10^E with the midpoints between
 *      the candidate float and its neighbours using big integers, and step one ulp at a
 *      time (ties to even).
 * Digits beyond the 120th significant one only matter as a "sticky" nonzero flag: a
 * float midpoint >= 2^-127 has at most 113 significant decimal digits ((2m+1) 5^150 has
 * fewer than 25*0.302 + 150*0.699 = 112.4), so 120 kept digits decide every comparison
 * exactly. Sizes: |D| < 10^120 (399 bits), the worst compare needs about 400 bits. */
#include "comm/numparse.h"

#include <stdbool.h>
#include <string.h>

#include "comm/bignum.h"

#define MAX_DIGITS 120u
#define EXP_SATURATE 100000
#define FLT_MIN_BITS 0x00800000u
#define FLT_MAX_BITS 0x7F7FFFFFu
#define FLT_INF_BITS 0x7F800000u

typedef struct {
  uint8_t d[MAX_DIGITS]; /* significant digits, leading zeros stripped */
  uint32_t n;            /* digits kept */
  int32_t e10;           /* value = D * 10^e10 (+ something below one unit if sticky) */
  bool sticky;           /* a nonzero digit was dropped beyond MAX_DIGITS */
} decimal_t;

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

/* Parse the grammar of numparse.h into *dec and the sign; false on a syntax error. */
static bool scan(const char *s, size_t len, decimal_t *dec, bool *neg)
{
  size_t i = 0;
  memset(dec, 0, sizeof *dec);
  *neg = false;
  if (i < len && (s[i] == '+' || s[i] == '-')) {
    *neg = (s[i] == '-');
    i++;
  }
  uint32_t mant_digits = 0u;
  bool frac = false;
  for (; i < len; i++) {
    const char c = s[i];
    if (c == '.' && !frac) {
      frac = true;
      continue;
    }
    if (!is_digit(c)) {
      break;
    }
    mant_digits++;
    const uint8_t d = (uint8_t)(c - '0');
    if (dec->n == 0u && d == 0u) {
      if (frac && dec->e10 > -EXP_SATURATE) {
        dec->e10--; /* leading zero after the point still shifts the value */
      }
    } else if (dec->n < MAX_DIGITS) {
      dec->d[dec->n++] = d;
      if (frac) {
        dec->e10--;
      }
    } else {
      dec->sticky = dec->sticky || (d != 0u);
      if (!frac && dec->e10 < EXP_SATURATE) {
        dec->e10++;
      }
    }
  }
  if (mant_digits == 0u) {
    return false;
  }
  if (i < len && (s[i] == 'e' || s[i] == 'E')) {
    i++;
    bool eneg = false;
    if (i < len && (s[i] == '+' || s[i] == '-')) {
      eneg = (s[i] == '-');
      i++;
    }
    int32_t ev = 0;
    uint32_t edigits = 0u;
    for (; i < len && is_digit(s[i]); i++) {
      edigits++;
      if (ev < EXP_SATURATE) {
        ev = ev * 10 + (int32_t)(s[i] - '0');
      }
    }
    if (edigits == 0u) {
      return false;
    }
    dec->e10 += eneg ? -ev : ev;
  }
  if (i != len) {
    return false;
  }
  /* trailing zeros carry no information unless digits were dropped after them */
  while (!dec->sticky && dec->n > 0u && dec->d[dec->n - 1u] == 0u) {
    dec->n--;
    dec->e10++;
  }
  return true;
}

static void digits_to_bignum(const decimal_t *dec, bignum_t *b)
{
  bignum_set_u32(b, 0u);
  uint32_t i = 0;
  while (i < dec->n) {
    uint32_t chunk = 0u;
    uint32_t mul = 1u;
    for (uint32_t k = 0; k < 9u && i < dec->n; k++, i++) {
      chunk = chunk * 10u + dec->d[i];
      mul *= 10u;
    }
    bignum_mul_add_small(b, mul, chunk);
  }
}

/* Compare the decimal value with k * 2^q: -1, 0, +1, or 2 if the big integers
 * overflowed (cannot happen within the range pre-check; treated as an error). */
static int cmp_value(const bignum_t *digits, const decimal_t *dec, uint32_t k, int32_t q)
{
  bignum_t lhs = *digits;
  bignum_t rhs;
  bignum_set_u32(&rhs, k);
  /* D 10^E = D 5^E 2^E: put the power of 5 and the net power of 2 on one side each */
  if (dec->e10 >= 0) {
    bignum_mul_pow5(&lhs, (uint32_t)dec->e10);
  } else {
    bignum_mul_pow5(&rhs, (uint32_t)(-dec->e10));
  }
  const int32_t shift = dec->e10 - q;
  if (shift >= 0) {
    bignum_shl(&lhs, (uint32_t)shift);
  } else {
    bignum_shl(&rhs, (uint32_t)(-shift));
  }
  if (lhs.overflow || rhs.overflow) {
    return 2;
  }
  const int c = bignum_cmp(&lhs, &rhs);
  return (c == 0 && dec->sticky) ? 1 : c;
}

/* Midpoint between the positive floats with bits b and b + 1, as k * 2^q. */
static void midpoint(uint32_t b, uint32_t *k, int32_t *q)
{
  const uint32_t expf = b >> 23;
  const uint32_t frac = b & 0x7FFFFFu;
  const uint32_t m = (expf == 0u) ? frac : (frac | 0x800000u);
  const int32_t e = (expf == 0u) ? -149 : (int32_t)expf - 150;
  *k = 2u * m + 1u;
  *q = e - 1;
}

static uint32_t approx_bits(const decimal_t *dec)
{
  static const double k_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  uint64_t u = 0u;
  uint32_t k = 0u;
  for (; k < dec->n && k < 19u; k++) {
    u = u * 10u + dec->d[k];
  }
  int32_t p = dec->e10 + (int32_t)(dec->n - k);
  double v = (double)u;
  for (; p > 22; p -= 22) {
    v *= 1e22;
  }
  for (; p < -22; p += 22) {
    v /= 1e22;
  }
  v = (p >= 0) ? v * k_pow10[p] : v / k_pow10[-p];
  if (v >= 3.4028234663852886e38) {
    return FLT_MAX_BITS;
  }
  if (v < 1.1754943508222875e-38) {
    return FLT_MIN_BITS;
  }
  const float f = (float)v;
  uint32_t b;
  memcpy(&b, &f, sizeof b);
  return b;
}

numparse_status_t numparse_f32(const char *s, size_t len, float *out)
{
  if (s == NULL || len == 0u) {
    return NUMPARSE_ERR_EMPTY;
  }
  decimal_t dec;
  bool neg = false;
  if (!scan(s, len, &dec, &neg)) {
    return NUMPARSE_ERR_SYNTAX;
  }
  uint32_t b = 0u;
  if (dec.n > 0u) {
    /* D has n digits: 10^(n-1+E) <= value < 10^(n+E); FLT_MAX < 1e39, FLT_MIN > 1e-38 */
    const int32_t top = (int32_t)dec.n + dec.e10;
    if (top - 1 >= 39 || top <= -38) {
      return NUMPARSE_ERR_RANGE;
    }
    bignum_t digits;
    digits_to_bignum(&dec, &digits);
    b = approx_bits(&dec);
    bool settled = false;
    for (int it = 0; it < 6 && !settled; it++) {
      uint32_t k;
      int32_t q;
      midpoint(b, &k, &q);
      int c = cmp_value(&digits, &dec, k, q);
      if (c == 2) {
        return NUMPARSE_ERR_RANGE;
      }
      if (c > 0 || (c == 0 && (b & 1u) != 0u)) {
        b++; /* above the upper midpoint (or on it, towards the even neighbour) */
        if (b >= FLT_INF_BITS) {
          return NUMPARSE_ERR_RANGE;
        }
        continue;
      }
      midpoint(b - 1u, &k, &q);
      c = cmp_value(&digits, &dec, k, q);
      if (c == 2) {
        return NUMPARSE_ERR_RANGE;
      }
      if (c < 0 || (c == 0 && (b & 1u) != 0u)) {
        b--;
        if (b < FLT_MIN_BITS) {
          return NUMPARSE_ERR_RANGE; /* rounds to a subnormal */
        }
        continue;
      }
      settled = true;
    }
    if (!settled) {
      return NUMPARSE_ERR_RANGE; /* not reached: the approximation is within one ulp */
    }
    if (b == FLT_MIN_BITS && cmp_value(&digits, &dec, 1u, -126) < 0) {
      return NUMPARSE_ERR_RANGE; /* below FLT_MIN, rounded up to it */
    }
  }
  if (neg) {
    b |= 0x80000000u;
  }
  memcpy(out, &b, sizeof *out);
  return NUMPARSE_OK;
}

numparse_status_t numparse_u32(const char *s, size_t len, uint32_t *out)
{
  if (s == NULL || len == 0u) {
    return NUMPARSE_ERR_EMPTY;
  }
  uint32_t v = 0u;
  bool overflow = false;
  for (size_t i = 0; i < len; i++) {
    if (!is_digit(s[i])) {
      return NUMPARSE_ERR_SYNTAX;
    }
    const uint32_t d = (uint32_t)(s[i] - '0');
    if (v > (UINT32_MAX - d) / 10u) {
      overflow = true;
    } else {
      v = v * 10u + d;
    }
  }
  if (overflow) {
    return NUMPARSE_ERR_RANGE;
  }
  *out = v;
  return NUMPARSE_OK;
}
