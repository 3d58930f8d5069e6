#include "stm32f4_clock.h"

#include "stm32f4_regs.h"

#define VCO_IN_MIN_HZ 1000000u
#define VCO_IN_MAX_HZ 2000000u
#define VCO_OUT_MIN_HZ 100000000u
#define VCO_OUT_MAX_HZ 432000000u
#define SYSCLK_MAX_HZ 168000000u
#define PCLK1_MAX_HZ 42000000u
#define PCLK2_MAX_HZ 84000000u
#define USB_HZ 48000000u
#define WAIT_STATE_STEP_HZ 30000000u /* 2.7..3.6 V supply */
#define CLOCK_POLL_LIMIT 200000u

uint32_t stm32f4_clock_ppre_bits(uint32_t div)
{
  switch (div) {
  case 2u: return 4u;
  case 4u: return 5u;
  case 8u: return 6u;
  case 16u: return 7u;
  default: return 0u;
  }
}

static uint32_t apb_divider(uint32_t hclk_hz, uint32_t max_hz)
{
  uint32_t div = 1u;
  while (div < 16u && hclk_hz / div > max_hz) {
    div *= 2u;
  }
  return div;
}

static void finish_plan(uint32_t hse_hz, uint32_t m, uint32_t n, uint32_t p,
                        stm32f4_clock_plan_t *plan)
{
  const uint32_t vco_out = (uint32_t)(((uint64_t)hse_hz * n) / m);
  uint32_t q = (vco_out + USB_HZ - 1u) / USB_HZ; /* never above 48 MHz */
  if (q < 2u) q = 2u;
  plan->pllm = m;
  plan->plln = n;
  plan->pllp = p;
  plan->pllq = q;
  plan->sysclk_hz = vco_out / p;
  plan->hclk_hz = plan->sysclk_hz;
  plan->flash_latency = (plan->hclk_hz - 1u) / WAIT_STATE_STEP_HZ;
  plan->apb1_div = apb_divider(plan->hclk_hz, PCLK1_MAX_HZ);
  plan->apb2_div = apb_divider(plan->hclk_hz, PCLK2_MAX_HZ);
  plan->pclk1_hz = plan->hclk_hz / plan->apb1_div;
  plan->pclk2_hz = plan->hclk_hz / plan->apb2_div;
  plan->tim_apb1_hz = plan->apb1_div == 1u ? plan->pclk1_hz : 2u * plan->pclk1_hz;
  plan->tim_apb2_hz = plan->apb2_div == 1u ? plan->pclk2_hz : 2u * plan->pclk2_hz;
  plan->pll48_hz = vco_out / q;
}

stm32f4_clock_status_t stm32f4_clock_plan(uint32_t hse_hz, uint32_t sysclk_hz,
                                          stm32f4_clock_plan_t *plan)
{
  static const uint32_t p_choices[4] = {2u, 4u, 6u, 8u};
  if (plan == 0 || hse_hz < 4000000u || hse_hz > 26000000u || sysclk_hz == 0u ||
      sysclk_hz > SYSCLK_MAX_HZ) {
    return STM32F4_CLOCK_ERR_PLAN;
  }
  /* Ascending PLLM = descending VCO input: the first hit has the least PLL jitter.
   * Among those, prefer a VCO from which PLLQ makes exactly 48 MHz. */
  uint32_t best_m = 0u, best_n = 0u, best_p = 0u;
  for (uint32_t m = 2u; m <= 63u; ++m) {
    if ((uint64_t)hse_hz > (uint64_t)VCO_IN_MAX_HZ * m) continue;
    if ((uint64_t)hse_hz < (uint64_t)VCO_IN_MIN_HZ * m) break;
    for (uint32_t i = 0u; i < 4u; ++i) {
      const uint64_t vco_out = (uint64_t)sysclk_hz * p_choices[i];
      if (vco_out < VCO_OUT_MIN_HZ || vco_out > VCO_OUT_MAX_HZ) continue;
      if ((vco_out * m) % hse_hz != 0u) continue;
      const uint64_t n = (vco_out * m) / hse_hz;
      if (n < 50u || n > 432u) continue;
      if (best_m == 0u) {
        best_m = m;
        best_n = (uint32_t)n;
        best_p = p_choices[i];
      }
      if (vco_out % USB_HZ == 0u && vco_out / USB_HZ <= 15u) {
        finish_plan(hse_hz, m, (uint32_t)n, p_choices[i], plan);
        return STM32F4_CLOCK_OK;
      }
    }
  }
  if (best_m == 0u) return STM32F4_CLOCK_ERR_PLAN;
  finish_plan(hse_hz, best_m, best_n, best_p, plan);
  return STM32F4_CLOCK_OK;
}

static int wait_set(const volatile uint32_t *reg, uint32_t mask, uint32_t value)
{
  for (uint32_t i = 0u; i < CLOCK_POLL_LIMIT; ++i) {
    if ((*reg & mask) == value) return 1;
    STM32F4_POLL_HOOK();
  }
  return 0;
}

stm32f4_clock_status_t stm32f4_clock_init(const stm32f4_clock_plan_t *plan)
{
  if (plan == 0 || plan->pllm < 2u || plan->pllm > 63u || plan->plln < 50u ||
      plan->plln > 432u || plan->pllp < 2u || plan->pllp > 8u || (plan->pllp & 1u) != 0u ||
      plan->pllq < 2u || plan->pllq > 15u || plan->flash_latency > 7u) {
    return STM32F4_CLOCK_ERR_PLAN;
  }
  /* 168 MHz needs the regulator's scale-1 output (RM0090 §5.1.4). */
  RCC->APB1ENR |= RCC_APB1ENR_PWREN;
  PWR->CR |= PWR_CR_VOS;

  RCC->CR |= RCC_CR_HSEON;
  if (!wait_set(&RCC->CR, RCC_CR_HSERDY, RCC_CR_HSERDY)) {
    RCC->CR &= ~RCC_CR_HSEON;
    return STM32F4_CLOCK_ERR_HSE;
  }
  /* Wait states first: the flash must be slow enough before the clock is fast. */
  FLASH_R->ACR = plan->flash_latency | FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
  if ((FLASH_R->ACR & FLASH_ACR_LATENCY_MASK) != plan->flash_latency) {
    return STM32F4_CLOCK_ERR_SWITCH;
  }
  RCC->PLLCFGR = (plan->pllm << RCC_PLLCFGR_PLLM_POS) | (plan->plln << RCC_PLLCFGR_PLLN_POS) |
                 (((plan->pllp / 2u) - 1u) << RCC_PLLCFGR_PLLP_POS) | RCC_PLLCFGR_PLLSRC_HSE |
                 (plan->pllq << RCC_PLLCFGR_PLLQ_POS);
  RCC->CFGR = (RCC->CFGR & RCC_CFGR_SW_MASK) |
              (stm32f4_clock_ppre_bits(plan->apb1_div) << RCC_CFGR_PPRE1_POS) |
              (stm32f4_clock_ppre_bits(plan->apb2_div) << RCC_CFGR_PPRE2_POS);
  RCC->CR |= RCC_CR_PLLON;
  if (!wait_set(&RCC->CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY)) {
    return STM32F4_CLOCK_ERR_PLL;
  }
  RCC->CFGR = (RCC->CFGR & ~RCC_CFGR_SW_MASK) | RCC_CFGR_SW_PLL;
  if (!wait_set(&RCC->CFGR, 3u << RCC_CFGR_SWS_POS, RCC_CFGR_SW_PLL << RCC_CFGR_SWS_POS)) {
    return STM32F4_CLOCK_ERR_SWITCH;
  }
  return STM32F4_CLOCK_OK;
}
