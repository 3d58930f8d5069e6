/* The reference board: STM32F405 at 168 MHz from an 8 MHz crystal, AD7606 ADC on SPI1,
 * AD5554 DAC on SPI2, tuning port on USART1 at 921600 baud.
 *
 * Pin map, clocks and converter scaling: board.h. */
#ifndef STM32F4_BOARD_H
#define STM32F4_BOARD_H

#include <stdint.h>

#include "board.h"
#include "cm4_startup.h" /* board_system_init: clock tree, fault handlers, cycle counter */
#include "stm32f4_clock.h"
#include "stm32f4_gpio.h"
#include "stm32f4_regs.h"

typedef struct {
  stm32f4_clock_status_t clock_status;
  stm32f4_clock_plan_t clock; /* the frequencies in force (HSI figures if the PLL failed) */
  uint32_t reset_flags;       /* RCC_CSR at boot: why the last reset happened */
} stm32f4_board_info_t;

const stm32f4_board_info_t *stm32f4_board_info(void);

/* Pins, converter resets, DAC sequencer, UART. Returns 0, or -1 if the UART baud rate
 * cannot be made from the clock in force. */
int stm32f4_board_init(void);

#endif /* STM32F4_BOARD_H */
