/* Self-calibration of vacuum-grade parts (issue 15, item 3): at Q = 10^3 the nine settled
 * steps, at Q = 10^4 the ring-down alone identifies the part, each within 60 s of
 * simulated time, the undamped resonance at the structure temperature within
 * max(0.01 Hz, f0 / (100 Q)) and Q within 2 % of the plant's. Q = 10^4 is beyond the
 * fixed-frequency drive's reach (SELFCAL_Q_FIXED_MAX): the sweep says so. Q = 5000 and
 * 10^5 are in tests/slow/test_selfcal_vacuum.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "selfcal_harness.h"

static void test_q_1e3(void **state)
{
  (void)state;
  high_q_case(1.0e3);
}

static void test_q_1e4(void **state)
{
  (void)state;
  high_q_case(1.0e4);
}

/* A thesis-preset part of the vacuum lot (examples/lot/vacuum_quick16.json, part 7:
 * 1474.52 Hz, Q 13345): its ring-down's gain under-estimated the resonance's, the burst
 * drove the vibration past the ADC budget in 86 ms, and the exec halved the force on
 * every tick the stored vibration stayed above it (615 times, to 0): "no response at the
 * resonance". Failed so before; now the burst waits for the vibration to decay and
 * bursts again with less force. */
static void test_burst_over_budget(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_default_cfg(&pc);
  pc.f_drive_hz = 1474.5234585971245;
  pc.q_drive = 13344.8;
  vacuum_part_case(&pc);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_q_1e3),
      cmocka_unit_test(test_q_1e4),
      cmocka_unit_test(test_burst_over_budget),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
