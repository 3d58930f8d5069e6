/* Parameter-store flash: a small number of erasable sectors reserved for the firmware's
 * A/B parameter images. NOR semantics: erase sets every byte of a sector to 0xFF;
 * programming can only clear bits (1 -> 0). Erase and program are slow and, on a
 * single-bank part, stall every instruction fetch from flash while they run. */
#ifndef HAL_FLASH_H
#define HAL_FLASH_H

#include <stddef.h>
#include <stdint.h>

typedef enum {
  HAL_FLASH_OK = 0,
  HAL_FLASH_ERR_RANGE = -1,   /* sector or address outside the store */
  HAL_FLASH_ERR_WRITE = -2,   /* program failed (tried to set a 0 bit, or hardware error) */
  HAL_FLASH_ERR_POWER = -3    /* power was lost during the operation (host fault injection) */
} hal_flash_status_t;

typedef struct {
  uint32_t num_sectors;  /* sectors reserved for the parameter store */
  uint32_t sector_size;  /* bytes per sector */
} hal_flash_geometry_t;

void hal_flash_geometry(hal_flash_geometry_t *geo);
hal_flash_status_t hal_flash_erase(uint32_t sector);
hal_flash_status_t hal_flash_program(uint32_t sector, uint32_t offset, const void *data, size_t len);
hal_flash_status_t hal_flash_read(uint32_t sector, uint32_t offset, void *buf, size_t len);

#endif /* HAL_FLASH_H */
