/* Microsecond uptime from TIM2 (32 bit, free running at 1 MHz; wraps after 71.6 min),
 * a time base independent of the sample chain: the bring-up tool checks the tick rate
 * against it. */
#ifndef STM32F4_UPTIME_H
#define STM32F4_UPTIME_H

#include <stdint.h>

void stm32f4_uptime_init(void);
uint32_t stm32f4_uptime_us(void);

#endif /* STM32F4_UPTIME_H */
