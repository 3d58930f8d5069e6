/* Reset entry of a Cortex-M4F image and the fault entry (the vector table itself is the
 * family's: cm4_startup.h).
 *
 * Reset_Handler, in this order: FPU access on (CPACR CP10/CP11) before any code that
 * may touch a float register; the main stack below its own frame painted for the
 * high-water mark (cm4_stack.h); .data, .ramfunc and .ccm_data copied from their load
 * addresses in flash; .bss and .ccm_bss zeroed (.noinit, the fault record, is left
 * alone); the vector table copied to SRAM and VTOR pointed at it, so that interrupts
 * keep being dispatched while a flash erase stalls fetches from flash; then
 * board_system_init (clock tree, fault handlers, cycle counter: per image) and main. */
#include <errno.h>
#include <stdint.h>

#include "cm4_core.h"
#include "cm4_fault.h"
#include "cm4_stack.h"
#include "cm4_startup.h"

/* Linker-script symbols (linker/stm32f405.ld). */
extern uint32_t _sstack[], _estack[];
extern uint32_t _sidata[], _sdata[], _edata[];
extern uint32_t _siramfunc[], _sramfunc[], _eramfunc[];
extern uint32_t _siccm_data[], _sccm_data[], _eccm_data[];
extern uint32_t _sbss[], _ebss[];
extern uint32_t _sccm_bss[], _eccm_bss[];
extern uint32_t _sram_vectors[];

int main(void);
void *_sbrk(int incr);

/* The entry of every fault and unexpected interrupt (the family's vector table points
 * HardFault, MemManage, BusFault, UsageFault and every interrupt no image handles here):
 * pick the stack the frame was pushed to (EXC_RETURN bit 2) and hand frame, EXC_RETURN
 * and IPSR to the C capture (cm4_fault.h). Naked: no prologue touches a stack that may
 * be the cause of the fault. */
__attribute__((naked)) CM4_BOOT_TEXT void Default_Handler(void)
{
  __asm volatile("tst lr, #4\n"
                 "ite eq\n"
                 "mrseq r0, msp\n"
                 "mrsne r0, psp\n"
                 "mov r1, lr\n"
                 "mrs r2, ipsr\n"
                 "ldr r3, =cm4_fault_capture\n"
                 "bx r3\n");
}
void HardFault_Handler(void) __attribute__((alias("Default_Handler")));

static CM4_BOOT_TEXT void copy_words(uint32_t *dst, const uint32_t *src, const uint32_t *end)
{
  while (dst < end) {
    *dst++ = *src++;
  }
}

static CM4_BOOT_TEXT void fill_words(uint32_t *dst, const uint32_t *end, uint32_t v)
{
  while (dst < end) {
    *dst++ = v;
  }
}

static CM4_BOOT_TEXT void zero_words(uint32_t *dst, const uint32_t *end)
{
  fill_words(dst, end, 0u);
}

/* Words of the stack left unpainted below Reset_Handler's stack pointer: its own frame
 * and that of fill_words. */
#define PAINT_GUARD_WORDS 16u

CM4_BOOT_TEXT void Reset_Handler(void)
{
  CPACR |= CPACR_CP10_CP11_FULL;
  cm4_dsb();
  cm4_isb();

  uintptr_t sp;
  __asm volatile("mov %0, sp" : "=r"(sp));
  fill_words(_sstack, (const uint32_t *)(sp & ~(uintptr_t)3u) - PAINT_GUARD_WORDS,
             CM4_STACK_PAINT);

  copy_words(_sdata, _sidata, _edata);
  copy_words(_sramfunc, _siramfunc, _eramfunc);
  copy_words(_sccm_data, _siccm_data, _eccm_data);
  zero_words(_sbss, _ebss);
  zero_words(_sccm_bss, _eccm_bss);

  const uint32_t *vec = (const uint32_t *)(const void *)cm4_vectors;
  copy_words(_sram_vectors, vec, _sram_vectors + cm4_num_vectors);
  SCB->VTOR = (uint32_t)(uintptr_t)_sram_vectors;
  cm4_dsb();
  cm4_isb();

  board_system_init();
  (void)main();
  for (;;) {
  }
}

/* No heap: the firmware never allocates, and anything that tries gets ENOMEM. */
void *_sbrk(int incr)
{
  (void)incr;
  errno = ENOMEM;
  return (void *)-1;
}
