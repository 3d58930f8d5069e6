#include "stm32f4_gpio.h"

/* OTYPER first and MODER last: the pin never drives in the wrong way. */
static void config(stm32f4_gpio_t *gpio, uint32_t pin, uint32_t mode, uint32_t af, int pull_up,
                   int open_drain)
{
  if (gpio == 0 || pin > 15u) return;
  const uint32_t s2 = pin * 2u;
  gpio->OTYPER = (gpio->OTYPER & ~(1u << pin)) | ((open_drain != 0 ? 1u : 0u) << pin);
  gpio->OSPEEDR = (gpio->OSPEEDR & ~(3u << s2)) | (GPIO_SPEED_VERY_HIGH << s2);
  gpio->PUPDR = (gpio->PUPDR & ~(3u << s2)) | ((pull_up != 0 ? 1u : 0u) << s2);
  const uint32_t idx = pin >> 3;
  const uint32_t s4 = (pin & 7u) * 4u;
  gpio->AFR[idx] = (gpio->AFR[idx] & ~(0xFu << s4)) | ((af & 0xFu) << s4);
  gpio->MODER = (gpio->MODER & ~(3u << s2)) | ((mode & 3u) << s2);
}

void stm32f4_gpio_config(stm32f4_gpio_t *gpio, uint32_t pin, uint32_t mode, uint32_t af,
                         int pull_up)
{
  config(gpio, pin, mode, af, pull_up, 0);
}

void stm32f4_gpio_config_open_drain(stm32f4_gpio_t *gpio, uint32_t pin, uint32_t af)
{
  config(gpio, pin, GPIO_MODE_AF, af, 0, 1);
}
