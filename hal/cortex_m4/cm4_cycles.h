/* DWT cycle counter set-up (the counter itself is read through hal_cycles_now). */
#ifndef CM4_CYCLES_H
#define CM4_CYCLES_H

/* Enable trace (DEMCR.TRCENA), zero and start CYCCNT. */
void cm4_cycles_init(void);

#endif /* CM4_CYCLES_H */
