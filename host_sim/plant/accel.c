#include "plant/accel.h"

#include <math.h>
#include <string.h>

void accel_default_cfg(accel_cfg_t *cfg)
{
  memset(cfg, 0, sizeof *cfg);
  cfg->drive_mps2_per_g[ACCEL_AXIS_DRIVE] = -ACCEL_G0_MPS2;
  cfg->sense_mps2_per_g[ACCEL_AXIS_SENSE] = -ACCEL_G0_MPS2;
}

int accel_init(accel_t *a, const accel_cfg_t *cfg)
{
  if (a == NULL || cfg == NULL) return -1;
  for (int i = 0; i < 3; i++) {
    const double d = cfg->drive_mps2_per_g[i], s = cfg->sense_mps2_per_g[i];
    if (!(isfinite(d) && isfinite(s) && fabs(d) <= 100.0 * ACCEL_G0_MPS2 &&
          fabs(s) <= 100.0 * ACCEL_G0_MPS2))
      return -1;
  }
  a->cfg = *cfg;
  return 0;
}

void accel_step(const accel_t *a, const double a_g[3], accel_out_t *out)
{
  double fd = 0.0, fs = 0.0;
  for (int i = 0; i < 3; i++) {
    fd += a->cfg.drive_mps2_per_g[i] * a_g[i];
    fs += a->cfg.sense_mps2_per_g[i] * a_g[i];
  }
  if (!(isfinite(fd) && isfinite(fs))) {
    fd = 0.0;
    fs = 0.0;
  }
  out->f_drive_mps2 = fd;
  out->f_sense_mps2 = fs;
}
