/* Scenario -> plant configuration, input profiles and firmware parameters. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "paramset/param_set.h"
#include "sim.h"

/* The thermal presets by number, as plant.thermal_preset takes them. */
static const char *const kThermalPresets[] = {"default", "tight", "loose"};

void sim_list_params(FILE *f)
{
  fprintf(f, "# plant parameters (plant.KEY)\n");
  plant_cfg_t c;
  plant_default_cfg(&c);
  for (size_t i = 0; i < plant_param_count(); i++) {
    const plant_param_desc_t *d = plant_param_at(i);
    fprintf(f, "plant.%-40s %-12g [%g, %g] %s  %s\n", d->name, plant_param_get(&c, d), d->min,
            d->max, d->unit, d->doc);
  }
  /* not a field of the plant: a set of them (thermal.h), applied where it stands among
   * the settings, so later tau_*, couple_*, rise_* settings override it */
  fprintf(f, "plant.%-40s %-12g [%g, %g] %s  %s\n", "thermal_preset", 0.0, 0.0, 2.0, "",
          "thermal network preset: 0 default, 1 tight, 2 loose (sets tau_*, couple_*, rise_*)");
  /* a name, not a number: the part the other plant settings start from (applied first,
   * wherever it stands among them) */
  fprintf(f, "plant.%-40s %-12s [%s] %s  %s\n", "preset", "thesis", "thesis, ideal", "",
          "part preset: thesis (the default part, with the thesis's measured imperfections) or "
          "ideal (every imperfection off); applied first, other plant settings override it");
  fprintf(f, "# firmware parameters (firmware.NAME)\n");
  param_values_t v;
  param_values_defaults(&v);
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    const param_value_t x = param_get(&v, (param_idx_t)i);
    if (pi->type == PARAM_T_F32) {
      fprintf(f, "firmware.%-37s %-12g [%g, %g] %s  %s\n", pi->name, (double)x.f,
              (double)pi->min.f, (double)pi->max.f, pi->unit, pi->help);
    } else {
      fprintf(f, "firmware.%-37s %-12u [%u, %u] %s  %s\n", pi->name, x.u, pi->min.u, pi->max.u,
              pi->unit, pi->help);
    }
  }
}

int sim_plant_cfg(const sim_scenario_t *sc, plant_cfg_t *cfg, plant_profiles_t *prof, char *err,
                  size_t err_len)
{
  plant_cfg_t c;
  /* the part preset first, whatever its place among the settings: the scenario's and
   * the command line's other plant settings then override it */
  if (sc->plant_preset[0] == '\0') {
    plant_default_cfg(&c);
  } else if (plant_preset(&c, sc->plant_preset) != 0) {
    snprintf(err, err_len, "plant.preset: '%s' is not a plant preset: %s", sc->plant_preset,
             PLANT_PRESET_NAMES);
    return -1;
  }
  for (int i = 0; i < sc->n_plant_set; i++) {
    const sim_set_t *s = &sc->plant_set[i];
    /* "thermal_preset" selects a coupling preset (tight/loose/default) by number. */
    if (strcmp(s->key, "thermal_preset") == 0) {
      const double v = s->value;
      const int k = (v >= 0.0 && v <= 2.0) ? (int)v : -1;
      if (k < 0 || v != (double)k || plant_thermal_preset(&c, kThermalPresets[k]) != 0) {
        snprintf(err, err_len,
                 "plant.thermal_preset: %g is not 0 (default), 1 (tight) or 2 (loose)", s->value);
        return -1;
      }
      continue;
    }
    char why[256];
    if (plant_param_set(&c, s->key, s->value, why, sizeof why) != 0) {
      snprintf(err, err_len, "plant.%s", why);
      return -1;
    }
  }
  char why[256];
  if (plant_cfg_check(&c, why, sizeof why) != 0) {
    snprintf(err, err_len, "plant: %s", why);
    return -1;
  }
  /* every band ends below 0.45 fs (vib.h), fs_hz being a parameter too */
  const accel_profile_t *acc = &sc->accel_g;
  for (int j = 0; sc->has_accel && j < acc->n_bands; j++) {
    if (!(acc->band_f_hi_hz[j] < 0.45 * c.fs_hz)) {
      snprintf(err, err_len,
               "accel_g.random[%d].f_hi_hz: %g Hz must be below 0.45 plant.fs_hz (%g Hz)", j,
               acc->band_f_hi_hz[j], 0.45 * c.fs_hz);
      return -1;
    }
  }
  memset(prof, 0, sizeof *prof);
  if (sc->has_rate) prof->rate_dps = sc->rate_dps;
  else profile_const(&prof->rate_dps, c.rate_dps);
  if (sc->has_ambient) prof->ambient_k = sc->ambient_c; /* parsed into kelvin */
  else profile_const(&prof->ambient_k, c.temp_k);
  if (sc->has_accel) prof->accel_g = sc->accel_g;
  else accel_profile_zero(&prof->accel_g);
  /* The run starts with the thermal nodes settled at the ambient of t = 0 (with
   * plant.cold_start, all at that ambient: plant_init). */
  c.temp_k = profile_eval(&prof->ambient_k, 0.0, NULL);
  *cfg = c;
  return 0;
}

int sim_fw_params(const sim_scenario_t *sc, param_values_t *v, char *err, size_t err_len)
{
  param_values_t t;
  param_values_defaults(&t);
  /* the parameter set first (as flash would hold it), then the settings over it */
  if (sc->fw_params_path[0] != '\0') {
    char why[480];
    if (param_set_load_file(sc->fw_params_path, &t, NULL, why, sizeof why) != 0) {
      snprintf(err, err_len, "firmware parameter set %s", why);
      return -1;
    }
  }
  for (int i = 0; i < sc->n_fw_set; i++) {
    const sim_set_t *s = &sc->fw_set[i];
    const param_idx_t idx = param_lookup(s->key, strlen(s->key));
    const param_info_t *pi = param_info(idx);
    if (pi == NULL) {
      snprintf(err, err_len, "firmware.%s: unknown parameter", s->key);
      return -1;
    }
    param_value_t val;
    if (pi->type == PARAM_T_F32) {
      val.f = (float)s->value;
    } else {
      if (s->value < 0.0 || s->value > 4294967295.0 || s->value != floor(s->value)) {
        snprintf(err, err_len, "firmware.%s: %g is not an unsigned integer", s->key, s->value);
        return -1;
      }
      val.u = (uint32_t)s->value;
    }
    const param_status_t st = param_check(idx, val);
    if (st != PARAM_OK) {
      if (pi->type == PARAM_T_F32) {
        snprintf(err, err_len, "firmware.%s: %g is not allowed (%s); range [%g, %g] %s", s->key,
                 s->value, param_status_str(st), (double)pi->min.f, (double)pi->max.f, pi->unit);
      } else {
        snprintf(err, err_len, "firmware.%s: %g is not allowed (%s); range [%u, %u] %s", s->key,
                 s->value, param_status_str(st), pi->min.u, pi->max.u, pi->unit);
      }
      return -1;
    }
    param_put(&t, idx, val);
  }
  gyro_design_t d;
  if (gyro_design(&t, &d) != 0) {
    snprintf(err, err_len,
             "firmware: these parameter values cannot be designed (drive loops or output filter)");
    return -1;
  }
  *v = t;
  return 0;
}
