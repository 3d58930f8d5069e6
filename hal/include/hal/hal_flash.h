/* Parameter-store flash: a small number of erasable sectors reserved for the firmware's
 * A/B parameter images. NOR semantics: erase sets every byte of a sector to 0xFF;
 * programming can only clear bits (1 -> 0). Erase and program are slow and, on a
 * single-bank part, stall every instruction fetch from flash while they run.
 *
 * Programming unit: flash with ECC programs whole units once between erases (an
 * STM32G4 a 64-bit double word, an STM32H7 a 256-bit flash word); plain NOR (the
 * STM32F4) takes bytes but programs a 32-bit word at a time at 2.7-3.6 V. The geometry
 * names the unit, and a user (the parameter store) programs only whole units at
 * offsets that are multiples of it, and never the same unit twice. */
#ifndef HAL_FLASH_H
#define HAL_FLASH_H

#include <stddef.h>
#include <stdint.h>

typedef enum {
  HAL_FLASH_OK = 0,
  HAL_FLASH_ERR_RANGE = -1, /* sector or address outside the store */
  HAL_FLASH_ERR_WRITE = -2, /* program failed (tried to set a 0 bit, or hardware error) */
  HAL_FLASH_ERR_POWER = -3  /* power was lost during the operation (host fault injection) */
} hal_flash_status_t;

typedef struct {
  uint32_t num_sectors;   /* sectors reserved for the parameter store */
  uint32_t sector_size;   /* bytes per sector */
  uint32_t program_bytes; /* programming unit in bytes: a power of two, 1..sector_size */
} hal_flash_geometry_t;

void hal_flash_geometry(hal_flash_geometry_t *geo);
hal_flash_status_t hal_flash_erase(uint32_t sector);
hal_flash_status_t hal_flash_program(uint32_t sector, uint32_t offset, const void *data,
                                     size_t len);
hal_flash_status_t hal_flash_read(uint32_t sector, uint32_t offset, void *buf, size_t len);

#endif /* HAL_FLASH_H */
