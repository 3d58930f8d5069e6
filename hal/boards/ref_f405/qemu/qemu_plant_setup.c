#include "qemu_plant_setup.h"

int qemu_plant_setup(plant_t *p, plant_profiles_t *prof)
{
  plant_cfg_t cfg;
  plant_default_cfg(&cfg);
  const int rc = plant_init(p, &cfg, QEMU_PLANT_SEED);
  if (rc != 0) return rc;
  *prof = p->prof; /* constant ambient at temp_k, no acceleration */
  const double dur_s[2] = {QEMU_PLANT_STEP_S, 1.0};
  const double rate_dps[2] = {0.0, QEMU_PLANT_STEP_DPS};
  if (profile_steps(&prof->rate_dps, 2, dur_s, rate_dps, QEMU_PLANT_EDGE_S, 0) != 0) return -2;
  return plant_set_profiles(p, prof) != 0 ? -2 : 0;
}

int qemu_plant_rate_ramp(plant_t *p, plant_profiles_t *prof, double rate_dps)
{
  if (!(rate_dps >= -1e4 && rate_dps <= 1e4)) return -1; /* plant_cfg rate_dps range */
  const double t_s = (double)p->k * p->T;
  const double from_dps = profile_eval(&prof->rate_dps, t_s, 0);
  plant_profiles_t next = *prof;
  profile_ramp(&next.rate_dps, from_dps, (rate_dps - from_dps) / QEMU_PLANT_EDGE_S, t_s,
               t_s + QEMU_PLANT_EDGE_S);
  if (plant_set_profiles(p, &next) != 0) return -1;
  *prof = next;
  return 0;
}
