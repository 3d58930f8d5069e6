/* Output integrity on a high-Q part calibrated by its own `sweep` (22.6 s of simulated
 * time at Q = 5000, then 3 s judged: label slow; test_cl_integrity runs the same case
 * with the values this sweep identifies): the structure 22.5 K warmer than at the sweep,
 * beyond the fixed-frequency drive's reach, and never a valid wrong rate
 * (integrity_judge.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "integrity_judge.h"

static void test_q5000_selfcal_warm(void **state)
{
  (void)state;
  plant_cfg_t pc;
  plant_ideal_cfg(&pc);
  pc.q_drive = 5000.0;
  param_values_t v;
  default_part_values(&v);
  start(&pc, &v);
  run_polled_s(0.05);
  sweep();
  assert_int_equal(app.selfcal.state, SELFCAL_DONE);
  /* The sense mode is the default part's: its rate channel's calibration holds, and is
   * confirmed at the frequency the sweep found (what the calibration flow writes). */
  param_values_t cal = *params_current(&app.params);
  cal.cal_ref_freq_hz = cal.drive_freq_hz;
  pc.temp_k += 22.5;
  app_plant_start(&pc, 31u, &cal);
  judge_t j;
  judge_reset(&j);
  judge_run(&j, 3.0);
  judge_print("Q 5000 self-calibrated, +22.5 K", &j);
  judge_assert(&j);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_q5000_selfcal_warm),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
