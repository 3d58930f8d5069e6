/* Clock tree of the board (hal/stm32f4/stm32f4_clock.c) against RM0090's PLL rules and a
 * fake RCC that plays the oscillator, PLL and clock switch. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "stm32f4_clock.h"
#include "stm32f4_host_regs.h"

/* The PLL relations of RM0090 §7.3.2, checked independently of the planner. */
static void assert_pll_rules(uint32_t hse_hz, const stm32f4_clock_plan_t *p)
{
  const double vco_in = (double)hse_hz / p->pllm;
  const double vco_out = vco_in * p->plln;
  assert_true(p->pllm >= 2u && p->pllm <= 63u);
  assert_true(vco_in >= 1e6 && vco_in <= 2e6);
  assert_true(p->plln >= 50u && p->plln <= 432u);
  assert_true(vco_out >= 100e6 && vco_out <= 432e6);
  assert_true(p->pllp == 2u || p->pllp == 4u || p->pllp == 6u || p->pllp == 8u);
  assert_true(p->pllq >= 2u && p->pllq <= 15u);
  assert_true(vco_out / p->pllq <= 48e6 + 1.0);
  /* Exact SYSCLK: hse * N == sysclk * M * P. */
  assert_true((uint64_t)hse_hz * p->plln == (uint64_t)p->sysclk_hz * p->pllm * p->pllp);
  assert_true(p->pclk1_hz <= 42000000u);
  assert_true(p->pclk2_hz <= 84000000u);
}

static void test_plan_168mhz_from_8mhz(void **state)
{
  (void)state;
  stm32f4_clock_plan_t p;
  assert_int_equal(stm32f4_clock_plan(8000000u, 168000000u, &p), STM32F4_CLOCK_OK);
  assert_pll_rules(8000000u, &p);
  /* 2 MHz VCO input (least jitter), 336 MHz VCO, /2 -> 168 MHz, /7 -> 48 MHz USB. */
  assert_int_equal(p.pllm, 4);
  assert_int_equal(p.plln, 168);
  assert_int_equal(p.pllp, 2);
  assert_int_equal(p.pllq, 7);
  assert_int_equal(p.pll48_hz, 48000000);
  /* RM0090 table 10, 2.7..3.6 V: 150 < HCLK <= 168 MHz needs 5 wait states. */
  assert_int_equal(p.flash_latency, 5);
  assert_int_equal(p.apb1_div, 4);
  assert_int_equal(p.apb2_div, 2);
  assert_int_equal(p.pclk1_hz, 42000000);
  assert_int_equal(p.pclk2_hz, 84000000);
  /* Timers on a divided APB run at twice its clock. */
  assert_int_equal(p.tim_apb1_hz, 84000000);
  assert_int_equal(p.tim_apb2_hz, 168000000);
}

static void test_plan_other_crystals_and_rates(void **state)
{
  (void)state;
  stm32f4_clock_plan_t p;
  assert_int_equal(stm32f4_clock_plan(25000000u, 168000000u, &p), STM32F4_CLOCK_OK);
  assert_pll_rules(25000000u, &p);
  assert_int_equal(p.sysclk_hz, 168000000);
  assert_int_equal(p.pll48_hz, 48000000);
  assert_int_equal(stm32f4_clock_plan(8000000u, 120000000u, &p), STM32F4_CLOCK_OK);
  assert_pll_rules(8000000u, &p);
  assert_int_equal(p.flash_latency, 3); /* 90 < 120 <= 120 MHz */
}

static void test_plan_rejects_impossible(void **state)
{
  (void)state;
  stm32f4_clock_plan_t p = {0};
  p.pllm = 77u;
  assert_int_equal(stm32f4_clock_plan(8000000u, 180000000u, &p), STM32F4_CLOCK_ERR_PLAN);
  assert_int_equal(stm32f4_clock_plan(8000000u, 0u, &p), STM32F4_CLOCK_ERR_PLAN);
  assert_int_equal(stm32f4_clock_plan(1000000u, 168000000u, &p), STM32F4_CLOCK_ERR_PLAN);
  assert_int_equal(stm32f4_clock_plan(8000000u, 168000000u, NULL), STM32F4_CLOCK_ERR_PLAN);
  assert_int_equal(p.pllm, 77); /* unchanged */
}

/* ---- fake RCC: the hardware's answers, given from the drivers' wait loops ---- */
static int s_hse_works;
static int s_pll_locks;
static int s_latency_before_switch;

static void rcc_hardware(void)
{
  if (s_hse_works && (RCC->CR & RCC_CR_HSEON) != 0u) RCC->CR |= RCC_CR_HSERDY;
  if (s_pll_locks && (RCC->CR & RCC_CR_PLLON) != 0u) RCC->CR |= RCC_CR_PLLRDY;
  const uint32_t sw = RCC->CFGR & RCC_CFGR_SW_MASK;
  if (sw == RCC_CFGR_SW_PLL) {
    /* The switch happens now: the wait states must already be in place. */
    s_latency_before_switch = (int)(FLASH_R->ACR & FLASH_ACR_LATENCY_MASK);
  }
  RCC->CFGR = (RCC->CFGR & ~(3u << RCC_CFGR_SWS_POS)) | (sw << RCC_CFGR_SWS_POS);
}

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  stm32f4_host_map.poll_hook = rcc_hardware;
  s_hse_works = 1;
  s_pll_locks = 1;
  s_latency_before_switch = -1;
  return 0;
}

static void test_init_programs_the_tree(void **state)
{
  (void)state;
  stm32f4_clock_plan_t p;
  assert_int_equal(stm32f4_clock_plan(8000000u, 168000000u, &p), STM32F4_CLOCK_OK);
  assert_int_equal(stm32f4_clock_init(&p), STM32F4_CLOCK_OK);
  /* PLLM=4, PLLN=168, PLLP=/2 (code 0), source HSE (bit 22), PLLQ=7. */
  assert_int_equal(RCC->PLLCFGR, 4u | (168u << 6) | (0u << 16) | (1u << 22) | (7u << 24));
  assert_int_equal(FLASH_R->ACR & FLASH_ACR_LATENCY_MASK, 5);
  assert_true((FLASH_R->ACR & (FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN)) ==
              (FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN));
  assert_int_equal((RCC->CFGR >> 10) & 7u, 5u); /* APB1 /4 */
  assert_int_equal((RCC->CFGR >> 13) & 7u, 4u); /* APB2 /2 */
  assert_int_equal((RCC->CFGR >> 4) & 15u, 0u); /* AHB /1 */
  assert_int_equal(RCC->CFGR & 3u, RCC_CFGR_SW_PLL);
  assert_true((PWR->CR & PWR_CR_VOS) != 0u);
  assert_true((RCC->APB1ENR & RCC_APB1ENR_PWREN) != 0u);
  assert_int_equal(s_latency_before_switch, 5);
}

static void test_init_without_crystal_stays_on_hsi(void **state)
{
  (void)state;
  s_hse_works = 0;
  stm32f4_clock_plan_t p;
  assert_int_equal(stm32f4_clock_plan(8000000u, 168000000u, &p), STM32F4_CLOCK_OK);
  assert_int_equal(stm32f4_clock_init(&p), STM32F4_CLOCK_ERR_HSE);
  assert_int_equal(RCC->CR & RCC_CR_HSEON, 0);
  assert_int_equal(RCC->CFGR & 3u, 0u);
  assert_int_equal(RCC->CR & RCC_CR_PLLON, 0);
}

static void test_init_without_pll_lock_stays_on_hsi(void **state)
{
  (void)state;
  s_pll_locks = 0;
  stm32f4_clock_plan_t p;
  assert_int_equal(stm32f4_clock_plan(8000000u, 168000000u, &p), STM32F4_CLOCK_OK);
  assert_int_equal(stm32f4_clock_init(&p), STM32F4_CLOCK_ERR_PLL);
  assert_int_equal(RCC->CFGR & 3u, 0u);
}

static void test_init_rejects_bad_plan(void **state)
{
  (void)state;
  stm32f4_clock_plan_t p;
  assert_int_equal(stm32f4_clock_plan(8000000u, 168000000u, &p), STM32F4_CLOCK_OK);
  p.pllp = 3u;
  assert_int_equal(stm32f4_clock_init(&p), STM32F4_CLOCK_ERR_PLAN);
  assert_int_equal(stm32f4_clock_init(NULL), STM32F4_CLOCK_ERR_PLAN);
  assert_int_equal(RCC->CR, 0u); /* nothing touched */
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plan_168mhz_from_8mhz),
      cmocka_unit_test(test_plan_other_crystals_and_rates),
      cmocka_unit_test(test_plan_rejects_impossible),
      cmocka_unit_test_setup(test_init_programs_the_tree, setup),
      cmocka_unit_test_setup(test_init_without_crystal_stays_on_hsi, setup),
      cmocka_unit_test_setup(test_init_without_pll_lock_stays_on_hsi, setup),
      cmocka_unit_test_setup(test_init_rejects_bad_plan, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
