/* CRC-32 of IEEE 802.3 (the zlib / PNG / Ethernet CRC): reflected, polynomial
 * 0x04C11DB7 (0xEDB88320 reflected), initial value 0xFFFFFFFF, final XOR 0xFFFFFFFF.
 * Check value: crc32_update(0, "123456789", 9) == 0xCBF43926.
 *
 * Same calling convention as zlib's crc32(): start with 0 and chain calls,
 *     c = crc32_update(0, a, na); c = crc32_update(c, b, nb);
 * gives the CRC of the concatenation (the pre/post inversion is done inside).
 * A 16-entry nibble table (64 bytes of flash) instead of 256 entries: the parameter
 * store checksums a few hundred bytes in the background loop, speed is not the point. */
#ifndef CRC32_H
#define CRC32_H

#include <stddef.h>
#include <stdint.h>

uint32_t crc32_update(uint32_t crc, const void *data, size_t len);

#endif /* CRC32_H */
