#include "comm/bignum.h"

#include <string.h>

static void trim(bignum_t *b)
{
  while (b->used > 0u && b->limb[b->used - 1u] == 0u) {
    b->used--;
  }
}

void bignum_set_u32(bignum_t *b, uint32_t v)
{
  memset(b, 0, sizeof *b);
  b->limb[0] = v;
  b->used = (v != 0u) ? 1u : 0u;
}

void bignum_mul_add_small(bignum_t *b, uint32_t mul, uint32_t add)
{
  uint64_t carry = add;
  for (uint32_t i = 0; i < b->used; i++) {
    const uint64_t t = (uint64_t)b->limb[i] * mul + carry;
    b->limb[i] = (uint32_t)t;
    carry = t >> 32;
  }
  if (carry != 0u) {
    if (b->used >= BIGNUM_LIMBS) {
      b->overflow = true;
      return;
    }
    b->limb[b->used++] = (uint32_t)carry;
  }
  trim(b);
}

void bignum_mul_pow5(bignum_t *b, uint32_t e)
{
  /* 5^13 = 1220703125 is the largest power of 5 below 2^32 */
  while (e >= 13u && !b->overflow) {
    bignum_mul_add_small(b, 1220703125u, 0u);
    e -= 13u;
  }
  uint32_t p = 1u;
  while (e-- > 0u) {
    p *= 5u;
  }
  bignum_mul_add_small(b, p, 0u);
}

void bignum_shl(bignum_t *b, uint32_t bits)
{
  if (b->used == 0u) {
    return;
  }
  const uint32_t words = bits / 32u;
  const uint32_t sh = bits % 32u;
  const uint32_t extra = (sh != 0u && (b->limb[b->used - 1u] >> (32u - sh)) != 0u) ? 1u : 0u;
  if (words >= BIGNUM_LIMBS || b->used + words + extra > BIGNUM_LIMBS) {
    b->overflow = true;
    return;
  }
  const uint32_t n = b->used + words + extra;
  for (uint32_t i = n; i-- > 0u;) {
    uint32_t v = 0u;
    if (i >= words) {
      const uint32_t j = i - words;
      const uint32_t lo = (j < b->used) ? b->limb[j] : 0u;
      v = lo << sh;
      if (sh != 0u && j >= 1u && j - 1u < b->used) {
        v |= b->limb[j - 1u] >> (32u - sh);
      }
    }
    b->limb[i] = v;
  }
  b->used = n;
  trim(b);
}

uint32_t bignum_divmod_small(bignum_t *b, uint32_t d)
{
  uint64_t rem = 0u;
  for (uint32_t i = b->used; i-- > 0u;) {
    const uint64_t cur = (rem << 32) | b->limb[i];
    b->limb[i] = (uint32_t)(cur / d);
    rem = cur % d;
  }
  trim(b);
  return (uint32_t)rem;
}

int bignum_cmp(const bignum_t *a, const bignum_t *b)
{
  if (a->used != b->used) {
    return (a->used > b->used) ? 1 : -1;
  }
  for (uint32_t i = a->used; i-- > 0u;) {
    if (a->limb[i] != b->limb[i]) {
      return (a->limb[i] > b->limb[i]) ? 1 : -1;
    }
  }
  return 0;
}

bool bignum_is_zero(const bignum_t *b) { return b->used == 0u; }
