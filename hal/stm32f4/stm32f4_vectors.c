/* Vector table of the STM32F405 (RM0090 table 61: 16 core exceptions and 82
 * interrupts), in .isr_vector at the start of flash; Reset_Handler and the fault entry
 * are the core's (hal/cortex_m4/cm4_startup.c). */
#include <stdint.h>

#include "cm4_fault.h"
#include "cm4_startup.h"
#include "stm32f4_core.h"

#define NUM_VECTORS (16u + STM32F4_NUM_IRQS)

/* Linker-script symbol (linker/stm32f405.ld): the top of the main stack. */
extern uint32_t _estack[];

/* Handlers an image may provide; an image that does not falls back to Default_Handler
 * (cm4_startup.c), which records the unexpected interrupt like a fault. A weak stub
 * branches there without touching LR or the stack, so the fault record sees the
 * interrupt's own EXC_RETURN and IPSR. */
#define WEAK_TO_DEFAULT(name) \
  __attribute__((weak, naked)) CM4_BOOT_TEXT void name(void) \
  { \
    __asm volatile("b Default_Handler\n"); \
  }
void SysTick_Handler(void);
void USART1_IRQHandler(void);
void DMA2_Stream0_IRQHandler(void);
WEAK_TO_DEFAULT(SysTick_Handler)
WEAK_TO_DEFAULT(USART1_IRQHandler)
WEAK_TO_DEFAULT(DMA2_Stream0_IRQHandler)

#define D \
  { \
    .fn = Default_Handler \
  }
#define D8 D, D, D, D, D, D, D, D

__attribute__((section(".isr_vector"), used)) const cm4_vector_t cm4_vectors[] = {
    {.sp = _estack},
    {.fn = Reset_Handler},
    D, /* NMI */
    {.fn = HardFault_Handler},
    {.fn = HardFault_Handler}, /* MemManage */
    {.fn = HardFault_Handler}, /* BusFault */
    {.fn = HardFault_Handler}, /* UsageFault */
    {.fn = 0},
    {.fn = 0},
    {.fn = 0},
    {.fn = 0},
    D, /* SVCall */
    D, /* DebugMonitor */
    {.fn = 0},
    D, /* PendSV */
    {.fn = SysTick_Handler},
    /* IRQ 0..39 */
    D8,
    D8,
    D8,
    D8,
    D,
    D,
    D,
    D,
    D,
    {.fn = USART1_IRQHandler} /* 37 */,
    D,
    D,
    /* IRQ 40..55 */
    D8,
    D8,
    /* IRQ 56..81 */
    {.fn = DMA2_Stream0_IRQHandler} /* 56 */,
    D,
    D,
    D,
    D,
    D,
    D,
    D,
    D8,
    D8,
    D,
    D,
};

_Static_assert(sizeof(cm4_vectors) == 4u * NUM_VECTORS,
               "one entry per core exception and per interrupt");

const uint32_t cm4_num_vectors = NUM_VECTORS;
