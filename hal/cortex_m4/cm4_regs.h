/* Cortex-M4 core registers used by the HAL: SCB, NVIC, SysTick, CPACR (Cortex-M4 Devices
 * Generic User Guide) and DWT, DEMCR (ARMv7-M Architecture Reference Manual). The same on
 * every Cortex-M4 part; a family's register file (e.g. stm32f4_regs.h) includes this one.
 *
 * Host builds (CM4_HOST_TEST defined) see the core registers through cm4_host_map, which
 * the host tests point at RAM structs (hal/cortex_m4/hosttest). */
#ifndef CM4_REGS_H
#define CM4_REGS_H

#include <stdint.h>

#define CM4_REG volatile uint32_t

typedef struct {
  CM4_REG CPUID, ICSR, VTOR, AIRCR, SCR, CCR;
  volatile uint8_t SHPR[12];
  CM4_REG SHCSR, CFSR, HFSR, DFSR, MMFAR, BFAR, AFSR;
} cm4_scb_t;

typedef struct {
  CM4_REG ISER[8], RES0[24], ICER[8], RES1[24], ISPR[8], RES2[24], ICPR[8], RES3[24], IABR[8],
      RES4[56];
  volatile uint8_t IP[240];
} cm4_nvic_t;

typedef struct {
  CM4_REG CTRL, LOAD, VAL, CALIB;
} cm4_systick_t;

typedef struct {
  CM4_REG CTRL, CYCCNT;
} cm4_dwt_t;

#define CM4_DWT_BASE 0xE0001000UL
#define CM4_SYSTICK_BASE 0xE000E010UL
#define CM4_NVIC_BASE 0xE000E100UL
#define CM4_SCB_BASE 0xE000ED00UL
#define CM4_CPACR_ADDR 0xE000ED88UL
#define CM4_DEMCR_ADDR 0xE000EDFCUL

#ifdef CM4_HOST_TEST
typedef struct {
  cm4_scb_t *scb;
  cm4_nvic_t *nvic;
  cm4_systick_t *systick;
  cm4_dwt_t *dwt;
  volatile uint32_t *cpacr, *demcr;
  uint32_t primask; /* emulated PRIMASK for the critical-section code */
} cm4_host_map_t;
extern cm4_host_map_t cm4_host_map;
#define CM4_PERIPH(field, type, addr) (cm4_host_map.field)
#define CM4_CORE_REG(field, addr) (cm4_host_map.field)
#else
#define CM4_PERIPH(field, type, addr) ((type *)(addr))
#define CM4_CORE_REG(field, addr) ((volatile uint32_t *)(addr))
#endif

#define SCB CM4_PERIPH(scb, cm4_scb_t, CM4_SCB_BASE)
#define NVIC CM4_PERIPH(nvic, cm4_nvic_t, CM4_NVIC_BASE)
#define SYSTICK CM4_PERIPH(systick, cm4_systick_t, CM4_SYSTICK_BASE)
#define DWT CM4_PERIPH(dwt, cm4_dwt_t, CM4_DWT_BASE)
#define CPACR (*CM4_CORE_REG(cpacr, CM4_CPACR_ADDR))
#define DEMCR (*CM4_CORE_REG(demcr, CM4_DEMCR_ADDR))

/* ---- Cortex-M4 core ---- */
#define SCB_AIRCR_VECTKEY (0x05FAu << 16)
#define SCB_AIRCR_SYSRESETREQ (1u << 2)
#define SCB_SHCSR_MEMFAULTENA (1u << 16)
#define SCB_SHCSR_BUSFAULTENA (1u << 17)
#define SCB_SHCSR_USGFAULTENA (1u << 18)
#define SCB_CCR_DIV_0_TRP (1u << 4)
#define CPACR_CP10_CP11_FULL (0xFu << 20)
#define DEMCR_TRCENA (1u << 24)
#define DWT_CTRL_CYCCNTENA (1u << 0)
#define SYSTICK_CTRL_ENABLE (1u << 0)
#define SYSTICK_CTRL_TICKINT (1u << 1)
#define SYSTICK_CTRL_CLKSOURCE (1u << 2) /* processor clock */
#define SYSTICK_CTRL_COUNTFLAG (1u << 16)

/* NVIC: priority prio (0 = highest) in the implemented top bits (4 on an STM32F4; the
 * value is shifted into the top nibble), then enable. */
static inline void cm4_nvic_enable(uint32_t irq, uint32_t prio)
{
  NVIC->IP[irq] = (uint8_t)((prio & 0xFu) << 4);
  NVIC->ISER[irq >> 5] = 1u << (irq & 31u);
}

static inline void cm4_nvic_disable(uint32_t irq) { NVIC->ICER[irq >> 5] = 1u << (irq & 31u); }

#endif /* CM4_REGS_H */
