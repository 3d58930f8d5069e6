/* The default part as its calibration left it: host_sim/parts/default/calibration.json,
 * made by the product's calibration flow (tools/calibrate; the file says with which
 * command), loaded onto the firmware's generic defaults as if from flash. The
 * closed-loop tests of the default part start from it; the firmware's defaults alone
 * are an uncalibrated part (`calibrated no`, its rate never valid). */
#ifndef DEFAULT_PART_H
#define DEFAULT_PART_H

#include "paramset/param_set.h"

static inline void default_part_values(param_values_t *v)
{
  param_values_defaults(v);
  char err[256];
  if (param_set_load_file(GYRO_DEFAULT_PART_CAL, v, NULL, err, sizeof err) != 0) {
    fail_msg("default part's calibration: %s", err);
  }
}

#endif /* DEFAULT_PART_H */
