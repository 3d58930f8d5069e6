/* GPIO pin set-up of the STM32F4 (RM0090 §8.4). */
#ifndef STM32F4_GPIO_H
#define STM32F4_GPIO_H

#include <stdint.h>

#include "stm32f4_regs.h"

/* Configure one pin: mode GPIO_MODE_*, alternate function af (used in AF mode),
 * very-high speed, push-pull, pull-up when pull_up != 0. */
void stm32f4_gpio_config(stm32f4_gpio_t *gpio, uint32_t pin, uint32_t mode, uint32_t af,
                         int pull_up);

/* Configure one pin as an open-drain alternate function af (an I2C line: the board's
 * resistors pull it up), very-high speed, no internal pull. */
void stm32f4_gpio_config_open_drain(stm32f4_gpio_t *gpio, uint32_t pin, uint32_t af);

#endif /* STM32F4_GPIO_H */
