#include "stm32f4_fault.h"

#include "stm32f4_core.h"
#include "stm32f4_regs.h"

#ifdef STM32F4_HOST_TEST
static stm32f4_fault_record_t s_record;
#else
static stm32f4_fault_record_t s_record __attribute__((section(".noinit")));
#endif

static uint32_t record_check(const stm32f4_fault_record_t *r)
{
  return r->magic ^ r->count ^ r->pc ^ r->cfsr;
}

int stm32f4_fault_get(stm32f4_fault_record_t *out)
{
  if (s_record.magic != STM32F4_FAULT_MAGIC || s_record.check != record_check(&s_record)) {
    return 0;
  }
  if (out != 0) *out = s_record;
  return 1;
}

void stm32f4_fault_clear(void)
{
  s_record.magic = 0u;
  s_record.check = 0u;
}

void stm32f4_fault_enable(void)
{
  SCB->SHCSR |= SCB_SHCSR_MEMFAULTENA | SCB_SHCSR_BUSFAULTENA | SCB_SHCSR_USGFAULTENA;
  SCB->CCR |= SCB_CCR_DIV_0_TRP;
}

STM32F4_BOOT_TEXT void stm32f4_fault_capture(const uint32_t *frame, uint32_t exc_return,
                                             uint32_t exc_number)
{
  const uint32_t previous = stm32f4_fault_get(0) ? s_record.count : 0u;
  s_record.magic = 0u; /* invalid while half written */
  s_record.count = previous + 1u;
  s_record.exc_number = exc_number;
  s_record.r0 = frame[0];
  s_record.r1 = frame[1];
  s_record.r2 = frame[2];
  s_record.r3 = frame[3];
  s_record.r12 = frame[4];
  s_record.lr = frame[5];
  s_record.pc = frame[6];
  s_record.xpsr = frame[7];
  s_record.cfsr = SCB->CFSR;
  s_record.hfsr = SCB->HFSR;
  s_record.mmfar = SCB->MMFAR;
  s_record.bfar = SCB->BFAR;
  s_record.exc_return = exc_return;
  s_record.magic = STM32F4_FAULT_MAGIC;
  s_record.check = record_check(&s_record);
  stm32f4_dsb();
  SCB->AIRCR = SCB_AIRCR_VECTKEY | SCB_AIRCR_SYSRESETREQ;
  stm32f4_dsb();
#ifndef STM32F4_HOST_TEST
  for (;;) {
  }
#endif
}

#ifndef STM32F4_HOST_TEST
/* Entry for every fault and unexpected interrupt: pick the stack the frame was pushed to
 * (EXC_RETURN bit 2), and hand frame, EXC_RETURN and IPSR to the C capture. Naked: no
 * prologue touches a stack that may be the cause of the fault. */
__attribute__((naked)) STM32F4_BOOT_TEXT void HardFault_Handler(void)
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

#endif
