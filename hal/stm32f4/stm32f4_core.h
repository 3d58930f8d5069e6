/* Cortex-M4 instructions the drivers need (barriers, PRIMASK, wait-for-interrupt),
 * written as GCC inline assembly since no CMSIS headers are used. In host builds they
 * act on the emulated PRIMASK of the fake register file and are otherwise no-ops. */
#ifndef STM32F4_CORE_H
#define STM32F4_CORE_H

#include <stdint.h>
#include "stm32f4_regs.h"

/* Code and constant tables that must keep running while a flash erase or program
 * stalls every fetch from flash (the sample ISR path, the flash driver's wait loop).
 * long_call: SRAM lies 384 MB away from flash, out of reach of a plain BL. */
#ifdef STM32F4_HOST_TEST
#define STM32F4_RAMFUNC
#define STM32F4_BOOT_TEXT
#else
#define STM32F4_RAMFUNC __attribute__((section(".ramfunc"), noinline, long_call))
#define STM32F4_BOOT_TEXT __attribute__((section(".boot_text")))
#endif

/* Large state that only the CPU touches (never DMA, never code) may live in the 64 KB
 * core-coupled RAM, which the DMA streams cannot reach and which has no bus contention. */
#define STM32F4_CCM_BSS __attribute__((section(".ccm_bss")))

#ifdef STM32F4_HOST_TEST
static inline void stm32f4_dsb(void) {}
static inline void stm32f4_isb(void) {}
static inline void stm32f4_wfi(void) {}
static inline uint32_t stm32f4_get_primask(void) { return stm32f4_host_map.primask; }
static inline void stm32f4_set_primask(uint32_t v) { stm32f4_host_map.primask = v & 1u; }
static inline void stm32f4_disable_irq(void) { stm32f4_host_map.primask = 1u; }
#else
static inline void stm32f4_dsb(void) { __asm volatile("dsb 0xF" ::: "memory"); }
static inline void stm32f4_isb(void) { __asm volatile("isb 0xF" ::: "memory"); }
static inline void stm32f4_wfi(void) { __asm volatile("wfi"); }
static inline uint32_t stm32f4_get_primask(void)
{
  uint32_t v;
  __asm volatile("mrs %0, primask" : "=r"(v)::"memory");
  return v;
}
static inline void stm32f4_set_primask(uint32_t v)
{
  __asm volatile("msr primask, %0" ::"r"(v) : "memory");
}
static inline void stm32f4_disable_irq(void) { __asm volatile("cpsid i" ::: "memory"); }
#endif

#endif /* STM32F4_CORE_H */
