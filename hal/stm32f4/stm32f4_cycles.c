/* hal_cycles_now on the board: the DWT cycle counter, one count per core clock
 * (5.95 ns at 168 MHz; wraps after 25.6 s, so differences of uint32 are exact). */
#include "hal/hal_sample_timer.h"
#include "stm32f4_core.h"
#include "stm32f4_cycles.h"
#include "stm32f4_regs.h"

void stm32f4_cycles_init(void)
{
  DEMCR |= DEMCR_TRCENA;
  DWT->CYCCNT = 0u;
  DWT->CTRL |= DWT_CTRL_CYCCNTENA;
}

STM32F4_RAMFUNC uint32_t hal_cycles_now(void)
{
  return DWT->CYCCNT;
}
