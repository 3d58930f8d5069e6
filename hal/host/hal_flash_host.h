/* Host implementation of hal_flash.h: test and simulator controls.
 *
 * Model: NOR flash as on the STM32F4 (RM0090 3.5): erase sets a whole sector to 0xFF;
 * program can only clear bits (1 -> 0); a program that would have to set a 0 bit back
 * to 1 is refused whole (HAL_FLASH_ERR_WRITE, nothing written).
 *
 * Programming unit (hal_flash_geometry's program_bytes): 4 by default, the STM32F4's
 * word, with the NOR rules above (any byte range may be programmed, again and again).
 * A unit of 8 or more models ECC flash (the STM32G4's 64-bit double word): offset and
 * length must be whole units (else HAL_FLASH_ERR_RANGE, nothing written), and a unit
 * that is not fully erased cannot be programmed again (HAL_FLASH_ERR_WRITE, nothing
 * written).
 *
 * Busy time is not slept but added to a simulated clock, so tests can reason about how
 * long the flash would have stalled the CPU without being timing-dependent. Defaults are
 * the STM32F405 datasheet figures for x32 parallelism: sector (16 KB) erase 250 ms
 * typical, 500 ms maximum; word (32-bit) program 16 us typical. A program of n bytes
 * costs ceil(n / 4) words.
 *
 * Backing store: a file (created and filled with 0xFF if missing or of the wrong size;
 * every erase/program writes through) or, with no path, memory only.
 *
 * Fault injection:
 *   - power cut after N more programmed bytes: the program call that crosses the limit
 *     writes the bytes before it, then half of the interrupted byte (its low nibble is
 *     programmed, the high nibble keeps its old bits: a torn cell), and returns
 *     HAL_FLASH_ERR_POWER; every later erase/program returns HAL_FLASH_ERR_POWER and
 *     changes nothing until hal_flash_host_power_restore() (the "reboot").
 *   - power cut during the next erase: the sector is left with only its first K bytes
 *     erased (the rest keeps the old content), the erase returns HAL_FLASH_ERR_POWER.
 *   - bit flip at (sector, offset, bit): the stored bit is inverted directly (retention
 *     loss or disturb), bypassing the NOR rules.
 *
 * Not thread-safe: the HAL has one flash, so this stub is a single instance.
 */
#ifndef HAL_FLASH_HOST_H
#define HAL_FLASH_HOST_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

/* Upper bound of the simulated store (sectors * sector_size). */
#define HAL_FLASH_HOST_MAX_BYTES (256u * 1024u)

typedef struct {
  uint32_t num_sectors;     /* 0 -> 2 */
  uint32_t sector_size;     /* bytes, multiple of 4; 0 -> 16384 (STM32F4 sectors 0-3) */
  const char *path;         /* backing file, or NULL for memory only */
  uint32_t erase_us;        /* busy time of one sector erase; 0 -> 250000 */
  uint32_t program_word_us; /* busy time per 32-bit word programmed; 0 -> 16 */
  uint32_t program_bytes;   /* programming unit, power of two <= sector_size; 0 -> 4 */
} hal_flash_host_cfg_t;

typedef struct {
  uint64_t busy_us;          /* simulated clock: total erase + program busy time */
  uint32_t longest_stall_us; /* longest single erase/program call */
  uint32_t erases;           /* erase calls that changed the array */
  uint32_t programmed_bytes; /* bytes written by program calls */
} hal_flash_host_stats_t;

/* (Re)configure and reset the stub: geometry, backing file, timing; clears faults and
 * statistics. Memory-only content starts erased (0xFF). Returns 0, or -1 for a bad
 * geometry or a file that cannot be opened (the stub is then unusable until a good
 * configuration is given). cfg == NULL: all defaults, memory only. */
int hal_flash_host_configure(const hal_flash_host_cfg_t *cfg);

/* Close the backing file (content already written through). */
void hal_flash_host_close(void);

/* Faults. */
void hal_flash_host_power_cut_after(uint32_t program_bytes);
void hal_flash_host_power_cut_in_erase(uint32_t erased_bytes);
void hal_flash_host_power_restore(void); /* clears armed and active power faults */
bool hal_flash_host_power_is_down(void);
int hal_flash_host_flip_bit(uint32_t sector, uint32_t offset, uint32_t bit);

/* Statistics and the simulated clock. */
void hal_flash_host_stats(hal_flash_host_stats_t *st);
void hal_flash_host_stats_clear(void);

/* Direct view of the array for tests (read-only). */
const uint8_t *hal_flash_host_data(void);

#endif /* HAL_FLASH_HOST_H */
