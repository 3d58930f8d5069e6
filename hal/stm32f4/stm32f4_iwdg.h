/* Independent watchdog, clocked by the ~32 kHz LSI (board.h: BOARD_LSI_HZ) (RM0090 §21: 17..47 kHz over
 * temperature and parts, so a timeout is only good to about a factor of 1.5).
 *   t_timeout = 4 * 2^PR * (RLR + 1) / f_lsi,  PR in 0..6, RLR in 0..4095. */
#ifndef STM32F4_IWDG_H
#define STM32F4_IWDG_H

#include <stdint.h>

typedef struct {
  uint32_t pr;  /* prescaler code: divide by 4 << pr */
  uint32_t rlr; /* reload value */
} stm32f4_iwdg_plan_t;

/* Smallest prescaler that reaches timeout_ms. Returns 0, or -1 if out of range. */
int stm32f4_iwdg_plan(uint32_t lsi_hz, uint32_t timeout_ms, stm32f4_iwdg_plan_t *plan);
/* Start the watchdog (it cannot be stopped again until reset). */
void stm32f4_iwdg_start(const stm32f4_iwdg_plan_t *plan);
void stm32f4_iwdg_kick(void);

#endif /* STM32F4_IWDG_H */
