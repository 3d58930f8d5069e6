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

int qemu_plant_setup_part(plant_t *p, plant_profiles_t *prof, int part)
{
  plant_cfg_t cfg;
  plant_default_cfg(&cfg);
  if (part == QEMU_PART_FR) {
    cfg.f_sense_hz = QEMU_PART_FR_F_SENSE_HZ;
    cfg.q_sense = QEMU_PART_FR_Q_SENSE;
    cfg.fb_mode = 3;
    cfg.ks_fb_mps2_per_v2 = QEMU_PART_FR_KS_FB;
  } else if (part != QEMU_PART_DEFAULT) {
    return -3;
  }
  const int rc = plant_init(p, &cfg, QEMU_PLANT_SEED);
  if (rc != 0) return rc;
  *prof = p->prof;
  return 0;
}

int qemu_plant_rate_ramp(plant_t *p, plant_profiles_t *prof, double rate_dps)
{
  if (plant_move_input(p, PLANT_INPUT_RATE, rate_dps, QEMU_PLANT_EDGE_S) != 0) return -1;
  *prof = p->prof;
  return 0;
}
