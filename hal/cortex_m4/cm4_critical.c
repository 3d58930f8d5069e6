/* hal_critical.h on the Cortex-M4: PRIMASK. BASEPRI cannot mask priority 0, and the
 * sample interrupt runs at priority 0, so only PRIMASK keeps it out. The previous PRIMASK
 * is returned and restored, which makes the sections nest. */
#include "hal/hal_critical.h"

#include "cm4_core.h"

CM4_RAMFUNC uint32_t hal_critical_enter(void)
{
  const uint32_t state = cm4_get_primask();
  cm4_disable_irq();
  return state;
}

CM4_RAMFUNC void hal_critical_exit(uint32_t state) { cm4_set_primask(state); }
