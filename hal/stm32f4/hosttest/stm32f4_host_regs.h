/* Fake register file for host unit tests of the board drivers: one RAM instance of each
 * peripheral, a RAM "flash" for the parameter sectors, and the hook through which a test
 * plays the hardware inside the drivers' wait loops. */
#ifndef STM32F4_HOST_REGS_H
#define STM32F4_HOST_REGS_H

#include "stm32f4_regs.h"

/* Zero every fake register (the core's too: cm4_host_reset), fill the parameter flash with 0xFF (erased), apply the
 * reset values the drivers rely on (FLASH_CR.LOCK), clear the hooks. */
void stm32f4_host_reset(void);

/* Direct access to the RAM flash (STM32F4_PARAM_NUM_SECTORS * SECTOR_BYTES bytes). */
uint8_t *stm32f4_host_param_flash(void);

#endif /* STM32F4_HOST_REGS_H */
