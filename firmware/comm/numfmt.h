/* Number formatting for the command line, without printf (newlib's float printf is
 * large, needs _printf_float and allocates).
 *
 * numfmt_f32 prints the shortest decimal (1 to 9 significant digits) that numparse_f32
 * reads back to the identical float, so `get` followed by `set` of the printed text is
 * exact. Style: positional when the decimal exponent k of d.ddd x 10^k is in [-5, 9]
 * ("1489.9", "0.000012", "1000000000"), else scientific with the shortest exponent
 * ("1.5e-7", "3.4028235e38"). Zero prints "0" or "-0"; non-finite values (never held by
 * a parameter) print "nan", "inf", "-inf".
 */
#ifndef NUMFMT_H
#define NUMFMT_H

#include <stddef.h>
#include <stdint.h>

/* Longest output including the NUL: "-1.2345678e-38" is 15 bytes, positional
 * "-0.0000123456789" is 17. */
#define NUMFMT_F32_MAX 20u
#define NUMFMT_U32_MAX 11u

/* Write into buf (cap bytes, NUL-terminated); returns the length, or 0 (buf[0] = 0
 * when cap > 0) if cap is too small. */
size_t numfmt_f32(char *buf, size_t cap, float x);
size_t numfmt_u32(char *buf, size_t cap, uint32_t x);

#endif /* NUMFMT_H */
