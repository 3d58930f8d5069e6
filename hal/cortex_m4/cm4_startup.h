/* What the Cortex-M4 start-up code (cm4_startup.c) needs from the family and the board.
 *
 * The family supplies the vector table (cm4_vectors, in section .isr_vector, which the
 * linker script puts first in flash): entry 0 the initial stack pointer, entry 1
 * Reset_Handler, the core exceptions, then the family's interrupts; cm4_num_vectors is
 * its length (16 + the family's interrupt count). Reset_Handler copies it to SRAM and
 * points VTOR at the copy. Every entry an image does not handle is Default_Handler.
 *
 * The board (or the image) supplies board_system_init, called by Reset_Handler after
 * .data/.bss and before main: clock tree, fault handlers, cycle counter. */
#ifndef CM4_STARTUP_H
#define CM4_STARTUP_H

#include <stdint.h>

typedef union {
  void (*fn)(void);
  void *sp;
} cm4_vector_t;

extern const cm4_vector_t cm4_vectors[];
extern const uint32_t cm4_num_vectors;

void Reset_Handler(void);
void Default_Handler(void);   /* records the fault or unexpected interrupt, then resets */
void HardFault_Handler(void); /* the same entry */

void board_system_init(void);

#endif /* CM4_STARTUP_H */
