/* gyro-sim's scenario files and settings (host_sim/gyro_sim/scenario.h, sim_cfg.c) for the
 * plant's inputs and parameters: half-sine shocks and random-vibration bands in
 * "accel_g", each field validated with the key named and nothing changed on error;
 * plant.thermal_preset, plant.preset and the new plant parameters through --set and in a
 * file; --list-params naming every plant parameter, plant.thermal_preset and plant.preset;
 * "firmware_params", a parameter set under the firmware settings; the "analyses" names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "paramset/param_set.h"
#include "scenario.h"
#include "sim.h"

static sim_scenario_t *fresh(void)
{
  static sim_scenario_t sc;
  scenario_defaults(&sc);
  return &sc;
}

/* Shocks and bands as written in a scenario, in the profile's units (duration in s). */
static void test_shocks_and_random_parsed(void **state)
{
  (void)state;
  sim_scenario_t *sc = fresh();
  char err[400];
  const char *json =
      "{\"accel_g\": {\"const\": [0, 0, -1],"
      " \"shocks\": [{\"t_s\": 0.5, \"peak_g\": 50, \"duration_ms\": 0.5, \"axis\": \"drive\"},"
      "              {\"t_s\": 1.5, \"peak_g\": -2, \"duration_ms\": 11, \"axis\": \"normal\"}],"
      " \"random\": [{\"axis\": \"sense\", \"psd_g2_per_hz\": 1e-5, \"f_lo_hz\": 20,"
      " \"f_hi_hz\": 2000}, {\"axis\": \"drive\", \"psd_g2_per_hz\": 0.01, \"f_hi_hz\": 100}]}}";
  assert_int_equal(scenario_parse(sc, json, err, sizeof err), 0);
  const accel_profile_t *a = &sc->accel_g;
  assert_true(sc->has_accel && a->const_g[2] == -1.0);
  assert_int_equal(a->n_shocks, 2);
  assert_true(a->shock_t_s[0] == 0.5 && a->shock_peak_g[0] == 50.0 && a->shock_axis[0] == 0);
  assert_true(fabs(a->shock_dur_s[0] - 0.5e-3) < 1e-18 && fabs(a->shock_dur_s[1] - 11e-3) < 1e-18);
  assert_true(a->shock_axis[1] == 2 && a->shock_peak_g[1] == -2.0);
  assert_int_equal(a->n_bands, 2);
  assert_true(a->band_axis[0] == 1 && a->band_psd_g2_per_hz[0] == 1e-5);
  assert_true(a->band_f_lo_hz[0] == 20.0 && a->band_f_hi_hz[0] == 2000.0);
  assert_true(a->band_axis[1] == 0 && a->band_f_lo_hz[1] == 0.0 && a->band_f_hi_hz[1] == 100.0);
  assert_int_equal(accel_profile_check(a, NULL), 0);
  plant_cfg_t c;
  plant_profiles_t pr;
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
  assert_memory_equal(&pr.accel_g, a, sizeof *a);
}

/* Every bad entry is refused with its key and leaves the scenario as it was. */
static void test_bad_entries_refused(void **state)
{
  (void)state;
  static const struct {
    const char *json, *msg;
  } bad[] = {
      {"{\"accel_g\": {\"shocks\": [{\"t_s\": 1, \"peak_g\": 5, \"duration_ms\": 1, \"axis\": "
       "\"drive\", \"shape\": 1}]}}",
       "accel_g.shocks[0].shape: unknown key"},
      {"{\"accel_g\": {\"shocks\": [{\"t_s\": 1, \"peak_g\": 5, \"axis\": \"drive\"}]}}",
       "accel_g.shocks[0].duration_ms: missing"},
      {"{\"accel_g\": {\"shocks\": [{\"t_s\": 1, \"peak_g\": 5, \"duration_ms\": 1, \"axis\": "
       "\"x\"}]}}",
       "accel_g.shocks[0].axis: expected \"drive\", \"sense\" or \"normal\""},
      {"{\"accel_g\": {\"shocks\": [{\"t_s\": -1, \"peak_g\": 5, \"duration_ms\": 1, \"axis\": "
       "\"sense\"}]}}",
       "accel_g.shocks[0].t_s: -1 is out of range"},
      {"{\"accel_g\": {\"shocks\": [{\"t_s\": 1, \"peak_g\": 5, \"duration_ms\": 0, \"axis\": "
       "\"sense\"}]}}",
       "accel_g.shocks[0].duration_ms: 0 is out of range"},
      {"{\"accel_g\": {\"shocks\": [{\"t_s\": 1, \"peak_g\": 2e5, \"duration_ms\": 1, \"axis\": "
       "\"sense\"}]}}",
       "accel_g.shocks[0].peak_g: 200000 is out of range"},
      {"{\"accel_g\": {\"shocks\": [{}, {}, {}, {}, {}, {}, {}, {}, {}]}}",
       "accel_g.shocks: expected a list of at most 8 shocks"},
      {"{\"accel_g\": {\"random\": [{\"axis\": \"sense\", \"psd_g2_per_hz\": 0, \"f_hi_hz\": "
       "100}]}}",
       "accel_g.random[0].psd_g2_per_hz: 0 is out of range"},
      {"{\"accel_g\": {\"random\": [{\"axis\": \"sense\", \"psd_g2_per_hz\": 1e-3, \"f_lo_hz\": "
       "0.05, \"f_hi_hz\": 100}]}}",
       "accel_g.random[0].f_lo_hz: 0.05 is neither 0"},
      {"{\"accel_g\": {\"random\": [{\"axis\": \"sense\", \"psd_g2_per_hz\": 1e-3, \"f_lo_hz\": "
       "80, \"f_hi_hz\": 100}]}}",
       "accel_g.random[0].f_hi_hz: the band must span an octave"},
      {"{\"accel_g\": {\"random\": [{\"axis\": \"sense\", \"f_hi_hz\": 100}]}}",
       "accel_g.random[0].psd_g2_per_hz: missing"},
      {"{\"accel_g\": {\"random\": {}}}", "accel_g.random: expected a list of at most 4 bands"},
      {"{\"accel_g\": {\"bump\": []}}", "accel_g.bump: unknown key"},
      {"{\"commands\": {}}", "commands: expected a list of at most 16"},
      {"{\"commands\": [[1, \"status\"], [0.5, \"status\"]]}",
       "commands[1]: 0.5 is out of range [1,"},
      {"{\"commands\": [[1]]}", "commands[0]: expected [t_s, \"line\"]"},
      {"{\"commands\": [[1, 2]]}", "commands[0]: expected [t_s, \"line\"]"},
      {"{\"commands\": [[-1, \"status\"]]}", "commands[0]: -1 is out of range"},
      {"{\"commands\": [[1, \"\"]]}", "commands[0]: a line of 1 to 119 characters"},
      {"{\"commands\": [[1, \"status\\nsave\"]]}", "commands[0]: printable ASCII only"},
      {"{\"mode\": \"open_loop\", \"commands\": [[1, \"status\"]]}",
       "commands: needs \"mode\": \"closed_loop\""},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    sim_scenario_t *sc = fresh();
    static sim_scenario_t before;
    before = *sc;
    char err[400] = "";
    assert_int_equal(scenario_parse(sc, bad[i].json, err, sizeof err), -1);
    if (strstr(err, bad[i].msg) == NULL) fail_msg("'%s' does not say '%s'", err, bad[i].msg);
    assert_memory_equal(sc, &before, sizeof before);
  }
}

/* "commands": kept in order, whole. */
static void test_commands_parsed(void **state)
{
  (void)state;
  sim_scenario_t *sc = fresh();
  char err[400] = "";
  assert_int_equal(scenario_parse(sc,
                                  "{\"commands\": [[0.5, \"selftest\"], [0.5, \"status\"], "
                                  "[2, \"set rate.lpf_cutoff_hz 50\"]]}",
                                  err, sizeof err),
                   0);
  assert_int_equal(sc->n_cmds, 3);
  assert_true(sc->cmds[1].t_s == 0.5 && sc->cmds[2].t_s == 2.0);
  assert_string_equal(sc->cmds[2].line, "set rate.lpf_cutoff_hz 50");
}

/* A band must end below 0.45 plant.fs_hz: refused by sim_plant_cfg naming the band and
 * the rate, accepted at a rate that allows it. */
static void test_band_against_sample_rate(void **state)
{
  (void)state;
  sim_scenario_t *sc = fresh();
  char err[400];
  assert_int_equal(scenario_parse(sc,
                                  "{\"accel_g\": {\"random\": [{\"axis\": \"drive\", "
                                  "\"psd_g2_per_hz\": 1e-6, \"f_hi_hz\": 30000}]}}",
                                  err, sizeof err),
                   0);
  plant_cfg_t c;
  plant_profiles_t pr;
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), -1);
  assert_non_null(
      strstr(err, "accel_g.random[0].f_hi_hz: 30000 Hz must be below 0.45 plant.fs_hz"));
  assert_int_equal(scenario_add_override(sc, "plant.fs_hz=100000", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
}

/* plant.thermal_preset takes 0, 1, 2; anything else is refused with the choices. The
 * imperfections' parameters and plant.cold_start go through --set like any other, with
 * their ranges. */
static void test_settings(void **state)
{
  (void)state;
  char err[400], arg[64];
  plant_cfg_t c, d;
  plant_profiles_t pr;
  plant_default_cfg(&d);
  static const double ok[3] = {0, 1, 2}, bad[4] = {3, 1.5, -1, 1e300};
  for (int i = 0; i < 3; i++) {
    sim_scenario_t *sc = fresh();
    snprintf(arg, sizeof arg, "plant.thermal_preset=%g", ok[i]);
    assert_int_equal(scenario_add_override(sc, arg, err, sizeof err), 0);
    assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
    assert_true((i == 0) == (c.couple_sc_per_s == d.couple_sc_per_s));
  }
  for (int i = 0; i < 4; i++) {
    sim_scenario_t *sc = fresh();
    snprintf(arg, sizeof arg, "plant.thermal_preset=%g", bad[i]);
    assert_int_equal(scenario_add_override(sc, arg, err, sizeof err), 0);
    assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), -1);
    assert_non_null(strstr(err, "plant.thermal_preset: "));
    assert_non_null(strstr(err, "is not 0 (default), 1 (tight) or 2 (loose)"));
  }
  sim_scenario_t *sc = fresh();
  assert_int_equal(scenario_add_override(sc, "plant.q_temp_law=3", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), -1);
  assert_string_equal(err, "plant.q_temp_law: out of range (allowed 0 .. 2)");
  /* plant.cold_start (power-on after a long power-off) is a switch: 0 or 1 */
  assert_false(d.cold_start);
  sc = fresh();
  assert_int_equal(scenario_parse(sc, "{\"plant\": {\"cold_start\": 1}}", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
  assert_true(c.cold_start);
  sc = fresh();
  assert_int_equal(scenario_add_override(sc, "plant.cold_start=2", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), -1);
  assert_string_equal(err, "plant.cold_start: out of range (allowed 0 .. 1)");
  sc = fresh();
  assert_int_equal(scenario_add_override(sc, "plant.cold_start=0.5", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), -1);
  assert_string_equal(err, "plant.cold_start: must be a whole number (allowed 0 .. 1)");
  sc = fresh();
  assert_int_equal(scenario_add_override(sc, "plant.k3_drive_per_m2=2e7", err, sizeof err), 0);
  assert_int_equal(scenario_add_override(sc, "plant.fb_gap_m=3e-6", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
  assert_true(c.k3_drive_per_m2 == 2e7 && c.fb_gap_m == 3e-6);
}

/* plant.preset: "ideal" gives plant_ideal_cfg, "thesis" (and no preset) the default part;
 * the preset is applied first wherever it stands, so the other plant settings override it
 * whether they come before or after it, on the command line or in the file. */
static void test_preset(void **state)
{
  (void)state;
  char err[400];
  plant_cfg_t c, want;
  plant_profiles_t pr;
  sim_scenario_t *sc = fresh();
  assert_int_equal(scenario_add_override(sc, "plant.pick_sense_phase_flicker_1hz_deg_rthz=1e-3",
                                         err, sizeof err),
                   0);
  assert_int_equal(scenario_add_override(sc, "plant.preset=ideal", err, sizeof err), 0);
  assert_int_equal(scenario_add_override(sc, "plant.k3_drive_per_m2=2e7", err, sizeof err), 0);
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
  plant_ideal_cfg(&want);
  want.pick_sense_phase_flicker_1hz_deg_rthz = 1e-3;
  want.k3_drive_per_m2 = 2e7;
  assert_memory_equal(&c, &want, sizeof c);
  /* in a file: the preset after the setting it must not undo */
  sc = fresh();
  assert_int_equal(scenario_parse(sc,
                                  "{\"plant\": {\"pick_drive_phase_flicker_1hz_deg_rthz\": 0,"
                                  " \"preset\": \"thesis\"}}",
                                  err, sizeof err),
                   0);
  assert_string_equal(sc->plant_preset, "thesis");
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
  plant_default_cfg(&want);
  assert_true(want.pick_drive_phase_flicker_1hz_deg_rthz > 0.0);
  want.pick_drive_phase_flicker_1hz_deg_rthz = 0.0;
  assert_memory_equal(&c, &want, sizeof c);
  /* no preset: the default part, which is "thesis" and not "ideal" */
  sc = fresh();
  assert_int_equal(sim_plant_cfg(sc, &c, &pr, err, sizeof err), 0);
  plant_default_cfg(&want);
  assert_memory_equal(&c, &want, sizeof c);
  assert_int_equal(plant_preset(&want, "thesis"), 0);
  assert_memory_equal(&c, &want, sizeof c);
  plant_ideal_cfg(&want);
  assert_true(memcmp(&c, &want, sizeof c) != 0);
}

/* A preset that is not a name of plant_preset is refused, with the choices, and leaves the
 * scenario as it was. */
static void test_preset_refused(void **state)
{
  (void)state;
  char err[400];
  static const char *const bad_set[] = {"plant.preset=nope", "plant.preset=1",
                                        "plant.preset=", "plant.preset=IDEAL"};
  for (size_t i = 0; i < sizeof bad_set / sizeof bad_set[0]; i++) {
    sim_scenario_t *sc = fresh();
    assert_int_equal(scenario_add_override(sc, bad_set[i], err, sizeof err), -1);
    assert_non_null(strstr(err, "--set plant.preset: '"));
    assert_non_null(strstr(err, "is not a plant preset: thesis (the default) or ideal"));
    assert_string_equal(sc->plant_preset, "");
  }
  static const char *const bad_json[] = {"{\"plant\": {\"preset\": 1}}",
                                         "{\"plant\": {\"preset\": \"bogus\"}}",
                                         "{\"plant\": {\"preset\": null}}"};
  for (size_t i = 0; i < sizeof bad_json / sizeof bad_json[0]; i++) {
    sim_scenario_t *sc = fresh();
    assert_int_equal(scenario_parse(sc, bad_json[i], err, sizeof err), -1);
    assert_non_null(strstr(err, "plant.preset: "));
    assert_string_equal(sc->plant_preset, "");
  }
}

/* "analyses": allan_unc (the Allan figures of the uncompensated rate) beside allan, by
 * name both ways; an unknown name is refused with the list, the scenario unchanged. */
static void test_analyses(void **state)
{
  (void)state;
  char err[400];
  sim_scenario_t *sc = fresh();
  assert_int_equal(
      scenario_parse(sc, "{\"analyses\": [\"allan\", \"allan_unc\"]}", err, sizeof err), 0);
  assert_true(sc->analyses == (SIM_AN_ALLAN | SIM_AN_ALLAN_UNC));
  assert_string_equal(scenario_analysis_name(SIM_AN_ALLAN_UNC), "allan_unc");
  assert_int_equal(scenario_parse(sc, "{\"analyses\": [\"allan_raw\"]}", err, sizeof err), -1);
  assert_non_null(strstr(err, "allan, allan_unc, drive_noise"));
  assert_true(sc->analyses == (SIM_AN_ALLAN | SIM_AN_ALLAN_UNC));
}

/* --list-params: every plant parameter of the table and plant.thermal_preset, each on a
 * line of its own with its default and range. */
static void test_list_params(void **state)
{
  (void)state;
  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  assert_non_null(f);
  sim_list_params(f);
  fclose(f);
  for (size_t i = 0; i < plant_param_count(); i++) {
    char key[96];
    snprintf(key, sizeof key, "\nplant.%s ", plant_param_at(i)->name);
    if (strstr(buf, key) == NULL) fail_msg("--list-params misses %s", key + 1);
  }
  assert_non_null(strstr(buf, "\nplant.thermal_preset "));
  assert_non_null(strstr(buf, "\nplant.preset "));
  assert_non_null(strstr(buf, "[thesis, ideal]"));
  assert_non_null(strstr(buf, "[0, 2]"));
  assert_non_null(strstr(buf, "\nfirmware.drive.amp_set_v "));
  free(buf);
}

/* "firmware_params" (--firmware-params): a parameter set loaded onto the defaults, a
 * relative path taken from the scenario file's folder, the scenario's firmware settings
 * over it; a bad set refused with its path and the entry. */
static void test_firmware_params(void **state)
{
  (void)state;
  param_idx_t a = PARAM_COUNT, b = PARAM_COUNT; /* two writable persistent floats */
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT && b == PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if (pi->type != PARAM_T_F32 || (pi->flags & PF_PERSIST) == 0u ||
        (pi->flags & PF_READONLY) != 0u || pi->def.f == pi->max.f)
      continue;
    if (a == PARAM_COUNT) a = (param_idx_t)i;
    else b = (param_idx_t)i;
  }
  assert_true(b < PARAM_COUNT);
  char dir[] = "/tmp/test_scenario_XXXXXX", path[160], scen[160], err[512];
  assert_non_null(mkdtemp(dir));
  snprintf(path, sizeof path, "%s/part.json", dir);
  snprintf(scen, sizeof scen, "%s/scen.json", dir);
  param_values_t set, v;
  param_values_defaults(&set);
  const param_value_t xa = {.f = nextafterf(param_info(a)->def.f, param_info(a)->max.f)};
  const param_value_t xb = {.f = nextafterf(param_info(b)->def.f, param_info(b)->max.f)};
  param_put(&set, a, xa);
  param_put(&set, b, xb);
  assert_int_equal(param_set_write_file(path, &set, NULL, err, sizeof err), 0);
  FILE *f = fopen(scen, "w");
  assert_non_null(f);
  fprintf(f, "{\"firmware_params\": \"part.json\", \"firmware\": {\"%s\": %.9g}}",
          param_info(b)->name, (double)param_info(b)->def.f);
  fclose(f);
  sim_scenario_t *sc = fresh();
  assert_int_equal(scenario_load(sc, scen, err, sizeof err), 0);
  assert_string_equal(sc->fw_params_path, path);
  assert_int_equal(sim_fw_params(sc, &v, err, sizeof err), 0);
  assert_int_equal(param_get(&v, a).u, xa.u);                 /* from the set */
  assert_int_equal(param_get(&v, b).u, param_info(b)->def.u); /* the setting over it */
  /* a bad set: nothing loaded, the file and the entry named */
  f = fopen(path, "w");
  assert_non_null(f);
  fputs("{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": "
        "[{\"id\": \"0xffff\", \"name\": \"x\", \"value\": 1}], \"crc32\": \"0x0\"}",
        f);
  fclose(f);
  assert_int_equal(sim_fw_params(sc, &v, err, sizeof err), -1);
  assert_non_null(strstr(err, path));
  assert_non_null(strstr(err, "params[0]"));
  sc = fresh();
  assert_int_equal(scenario_parse(sc, "{\"firmware_params\": 3}", err, sizeof err), -1);
  assert_string_equal(err, "firmware_params: expected the path of a parameter set file");
  assert_int_equal(scenario_parse(sc, "{\"firmware_params\": \"/abs/p.json\"}", err, sizeof err),
                   0);
  assert_string_equal(sc->fw_params_path, "/abs/p.json");
  remove(path);
  remove(scen);
  remove(dir);
}

/* The open-loop drive (sim_run_open_loop: sweep and square law) writes a whole frame every
 * tick: the sense electrodes' channels at mid-scale too, so the plant's DAC refuses none
 * (a frame with a code beyond 14 bits is refused and the previous one held: the drive
 * would stop moving). A three-point sweep over the resonance. */
static void test_open_loop_frames_taken(void **state)
{
  (void)state;
  char err[400];
  sim_scenario_t *sc = fresh();
  assert_int_equal(scenario_parse(sc,
                                  "{\"mode\": \"open_loop_sweep\", \"duration_s\": 0.06,"
                                  " \"open_loop\": {\"u_amp_v\": 12.0, \"sweep\": {"
                                  "\"f_start_hz\": 1480, \"f_stop_hz\": 1500, \"points\": 3,"
                                  " \"dwell_s\": 0.02, \"settle_s\": 0.01}}}",
                                  err, sizeof err),
                   0);
  static sim_result_t res;
  static sim_sweep_t sw;
  static sim_square_t sq;
  const sim_opts_t opt = {NULL, 100.0, 0, 0, NULL, 1.0};
  assert_int_equal(sim_run_open_loop(sc, &opt, &res, &sw, &sq, err, sizeof err), 0);
  assert_int_equal(sw.n, 3);
  print_message("open-loop sweep: %llu frames refused, amplitude %.4f V at %.0f Hz\n",
                (unsigned long long)res.dac_rejects, sw.amp_v[2], sw.f_hz[2]);
  assert_int_equal(res.dac_rejects, 0);
  assert_true(sw.amp_v[1] > 0.1); /* the drive moved the resonator */
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_shocks_and_random_parsed),
      cmocka_unit_test(test_bad_entries_refused),
      cmocka_unit_test(test_commands_parsed),
      cmocka_unit_test(test_band_against_sample_rate),
      cmocka_unit_test(test_settings),
      cmocka_unit_test(test_preset),
      cmocka_unit_test(test_preset_refused),
      cmocka_unit_test(test_analyses),
      cmocka_unit_test(test_list_params),
      cmocka_unit_test(test_firmware_params),
      cmocka_unit_test(test_open_loop_frames_taken),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
