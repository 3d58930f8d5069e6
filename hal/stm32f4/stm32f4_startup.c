/* Reset entry and vector table of the STM32F405 (RM0090 table 61: 16 core exceptions
 * and 82 interrupts).
 *
 * Reset_Handler, in this order: FPU access on (CPACR CP10/CP11) before any code that
 * may touch a float register; the main stack below its own frame painted for the
 * high-water mark (stm32f4_stack.h); .data, .ramfunc and .ccm_data copied from their load
 * addresses in flash; .bss and .ccm_bss zeroed (.noinit, the fault record, is left
 * alone); the vector table copied to SRAM and VTOR pointed at it, so that interrupts
 * keep being dispatched while a flash erase stalls fetches from flash; then
 * stm32f4_system_init (clock tree, fault handlers, cycle counter: per image) and main. */
#include <errno.h>
#include <stdint.h>

#include "stm32f4_board.h"
#include "stm32f4_core.h"
#include "stm32f4_fault.h"
#include "stm32f4_stack.h"
#include "stm32f4_regs.h"

#define NUM_VECTORS (16u + STM32F4_NUM_IRQS)

/* Linker-script symbols (linker/stm32f405.ld). */
extern uint32_t _sstack[], _estack[];
extern uint32_t _sidata[], _sdata[], _edata[];
extern uint32_t _siramfunc[], _sramfunc[], _eramfunc[];
extern uint32_t _siccm_data[], _sccm_data[], _eccm_data[];
extern uint32_t _sbss[], _ebss[];
extern uint32_t _sccm_bss[], _eccm_bss[];
extern uint32_t _sram_vectors[];

int main(void);
void Reset_Handler(void);
void *_sbrk(int incr);

typedef union {
  void (*fn)(void);
  void *sp;
} vector_t;

/* Handlers an image may provide; an image that does not falls back to Default_Handler,
 * which records the unexpected interrupt like a fault. */
__attribute__((naked)) STM32F4_BOOT_TEXT void Default_Handler(void)
{
  __asm volatile(
      "tst lr, #4\n"
      "ite eq\n"
      "mrseq r0, msp\n"
      "mrsne r0, psp\n"
      "mov r1, lr\n"
      "mrs r2, ipsr\n"
      "ldr r3, =stm32f4_fault_capture\n"
      "bx r3\n");
}
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void USART1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
void DMA2_Stream0_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

#define D {.fn = Default_Handler}
#define D8 D, D, D, D, D, D, D, D

__attribute__((section(".isr_vector"), used)) const vector_t stm32f4_vectors[] = {
    {.sp = _estack},
    {.fn = Reset_Handler},
    D,                           /* NMI */
    {.fn = HardFault_Handler},
    {.fn = HardFault_Handler},   /* MemManage */
    {.fn = HardFault_Handler},   /* BusFault */
    {.fn = HardFault_Handler},   /* UsageFault */
    {.fn = 0}, {.fn = 0}, {.fn = 0}, {.fn = 0},
    D,                           /* SVCall */
    D,                           /* DebugMonitor */
    {.fn = 0},
    D,                           /* PendSV */
    {.fn = SysTick_Handler},
    /* IRQ 0..39 */
    D8, D8, D8, D8, D, D, D, D, D, {.fn = USART1_IRQHandler} /* 37 */, D, D,
    /* IRQ 40..55 */
    D8, D8,
    /* IRQ 56..81 */
    {.fn = DMA2_Stream0_IRQHandler} /* 56 */, D, D, D, D, D, D, D,
    D8, D8, D, D,
};

_Static_assert(sizeof(stm32f4_vectors) == 4u * NUM_VECTORS, "one entry per core exception and per interrupt");

static STM32F4_BOOT_TEXT void copy_words(uint32_t *dst, const uint32_t *src, const uint32_t *end)
{
  while (dst < end) {
    *dst++ = *src++;
  }
}

static STM32F4_BOOT_TEXT void fill_words(uint32_t *dst, const uint32_t *end, uint32_t v)
{
  while (dst < end) {
    *dst++ = v;
  }
}

static STM32F4_BOOT_TEXT void zero_words(uint32_t *dst, const uint32_t *end)
{
  fill_words(dst, end, 0u);
}

/* Words of the stack left unpainted below Reset_Handler's stack pointer: its own frame
 * and that of fill_words. */
#define PAINT_GUARD_WORDS 16u

STM32F4_BOOT_TEXT void Reset_Handler(void)
{
  CPACR |= CPACR_CP10_CP11_FULL;
  stm32f4_dsb();
  stm32f4_isb();

  uintptr_t sp;
  __asm volatile("mov %0, sp" : "=r"(sp));
  fill_words(_sstack, (const uint32_t *)(sp & ~(uintptr_t)3u) - PAINT_GUARD_WORDS,
             STM32F4_STACK_PAINT);

  copy_words(_sdata, _sidata, _edata);
  copy_words(_sramfunc, _siramfunc, _eramfunc);
  copy_words(_sccm_data, _siccm_data, _eccm_data);
  zero_words(_sbss, _ebss);
  zero_words(_sccm_bss, _eccm_bss);

  const uint32_t *vec = (const uint32_t *)(const void *)stm32f4_vectors;
  copy_words(_sram_vectors, vec, _sram_vectors + NUM_VECTORS);
  SCB->VTOR = (uint32_t)(uintptr_t)_sram_vectors;
  stm32f4_dsb();
  stm32f4_isb();

  stm32f4_system_init();
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
