/* Cortex-M4 instructions the drivers need (barriers, PRIMASK, wait-for-interrupt),
 * written as GCC inline assembly since no CMSIS headers are used. In host builds they
 * act on the emulated PRIMASK of the fake register file and are otherwise no-ops. */
#ifndef CM4_CORE_H
#define CM4_CORE_H

#include <stdint.h>
#include "cm4_regs.h"

/* Code and constant tables that must keep running while a flash erase or program
 * stalls every fetch from flash (the sample ISR path, the flash driver's wait loop).
 * long_call: SRAM lies 384 MB away from flash, out of reach of a plain BL. */
#ifdef CM4_HOST_TEST
#define CM4_RAMFUNC
#define CM4_BOOT_TEXT
#else
#define CM4_RAMFUNC __attribute__((section(".ramfunc"), noinline, long_call))
#define CM4_BOOT_TEXT __attribute__((section(".boot_text")))
#endif

/* A condition rarely true (an error, an overrun): the compiler lays out its branch so that
 * the common path falls through (a taken branch refills the pipeline). */
#define CM4_UNLIKELY(x) __builtin_expect((x) != 0, 0)

#ifdef CM4_HOST_TEST
static inline void cm4_dsb(void) {}
static inline void cm4_isb(void) {}
static inline void cm4_wfi(void) {}
static inline uint32_t cm4_get_primask(void) { return cm4_host_map.primask; }
static inline void cm4_set_primask(uint32_t v) { cm4_host_map.primask = v & 1u; }
static inline void cm4_disable_irq(void) { cm4_host_map.primask = 1u; }
#else
static inline void cm4_dsb(void) { __asm volatile("dsb 0xF" ::: "memory"); }
static inline void cm4_isb(void) { __asm volatile("isb 0xF" ::: "memory"); }
static inline void cm4_wfi(void) { __asm volatile("wfi"); }
static inline uint32_t cm4_get_primask(void)
{
  uint32_t v;
  __asm volatile("mrs %0, primask" : "=r"(v)::"memory");
  return v;
}
static inline void cm4_set_primask(uint32_t v)
{
  __asm volatile("msr primask, %0" ::"r"(v) : "memory");
}
static inline void cm4_disable_irq(void) { __asm volatile("cpsid i" ::: "memory"); }
#endif

/* Software reset (SCB AIRCR SYSRESETREQ); does not return on the target. */
static inline void cm4_system_reset(void)
{
  cm4_dsb();
  SCB->AIRCR = SCB_AIRCR_VECTKEY | SCB_AIRCR_SYSRESETREQ;
  cm4_dsb();
#ifndef CM4_HOST_TEST
  for (;;) {
  }
#endif
}

#endif /* CM4_CORE_H */
