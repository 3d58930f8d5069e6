/* The parameter flash of the emulator image (gyro-fw-qemu): QEMU's netduinoplus2 has
 * read-only flash and no flash interface, so sectors 1-2 and the FLASH registers are
 * modelled in SRAM (stm32f4_regs.h, STM32F4_QEMU_FLASH_MODEL) and the board's driver
 * (stm32f4_flash.c) runs unchanged against them. The controller is played from the
 * driver's busy-wait hook: the key sequence unlocks it; SER + STRT erases the selected
 * sector to 0xFF at once (the chip takes a few hundred ms, RM0090 / datasheet: the
 * model does not stall); programming is the driver's own store into the array. The
 * contents live as long as the emulator runs: a save survives `load` and `defaults`,
 * not a restart of QEMU (the store then reads the factory image again). The factory
 * image is the default part's calibration, as a calibrated part leaves the factory: the
 * emulated part is the default one (qemu_plant_setup.c), and without its calibration
 * it would say `calibrated no` and never give a valid rate. */
#include <stdint.h>

#include "stm32f4_core.h"
#include "stm32f4_qemu.h"
#include "stm32f4_regs.h"

#define QEMU_PARAM_BYTES (STM32F4_PARAM_NUM_SECTORS * STM32F4_PARAM_SECTOR_BYTES)

stm32f4_flash_t stm32f4_qemu_flash_regs = {.CR = FLASH_CR_LOCK}; /* RM0090 reset value */
volatile uint8_t stm32f4_qemu_param_flash[QEMU_PARAM_BYTES];

static void erase_sector(uint32_t store_sector)
{
  volatile uint8_t *p = stm32f4_qemu_param_flash + store_sector * STM32F4_PARAM_SECTOR_BYTES;
  for (uint32_t i = 0u; i < STM32F4_PARAM_SECTOR_BYTES; ++i) p[i] = 0xFFu;
}

void stm32f4_qemu_flash_init(void)
{
  /* A blank part (the .bss zeroes would read as programmed bits). */
  for (uint32_t s = 0u; s < STM32F4_PARAM_NUM_SECTORS; ++s) erase_sector(s);
  const uint32_t n = stm32f4_qemu_factory_store_len <= STM32F4_PARAM_SECTOR_BYTES
                         ? stm32f4_qemu_factory_store_len
                         : 0u; /* too long: a blank part, which says so */
  for (uint32_t i = 0u; i < n; ++i) stm32f4_qemu_param_flash[i] = stm32f4_qemu_factory_store[i];
  stm32f4_qemu_flash_regs.CR = FLASH_CR_LOCK;
}

CM4_RAMFUNC void stm32f4_qemu_flash_controller(void)
{
  stm32f4_flash_t *f = &stm32f4_qemu_flash_regs;
  /* The hook sees KEYR after the driver's two writes: KEY2 last means the sequence. */
  if (f->KEYR == FLASH_KEY2) {
    f->CR &= ~FLASH_CR_LOCK;
  }
  f->KEYR = 0u;
  const uint32_t cr = f->CR;
  if ((cr & (FLASH_CR_STRT | FLASH_CR_SER)) == (FLASH_CR_STRT | FLASH_CR_SER) &&
      (cr & FLASH_CR_LOCK) == 0u) {
    const uint32_t snb = (cr & FLASH_CR_SNB_MASK) >> FLASH_CR_SNB_POS;
    if (snb >= STM32F4_PARAM_SECTOR_FIRST &&
        snb < STM32F4_PARAM_SECTOR_FIRST + STM32F4_PARAM_NUM_SECTORS) {
      erase_sector(snb - STM32F4_PARAM_SECTOR_FIRST);
    }
    f->CR = cr & ~FLASH_CR_STRT;
  }
  f->SR = 0u; /* never busy, no error; write-1-to-clear of stale flags taken as done */
}
