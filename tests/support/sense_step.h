/* The closed-loop sense tests' rate step: 20 ms at rest, then the plant's rate held at
 * step_dps, 0.1 s of blocks. Header-only, on the harness of app_plant.h. */
#ifndef SENSE_STEP_H
#define SENSE_STEP_H

#include <math.h>

#include "app_plant.h"

#define SENSE_STEP_BLOCK_S ((double)GYRO_BLOCK / 50000.0)
#define SENSE_STEP_N_AFTER 500 /* 0.1 s of blocks */

/* The last block outside 1 % of the step around the final value (the mean of the last
 * 20 ms), ms after the step; *final_dps that mean, *rest_dps the mean of the 20 ms before
 * the step (the bias: the quadrature a feedback phase error turns into the rate). */
static inline double sense_step_settle_ms(double step_dps, double *final_dps, double *rest_dps)
{
  static float rate[SENSE_STEP_N_AFTER];
  const int tail = (int)(0.020 / SENSE_STEP_BLOCK_S);
  *rest_dps = 0.0;
  for (int n = 0; n < tail; n++) {
    hal_host_run(GYRO_BLOCK);
    *rest_dps += (double)app.gyro.out.rate_dps / tail;
  }
  app_plant_hold_rate(step_dps);
  for (int n = 0; n < SENSE_STEP_N_AFTER; n++) {
    hal_host_run(GYRO_BLOCK);
    rate[n] = app.gyro.out.rate_dps;
  }
  double fin = 0.0;
  for (int i = SENSE_STEP_N_AFTER - tail; i < SENSE_STEP_N_AFTER; i++)
    fin += (double)rate[i] / tail;
  double settle_ms = 0.0;
  for (int i = 0; i < SENSE_STEP_N_AFTER; i++)
    if (fabs((double)rate[i] - fin) > 0.01 * fabs(step_dps))
      settle_ms = (i + 1) * SENSE_STEP_BLOCK_S * 1e3;
  *final_dps = fin;
  return settle_ms;
}

#endif /* SENSE_STEP_H */
