/* hal_cycles_now on the board: the DWT cycle counter, one count per core clock
 * (5.95 ns at 168 MHz; wraps after 25.6 s, so differences of uint32 are exact). */
#include "hal/hal_sample_timer.h"
#include "cm4_core.h"
#include "cm4_cycles.h"
#include "cm4_regs.h"

void cm4_cycles_init(void)
{
  DEMCR |= DEMCR_TRCENA;
  DWT->CYCCNT = 0u;
  DWT->CTRL |= DWT_CTRL_CYCCNTENA;
}

CM4_RAMFUNC uint32_t hal_cycles_now(void) { return DWT->CYCCNT; }
