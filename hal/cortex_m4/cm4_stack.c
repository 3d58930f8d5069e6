#include "cm4_stack.h"

#include <stdint.h>

#include "cm4_core.h"

/* Words left unpainted below the painter's own stack pointer: its frame and the calls it
 * makes must not be painted over while in use. */
#define STACK_GUARD_WORDS 16u

uint32_t cm4_stack_used_bytes(const uint32_t *lo, const uint32_t *hi)
{
  if (lo == 0 || hi == 0 || hi <= lo) return 0u;
  const uint32_t *p = lo;
  while (p < hi && *p == CM4_STACK_PAINT) ++p;
  return (uint32_t)((uintptr_t)hi - (uintptr_t)p);
}

/* The board figures need the linker's symbols: not in the host build of the drivers. */
#ifndef CM4_HOST_TEST
extern uint32_t _sstack[], _estack[];

static uint32_t s_boot_bytes; /* deepest use before cm4_stack_mark, 0 if never marked */

uint32_t cm4_stack_size_bytes(void)
{
  return (uint32_t)((uintptr_t)_estack - (uintptr_t)_sstack);
}

uint32_t cm4_stack_run_bytes(void) { return cm4_stack_used_bytes(_sstack, _estack); }

uint32_t cm4_stack_hwm_bytes(void)
{
  const uint32_t run = cm4_stack_run_bytes();
  return run > s_boot_bytes ? run : s_boot_bytes;
}

static uintptr_t current_sp(void)
{
  uintptr_t sp;
  __asm volatile("mov %0, sp" : "=r"(sp));
  return sp;
}

void cm4_stack_mark(void)
{
  const uint32_t primask = cm4_get_primask();
  cm4_disable_irq();
  s_boot_bytes = cm4_stack_hwm_bytes();
  const uintptr_t end = (current_sp() & ~(uintptr_t)3u) - 4u * STACK_GUARD_WORDS;
  for (volatile uint32_t *p = _sstack; (uintptr_t)p < end; ++p) *p = CM4_STACK_PAINT;
  cm4_set_primask(primask);
}
#endif
