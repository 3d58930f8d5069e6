/* Number parsing for the command line: whole-token, locale-free, no allocation.
 *
 * Why not strtof/atoi: atoi has no end or overflow check (`set x abc` would become 0,
 * the Betaflight trap); strtof follows the C locale's decimal point, accepts nan, inf,
 * hex floats and leading white space, and newlib's implementation allocates through
 * Balloc/malloc. These functions take a token (pointer + length, need not be
 * NUL-terminated) and either accept all of it or change nothing.
 *
 * numparse_f32 grammar (the whole token must match):
 *     [+-] ( digits [ "." [digits] ] | "." digits ) [ ("e"|"E") [+-] digits ]
 *   - no white space anywhere, no "nan"/"inf", no hex, no thousands separators;
 *   - any number of digits; the result is the correctly rounded float (round to
 *     nearest, ties to even), exactly what a correct strtof returns;
 *   - results must be normal floats: a nonzero value whose magnitude is below FLT_MIN
 *     (1.17549435e-38) or that rounds above FLT_MAX is NUMPARSE_ERR_RANGE (no
 *     subnormals, no infinities); zero of either sign is accepted.
 * numparse_u32 grammar: digits only (no sign, no point, no exponent), value
 *   0..4294967295, leading zeros allowed.
 */
#ifndef NUMPARSE_H
#define NUMPARSE_H

#include <stddef.h>
#include <stdint.h>

typedef enum {
  NUMPARSE_OK = 0,
  NUMPARSE_ERR_EMPTY,  /* zero-length token */
  NUMPARSE_ERR_SYNTAX, /* not a number of the grammar (including trailing junk) */
  NUMPARSE_ERR_RANGE   /* a number, but not representable (overflow, underflow) */
} numparse_status_t;

/* On NUMPARSE_OK store the value in *out; otherwise leave *out unchanged. */
numparse_status_t numparse_f32(const char *s, size_t len, float *out);
numparse_status_t numparse_u32(const char *s, size_t len, uint32_t *out);

#endif /* NUMPARSE_H */
