#include "stm32f4_host_regs.h"

#include <string.h>

#include "cm4_host_regs.h"

static stm32f4_rcc_t s_rcc;
static stm32f4_pwr_t s_pwr;
static stm32f4_flash_t s_flash;
static stm32f4_gpio_t s_gpioa, s_gpiob, s_gpioc;
static stm32f4_tim_t s_tim1, s_tim2, s_tim4, s_tim8;
static stm32f4_spi_t s_spi1, s_spi2, s_spi3;
static stm32f4_dma_t s_dma2;
static stm32f4_usart_t s_usart1;
static stm32f4_iwdg_t s_iwdg;
static stm32f4_i2c_t s_i2c1;
static uint8_t s_param_flash[STM32F4_PARAM_NUM_SECTORS * STM32F4_PARAM_SECTOR_BYTES]
    __attribute__((aligned(4)));

stm32f4_host_map_t stm32f4_host_map = {.rcc = &s_rcc,
                                       .pwr = &s_pwr,
                                       .flash = &s_flash,
                                       .gpioa = &s_gpioa,
                                       .gpiob = &s_gpiob,
                                       .gpioc = &s_gpioc,
                                       .tim1 = &s_tim1,
                                       .tim2 = &s_tim2,
                                       .tim4 = &s_tim4,
                                       .tim8 = &s_tim8,
                                       .spi1 = &s_spi1,
                                       .spi2 = &s_spi2,
                                       .spi3 = &s_spi3,
                                       .dma2 = &s_dma2,
                                       .usart1 = &s_usart1,
                                       .iwdg = &s_iwdg,
                                       .i2c1 = &s_i2c1,
                                       .param_flash = s_param_flash,
                                       .poll_hook = 0,
                                       .access_hook = 0};

#define ZERO(x) memset((void *)&(x), 0, sizeof(x))

void stm32f4_host_reset(void)
{
  ZERO(s_rcc);
  ZERO(s_pwr);
  ZERO(s_flash);
  ZERO(s_gpioa);
  ZERO(s_gpiob);
  ZERO(s_gpioc);
  ZERO(s_tim1);
  ZERO(s_tim2);
  ZERO(s_tim4);
  ZERO(s_tim8);
  ZERO(s_spi1);
  ZERO(s_spi2);
  ZERO(s_spi3);
  ZERO(s_dma2);
  ZERO(s_usart1);
  ZERO(s_iwdg);
  ZERO(s_i2c1);
  memset(s_param_flash, 0xFF, sizeof(s_param_flash));
  s_flash.CR = FLASH_CR_LOCK; /* RM0090: FLASH_CR reset value 0x8000_0000 */
  stm32f4_host_map.poll_hook = 0;
  stm32f4_host_map.access_hook = 0;
  cm4_host_reset();
}

uint8_t *stm32f4_host_param_flash(void) { return s_param_flash; }
