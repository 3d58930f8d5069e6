/* gyro-sim scenario files (JSON, parsed with cJSON) and command-line overrides.
 *
 * A scenario names its plant, firmware and input settings; everything not given keeps
 * its default (plant_default_cfg, the firmware parameter table). Layout:
 *   {
 *     "name": "startup", "description": "...", "duration_s": 1.0, "seed": 1,
 *     "mode": "closed_loop" | "open_loop" | "open_loop_sweep",
 *     "analyses": ["startup", "rate_table", ...],
 *                 ("allan": Allan figures of the output rate_dps; "allan_unc": the same of
 *                  the uncompensated rate_unc_dps, as figures unc_*)
 *     "csv_rate_hz": 1000,
 *     "selfcal": false,   (true: the firmware's own `sweep` first, at the initial
 *                          conditions; the timeline then starts from power-on with
 *                          what it identified, as if saved; closed loop only)
 *     "plant":    { "<plant parameter>": number, ... },       (plant.h descriptor table)
 *                 ("preset": "thesis" | "ideal" there selects the part the other plant
 *                  settings start from, wherever it stands: plant_preset; the default is
 *                  "thesis"; "thermal_preset": 0..2 a thermal network, applied in order)
 *     "firmware_params": "part.json",  (a firmware parameter set, docs/param-set.md,
 *                          loaded onto the defaults before the "firmware" settings; a
 *                          relative path is taken from the scenario file's folder)
 *     "firmware": { "<firmware parameter>": number, ... },    (params/param_list.h)
 *     "rate_dps":  PROFILE, "ambient_c": PROFILE,             (input profiles)
 *     "accel_g": { "const": [x,y,z], "amp": [x,y,z], "freq_hz": [x,y,z], "phase_rad": [x,y,z],
 *                  "shocks": [ {"t_s": t, "peak_g": p, "duration_ms": d, "axis": AXIS}, ... ],
 *                  "random": [ {"axis": AXIS, "psd_g2_per_hz": G, "f_lo_hz": lo,
 *                               "f_hi_hz": hi}, ... ] },
 *                 (x, y, z and AXIS "drive", "sense", "normal": accel.h's axes; up to 8
 *                  half-sine shocks and 4 random-vibration bands, profile.h; f_lo_hz
 *                  optional, 0: flat from DC; a band spans an octave at least and
 *                  ends below 0.45 plant.fs_hz. The self-calibration's initial
 *                  conditions hold the deterministic part's value at t = 0, no random
 *                  vibration),
 *     "open_loop": { "u_amp_v": 8, "freq_hz": 1489.9,
 *                    "sweep": { "f_start_hz": 1400, "f_stop_hz": 1600, "points": 81,
 *                               "dwell_s": 0.2, "settle_s": 0.1 } },
 *     "commands": [ [t_s, "command line"], ... ],   (closed loop: up to SIM_CMDS_MAX lines
 *                 typed into the firmware's command line at simulated times t_s, in
 *                 order; each reply is kept whole for the JSON output, "commands")
 *     "notes": { "<parameter>": "how its value was chosen", ... }  (documentation only)
 *   }
 *   PROFILE: { "kind": "const", "value": v }
 *          | { "kind": "steps", "steps": [[duration_s, value], ...], "edge_s": e, "repeat": false }
 *          | { "kind": "sine", "value": offset, "amp": a, "freq_hz": f, "phase_rad": p }
 *          | { "kind": "ramp", "value": start, "slope_per_s": s, "t_start_s": t0, "t_end_s": t1 }
 *          | { "kind": "heat_cool", "value": base, "hot_value": hot, "t_start_s": t0,
 *              "heat_s": h, "tau_heat_s": th, "tau_cool_s": tc }
 * Unknown keys are errors (a misspelt key must not silently do nothing). Every error
 * names the key and, for numbers, the allowed range; nothing is half-applied.
 */
#ifndef SIM_SCENARIO_H
#define SIM_SCENARIO_H

#include <stddef.h>
#include <stdint.h>

#include "plant/profile.h"

#define SIM_MAX_SETS 160
#define SIM_NAME_MAX 64
#define SIM_PATH_MAX 1024
#define SIM_CMDS_MAX 16
#define SIM_CMD_LINE_MAX 120 /* the firmware's line (CLI_LINE_MAX) with room to spare */

typedef enum {
  SIM_CLOSED_LOOP = 0,
  SIM_OPEN_LOOP = 1,      /* fixed half-frequency drive, no firmware */
  SIM_OPEN_LOOP_SWEEP = 2 /* stepped half-frequency drive across a band, no firmware */
} sim_loop_t;             /* the scenario key "mode" */

typedef enum {
  SIM_AN_STARTUP = 1u << 0,
  SIM_AN_RATE_TABLE = 1u << 1,
  SIM_AN_NOISE = 1u << 2, /* Brownian floor comparison (brownian_only) */
  SIM_AN_ALLAN = 1u << 3, /* static Allan figures */
  SIM_AN_DRIVE_NOISE = 1u << 4,
  SIM_AN_TEMP = 1u << 5,       /* temperature chamber / cool-down compensation */
  SIM_AN_SWEEP = 1u << 6,      /* open-loop frequency response */
  SIM_AN_SQUARE_LAW = 1u << 7, /* table 7-1: amplitude versus drive voltage */
  SIM_AN_ALLAN_UNC = 1u << 8   /* static Allan figures of the uncompensated rate (unc_*) */
} sim_analysis_t;

typedef struct {
  char key[SIM_NAME_MAX];
  double value;
} sim_set_t;

typedef struct {
  double u_amp_v; /* half-frequency voltage amplitude */
  double freq_hz; /* drive (force) frequency */
  double f_start_hz, f_stop_hz;
  int points;
  double dwell_s, settle_s;
  int n_amps; /* square law: voltage amplitudes stepped at freq_hz */
  double amps_v[16];
} sim_open_loop_t;

typedef struct {
  char name[SIM_NAME_MAX];
  char description[256];
  double duration_s;
  uint64_t seed;
  sim_loop_t loop;
  uint32_t analyses;
  double csv_rate_hz;
  char plant_preset[SIM_NAME_MAX]; /* "": the default part; else a plant_preset name */
  sim_set_t plant_set[SIM_MAX_SETS];
  int n_plant_set;
  sim_set_t fw_set[SIM_MAX_SETS];
  int n_fw_set;
  int has_rate, has_ambient, has_accel;
  profile_t rate_dps;
  profile_t ambient_c;
  accel_profile_t accel_g;
  sim_open_loop_t ol;
  int selfcal; /* key "selfcal" / --selfcal: self-calibrate before the timeline */
  /* key "firmware_params" / --firmware-params: a parameter set (param_set.h) under the
   * firmware settings; "" none */
  char fw_params_path[SIM_PATH_MAX];
  /* key "commands": lines typed into the command line at simulated times, in order */
  struct {
    double t_s;
    char line[SIM_CMD_LINE_MAX];
  } cmds[SIM_CMDS_MAX];
  int n_cmds;
} sim_scenario_t;

/* Defaults: closed loop, 1 s, seed 1, no analyses, CSV at 1 kHz. */
void scenario_defaults(sim_scenario_t *sc);

/* Parse a JSON scenario into sc (on top of its current content). Returns 0, or -1 with
 * a one-line message in err naming the key. A relative "firmware_params" path is kept as
 * written here; scenario_load makes it relative to the file's folder. */
int scenario_parse(sim_scenario_t *sc, const char *json, char *err, size_t err_len);
int scenario_load(sim_scenario_t *sc, const char *path, char *err, size_t err_len);

/* A command-line override "plant.KEY=VALUE" or "firmware.KEY=VALUE" (the firmware key
 * is the parameter's own dotted name, e.g. firmware.drive.amp_bw_hz=20). Only the
 * syntax and the number are checked here; the key and range when applied. The one
 * value that is a name, "plant.preset=NAME", is checked here (plant_preset's names). */
int scenario_add_override(sim_scenario_t *sc, const char *arg, char *err, size_t err_len);

const char *scenario_analysis_name(sim_analysis_t a);

#endif /* SIM_SCENARIO_H */
