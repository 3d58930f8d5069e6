/* Fault record (hal/cortex_m4/cm4_fault.c): what the HardFault path stores, that it
 * asks for a reset, and that only a complete record reads back. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "cm4_fault.h"
#include "stm32f4_host_regs.h"

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  cm4_fault_clear();
  return 0;
}

static void test_capture_records_frame_and_resets(void **state)
{
  (void)state;
  const uint32_t frame[8] = {1u, 2u, 3u, 4u, 12u, 0x0800C123u, 0x0800D324u, 0x61000000u};
  SCB->CFSR = 0x00010000u; /* UNDEFINSTR */
  SCB->HFSR = 0x40000000u;
  SCB->BFAR = 0xDEADBEEFu;
  cm4_fault_record_t r;
  assert_int_equal(cm4_fault_get(&r), 0);
  cm4_fault_capture(frame, 0xFFFFFFF9u, 6u);
  assert_int_equal(SCB->AIRCR, SCB_AIRCR_VECTKEY | SCB_AIRCR_SYSRESETREQ);
  assert_int_equal(cm4_fault_get(&r), 1);
  assert_int_equal(r.magic, CM4_FAULT_MAGIC);
  assert_int_equal(r.count, 1);
  assert_int_equal(r.exc_number, 6);
  assert_int_equal(r.r0, 1u);
  assert_int_equal(r.r12, 12u);
  assert_int_equal(r.lr, 0x0800C123u);
  assert_int_equal(r.pc, 0x0800D324u);
  assert_int_equal(r.xpsr, 0x61000000u);
  assert_int_equal(r.cfsr, 0x00010000u);
  assert_int_equal(r.hfsr, 0x40000000u);
  assert_int_equal(r.bfar, 0xDEADBEEFu);
  assert_int_equal(r.exc_return, 0xFFFFFFF9u);

  cm4_fault_capture(frame, 0xFFFFFFF9u, 3u);
  assert_int_equal(cm4_fault_get(&r), 1);
  assert_int_equal(r.count, 2); /* counts across resets until cleared */
  assert_int_equal(r.exc_number, 3);

  cm4_fault_clear();
  assert_int_equal(cm4_fault_get(&r), 0);
  assert_int_equal(cm4_fault_get(NULL), 0);
}

static void test_enable_sets_handlers(void **state)
{
  (void)state;
  cm4_fault_enable();
  assert_int_equal(SCB->SHCSR & 0x70000u, 0x70000u);
  assert_true((SCB->CCR & SCB_CCR_DIV_0_TRP) != 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_capture_records_frame_and_resets, setup),
      cmocka_unit_test_setup(test_enable_sets_handlers, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
