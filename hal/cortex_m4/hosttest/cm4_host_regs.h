/* Fake Cortex-M4 core registers for host unit tests (SCB, NVIC, SysTick, DWT, CPACR,
 * DEMCR and an emulated PRIMASK), reached through cm4_host_map (cm4_regs.h). */
#ifndef CM4_HOST_REGS_H
#define CM4_HOST_REGS_H

#include "cm4_regs.h"

/* Zero every fake core register and PRIMASK. */
void cm4_host_reset(void);

#endif /* CM4_HOST_REGS_H */
