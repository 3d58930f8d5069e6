/* High-water mark of the main stack (the only stack: thread mode and every interrupt run
 * on MSP, linker/stm32f405_sections.ld puts it at the bottom of CCM, growing down from
 * _estack towards _sstack).
 *
 * Reset_Handler paints the stack from _sstack up to just below its own frame with
 * CM4_STACK_PAINT before anything else runs; a word that no longer holds the paint
 * has been written. The deepest use is the distance from _estack down to the lowest
 * such word (a pushed value that happens to equal the paint word can hide a few bytes:
 * the figure is a lower bound by at most that word's depth).
 *
 * The image's main may call cm4_stack_mark once its initialisation is done (init-time
 * design code runs deeper than the running loop): the figure so far is kept as the
 * boot figure and the stack below the caller is painted again, so that
 * cm4_stack_run_bytes shows what the sample interrupt and the background loop use
 * from then on. cm4_stack_hwm_bytes is the deepest since reset either way. */
#ifndef CM4_STACK_H
#define CM4_STACK_H

#include <stdint.h>

#define CM4_STACK_PAINT 0xC5A3E1F7u /* no repeated byte: never a memset pattern */

/* Bytes of the region [lo, hi) in use by a stack that grows down from hi: from hi to
 * the lowest word that is not the paint. 0 if the whole region still holds the paint;
 * hi - lo if its lowest word is written (the stack may have overflowed). */
uint32_t cm4_stack_used_bytes(const uint32_t *lo, const uint32_t *hi);

/* Board figures of the main stack (linker symbols _sstack, _estack). */
uint32_t cm4_stack_size_bytes(void);
uint32_t cm4_stack_hwm_bytes(void); /* deepest use since reset */
uint32_t cm4_stack_run_bytes(void); /* since cm4_stack_mark (or reset) */

/* Keep the figure so far, repaint the stack below the caller's frame. Interrupts are
 * masked while painting, so that no handler frame is half painted over. */
void cm4_stack_mark(void);

#endif /* CM4_STACK_H */
