/* The reference board: STM32F405 at 168 MHz from an 8 MHz crystal, AD7606 ADC on SPI1,
 * AD5554 DAC on SPI2, tuning port on USART1 at 921600 baud.
 *
 * Pin map (alternate functions from the STM32F405 datasheet, table 9):
 *   PA8  TIM1_CH1 AF1 -> ADC CONVST A+B       PA5  SPI1_SCK  AF5 -> ADC SCLK
 *   PA9  TIM1_CH2 AF1 -> DAC LDAC             PA6  SPI1_MISO AF5 <- ADC DOUTA
 *   PA10 TIM1_CH3 AF1 -> ADC CS               PB13 SPI2_SCK  AF5 -> DAC CLK
 *   PC6  TIM8_CH1 AF3 -> DAC CS               PB15 SPI2_MOSI AF5 -> DAC SDI
 *   PB6  USART1_TX AF7, PB7 USART1_RX AF7     PB0 -> ADC RESET, PB1 -> DAC RS (low = reset)
 *   PC7  <- ADC BUSY (input, diagnostics only)
 * Strapped on the board: AD7606 PAR/SER/BYTE SEL high (serial), RANGE low (+-5 V),
 * OS[2:0] = 000 (no oversampling); AD5554 MSB high (RS resets to mid-scale = 0 V). */
#ifndef STM32F4_BOARD_H
#define STM32F4_BOARD_H

#include <stdint.h>

#include "stm32f4_clock.h"
#include "stm32f4_regs.h"

typedef struct {
  stm32f4_clock_status_t clock_status;
  stm32f4_clock_plan_t clock; /* the frequencies in force (HSI figures if the PLL failed) */
  uint32_t reset_flags;       /* RCC_CSR at boot: why the last reset happened */
} stm32f4_board_info_t;

/* Called by Reset_Handler before main: clock tree, fault handlers, cycle counter. */
void stm32f4_system_init(void);
const stm32f4_board_info_t *stm32f4_board_info(void);

/* Pins, converter resets, DAC sequencer, UART. Returns 0, or -1 if the UART baud rate
 * cannot be made from the clock in force. */
int stm32f4_board_init(void);

/* Software reset (SYSRESETREQ). */
void stm32f4_board_reset(void);

/* Configure one pin: mode GPIO_MODE_*, alternate function af (used in AF mode),
 * very-high speed, push-pull, pull-up when pull_up != 0. */
void stm32f4_gpio_config(stm32f4_gpio_t *gpio, uint32_t pin, uint32_t mode, uint32_t af,
                         int pull_up);

#endif /* STM32F4_BOARD_H */
