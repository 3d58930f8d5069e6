/* STM32F4 memory placement on top of the Cortex-M4 core (cm4_core.h). */
#ifndef STM32F4_CORE_H
#define STM32F4_CORE_H

#include "cm4_core.h"
#include "stm32f4_regs.h"

/* Large state that only the CPU touches (never DMA, never code) may live in the 64 KB
 * core-coupled RAM, which the DMA streams cannot reach and which has no bus contention. */
#define STM32F4_CCM_BSS __attribute__((section(".ccm_bss")))

#endif /* STM32F4_CORE_H */
