#include "stm32f4_board.h"

#include "hal/hal_sample_timer.h"
#include "stm32f4_core.h"
#include "cm4_cycles.h"
#include "stm32f4_dac.h"
#include "cm4_fault.h"
#include "stm32f4_uart.h"

#define HSI_HZ 16000000u

static stm32f4_board_info_t s_info;

static void hsi_figures(stm32f4_clock_plan_t *p)
{
  RCC->CFGR &= ~((7u << RCC_CFGR_PPRE1_POS) | (7u << RCC_CFGR_PPRE2_POS));
  p->sysclk_hz = HSI_HZ;
  p->hclk_hz = HSI_HZ;
  p->pclk1_hz = HSI_HZ;
  p->pclk2_hz = HSI_HZ;
  p->tim_apb1_hz = HSI_HZ;
  p->tim_apb2_hz = HSI_HZ;
  p->apb1_div = 1u;
  p->apb2_div = 1u;
}

void board_system_init(void)
{
  s_info.reset_flags = RCC->CSR;
  RCC->CSR |= RCC_CSR_RMVF;
  s_info.clock_status = stm32f4_clock_plan(BOARD_HSE_HZ, BOARD_SYSCLK_HZ, &s_info.clock);
  if (s_info.clock_status == STM32F4_CLOCK_OK) {
    s_info.clock_status = stm32f4_clock_init(&s_info.clock);
  }
  if (s_info.clock_status != STM32F4_CLOCK_OK) {
    hsi_figures(&s_info.clock);
  }
  cm4_fault_enable();
  cm4_cycles_init();
}

const stm32f4_board_info_t *stm32f4_board_info(void) { return &s_info; }

static void short_delay(void)
{
  for (volatile uint32_t i = 0u; i < 200u; ++i) {
  }
}

int stm32f4_board_init(void)
{
  RCC->AHB1ENR |= RCC_AHB1ENR_GPIOAEN | RCC_AHB1ENR_GPIOBEN | RCC_AHB1ENR_GPIOCEN |
                  RCC_AHB1ENR_DMA2EN;
  RCC->APB2ENR |= RCC_APB2ENR_TIM1EN | RCC_APB2ENR_SPI1EN;

  /* Converter resets: AD5554 RS low (all channels to mid-scale = 0 V with MSB strapped
   * high), AD7606 RESET high for > 50 ns; then both released. */
  GPIOB->BSRR = (1u << (1u + 16u)) | (1u << 0);
  stm32f4_gpio_config(GPIOB, 0u, GPIO_MODE_OUTPUT, 0u, 0);
  stm32f4_gpio_config(GPIOB, 1u, GPIO_MODE_OUTPUT, 0u, 0);
  short_delay();
  GPIOB->BSRR = (1u << 1) | (1u << (0u + 16u));
  stm32f4_gpio_config(GPIOC, 7u, GPIO_MODE_INPUT, 0u, 0);

  /* TIM1 outputs driven to their idle levels before the pins are handed to TIM1. */
  hal_sample_timer_stop();
  stm32f4_gpio_config(GPIOA, 8u, GPIO_MODE_AF, 1u, 0);
  stm32f4_gpio_config(GPIOA, 9u, GPIO_MODE_AF, 1u, 0);
  stm32f4_gpio_config(GPIOA, 10u, GPIO_MODE_AF, 1u, 0);
  stm32f4_gpio_config(GPIOA, 5u, GPIO_MODE_AF, 5u, 0);
  stm32f4_gpio_config(GPIOA, 6u, GPIO_MODE_AF, 5u, 0);

  stm32f4_dac_init();
  stm32f4_gpio_config(GPIOB, 13u, GPIO_MODE_AF, 5u, 0);
  stm32f4_gpio_config(GPIOB, 15u, GPIO_MODE_AF, 5u, 0);
  stm32f4_gpio_config(GPIOC, 6u, GPIO_MODE_AF, 3u, 0);
  stm32f4_gpio_config(GPIOC, 10u, GPIO_MODE_AF, 6u, 0); /* second AD5554: SPI3 SCK */
  stm32f4_gpio_config(GPIOC, 12u, GPIO_MODE_AF, 6u, 0); /* SPI3 MOSI */

  stm32f4_gpio_config(GPIOB, 6u, GPIO_MODE_AF, 7u, 0);
  stm32f4_gpio_config(GPIOB, 7u, GPIO_MODE_AF, 7u, 1);
  return stm32f4_uart_init(s_info.clock.pclk2_hz, BOARD_UART_BAUD);
}
