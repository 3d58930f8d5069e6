/* The output-integrity battery's judge (test_cl_integrity, and the slow variants in
 * tests/slow): every block's output on the plant, against the rule
 *   - once the rate has first been valid, no block has rate_valid = 1 with
 *     |rate - true rate| > max(1 deg/s, 1 % of the input);
 *   - whenever the rate is not valid, the analog rate output is commanded to the fault
 *     level rate.fault_out_v in the same block (never the 0 V of "no rotation").
 * Header-only (static), on the app-on-plant harness. */
#ifndef INTEGRITY_JUDGE_H
#define INTEGRITY_JUDGE_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "selfcal_harness.h"

typedef struct {
  uint32_t blocks, valid_blocks, valid_after_0p3, blocks_after_0p3;
  uint32_t wrong_valid;  /* valid blocks with a wrong rate, once first valid */
  uint32_t not_at_fault; /* invalid blocks whose analog output is not the fault level */
  double first_valid_s;
  double worst_err_dps, worst_err_t_s;
  double t0_s; /* power-on of this run */
} judge_t;

static inline int rate_valid_now(void)
{
  return (app.gyro.out.flags & GYRO_FLAG_RATE_VALID) != 0u;
}

static inline double analog_out_v(void)
{
  return ((double)app.gyro.rate_code - (double)HAL_DAC_CODE_MID) * (double)HAL_DAC_V_PER_CODE;
}

/* The fault level as the DAC can command it (one code of the 14-bit converter). */
static inline int at_fault_level(void)
{
  const double fault_v = (double)params_current(&app.params)->rate_fault_out_v;
  return fabs(analog_out_v() - fault_v) <= (double)HAL_DAC_V_PER_CODE;
}

static inline void judge_reset(judge_t *j)
{
  memset(j, 0, sizeof *j);
  j->first_valid_s = -1.0;
  j->t0_s = (double)plant_truth(&plant)->sample / 50000.0;
}

/* Run s seconds block by block (the snapshot and the analog code change together on the
 * block's last tick), the background loop polled every millisecond. */
static inline void judge_run(judge_t *j, double s)
{
  const uint64_t n = (uint64_t)(s * 5000.0 + 0.5);
  for (uint64_t i = 0; i < n; i++) {
    hal_host_run(GYRO_BLOCK);
    if (i % 5u == 4u) app_poll(&app);
    const double t = (double)plant_truth(&plant)->sample / 50000.0 - j->t0_s;
    const int valid = rate_valid_now();
    j->blocks++;
    if (t >= 0.3) {
      j->blocks_after_0p3++;
      if (valid) j->valid_after_0p3++;
    }
    if (!valid) {
      if (!at_fault_level()) j->not_at_fault++;
      continue;
    }
    j->valid_blocks++;
    if (j->first_valid_s < 0.0) j->first_valid_s = t;
    const double truth = plant_truth(&plant)->rate_dps;
    const double err = fabs((double)app.gyro.out.rate_dps - truth);
    if (err > fmax(1.0, 0.01 * fabs(truth))) j->wrong_valid++;
    if (err > j->worst_err_dps) {
      j->worst_err_dps = err;
      j->worst_err_t_s = t;
    }
  }
}

static inline void judge_print(const char *name, const judge_t *j)
{
  printf("# %-28s valid %5.1f %% (first at %.3f s), wrong-but-valid blocks %u (worst "
         "valid error %.3g deg/s at %.3f s), invalid blocks off the fault level %u, mode %u "
         "fault 0x%x\n",
         name, 100.0 * j->valid_blocks / (j->blocks ? j->blocks : 1u), j->first_valid_s,
         j->wrong_valid, j->worst_err_dps, j->worst_err_t_s, j->not_at_fault,
         (unsigned)app.gyro.sup.mode, (unsigned)app.gyro.sup.fault);
}

static inline void judge_assert(const judge_t *j)
{
  assert_int_equal(j->wrong_valid, 0u);
  assert_int_equal(j->not_at_fault, 0u);
}

static inline void start_part(const plant_cfg_t *pc, const param_values_t *v)
{
  app_plant_start(pc, 31u, v);
}

/* One case: part pc, firmware values v (NULL: the defaults), s seconds from power-on. */
static inline void run_case(const char *name, const plant_cfg_t *pc, const param_values_t *v,
                            double s)
{
  judge_t j;
  start_part(pc, v);
  judge_reset(&j);
  judge_run(&j, s);
  judge_print(name, &j);
  judge_assert(&j);
}

#endif /* INTEGRITY_JUDGE_H */
