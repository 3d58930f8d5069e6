/* Clock tree of the reference board: HSE crystal -> main PLL -> SYSCLK, with the flash
 * wait states, bus prescalers and voltage scale that the chosen SYSCLK requires.
 *
 *   f_vco_in  = f_hse / PLLM          (1..2 MHz; 2 MHz gives the lowest PLL jitter)
 *   f_vco_out = f_vco_in * PLLN       (100..432 MHz, 50 <= PLLN <= 432)
 *   f_sysclk  = f_vco_out / PLLP      (PLLP in {2, 4, 6, 8}, <= 168 MHz)
 *   f_pll48   = f_vco_out / PLLQ      (USB/SDIO clock, 48 MHz when it can be made)
 *   HCLK = SYSCLK, PCLK1 <= 42 MHz, PCLK2 <= 84 MHz; a timer on an APB bus whose
 *   prescaler is not 1 runs at twice that bus clock (RM0090 §7.2 and fig. 21).
 * Flash wait states for 2.7..3.6 V: one per started 30 MHz of HCLK (RM0090 table 10). */
#ifndef STM32F4_CLOCK_H
#define STM32F4_CLOCK_H

#include <stdint.h>

typedef struct {
  uint32_t pllm, plln, pllp, pllq;
  uint32_t flash_latency; /* wait states */
  uint32_t apb1_div, apb2_div;
  uint32_t sysclk_hz, hclk_hz, pclk1_hz, pclk2_hz;
  uint32_t tim_apb1_hz, tim_apb2_hz; /* timer kernel clocks (TIM2..5 / TIM1, TIM8) */
  uint32_t pll48_hz;
} stm32f4_clock_plan_t;

typedef enum {
  STM32F4_CLOCK_OK = 0,
  STM32F4_CLOCK_ERR_PLAN = -1,  /* no PLL setting makes this SYSCLK from this crystal */
  STM32F4_CLOCK_ERR_HSE = -2,   /* crystal did not start: still on the 16 MHz HSI */
  STM32F4_CLOCK_ERR_PLL = -3,   /* PLL did not lock: still on the HSI */
  STM32F4_CLOCK_ERR_SWITCH = -4 /* SYSCLK switch not acknowledged */
} stm32f4_clock_status_t;


/* Compute the PLL and bus settings for sysclk_hz from an hse_hz crystal; exact
 * frequencies only. Returns STM32F4_CLOCK_OK or STM32F4_CLOCK_ERR_PLAN (plan unchanged). */
stm32f4_clock_status_t stm32f4_clock_plan(uint32_t hse_hz, uint32_t sysclk_hz,
                                          stm32f4_clock_plan_t *plan);

/* Program the plan: scale-1 regulator, HSE on, wait states, PLL, prescalers, switch.
 * Every wait is bounded; on failure the core keeps running from the HSI. */
stm32f4_clock_status_t stm32f4_clock_init(const stm32f4_clock_plan_t *plan);

/* PPRE field encoding of an APB divider (1, 2, 4, 8 or 16). */
uint32_t stm32f4_clock_ppre_bits(uint32_t div);

#endif /* STM32F4_CLOCK_H */
