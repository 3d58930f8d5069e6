#include "stm32f4_uptime.h"

#include "stm32f4_board.h"
#include "stm32f4_regs.h"

void stm32f4_uptime_init(void)
{
  RCC->APB1ENR |= RCC_APB1ENR_TIM2EN;
  TIM2->CR1 = 0u;
  TIM2->PSC = stm32f4_board_info()->clock.tim_apb1_hz / 1000000u - 1u;
  TIM2->ARR = 0xFFFFFFFFu;
  TIM2->EGR = TIM_EGR_UG; /* PSC is buffered: load it now */
  TIM2->CR1 = TIM_CR1_CEN;
}

uint32_t stm32f4_uptime_us(void) { return TIM2->CNT; }
