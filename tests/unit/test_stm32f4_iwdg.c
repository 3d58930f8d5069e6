/* Independent watchdog (hal/stm32f4/stm32f4_iwdg.c): prescaler/reload for a timeout,
 * t = 4 * 2^PR * (RLR + 1) / f_LSI (RM0090 §21.3), and the start sequence. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "stm32f4_host_regs.h"
#include "stm32f4_iwdg.h"

static double timeout_ms(const stm32f4_iwdg_plan_t *p, double lsi_hz)
{
  return 4.0 * (double)(1u << p->pr) * (p->rlr + 1u) / lsi_hz * 1000.0;
}

static void test_plans(void **state)
{
  (void)state;
  stm32f4_iwdg_plan_t p;
  assert_int_equal(stm32f4_iwdg_plan(32000u, 250u, &p), 0);
  assert_int_equal(p.pr, 0);
  assert_int_equal(p.rlr, 1999);
  assert_true(timeout_ms(&p, 32000.0) >= 250.0);
  assert_int_equal(stm32f4_iwdg_plan(32000u, 1000u, &p), 0);
  assert_int_equal(p.pr, 1);
  assert_int_equal(p.rlr, 3999);
  const uint32_t ms[] = {1u, 7u, 100u, 513u, 2000u, 10000u, 32000u};
  for (size_t i = 0; i < sizeof(ms) / sizeof(ms[0]); ++i) {
    assert_int_equal(stm32f4_iwdg_plan(32000u, ms[i], &p), 0);
    assert_true(p.pr <= 6u && p.rlr <= 4095u);
    assert_true(timeout_ms(&p, 32000.0) >= ms[i]);
    assert_true(timeout_ms(&p, 32000.0) < ms[i] + 4.0 * (1u << p.pr) / 32.0 + 1e-9);
  }
  assert_int_equal(stm32f4_iwdg_plan(32000u, 40000u, &p), -1); /* > 32.8 s */
  assert_int_equal(stm32f4_iwdg_plan(32000u, 0u, &p), -1);
  assert_int_equal(stm32f4_iwdg_plan(32000u, 10u, NULL), -1);
}

static void test_start(void **state)
{
  (void)state;
  stm32f4_host_reset();
  const stm32f4_iwdg_plan_t p = {3u, 1234u};
  stm32f4_iwdg_start(&p);
  assert_int_equal(IWDG->PR, 3);
  assert_int_equal(IWDG->RLR, 1234);
  assert_int_equal(IWDG->KR, IWDG_KEY_RELOAD);
  IWDG->KR = 0u;
  stm32f4_iwdg_kick();
  assert_int_equal(IWDG->KR, IWDG_KEY_RELOAD);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plans),
      cmocka_unit_test(test_start),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
