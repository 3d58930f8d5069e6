#include "scenario.h"

#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plant/plant.h"

static const struct {
  sim_analysis_t bit;
  const char *name;
} analyses[] = {
    {SIM_AN_STARTUP, "startup"},
    {SIM_AN_RATE_TABLE, "rate_table"},
    {SIM_AN_NOISE, "brownian_noise"},
    {SIM_AN_ALLAN, "allan"},
    {SIM_AN_DRIVE_NOISE, "drive_noise"},
    {SIM_AN_TEMP, "temp_comp"},
    {SIM_AN_SWEEP, "sweep"},
    {SIM_AN_SQUARE_LAW, "square_law"},
    {SIM_AN_ALLAN_UNC, "allan_unc"},
};

const char *scenario_analysis_name(sim_analysis_t a)
{
  for (size_t i = 0; i < sizeof analyses / sizeof analyses[0]; i++) {
    if (analyses[i].bit == a) return analyses[i].name;
  }
  return "?";
}

void scenario_defaults(sim_scenario_t *sc)
{
  memset(sc, 0, sizeof *sc);
  snprintf(sc->name, sizeof sc->name, "unnamed");
  sc->duration_s = 1.0;
  sc->seed = 1u;
  sc->loop = SIM_CLOSED_LOOP;
  sc->csv_rate_hz = 1000.0;
  profile_const(&sc->rate_dps, 0.0);
  profile_const(&sc->ambient_c, 25.0);
  accel_profile_zero(&sc->accel_g);
  sc->ol.u_amp_v = 8.0;
  sc->ol.freq_hz = 1489.9;
  sc->ol.f_start_hz = 1400.0;
  sc->ol.f_stop_hz = 1600.0;
  sc->ol.points = 41;
  sc->ol.dwell_s = 0.3;
  sc->ol.settle_s = 0.2;
}

static int fail(char *err, size_t len, const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, len, fmt, ap);
  va_end(ap);
  return -1;
}

/* A finite number within [lo, hi] at key `where`. */
static int get_num(const cJSON *j, const char *where, double lo, double hi, double *out,
                   char *err, size_t len)
{
  if (!cJSON_IsNumber(j) || !isfinite(j->valuedouble)) {
    return fail(err, len, "%s: expected a number in [%g, %g]", where, lo, hi);
  }
  if (j->valuedouble < lo || j->valuedouble > hi) {
    return fail(err, len, "%s: %g is out of range [%g, %g]", where, j->valuedouble, lo, hi);
  }
  *out = j->valuedouble;
  return 0;
}

static int add_set(sim_set_t *arr, int *n, const char *key, double v, const char *where,
                   char *err, size_t len)
{
  if (*n >= SIM_MAX_SETS)
    return fail(err, len, "%s: more than %d settings", where, SIM_MAX_SETS);
  if (strlen(key) >= SIM_NAME_MAX) return fail(err, len, "%s.%s: key too long", where, key);
  for (int i = 0; i < *n; i++) {
    if (strcmp(arr[i].key, key) == 0) {
      arr[i].value = v;
      return 0;
    }
  }
  snprintf(arr[*n].key, SIM_NAME_MAX, "%s", key);
  arr[*n].value = v;
  (*n)++;
  return 0;
}

/* The part preset by name into sc (checked against plant_preset's names). */
static int set_preset(sim_scenario_t *sc, const char *name, const char *where, char *err,
                      size_t len)
{
  plant_cfg_t probe;
  if (name == NULL || strlen(name) >= SIM_NAME_MAX || plant_preset(&probe, name) != 0)
    return fail(err, len, "%s: '%s' is not a plant preset: %s", where, name ? name : "",
                PLANT_PRESET_NAMES);
  snprintf(sc->plant_preset, SIM_NAME_MAX, "%s", name);
  return 0;
}

static int parse_sets(const cJSON *obj, const char *where, sim_set_t *arr, int *n, char *err,
                      size_t len)
{
  if (!cJSON_IsObject(obj))
    return fail(err, len, "%s: expected an object of name: number", where);
  const cJSON *it;
  cJSON_ArrayForEach(it, obj)
  {
    char key[160];
    snprintf(key, sizeof key, "%s.%s", where, it->string);
    if (strcmp(key, "plant.preset") == 0) {
      if (!cJSON_IsString(it))
        return fail(err, len, "plant.preset: expected a name: %s", PLANT_PRESET_NAMES);
      continue; /* applied by scenario_parse (parse_sets has no scenario) */
    }
    double v = 0.0;
    if (cJSON_IsBool(it)) {
      v = cJSON_IsTrue(it) ? 1.0 : 0.0;
    } else if (get_num(it, key, -HUGE_VAL, HUGE_VAL, &v, err, len) != 0) {
      return -1;
    }
    if (add_set(arr, n, it->string, v, where, err, len) != 0) return -1;
  }
  return 0;
}

/* Temperatures are given in degC in scenario files; the plant works in kelvin. */
static int parse_profile(const cJSON *obj, const char *where, double offset, double lo,
                         double hi, profile_t *p, char *err, size_t len)
{
  if (!cJSON_IsObject(obj))
    return fail(err, len, "%s: expected an object with \"kind\"", where);
  const cJSON *kind = cJSON_GetObjectItemCaseSensitive(obj, "kind");
  if (!cJSON_IsString(kind))
    return fail(err, len, "%s.kind: expected const|steps|sine|ramp|heat_cool", where);
  const int k = profile_kind_from_name(kind->valuestring);
  if (k < 0)
    return fail(err, len, "%s.kind: '%s' is not one of const|steps|sine|ramp|heat_cool", where,
                kind->valuestring);
  profile_t t;
  memset(&t, 0, sizeof t);
  t.kind = (profile_kind_t)k;
  static const char *const allowed[] = {"kind",      "value",       "amp",        "freq_hz",
                                        "phase_rad", "slope_per_s", "t_start_s",  "t_end_s",
                                        "hot_value", "heat_s",      "tau_heat_s", "tau_cool_s",
                                        "steps",     "edge_s",      "repeat"};
  const cJSON *it;
  cJSON_ArrayForEach(it, obj)
  {
    int known = 0;
    for (size_t i = 0; i < sizeof allowed / sizeof allowed[0]; i++)
      known |= strcmp(it->string, allowed[i]) == 0;
    if (!known) return fail(err, len, "%s.%s: unknown key", where, it->string);
  }
  char key[128];
#define NUM(field, name, l, h, off) \
  do { \
    const cJSON *j_ = cJSON_GetObjectItemCaseSensitive(obj, name); \
    if (j_ != NULL) { \
      snprintf(key, sizeof key, "%s.%s", where, name); \
      if (get_num(j_, key, l, h, &t.field, err, len) != 0) return -1; \
      t.field += off; \
    } \
  } while (0)
  NUM(value, "value", lo, hi, offset);
  NUM(amp, "amp", -(hi - lo), hi - lo, 0.0);
  NUM(freq_hz, "freq_hz", 0.0, 1e4, 0.0);
  NUM(phase_rad, "phase_rad", -1e3, 1e3, 0.0);
  NUM(slope_per_s, "slope_per_s", -1e6, 1e6, 0.0);
  NUM(t_start_s, "t_start_s", 0.0, 1e7, 0.0);
  NUM(t_end_s, "t_end_s", 0.0, 1e7, 0.0);
  NUM(hot_value, "hot_value", lo, hi, offset);
  NUM(heat_s, "heat_s", 0.0, 1e7, 0.0);
  NUM(tau_heat_s, "tau_heat_s", 1e-6, 1e7, 0.0);
  NUM(tau_cool_s, "tau_cool_s", 1e-6, 1e7, 0.0);
  NUM(edge_s, "edge_s", 0.0, 1e7, 0.0);
#undef NUM
  const cJSON *rep = cJSON_GetObjectItemCaseSensitive(obj, "repeat");
  if (rep != NULL) {
    if (!cJSON_IsBool(rep)) return fail(err, len, "%s.repeat: expected true or false", where);
    t.repeat = cJSON_IsTrue(rep);
  }
  const cJSON *steps = cJSON_GetObjectItemCaseSensitive(obj, "steps");
  if (t.kind == PROFILE_STEPS) {
    if (!cJSON_IsArray(steps) || cJSON_GetArraySize(steps) < 1 ||
        cJSON_GetArraySize(steps) > PROFILE_MAX_STEPS) {
      return fail(err, len, "%s.steps: expected 1..%d pairs [duration_s, value]", where,
                  PROFILE_MAX_STEPS);
    }
    int i = 0;
    const cJSON *pair;
    cJSON_ArrayForEach(pair, steps)
    {
      if (!cJSON_IsArray(pair) || cJSON_GetArraySize(pair) != 2) {
        return fail(err, len, "%s.steps[%d]: expected [duration_s, value]", where, i);
      }
      snprintf(key, sizeof key, "%s.steps[%d][0]", where, i);
      if (get_num(cJSON_GetArrayItem(pair, 0), key, 1e-6, 1e7, &t.step_s[i], err, len) != 0)
        return -1;
      snprintf(key, sizeof key, "%s.steps[%d][1]", where, i);
      if (get_num(cJSON_GetArrayItem(pair, 1), key, lo, hi, &t.step_value[i], err, len) != 0)
        return -1;
      t.step_value[i] += offset;
      i++;
    }
    t.n_steps = i;
  } else if (steps != NULL) {
    return fail(err, len, "%s.steps: only for kind \"steps\"", where);
  }
  if (t.kind == PROFILE_HEAT_COOL) {
    if (t.tau_heat_s <= 0.0) t.tau_heat_s = 1.0;
    if (t.tau_cool_s <= 0.0) t.tau_cool_s = 1.0;
  }
  const char *bad = NULL;
  if (profile_check(&t, &bad) != 0) {
    return fail(err, len, "%s.%s: invalid for kind %s", where, bad ? bad : "?",
                kind->valuestring);
  }
  *p = t;
  return 0;
}

static int parse_vec3(const cJSON *j, const char *where, double lim, double out[3], char *err,
                      size_t len)
{
  if (!cJSON_IsArray(j) || cJSON_GetArraySize(j) != 3)
    return fail(err, len, "%s: expected [x, y, z]", where);
  for (int i = 0; i < 3; i++) {
    char key[96];
    snprintf(key, sizeof key, "%s[%d]", where, i);
    if (get_num(cJSON_GetArrayItem(j, i), key, -lim, lim, &out[i], err, len) != 0) return -1;
  }
  return 0;
}

/* "axis": "drive" | "sense" | "normal" (accel.h's ACCEL_AXIS_* order). */
static int parse_axis(const cJSON *j, const char *where, int *axis, char *err, size_t len)
{
  static const char *const names[3] = {"drive", "sense", "normal"};
  for (int i = 0; cJSON_IsString(j) && i < 3; i++) {
    if (strcmp(j->valuestring, names[i]) == 0) {
      *axis = i;
      return 0;
    }
  }
  return fail(err, len, "%s: expected \"drive\", \"sense\" or \"normal\"", where);
}

/* Every key of the entry obj is one of allowed (n of them) and the required ones (the
 * first n_req) are there. */
static int entry_keys(const cJSON *obj, const char *where, const char *const *allowed, int n,
                      int n_req, char *err, size_t len)
{
  if (!cJSON_IsObject(obj)) return fail(err, len, "%s: expected an object", where);
  const cJSON *it;
  cJSON_ArrayForEach(it, obj)
  {
    int known = 0;
    for (int i = 0; i < n; i++) known |= strcmp(it->string, allowed[i]) == 0;
    if (!known) return fail(err, len, "%s.%s: unknown key", where, it->string);
  }
  for (int i = 0; i < n_req; i++)
    if (cJSON_GetObjectItemCaseSensitive(obj, allowed[i]) == NULL)
      return fail(err, len, "%s.%s: missing", where, allowed[i]);
  return 0;
}

/* accel_g.shocks: [{"t_s", "peak_g", "duration_ms", "axis"}, ...], half-sine shocks. */
static int parse_shocks(const cJSON *arr, accel_profile_t *t, char *err, size_t len)
{
  static const char *const keys[] = {"t_s", "peak_g", "duration_ms", "axis"};
  if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) > PROFILE_MAX_SHOCKS)
    return fail(err, len, "accel_g.shocks: expected a list of at most %d shocks",
                PROFILE_MAX_SHOCKS);
  const cJSON *e;
  int j = 0;
  cJSON_ArrayForEach(e, arr)
  {
    char w[64], k[96];
    snprintf(w, sizeof w, "accel_g.shocks[%d]", j);
    if (entry_keys(e, w, keys, 4, 4, err, len) != 0) return -1;
    double ms = 0.0;
    snprintf(k, sizeof k, "%s.t_s", w);
    if (get_num(cJSON_GetObjectItemCaseSensitive(e, "t_s"), k, 0.0, 1e7, &t->shock_t_s[j], err,
                len) != 0)
      return -1;
    snprintf(k, sizeof k, "%s.peak_g", w);
    if (get_num(cJSON_GetObjectItemCaseSensitive(e, "peak_g"), k, -1e5, 1e5,
                &t->shock_peak_g[j], err, len) != 0)
      return -1;
    snprintf(k, sizeof k, "%s.duration_ms", w);
    if (get_num(cJSON_GetObjectItemCaseSensitive(e, "duration_ms"), k, 1e-3, 1e4, &ms, err,
                len) != 0)
      return -1;
    t->shock_dur_s[j] = 1e-3 * ms;
    snprintf(k, sizeof k, "%s.axis", w);
    if (parse_axis(cJSON_GetObjectItemCaseSensitive(e, "axis"), k, &t->shock_axis[j], err,
                   len) != 0)
      return -1;
    j++;
  }
  t->n_shocks = j;
  return 0;
}

/* accel_g.random: [{"axis", "psd_g2_per_hz", "f_hi_hz", "f_lo_hz"}, ...], random
 * vibration bands (f_lo_hz optional: 0, a flat spectrum from DC). */
static int parse_random(const cJSON *arr, accel_profile_t *t, char *err, size_t len)
{
  static const char *const keys[] = {"axis", "psd_g2_per_hz", "f_hi_hz", "f_lo_hz"};
  if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) > PROFILE_MAX_VIB_BANDS)
    return fail(err, len, "accel_g.random: expected a list of at most %d bands",
                PROFILE_MAX_VIB_BANDS);
  const cJSON *e;
  int j = 0;
  cJSON_ArrayForEach(e, arr)
  {
    char w[64], k[96];
    snprintf(w, sizeof w, "accel_g.random[%d]", j);
    if (entry_keys(e, w, keys, 4, 3, err, len) != 0) return -1;
    snprintf(k, sizeof k, "%s.axis", w);
    if (parse_axis(cJSON_GetObjectItemCaseSensitive(e, "axis"), k, &t->band_axis[j], err, len) !=
        0)
      return -1;
    snprintf(k, sizeof k, "%s.psd_g2_per_hz", w);
    if (get_num(cJSON_GetObjectItemCaseSensitive(e, "psd_g2_per_hz"), k, 1e-12, 1e3,
                &t->band_psd_g2_per_hz[j], err, len) != 0)
      return -1;
    snprintf(k, sizeof k, "%s.f_hi_hz", w);
    if (get_num(cJSON_GetObjectItemCaseSensitive(e, "f_hi_hz"), k, 0.2, 1e5,
                &t->band_f_hi_hz[j], err, len) != 0)
      return -1;
    const cJSON *lo = cJSON_GetObjectItemCaseSensitive(e, "f_lo_hz");
    t->band_f_lo_hz[j] = 0.0;
    snprintf(k, sizeof k, "%s.f_lo_hz", w);
    if (lo != NULL && get_num(lo, k, 0.0, 1e5, &t->band_f_lo_hz[j], err, len) != 0) return -1;
    if (t->band_f_lo_hz[j] != 0.0 && t->band_f_lo_hz[j] < 0.1)
      return fail(err, len, "%s: %g is neither 0 (from DC) nor at least 0.1 Hz", k,
                  t->band_f_lo_hz[j]);
    if (t->band_f_hi_hz[j] < 2.0 * t->band_f_lo_hz[j])
      return fail(err, len,
                  "%s.f_hi_hz: the band must span an octave at least (f_hi_hz >= 2 f_lo_hz)", w);
    j++;
  }
  t->n_bands = j;
  return 0;
}

static int parse_accel(const cJSON *obj, accel_profile_t *a, char *err, size_t len)
{
  if (!cJSON_IsObject(obj)) return fail(err, len, "accel_g: expected an object");
  accel_profile_t t;
  accel_profile_zero(&t);
  const cJSON *it;
  cJSON_ArrayForEach(it, obj)
  {
    int rc;
    if (strcmp(it->string, "const") == 0)
      rc = parse_vec3(it, "accel_g.const", 1000.0, t.const_g, err, len);
    else if (strcmp(it->string, "amp") == 0)
      rc = parse_vec3(it, "accel_g.amp", 1000.0, t.amp_g, err, len);
    else if (strcmp(it->string, "freq_hz") == 0)
      rc = parse_vec3(it, "accel_g.freq_hz", 1e4, t.freq_hz, err, len);
    else if (strcmp(it->string, "phase_rad") == 0)
      rc = parse_vec3(it, "accel_g.phase_rad", 1e3, t.phase_rad, err, len);
    else if (strcmp(it->string, "shocks") == 0) rc = parse_shocks(it, &t, err, len);
    else if (strcmp(it->string, "random") == 0) rc = parse_random(it, &t, err, len);
    else
      return fail(err, len,
                  "accel_g.%s: unknown key (const, amp, freq_hz, phase_rad, shocks, random)",
                  it->string);
    if (rc != 0) return -1;
  }
  const char *bad = NULL;
  if (accel_profile_check(&t, &bad) != 0)
    return fail(err, len, "accel_g.%s: invalid", bad ? bad : "?");
  *a = t;
  return 0;
}

static int parse_open_loop(const cJSON *obj, sim_open_loop_t *ol, char *err, size_t len)
{
  if (!cJSON_IsObject(obj)) return fail(err, len, "open_loop: expected an object");
  sim_open_loop_t t = *ol;
  const cJSON *it;
  cJSON_ArrayForEach(it, obj)
  {
    const char *k = it->string;
    char key[96];
    snprintf(key, sizeof key, "open_loop.%s", k);
    int rc = 0;
    if (strcmp(k, "u_amp_v") == 0) rc = get_num(it, key, 0.0, 15.0, &t.u_amp_v, err, len);
    else if (strcmp(k, "freq_hz") == 0)
      rc = get_num(it, key, 1.0, 12500.0, &t.freq_hz, err, len);
    else if (strcmp(k, "amps_v") == 0) {
      if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) < 1 || cJSON_GetArraySize(it) > 16) {
        return fail(err, len, "%s: expected 1..16 voltages", key);
      }
      t.n_amps = 0;
      const cJSON *v;
      cJSON_ArrayForEach(v, it)
      {
        char k2[112];
        snprintf(k2, sizeof k2, "%s[%d]", key, t.n_amps);
        if (get_num(v, k2, 0.0, 15.0, &t.amps_v[t.n_amps], err, len) != 0) return -1;
        t.n_amps++;
      }
    } else if (strcmp(k, "dwell_s") == 0)
      rc = get_num(it, key, 1e-3, 1e4, &t.dwell_s, err, len);
    else if (strcmp(k, "settle_s") == 0) rc = get_num(it, key, 0.0, 1e4, &t.settle_s, err, len);
    else if (strcmp(k, "sweep") == 0) {
      if (!cJSON_IsObject(it)) return fail(err, len, "%s: expected an object", key);
      const cJSON *s;
      cJSON_ArrayForEach(s, it)
      {
        char k2[112];
        snprintf(k2, sizeof k2, "open_loop.sweep.%s", s->string);
        double v = 0.0;
        if (strcmp(s->string, "f_start_hz") == 0)
          rc = get_num(s, k2, 1.0, 12500.0, &t.f_start_hz, err, len);
        else if (strcmp(s->string, "f_stop_hz") == 0)
          rc = get_num(s, k2, 1.0, 12500.0, &t.f_stop_hz, err, len);
        else if (strcmp(s->string, "points") == 0) {
          rc = get_num(s, k2, 2.0, 10000.0, &v, err, len);
          t.points = (int)v;
        } else if (strcmp(s->string, "dwell_s") == 0)
          rc = get_num(s, k2, 1e-3, 1e4, &t.dwell_s, err, len);
        else if (strcmp(s->string, "settle_s") == 0)
          rc = get_num(s, k2, 0.0, 1e4, &t.settle_s, err, len);
        else return fail(err, len, "%s: unknown key", k2);
        if (rc != 0) return -1;
      }
    } else return fail(err, len, "%s: unknown key", key);
    if (rc != 0) return -1;
  }
  if (t.f_stop_hz <= t.f_start_hz)
    return fail(err, len, "open_loop.sweep: f_stop_hz must exceed f_start_hz");
  if (t.settle_s >= t.dwell_s)
    return fail(err, len, "open_loop: settle_s must be shorter than dwell_s");
  *ol = t;
  return 0;
}

/* "commands": [[t_s, "line"], ...]: times from 0 and not decreasing, printable lines
 * without a line end (gyro-sim adds it). */
static int parse_commands(const cJSON *arr, sim_scenario_t *sc, char *err, size_t len)
{
  const int n = cJSON_IsArray(arr) ? cJSON_GetArraySize(arr) : -1;
  if (n < 0 || n > SIM_CMDS_MAX)
    return fail(err, len, "commands: expected a list of at most %d [t_s, \"line\"] pairs",
                SIM_CMDS_MAX);
  double t_last = 0.0;
  for (int j = 0; j < n; j++) {
    const cJSON *e = cJSON_GetArrayItem(arr, j);
    const cJSON *t = cJSON_GetArrayItem(e, 0), *l = cJSON_GetArrayItem(e, 1);
    if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 2 || !cJSON_IsString(l))
      return fail(err, len, "commands[%d]: expected [t_s, \"line\"]", j);
    char w[32];
    snprintf(w, sizeof w, "commands[%d]", j);
    double t_s = 0.0;
    if (get_num(t, w, t_last, 1e6, &t_s, err, len) != 0) return -1;
    const size_t m = strlen(l->valuestring);
    if (m == 0u || m >= SIM_CMD_LINE_MAX)
      return fail(err, len, "commands[%d]: a line of 1 to %d characters", j,
                  SIM_CMD_LINE_MAX - 1);
    for (size_t i = 0; i < m; i++) {
      const unsigned char c = (unsigned char)l->valuestring[i];
      if (c < 0x20u || c > 0x7Eu)
        return fail(err, len, "commands[%d]: printable ASCII only, no line end", j);
    }
    sc->cmds[j].t_s = t_s;
    memcpy(sc->cmds[j].line, l->valuestring, m + 1u);
    t_last = t_s;
  }
  sc->n_cmds = n;
  return 0;
}

int scenario_parse(sim_scenario_t *out, const char *json, char *err, size_t len)
{
  cJSON *root = cJSON_Parse(json);
  if (root == NULL) {
    const char *at = cJSON_GetErrorPtr();
    char near[24] = "";
    if (at != NULL) snprintf(near, sizeof near, "%.20s", at);
    return fail(err, len, "not valid JSON near '%s'", near);
  }
  /* Work on a copy: a failure anywhere leaves *out as it was. */
  sim_scenario_t *sc = malloc(sizeof *sc);
  if (sc == NULL) {
    cJSON_Delete(root);
    return fail(err, len, "out of memory");
  }
  *sc = *out;
  int rc = 0;
  if (!cJSON_IsObject(root)) rc = fail(err, len, "top level: expected an object");
  const cJSON *it;
  if (rc == 0) {
    cJSON_ArrayForEach(it, root)
    {
      const char *k = it->string;
      if (strcmp(k, "name") == 0 || strcmp(k, "description") == 0) {
        if (!cJSON_IsString(it)) {
          rc = fail(err, len, "%s: expected a string", k);
          break;
        }
        if (k[0] == 'n') {
          if (strlen(it->valuestring) >= SIM_NAME_MAX ||
              strpbrk(it->valuestring, "/\\\"") != NULL) {
            rc = fail(err, len, "name: at most %d characters, no slashes or quotes",
                      SIM_NAME_MAX - 1);
            break;
          }
          snprintf(sc->name, sizeof sc->name, "%s", it->valuestring);
        } else {
          snprintf(sc->description, sizeof sc->description, "%s", it->valuestring);
        }
      } else if (strcmp(k, "duration_s") == 0) {
        rc = get_num(it, k, 1e-3, 1e6, &sc->duration_s, err, len);
      } else if (strcmp(k, "seed") == 0) {
        double v = 0.0;
        rc = get_num(it, k, 0.0, 9007199254740992.0, &v, err, len);
        if (rc == 0 && v != floor(v)) rc = fail(err, len, "seed: expected a whole number");
        sc->seed = (uint64_t)v;
      } else if (strcmp(k, "csv_rate_hz") == 0) {
        rc = get_num(it, k, 0.001, 50000.0, &sc->csv_rate_hz, err, len);
      } else if (strcmp(k, "mode") == 0) {
        if (!cJSON_IsString(it))
          rc = fail(err, len, "mode: expected closed_loop|open_loop|open_loop_sweep");
        else if (strcmp(it->valuestring, "closed_loop") == 0) sc->loop = SIM_CLOSED_LOOP;
        else if (strcmp(it->valuestring, "open_loop") == 0) sc->loop = SIM_OPEN_LOOP;
        else if (strcmp(it->valuestring, "open_loop_sweep") == 0)
          sc->loop = SIM_OPEN_LOOP_SWEEP;
        else
          rc = fail(err, len, "mode: '%s' is not closed_loop|open_loop|open_loop_sweep",
                    it->valuestring);
      } else if (strcmp(k, "analyses") == 0) {
        if (!cJSON_IsArray(it)) {
          rc = fail(err, len, "analyses: expected a list of names");
          break;
        }
        sc->analyses = 0u;
        const cJSON *a;
        cJSON_ArrayForEach(a, it)
        {
          uint32_t bit = 0u;
          for (size_t i = 0; cJSON_IsString(a) && i < sizeof analyses / sizeof analyses[0]; i++) {
            if (strcmp(a->valuestring, analyses[i].name) == 0) bit = analyses[i].bit;
          }
          if (bit == 0u) {
            rc = fail(
                err, len,
                "analyses: unknown analysis (startup, rate_table, brownian_noise, allan, allan_unc, drive_noise, temp_comp, sweep, square_law)");
            break;
          }
          sc->analyses |= bit;
        }
      } else if (strcmp(k, "plant") == 0) {
        rc = parse_sets(it, "plant", sc->plant_set, &sc->n_plant_set, err, len);
        const cJSON *pre = cJSON_GetObjectItemCaseSensitive(it, "preset");
        if (rc == 0 && pre != NULL)
          rc = set_preset(sc, pre->valuestring, "plant.preset", err, len);
      } else if (strcmp(k, "firmware") == 0) {
        rc = parse_sets(it, "firmware", sc->fw_set, &sc->n_fw_set, err, len);
      } else if (strcmp(k, "rate_dps") == 0) {
        rc = parse_profile(it, "rate_dps", 0.0, -1e5, 1e5, &sc->rate_dps, err, len);
        sc->has_rate = 1;
      } else if (strcmp(k, "ambient_c") == 0) {
        rc = parse_profile(it, "ambient_c", 273.15, -100.0, 200.0, &sc->ambient_c, err, len);
        sc->has_ambient = 1;
      } else if (strcmp(k, "accel_g") == 0) {
        rc = parse_accel(it, &sc->accel_g, err, len);
        sc->has_accel = 1;
      } else if (strcmp(k, "open_loop") == 0) {
        rc = parse_open_loop(it, &sc->ol, err, len);
      } else if (strcmp(k, "selfcal") == 0) {
        if (!cJSON_IsBool(it)) rc = fail(err, len, "selfcal: expected true or false");
        else sc->selfcal = cJSON_IsTrue(it);
      } else if (strcmp(k, "firmware_params") == 0) {
        if (!cJSON_IsString(it) || it->valuestring[0] == '\0' ||
            strlen(it->valuestring) >= SIM_PATH_MAX)
          rc = fail(err, len, "firmware_params: expected the path of a parameter set file");
        else snprintf(sc->fw_params_path, SIM_PATH_MAX, "%s", it->valuestring);
      } else if (strcmp(k, "commands") == 0) {
        rc = parse_commands(it, sc, err, len);
      } else if (strcmp(k, "notes") == 0) {
        if (!cJSON_IsObject(it)) rc = fail(err, len, "notes: expected an object of strings");
      } else {
        rc = fail(err, len, "%s: unknown key", k);
      }
      if (rc != 0) break;
    }
  }
  if (rc == 0 && sc->selfcal && sc->loop != SIM_CLOSED_LOOP)
    rc = fail(err, len, "selfcal: needs \"mode\": \"closed_loop\" (the firmware runs the sweep)");
  if (rc == 0 && sc->n_cmds > 0 && sc->loop != SIM_CLOSED_LOOP)
    rc = fail(err, len, "commands: needs \"mode\": \"closed_loop\" (the firmware reads them)");
  if (rc == 0) *out = *sc;
  free(sc);
  cJSON_Delete(root);
  return rc;
}

/* A "firmware_params" this file gave with a relative path: from the file's folder. */
static int resolve_fw_params(sim_scenario_t *sc, const char *before, const char *path,
                             char *err, size_t len)
{
  const char *rel = sc->fw_params_path;
  if (strcmp(rel, before) == 0 || rel[0] == '/') return 0;
  const char *slash = strrchr(path, '/');
  if (slash == NULL) return 0; /* the scenario is in the working folder */
  char full[2 * SIM_PATH_MAX];
  snprintf(full, sizeof full, "%.*s/%s", (int)(slash - path), path, rel);
  const size_t n = strlen(full);
  if (n >= SIM_PATH_MAX) {
    snprintf(sc->fw_params_path, SIM_PATH_MAX, "%s", before);
    return fail(err, len, "%s: firmware_params: path too long", path);
  }
  memcpy(sc->fw_params_path, full, n + 1u);
  return 0;
}

int scenario_load(sim_scenario_t *sc, const char *path, char *err, size_t len)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL) return fail(err, len, "%s: %s", path, strerror(errno));
  char *buf = NULL;
  size_t cap = 0, n = 0;
  for (;;) {
    if (n + 4096 + 1 > cap) {
      cap = cap ? 2 * cap : 8192;
      if (cap > (size_t)16 << 20) {
        free(buf);
        fclose(f);
        return fail(err, len, "%s: larger than 16 MiB", path);
      }
      char *g = realloc(buf, cap);
      if (g == NULL) {
        free(buf);
        fclose(f);
        return fail(err, len, "out of memory");
      }
      buf = g;
    }
    const size_t r = fread(buf + n, 1, 4096, f);
    n += r;
    if (r < 4096) break;
  }
  fclose(f);
  buf[n] = '\0';
  if (memchr(buf, '\0', n) != NULL) {
    free(buf);
    return fail(err, len, "%s: contains a NUL byte", path);
  }
  char inner[400];
  char before[SIM_PATH_MAX];
  snprintf(before, sizeof before, "%s", sc->fw_params_path);
  const int rc = scenario_parse(sc, buf, inner, sizeof inner);
  free(buf);
  if (rc != 0) return fail(err, len, "%s: %s", path, inner);
  return resolve_fw_params(sc, before, path, err, len);
}

int scenario_add_override(sim_scenario_t *sc, const char *arg, char *err, size_t len)
{
  const char *eq = strchr(arg, '=');
  if (eq == NULL)
    return fail(err, len, "--set %s: expected plant.KEY=VALUE or firmware.KEY=VALUE", arg);
  const char *val = eq + 1;
  static const char k_preset[] = "plant.preset";
  if ((size_t)(eq - arg) == sizeof k_preset - 1u &&
      strncmp(arg, k_preset, sizeof k_preset - 1u) == 0)
    return set_preset(sc, val, "--set plant.preset", err, len);
  char *end = NULL;
  errno = 0;
  const double v = strtod(val, &end);
  if (*val == '\0' || end == val || *end != '\0' || errno == ERANGE || !isfinite(v)) {
    return fail(err, len, "--set %s: '%s' is not a finite number", arg, val);
  }
  char key[SIM_NAME_MAX + 16];
  const size_t klen = (size_t)(eq - arg);
  if (klen >= sizeof key) return fail(err, len, "--set %s: key too long", arg);
  memcpy(key, arg, klen);
  key[klen] = '\0';
  if (strncmp(key, "plant.", 6) == 0) {
    return add_set(sc->plant_set, &sc->n_plant_set, key + 6, v, "plant", err, len);
  }
  if (strncmp(key, "firmware.", 9) == 0) {
    return add_set(sc->fw_set, &sc->n_fw_set, key + 9, v, "firmware", err, len);
  }
  if (strncmp(key, "fw.", 3) == 0) {
    return add_set(sc->fw_set, &sc->n_fw_set, key + 3, v, "firmware", err, len);
  }
  return fail(err, len, "--set %s: key must start with plant. or firmware.", arg);
}
