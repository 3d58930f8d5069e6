/* Critical sections (hal/cortex_m4/cm4_critical.c) on the emulated PRIMASK: masked
 * inside, nestable, and the caller's state restored on exit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "hal/hal_critical.h"
#include "stm32f4_host_regs.h"

static void test_nesting(void **state)
{
  (void)state;
  stm32f4_host_reset();
  const uint32_t outer = hal_critical_enter();
  assert_int_equal(outer, 0);
  assert_int_equal(cm4_host_map.primask, 1);
  const uint32_t inner = hal_critical_enter();
  assert_int_equal(inner, 1);
  hal_critical_exit(inner);
  assert_int_equal(cm4_host_map.primask, 1); /* still inside the outer section */
  hal_critical_exit(outer);
  assert_int_equal(cm4_host_map.primask, 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_nesting)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
