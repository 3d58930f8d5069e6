/* Critical sections: mask the sample interrupt around short shared-state updates in the
 * background loop. Nestable: the returned state is given back to hal_critical_exit. */
#ifndef HAL_CRITICAL_H
#define HAL_CRITICAL_H

#include <stdint.h>

uint32_t hal_critical_enter(void);
void hal_critical_exit(uint32_t state);

#endif /* HAL_CRITICAL_H */
