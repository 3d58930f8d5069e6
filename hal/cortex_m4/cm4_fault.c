#include "cm4_fault.h"

#include "cm4_core.h"
#include "cm4_regs.h"

#ifdef CM4_HOST_TEST
static cm4_fault_record_t s_record;
#else
static cm4_fault_record_t s_record __attribute__((section(".noinit")));
#endif

static uint32_t record_check(const cm4_fault_record_t *r)
{
  return r->magic ^ r->count ^ r->pc ^ r->cfsr;
}

int cm4_fault_get(cm4_fault_record_t *out)
{
  if (s_record.magic != CM4_FAULT_MAGIC || s_record.check != record_check(&s_record)) {
    return 0;
  }
  if (out != 0) *out = s_record;
  return 1;
}

void cm4_fault_clear(void)
{
  s_record.magic = 0u;
  s_record.check = 0u;
}

void cm4_fault_enable(void)
{
  SCB->SHCSR |= SCB_SHCSR_MEMFAULTENA | SCB_SHCSR_BUSFAULTENA | SCB_SHCSR_USGFAULTENA;
  SCB->CCR |= SCB_CCR_DIV_0_TRP;
}

CM4_BOOT_TEXT void cm4_fault_capture(const uint32_t *frame, uint32_t exc_return,
                                     uint32_t exc_number)
{
  const uint32_t previous = cm4_fault_get(0) ? s_record.count : 0u;
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
  s_record.magic = CM4_FAULT_MAGIC;
  s_record.check = record_check(&s_record);
  cm4_system_reset();
}
