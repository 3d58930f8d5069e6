/* Parameter-store flash behind hal_flash.h: sectors 1 and 2 of the STM32F405 (16 KB
 * each at 0x08004000 and 0x08008000), store sector 0 = flash sector 1.
 *
 * Sequence (RM0090 §3.6): unlock with KEY1 then KEY2, wait for BSY = 0, clear stale
 * error flags, select the operation (SER + SNB for a sector erase, PG for programming),
 * PSIZE x32 for the 2.7..3.6 V supply (x8 for unaligned bytes), start, wait for BSY = 0,
 * check the error flags, clear the operation bits and lock again. The data cache is
 * reset afterwards so that reads see the new contents.
 *
 * A single-bank F405 stalls every fetch from flash while BSY is set, so these functions
 * run from SRAM (.ramfunc) and call nothing in flash: interrupts whose vectors and
 * handlers are in SRAM (the sample ISR) keep running during a 16 KB erase (RM0090:
 * typically a few hundred ms). The wait loop reloads the watchdog. */
#include "hal/hal_flash.h"

#include "stm32f4_core.h"
#include "stm32f4_regs.h"

/* Bounded wait: ~10 cycles per turn at 168 MHz is about 3 s, several times the worst
 * sector-erase time in the STM32F405 datasheet. */
#define FLASH_POLL_LIMIT 50000000u

static CM4_RAMFUNC int flash_wait_idle(void)
{
  for (uint32_t i = 0u; i < FLASH_POLL_LIMIT; ++i) {
    STM32F4_POLL_HOOK();
    if ((FLASH_R->SR & FLASH_SR_BSY) == 0u) return 1;
    IWDG->KR = IWDG_KEY_RELOAD;
  }
  return 0;
}

static CM4_RAMFUNC int flash_unlock(void)
{
  if ((FLASH_R->CR & FLASH_CR_LOCK) != 0u) {
    FLASH_R->KEYR = FLASH_KEY1;
    FLASH_R->KEYR = FLASH_KEY2;
  }
  /* LOCK clears as soon as the keys are accepted; a wrong sequence keeps the controller
   * locked until the next reset, which the bounded wait turns into an error. */
  for (uint32_t i = 0u; i < 1000u && (FLASH_R->CR & FLASH_CR_LOCK) != 0u; ++i) {
    STM32F4_POLL_HOOK();
  }
  return (FLASH_R->CR & FLASH_CR_LOCK) == 0u;
}

static CM4_RAMFUNC void flash_lock_and_flush(void)
{
  FLASH_R->CR = FLASH_CR_LOCK;
  const uint32_t acr = FLASH_R->ACR;
  if ((acr & FLASH_ACR_DCEN) != 0u) {
    /* The data cache may hold the old contents; it can only be reset while disabled. */
    FLASH_R->ACR = acr & ~FLASH_ACR_DCEN;
    FLASH_R->ACR = (acr & ~FLASH_ACR_DCEN) | FLASH_ACR_DCRST;
    FLASH_R->ACR = acr;
  }
}

static CM4_RAMFUNC int flash_start(void)
{
  if (!flash_unlock()) return 0;
  if (!flash_wait_idle()) return 0;
  FLASH_R->SR = FLASH_SR_ERRORS | FLASH_SR_EOP; /* write 1 to clear */
  return 1;
}

void hal_flash_geometry(hal_flash_geometry_t *geo)
{
  if (geo == 0) return;
  geo->num_sectors = STM32F4_PARAM_NUM_SECTORS;
  geo->sector_size = STM32F4_PARAM_SECTOR_BYTES;
  /* The driver takes any byte range, but a whole aligned word is one x32 program
   * operation (RM0090 3.5.2): the store writes words. */
  geo->program_bytes = 4u;
}

CM4_RAMFUNC hal_flash_status_t hal_flash_erase(uint32_t sector)
{
  if (sector >= STM32F4_PARAM_NUM_SECTORS) return HAL_FLASH_ERR_RANGE;
  hal_flash_status_t st = HAL_FLASH_OK;
  if (!flash_start()) {
    st = HAL_FLASH_ERR_WRITE;
  } else {
    const uint32_t snb = STM32F4_PARAM_SECTOR_FIRST + sector;
    FLASH_R->CR = FLASH_CR_PSIZE_X32 | FLASH_CR_SER | (snb << FLASH_CR_SNB_POS);
    FLASH_R->CR |= FLASH_CR_STRT;
    if (!flash_wait_idle() || (FLASH_R->SR & FLASH_SR_ERRORS) != 0u) {
      st = HAL_FLASH_ERR_WRITE;
    }
  }
  flash_lock_and_flush();
  if (st == HAL_FLASH_OK) {
    const volatile uint8_t *p = STM32F4_PARAM_FLASH + sector * STM32F4_PARAM_SECTOR_BYTES;
    for (uint32_t i = 0u; i < STM32F4_PARAM_SECTOR_BYTES; ++i) {
      if (p[i] != 0xFFu) return HAL_FLASH_ERR_WRITE;
    }
  }
  return st;
}

static int range_ok(uint32_t sector, uint32_t offset, size_t len)
{
  return sector < STM32F4_PARAM_NUM_SECTORS && offset <= STM32F4_PARAM_SECTOR_BYTES &&
         len <= (size_t)(STM32F4_PARAM_SECTOR_BYTES - offset);
}

CM4_RAMFUNC hal_flash_status_t hal_flash_program(uint32_t sector, uint32_t offset,
                                                 const void *data, size_t len)
{
  if (!range_ok(sector, offset, len) || (data == 0 && len > 0u)) return HAL_FLASH_ERR_RANGE;
  volatile uint8_t *dst = STM32F4_PARAM_FLASH + sector * STM32F4_PARAM_SECTOR_BYTES + offset;
  const uint8_t *src = (const uint8_t *)data;
  /* NOR: programming can only clear bits. Refuse before touching anything. */
  for (size_t i = 0u; i < len; ++i) {
    if ((uint8_t)(dst[i] & src[i]) != src[i]) return HAL_FLASH_ERR_WRITE;
  }
  if (len == 0u) return HAL_FLASH_OK;

  hal_flash_status_t st = HAL_FLASH_OK;
  if (!flash_start()) {
    st = HAL_FLASH_ERR_WRITE;
  } else {
    size_t i = 0u;
    while (i < len && st == HAL_FLASH_OK) {
      const uintptr_t addr = (uintptr_t)(dst + i);
      if ((addr & 3u) == 0u && len - i >= 4u) {
        const uint32_t word = (uint32_t)src[i] | ((uint32_t)src[i + 1u] << 8) |
                              ((uint32_t)src[i + 2u] << 16) | ((uint32_t)src[i + 3u] << 24);
        volatile uint32_t *w = (volatile uint32_t *)addr;
        if (*w != word) {
          FLASH_R->CR = FLASH_CR_PSIZE_X32 | FLASH_CR_PG;
          *w = word;
        }
        i += 4u;
      } else {
        if (dst[i] != src[i]) {
          FLASH_R->CR = FLASH_CR_PSIZE_X8 | FLASH_CR_PG;
          dst[i] = src[i];
        }
        i += 1u;
      }
      if (!flash_wait_idle() || (FLASH_R->SR & FLASH_SR_ERRORS) != 0u) {
        st = HAL_FLASH_ERR_WRITE;
      }
    }
  }
  flash_lock_and_flush();
  if (st == HAL_FLASH_OK) {
    for (size_t i = 0u; i < len; ++i) {
      if (dst[i] != src[i]) return HAL_FLASH_ERR_WRITE;
    }
  }
  return st;
}

hal_flash_status_t hal_flash_read(uint32_t sector, uint32_t offset, void *buf, size_t len)
{
  if (!range_ok(sector, offset, len) || (buf == 0 && len > 0u)) return HAL_FLASH_ERR_RANGE;
  const volatile uint8_t *src = STM32F4_PARAM_FLASH + sector * STM32F4_PARAM_SECTOR_BYTES +
                                offset;
  uint8_t *out = (uint8_t *)buf;
  for (size_t i = 0u; i < len; ++i) {
    out[i] = src[i];
  }
  return HAL_FLASH_OK;
}
