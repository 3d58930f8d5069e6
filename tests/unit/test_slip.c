/* gyro-sim's phase-slip counter (host_sim/gyro_sim/slip.h): a true slip counts, a phase
 * that is undefined because the force vanished does not. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "slip.h"

static const double kPi = 3.141592653589793;
static const double kDt = 1e-3;

/* Locked at resonance (-90 deg) with a steady force for 2 s. */
static void settle(slip_t *s)
{
  slip_init(s, kDt);
  for (int k = 0; k < 2000; k++) slip_sample(s, 1, 1, -0.5 * kPi, 1.0);
}

/* The force touches zero for a few ms now and then (a Q = 10^5 part's amplitude loop):
 * its fundamental's phase is a residue (here the opposite one), which is no slip. */
static void test_vanishing_force_is_no_slip(void **state)
{
  (void)state;
  slip_t s;
  settle(&s);
  for (int n = 0; n < 50; n++) {
    for (int k = 0; k < 3; k++) slip_sample(&s, 1, 1, 0.95 * kPi, 0.02);
    for (int k = 0; k < 200; k++) slip_sample(&s, 1, 1, -0.5 * kPi, 1.0);
  }
  assert_int_equal(s.count, 0);
}

/* A real slip with the force on: the phase walks 1.1 turns; every 90 deg counts. */
static void test_slip_with_force_counts(void **state)
{
  (void)state;
  slip_t s;
  settle(&s);
  for (int k = 0; k <= 1100; k++)
    slip_sample(&s, 1, 1, -0.5 * kPi - 2.0 * kPi * k / 1000.0, 1.0);
  assert_int_equal(s.count, 4);
}

/* A slip that happens while there is no force is counted when the force returns. */
static void test_slip_during_blind_time_counts(void **state)
{
  (void)state;
  slip_t s;
  settle(&s);
  for (int k = 0; k < 100; k++) slip_sample(&s, 1, 1, 0.0, 0.0);
  for (int k = 0; k < 100; k++) slip_sample(&s, 1, 1, 0.6 * kPi, 1.0);
  assert_int_equal(s.count, 1);
}

/* Not armed before the first lock; disarmed when the drive stops. */
static void test_arming(void **state)
{
  (void)state;
  slip_t s;
  slip_init(&s, kDt);
  for (int k = 0; k < 100; k++) slip_sample(&s, 1, 0, k * 0.1, 1.0); /* ACQUIRE */
  assert_int_equal(s.count, 0);
  assert_int_equal(s.armed, 0);
  settle(&s);
  slip_sample(&s, 0, 0, 0.0, 0.0); /* drive off */
  slip_sample(&s, 1, 0, 0.9 * kPi, 1.0);
  assert_int_equal(s.count, 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_vanishing_force_is_no_slip),
      cmocka_unit_test(test_slip_with_force_counts),
      cmocka_unit_test(test_slip_during_blind_time_counts),
      cmocka_unit_test(test_arming),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
