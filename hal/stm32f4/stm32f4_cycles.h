/* DWT cycle counter set-up (the counter itself is read through hal_cycles_now). */
#ifndef STM32F4_CYCLES_H
#define STM32F4_CYCLES_H

/* Enable trace (DEMCR.TRCENA), zero and start CYCCNT. */
void stm32f4_cycles_init(void);

#endif /* STM32F4_CYCLES_H */
