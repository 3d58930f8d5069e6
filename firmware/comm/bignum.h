/* Fixed-size unsigned big integers for exact decimal <-> binary conversion (numparse,
 * numfmt). Little-endian 32-bit limbs, no allocation. An operation whose result does
 * not fit sets `overflow` and leaves the value meaningless; callers check it once at
 * the end. 512 bits cover the worst case of a float conversion with 120 significant
 * digits (about 400 bits, see numparse.c). */
#ifndef BIGNUM_H
#define BIGNUM_H

#include <stdbool.h>
#include <stdint.h>

#define BIGNUM_LIMBS 16u

typedef struct {
  uint32_t limb[BIGNUM_LIMBS];
  uint32_t used; /* limbs in use; limb[used-1] != 0 unless used == 0 */
  bool overflow;
} bignum_t;

void bignum_set_u32(bignum_t *b, uint32_t v);
void bignum_mul_add_small(bignum_t *b, uint32_t mul, uint32_t add); /* b = b*mul + add */
void bignum_mul_pow5(bignum_t *b, uint32_t e);                      /* b *= 5^e */
void bignum_shl(bignum_t *b, uint32_t bits);                        /* b <<= bits */
uint32_t bignum_divmod_small(bignum_t *b, uint32_t d); /* b /= d, returns b % d; d > 0 */
int bignum_cmp(const bignum_t *a, const bignum_t *b);  /* -1, 0, +1 */
bool bignum_is_zero(const bignum_t *b);

#endif /* BIGNUM_H */
