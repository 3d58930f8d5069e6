/* gyro-sim: run a scenario of the gyro plant with the real firmware in closed loop (or
 * the bare plant in open loop), print its figures, write a CSV trace and a JSON of the
 * parameters and figures.
 *
 *   gyro-sim --scenario FILE [--duration S] [--seed N] [--csv FILE] [--csv-rate HZ]
 *            [--json FILE] [--out DIR] [--set plant.KEY=V | firmware.NAME=V ...]
 *            [--no-analysis] [--quiet] [--uart-pty[=LINK]] [--pace X] [--selfcal]
 *            [--firmware-params FILE] [--save-params FILE]
 *   gyro-sim --list-params
 */
#define _XOPEN_SOURCE 700 /* nftw */
#include <cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <ftw.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bench_figs.h"
#include "paramset/param_set.h"
#include "post.h"
#include "scenario.h"
#include "sim.h"
#include "plant/plant_const.h"

#define KB_J_PER_K 1.380649e-23

static void usage(FILE *f)
{
  fputs("usage: gyro-sim --scenario FILE [--duration S] [--seed N] [--csv FILE]\n"
        "                [--csv-rate HZ] [--json FILE] [--out DIR]\n"
        "                [--set plant.KEY=VALUE | --set firmware.NAME=VALUE ...]\n"
        "                [--no-analysis] [--quiet] [--uart-pty[=LINK]] [--pace X] [--selfcal]\n"
        "                [--firmware-params FILE] [--save-params FILE]\n"
        "       gyro-sim --list-params\n"
        "Runs a scenario (host_sim/scenarios/*.json) of the plant with the firmware in\n"
        "closed loop and prints its figures. --out keeps the analysis plots (PNG) and\n"
        "tool outputs; --set overrides any plant or firmware parameter. --uart-pty runs\n"
        "in real time with the tuning UART on a pseudo-terminal (path printed as\n"
        "'pty PATH'; optional symlink LINK) for gyroctl; SIGINT/SIGTERM end the run.\n"
        "Its command line has `emu`, the simulated bench: `emu rate DPS [EDGE_S]` turns\n"
        "the rate table, `emu ambient DEGC [EDGE_S]` sets the chamber (a linear move\n"
        "from the value now, then held). --pace X runs the session at X times real time\n"
        "(0: as fast as it runs; default 1).\n"
        "--isr-figures adds the Cortex-M4F interrupt cost that tools/bench/run-bench\n"
        "--json measured to the figures (isr_instructions_per_tick, ...).\n"
        "--selfcal (scenario key \"selfcal\": true; closed loop only) first runs the\n"
        "firmware's own `sweep` at the scenario's initial conditions from the parameter\n"
        "defaults and the scenario's firmware settings, saves what it identified (`save`),\n"
        "puts the mechanics at rest (temperatures kept) and starts the timeline from\n"
        "power-on with the stored values (t_s = 0 there; --duration counts the timeline).\n"
        "Figures selfcal_f0_hz, selfcal_q, selfcal_s (the firmware's sweep time) and the\n"
        "plant's selfcal_true_f0_hz, selfcal_true_q; a failed sweep says why, exit 1.\n"
        "With firmware.sense.cal=1 the sweep identifies the sense mode too: figures\n"
        "selfcal_sense_identified (else selfcal_sense_why), selfcal_sense_s (its share\n"
        "of selfcal_s), selfcal_sense_f0_hz, _q, _fb_gain_v_per_v2, _fb_phase_deg,\n"
        "_tune_ke_per_s2_per_v2 (else selfcal_sense_tune_why) beside the plant's\n"
        "selfcal_true_sense_*: its resonance (2-32) and Q at the structure temperature,\n"
        "its tuning slope; the feedback gain as the force Ks_fb per V^2 balancing\n"
        "2 Omega A0 wc over the firmware's rate.scale_dps, phase 0 (the feedback pair's\n"
        "path is the drive's): both hold when rate.scale_dps and rate.demod_phase_deg\n"
        "are the part's.\n"
        "--firmware-params FILE (scenario key \"firmware_params\", relative to the\n"
        "scenario's folder; the option wins) loads a firmware parameter set\n"
        "(docs/param-set.md) onto the defaults, as if from flash, before the scenario's\n"
        "firmware settings and --set; --selfcal then sweeps from it. A bad set is refused\n"
        "with the entry and why (exit 2, nothing run). --save-params FILE (closed loop)\n"
        "writes the firmware's values at the end of the run as a parameter set: with\n"
        "--selfcal those the self-calibration saved, else those the firmware holds.\n",
        f);
}

/* Brownian floor of the rate (4-24) at the run's actual drive frequency, amplitude and
 * structure temperature: the white-rate coefficient N of the Allan deviation (IEEE,
 * two-sided; a one-sided spectrum shows sqrt(2) N), in deg/h/sqrt(Hz). */
static double brownian_floor_dph(const plant_cfg_t *pc, double f_drive_hz, double amp_m,
                                 double t_k)
{
  const double w1 = 2.0 * PLANT_PI * f_drive_hz;
  const double w2 = 2.0 * PLANT_PI * pc->f_sense_hz *
                    (1.0 - 0.5 * pc->ket_per_k * (t_k - pc->temp_ref_k));
  const double om = sqrt(4.0 * KB_J_PER_K * t_k * w2 / (pc->mass_kg * pc->q_sense)) /
                    (2.0 * amp_m * w1);
  return om * 180.0 / PLANT_PI * 3600.0;
}

static void add_num(cJSON *o, const char *k, double v)
{
  if (isfinite(v)) cJSON_AddNumberToObject(o, k, v);
  else cJSON_AddNullToObject(o, k);
}

static int mkdir_p(const char *d)
{
  char buf[1024];
  snprintf(buf, sizeof buf, "%s", d);
  for (char *p = buf + 1; *p; p++) {
    if (*p == '/') {
      *p = '\0';
      mkdir(buf, 0777);
      *p = '/';
    }
  }
  return (mkdir(buf, 0777) == 0 || errno == EEXIST) ? 0 : -1;
}

/* Removes a file or an emptied folder on the way out of the temporary tree. */
static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
  (void)st;
  (void)flag;
  (void)ftw;
  return remove(path);
}

/* Removes the folder and everything in it (the analyses' temporary folder), without
 * following symbolic links. */
static int remove_tree(const char *dir)
{
  return nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

/* The command line, as given. */
typedef struct {
  const char *scen_path, *csv_path, *json_path, *out_dir;
  double duration_s, csv_rate_hz; /* <= 0: the scenario's */
  long long seed;                 /* < 0: the scenario's */
  int quiet, analysis, uart_pty, selfcal;
  const char *uart_pty_link;
  double pace; /* --pace: with --uart-pty, simulated s per wall s */
  const char *isr_json;
  const char *fw_params;   /* --firmware-params */
  const char *save_params; /* --save-params */
  char sets[SIM_MAX_SETS][160];
  int n_sets;
  int argc;
  char **argv; /* the command line, for the saved set's meta */
} cli_args_t;

/* Parses the options into a. Returns -1 to go on, else the exit code (usage, --help,
 * --list-params). */
static int parse_args(int argc, char **argv, cli_args_t *a)
{
  static const struct option lo[] = {{"scenario", required_argument, 0, 's'},
                                     {"duration", required_argument, 0, 'd'},
                                     {"seed", required_argument, 0, 'S'},
                                     {"csv", required_argument, 0, 'c'},
                                     {"csv-rate", required_argument, 0, 'r'},
                                     {"json", required_argument, 0, 'j'},
                                     {"out", required_argument, 0, 'o'},
                                     {"set", required_argument, 0, 'x'},
                                     {"quiet", no_argument, 0, 'q'},
                                     {"no-analysis", no_argument, 0, 'n'},
                                     {"list-params", no_argument, 0, 'L'},
                                     {"help", no_argument, 0, 'h'},
                                     {"uart-pty", optional_argument, 0, 'u'},
                                     {"pace", required_argument, 0, 'p'},
                                     {"isr-figures", required_argument, 0, 'i'},
                                     {"selfcal", no_argument, 0, 'C'},
                                     {"firmware-params", required_argument, 0, 'P'},
                                     {"save-params", required_argument, 0, 'W'},
                                     {0, 0, 0, 0}};
  memset(a, 0, sizeof *a);
  a->argc = argc;
  a->argv = argv;
  a->duration_s = -1.0;
  a->csv_rate_hz = -1.0;
  a->seed = -1;
  a->analysis = 1;
  a->pace = 1.0;
  int opt;
  char *end;
  while ((opt = getopt_long(argc, argv, "", lo, NULL)) != -1) {
    switch (opt) {
    case 's': a->scen_path = optarg; break;
    case 'd':
      errno = 0;
      a->duration_s = strtod(optarg, &end);
      if (*end || errno || !(a->duration_s > 0.0) || a->duration_s > 1e6) {
        fprintf(stderr, "gyro-sim: --duration: '%s' is not a number of seconds in (0, 1e6]\n",
                optarg);
        return 2;
      }
      break;
    case 'S':
      errno = 0;
      a->seed = strtoll(optarg, &end, 10);
      if (*end || errno || a->seed < 0) {
        fprintf(stderr, "gyro-sim: --seed: '%s' is not a non-negative integer\n", optarg);
        return 2;
      }
      break;
    case 'c': a->csv_path = optarg; break;
    case 'r':
      errno = 0;
      a->csv_rate_hz = strtod(optarg, &end);
      if (*end || errno || !(a->csv_rate_hz > 0.0) || a->csv_rate_hz > 50000.0) {
        fprintf(stderr, "gyro-sim: --csv-rate: '%s' is not a rate in (0, 50000] Hz\n", optarg);
        return 2;
      }
      break;
    case 'j': a->json_path = optarg; break;
    case 'o': a->out_dir = optarg; break;
    case 'x':
      if (a->n_sets >= SIM_MAX_SETS || strlen(optarg) >= sizeof a->sets[0]) {
        fprintf(stderr, "gyro-sim: too many or too long --set\n");
        return 2;
      }
      snprintf(a->sets[a->n_sets++], sizeof a->sets[0], "%s", optarg);
      break;
    case 'q': a->quiet = 1; break;
    case 'u':
      a->uart_pty = 1;
      a->uart_pty_link = optarg;
      break;
    case 'p':
      errno = 0;
      a->pace = strtod(optarg, &end);
      if (*end || errno || !(a->pace >= 0.0) || a->pace > 1e4) {
        fprintf(stderr, "gyro-sim: --pace: '%s' is not a factor of real time in [0, 1e4]\n",
                optarg);
        return 2;
      }
      break;
    case 'n': a->analysis = 0; break;
    case 'i': a->isr_json = optarg; break;
    case 'C': a->selfcal = 1; break;
    case 'P': a->fw_params = optarg; break;
    case 'W': a->save_params = optarg; break;
    case 'L': sim_list_params(stdout); return 0;
    case 'h': usage(stdout); return 0;
    default: usage(stderr); return 2;
    }
  }
  if (a->scen_path == NULL || optind != argc) {
    usage(stderr);
    return 2;
  }
  return -1;
}

/* Loads the scenario and applies --set, --duration, --seed and --csv-rate. Returns 0, or
 * the exit code after the message. */
static int load_scenario(const cli_args_t *a, sim_scenario_t *sc)
{
  char err[512];
  scenario_defaults(sc);
  if (scenario_load(sc, a->scen_path, err, sizeof err) != 0) {
    fprintf(stderr, "gyro-sim: %s\n", err);
    return 2;
  }
  for (int i = 0; i < a->n_sets; i++) {
    if (scenario_add_override(sc, a->sets[i], err, sizeof err) != 0) {
      fprintf(stderr, "gyro-sim: %s\n", err);
      return 2;
    }
  }
  if (a->fw_params != NULL) {
    if (a->fw_params[0] == '\0' || strlen(a->fw_params) >= sizeof sc->fw_params_path) {
      fprintf(stderr, "gyro-sim: --firmware-params: expected the path of a parameter set\n");
      return 2;
    }
    snprintf(sc->fw_params_path, sizeof sc->fw_params_path, "%s", a->fw_params);
  }
  if (a->save_params != NULL && sc->loop != SIM_CLOSED_LOOP) {
    fprintf(stderr, "gyro-sim: --save-params needs a closed-loop scenario (the firmware's "
                    "values)\n");
    return 2;
  }
  if (a->duration_s > 0.0) sc->duration_s = a->duration_s;
  if (a->seed >= 0) sc->seed = (uint64_t)a->seed;
  if (a->csv_rate_hz > 0.0) sc->csv_rate_hz = a->csv_rate_hz;
  if (a->selfcal) {
    if (sc->loop != SIM_CLOSED_LOOP) {
      fprintf(stderr, "gyro-sim: --selfcal needs a closed-loop scenario (the firmware runs "
                      "the sweep)\n");
      return 2;
    }
    sc->selfcal = 1;
  }
  return 0;
}

/* What the figures are built from and where they go. */
typedef struct {
  const sim_scenario_t *sc;
  const plant_cfg_t *pc;
  const sim_result_t *res;
  const char *out_dir;  /* the tools' folder; NULL when no tool runs */
  const char *csv_path; /* the trace the tools read */
  int quiet;
  cJSON *fig; /* "figures" of the JSON */
  int failed; /* a tool failed */
  char err[512];
} report_t;

/* Runs one analysis tool; NULL (after the message, marking the run failed) if it fails. */
static cJSON *run_tool(report_t *r, const char *tool, const char *const *args,
                       const char *json_name)
{
  cJSON *j = post_run_tool(tool, args, r->out_dir, json_name, r->err, sizeof r->err);
  if (j == NULL) {
    fprintf(stderr, "gyro-sim: %s\n", r->err);
    r->failed = 1;
  }
  return j;
}

static void add_params(cJSON *root, const sim_scenario_t *sc, const plant_cfg_t *pc,
                       const param_values_t *fw)
{
  cJSON *params = cJSON_AddObjectToObject(root, "params");
  for (size_t i = 0; i < plant_param_count(); i++) {
    const plant_param_desc_t *d = plant_param_at(i);
    add_num(params, d->name, plant_param_get(pc, d));
  }
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    const param_value_t x = param_get(fw, (param_idx_t)i);
    add_num(params, pi->name, pi->type == PARAM_T_F32 ? (double)x.f : (double)x.u);
  }
  add_num(params, "duration_s", sc->duration_s);
  add_num(params, "seed", (double)sc->seed);
  /* the part preset the plant parameters above started from (sim_plant_cfg) */
  cJSON_AddStringToObject(params, "plant_preset",
                          sc->plant_preset[0] != '\0' ? sc->plant_preset : "thesis");
}

/* The run's speed and, with --isr-figures, the interrupt cost measured on the target. */
static void report_run(report_t *r, const char *isr_json, const bench_figs_t *isr)
{
  if (isr_json != NULL) {
    add_num(r->fig, "isr_instructions_per_tick", isr->insns_mean);
    add_num(r->fig, "isr_instructions_per_tick_max", isr->insns_max);
    if (isr->have_cycles) {
      add_num(r->fig, "isr_cycles_est_mean", isr->cycles_mean);
      add_num(r->fig, "isr_cycles_est_max", isr->cycles_max);
    }
  }
  if (r->quiet) return;
  const sim_result_t *res = r->res;
  printf("scenario %s: %s\n", r->sc->name, r->sc->description);
  if (res->sim_s > 0.0) {
    printf("  simulated %.1f s in %.2f s wall (%.2f s CPU): %.0fx real time (%.0fx per CPU "
           "second)\n",
           res->sim_s, res->wall_s, res->cpu_s, res->realtime_factor, res->realtime_factor_cpu);
  }
  if (isr_json != NULL) {
    printf("  Cortex-M4F sample interrupt (%s): %.0f instructions per tick (worst %.0f)",
           isr_json, isr->insns_mean, isr->insns_max);
    if (isr->have_cycles)
      printf(", about %.0f cycles (worst %.0f)", isr->cycles_mean, isr->cycles_max);
    printf("\n");
  }
}

/* The sense mode's identification (firmware sense.cal 1): each value beside the plant's
 * truth (sim.h), its share of the sweep's time, and why a value was not identified. */
static void report_selfcal_sense(report_t *r)
{
  const sim_selfcal_t *c = &r->res->selfcal;
  cJSON_AddBoolToObject(r->fig, "selfcal_sense_identified", c->sense_ok);
  if (!c->sense_ok) cJSON_AddStringToObject(r->fig, "selfcal_sense_why", c->sense_why);
  add_num(r->fig, "selfcal_sense_s", c->sense_s);
  add_num(r->fig, "selfcal_sense_f0_hz", c->sense_f0_hz);
  add_num(r->fig, "selfcal_sense_q", c->sense_q);
  add_num(r->fig, "selfcal_sense_fb_gain_v_per_v2", c->sense_fb_gain_v_per_v2);
  add_num(r->fig, "selfcal_sense_fb_phase_deg", c->sense_fb_phase_deg);
  add_num(r->fig, "selfcal_sense_tune_ke_per_s2_per_v2", c->sense_tune_ke_per_s2_per_v2);
  if (!c->tune_ok) cJSON_AddStringToObject(r->fig, "selfcal_sense_tune_why", c->tune_why);
  add_num(r->fig, "selfcal_true_sense_f0_hz", c->true_sense_f0_hz);
  add_num(r->fig, "selfcal_true_sense_q", c->true_sense_q);
  add_num(r->fig, "selfcal_true_sense_fb_gain_v_per_v2", c->true_sense_fb_gain_v_per_v2);
  add_num(r->fig, "selfcal_true_sense_fb_phase_deg", c->true_sense_fb_phase_deg);
  add_num(r->fig, "selfcal_true_sense_tune_ke_per_s2_per_v2", c->true_tune_ke_per_s2_per_v2);
}

static void print_selfcal_sense(const sim_selfcal_t *c)
{
  if (!c->sense_ok) {
    printf("  sense mode not identified in %.2f s: %s (plant %.4f Hz, Q %.4g)\n", c->sense_s,
           c->sense_why, c->true_sense_f0_hz, c->true_sense_q);
    return;
  }
  printf("  sense mode identified in %.2f s: f0 %.4f Hz, Q %.4g, fb gain %.5f V/V^2, phase "
         "%+.2f deg (plant %.4f Hz, Q %.4g, model %.5f V/V^2, %+.2f deg); tuning slope ",
         c->sense_s, c->sense_f0_hz, c->sense_q, c->sense_fb_gain_v_per_v2,
         c->sense_fb_phase_deg, c->true_sense_f0_hz, c->true_sense_q,
         c->true_sense_fb_gain_v_per_v2, c->true_sense_fb_phase_deg);
  if (c->tune_ok)
    printf("%.4g (plant %.4g) 1/s^2/V^2\n", c->sense_tune_ke_per_s2_per_v2,
           c->true_tune_ke_per_s2_per_v2);
  else printf("not identified: %s\n", c->tune_why);
}

/* The self-calibration before the timeline: the firmware's result and time, the plant's
 * truth during it. */
static void report_selfcal(report_t *r)
{
  const sim_selfcal_t *c = &r->res->selfcal;
  add_num(r->fig, "selfcal_f0_hz", c->f0_hz);
  add_num(r->fig, "selfcal_q", c->q);
  add_num(r->fig, "selfcal_s", c->s);
  add_num(r->fig, "selfcal_true_f0_hz", c->true_f0_hz);
  add_num(r->fig, "selfcal_true_q", c->true_q);
  if (c->sense_ran) report_selfcal_sense(r);
  if (r->quiet) return;
  printf("  self-calibration (`sweep`) %s in %.2f s: f0 %.4f Hz, Q %.2f (plant %.4f Hz, Q %.2f)%s%s\n",
         c->ok ? "saved" : "FAILED", c->s, c->f0_hz, c->q, c->true_f0_hz, c->true_q,
         c->ok ? "" : ": ", c->ok ? "" : c->why);
  if (c->sense_ran) print_selfcal_sense(c);
}

static void report_startup(report_t *r)
{
  const sim_startup_t *s = &r->res->startup;
  add_num(r->fig, "lock_time_s", s->lock_time_s);
  add_num(r->fig, "overshoot_pct", s->overshoot_pct);
  add_num(r->fig, "amp_err_rms_pct", s->amp_err_rms_pct);
  add_num(r->fig, "phase_err_rms_deg", s->phase_err_rms_deg);
  add_num(r->fig, "fw_lock_time_s", s->fw_lock_time_s);
  add_num(r->fig, "rate_settle_s", s->rate_settle_s);
  add_num(r->fig, "drive_amp_true_m", s->final_amp_m);
  if (r->quiet) return;
  printf("  start-up (true motion): within 1 %% and held from %.3f s; overshoot %.2f %%\n",
         s->lock_time_s, s->overshoot_pct);
  printf("  after lock, 0.1-100 Hz: amplitude error %.4f %% rms, phase error %.5f deg rms\n",
         s->amp_err_rms_pct, s->phase_err_rms_deg);
  printf("  firmware LOCKED at %.3f s; drive amplitude %.3f um; rate output within 0.5 deg/s "
         "of its final error from %.3f s\n",
         s->fw_lock_time_s, 1e6 * s->final_amp_m, s->rate_settle_s);
}

static void report_closed_loop(report_t *r)
{
  const sim_result_t *res = r->res;
  add_num(r->fig, "faults", res->faults);
  add_num(r->fig, "final_mode", res->final_mode);
  add_num(r->fig, "rate_valid_fraction", res->rate_valid_fraction);
  add_num(r->fig, "rate_first_valid_s", res->rate_first_valid_s);
  add_num(r->fig, "phase_slips", res->phase_slips);
  if (!r->quiet) {
    printf("  rate output valid from %.3f s, %.1f %% of the run (faults %u, phase slips %u)\n",
           res->rate_first_valid_s, 100.0 * res->rate_valid_fraction, (unsigned)res->faults,
           (unsigned)res->phase_slips);
  }
  add_num(r->fig, "mean_drive_freq_hz", res->mean_drive_freq_hz);
  add_num(r->fig, "mean_drive_amp_m", res->mean_drive_amp_m);
  add_num(r->fig, "mean_struct_temp_k", res->mean_struct_k);
}

/* The open-loop sweep's trace (sweep.csv) and the drive resonance identified on it. */
static void report_sweep(report_t *r, const sim_sweep_t *sweep, int analysis)
{
  char sp[1100];
  snprintf(sp, sizeof sp, "%s/sweep.csv", r->out_dir ? r->out_dir : ".");
  FILE *f = fopen(sp, "w");
  if (f != NULL) {
    fputs("f_hz,amp,phase_deg\n", f);
    for (int i = 0; i < sweep->n; i++)
      fprintf(f, "%.6f,%.9g,%.6f\n", sweep->f_hz[i], sweep->amp_v[i], sweep->phase_deg[i]);
    fclose(f);
  }
  if (!analysis || !(r->sc->analyses & SIM_AN_SWEEP)) return;
  const char *args[] = {sp, NULL};
  cJSON *j = run_tool(r, "gyro-freqresp", args, "freqresp.json");
  if (j == NULL) return;
  add_num(r->fig, "f0_hz", post_num(j, "f0_hz"));
  add_num(r->fig, "q", post_num(j, "q"));
  add_num(r->fig, "phase_at_f0_deg", post_num(j, "phase_at_f0_deg"));
  add_num(r->fig, "peak_gain_v", post_num(j, "peak_gain"));
  add_num(r->fig, "f_3db_lo_hz", post_num(j, "f_3db_lo_hz"));
  add_num(r->fig, "f_3db_hi_hz", post_num(j, "f_3db_hi_hz"));
  if (!r->quiet) {
    printf("  identified drive resonance %.3f Hz (plant %.3f Hz), Q %.2f (plant %.2f),\n"
           "    phase at resonance %.2f deg, -3 dB %.2f..%.2f Hz\n",
           post_num(j, "f0_hz"), r->pc->f_drive_hz, post_num(j, "q"), r->pc->q_drive,
           post_num(j, "phase_at_f0_deg"), post_num(j, "f_3db_lo_hz"),
           post_num(j, "f_3db_hi_hz"));
  }
  cJSON_Delete(j);
}

/* The thesis's figure for table 7-1: a least-squares line amp = a + b U^2 (with an
 * intercept) and the RMS of its residuals; over the largest amplitude that is 0.2417 %
 * on the thesis's own sixteen points, its "0.25 %" (the through-the-origin largest
 * deviation below gives 0.735 % on them). */
static double square_law_rms(const sim_square_t *sq)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = (double)sq->n;
  for (int i = 0; i < sq->n; i++) {
    const double x = sq->u_v[i] * sq->u_v[i];
    sx += x;
    sy += sq->amp_v[i];
    sxx += x * x;
    sxy += x * sq->amp_v[i];
  }
  const double den = n * sxx - sx * sx;
  if (sq->n < 3 || den == 0.0) return NAN;
  const double b = (n * sxy - sx * sy) / den, a = (sy - b * sx) / n;
  double ss = 0;
  for (int i = 0; i < sq->n; i++) {
    const double e = sq->amp_v[i] - (a + b * sq->u_v[i] * sq->u_v[i]);
    ss += e * e;
  }
  return sqrt(ss / n);
}

/* Table 7-1: the half-frequency drive's amplitude goes with U^2 (6-19). Fits
 * amp = k U^2 through the origin and reports the largest deviation. */
static void report_square_law(report_t *r, const sim_square_t *sq)
{
  double sxy = 0, sxx = 0, amax = 0, dmax = 0;
  for (int i = 0; i < sq->n; i++) {
    const double u2 = sq->u_v[i] * sq->u_v[i];
    sxy += u2 * sq->amp_v[i];
    sxx += u2 * u2;
    if (sq->amp_v[i] > amax) amax = sq->amp_v[i];
  }
  const double k = sxy / sxx;
  cJSON *tab = cJSON_AddArrayToObject(r->fig, "square_law");
  if (!r->quiet)
    printf("  square law (table 7-1): U (V) -> drive pickoff (V), displacement (um), fit k U^2\n");
  for (int i = 0; i < sq->n; i++) {
    const double fit = k * sq->u_v[i] * sq->u_v[i];
    if (fabs(sq->amp_v[i] - fit) > dmax) dmax = fabs(sq->amp_v[i] - fit);
    cJSON *row = cJSON_CreateObject();
    add_num(row, "u_v", sq->u_v[i]);
    add_num(row, "amp_v", sq->amp_v[i]);
    add_num(row, "amp_m", sq->amp_m[i]);
    cJSON_AddItemToArray(tab, row);
    if (!r->quiet)
      printf("    %6.2f  %8.4f  %8.4f  %8.4f\n", sq->u_v[i], sq->amp_v[i], 1e6 * sq->amp_m[i],
             fit);
  }
  add_num(r->fig, "square_law_k_v_per_v2", k);
  add_num(r->fig, "square_law_nonlinearity_pct", 100.0 * dmax / amax);
  const double rms_pct = 100.0 * square_law_rms(sq) / amax;
  add_num(r->fig, "square_law_nonlinearity_rms_pct", rms_pct);
  if (!r->quiet)
    printf("  k = %.6g V/V^2, largest deviation %.3f %% of the largest amplitude; RMS residual "
           "of a line with intercept %.3f %% (the thesis's figure)\n",
           k, 100.0 * dmax / amax, rms_pct);
}

/* The same table read at the analog output (CSV aout_v, what the thesis's multimeter read
 * in §7.2.4): the converter's INL and step size join the rate path's own nonlinearity. */
static void analyse_rate_table_analog(report_t *r)
{
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/analog_out", r->out_dir);
  if (mkdir_p(dir) != 0) {
    fprintf(stderr, "gyro-sim: %s: cannot create the folder\n", dir);
    r->failed = 1;
    return;
  }
  /* a meter reads the output once it is valid: before, it sits at the fault level */
  const char *args[] = {r->csv_path, "--column",       "aout_v",     "--unit",
                        "V",         "--settle",       "0.5",        "--min-avg",
                        "0.5",       "--valid-column", "rate_valid", NULL};
  cJSON *j = post_run_tool("gyro-scalefactor", args, dir, "scalefactor.json", r->err,
                           sizeof r->err);
  if (j == NULL) {
    fprintf(stderr, "gyro-sim: %s\n", r->err);
    r->failed = 1;
    return;
  }
  add_num(r->fig, "aout_scale_factor_v_per_dps", post_num(j, "scale_factor_out_per_dps"));
  add_num(r->fig, "aout_nonlinearity_pct", post_num(j, "nonlinearity_rms_percent_of_fs"));
  add_num(r->fig, "aout_nonlinearity_max_pct", post_num(j, "nonlinearity_max_percent_of_fs"));
  if (!r->quiet) {
    printf("  analog output: scale factor %.7f V/(deg/s), nonlinearity %.4f %% FS rms\n",
           post_num(j, "scale_factor_out_per_dps"),
           post_num(j, "nonlinearity_rms_percent_of_fs"));
  }
  cJSON_Delete(j);
}

static void analyse_rate_table(report_t *r)
{
  const char *args[] = {r->csv_path, "--settle", "0.5", "--min-avg", "0.5", NULL};
  cJSON *j = run_tool(r, "gyro-scalefactor", args, "scalefactor.json");
  if (j == NULL) return;
  add_num(r->fig, "scale_factor", post_num(j, "scale_factor_out_per_dps"));
  add_num(r->fig, "bias_dps", post_num(j, "bias_out"));
  add_num(r->fig, "nonlinearity_pct", post_num(j, "nonlinearity_rms_percent_of_fs"));
  add_num(r->fig, "nonlinearity_max_pct", post_num(j, "nonlinearity_max_percent_of_fs"));
  add_num(r->fig, "asymmetry", post_num(j, "asymmetry_fraction"));
  if (!r->quiet) {
    printf("  rate table: scale factor %.6f (deg/s)/(deg/s), bias %.4f deg/s, nonlinearity %.4f %% FS rms\n",
           post_num(j, "scale_factor_out_per_dps"), post_num(j, "bias_out"),
           post_num(j, "nonlinearity_rms_percent_of_fs"));
  }
  cJSON_Delete(j);
  analyse_rate_table_analog(r);
}

/* White rate noise against the Brownian floor (4-24), from the Allan fit j scaled to the
 * input by the scale factor sf. */
static void report_noise(report_t *r, const cJSON *j, double sf)
{
  const sim_result_t *res = r->res;
  const double n_in = post_num(j, "arw_dph_per_rthz") / sf;
  const double floor = brownian_floor_dph(r->pc, res->mean_drive_freq_hz, res->mean_drive_amp_m,
                                          res->mean_struct_k);
  add_num(r->fig, "arw_coeff_dph_rthz", n_in);
  add_num(r->fig, "adev_1s_dph", post_num(j, "adev_at_1s_dph") / sf);
  add_num(r->fig, "brownian_floor_dph_rthz", floor);
  add_num(r->fig, "arw_over_floor", n_in / floor);
  if (!r->quiet) {
    printf("  rate noise N = %.3f deg/h/rtHz (Allan -1/2 slope, two-sided; one-sided ASD %.3f),\n"
           "    Brownian floor (4-24) at %.3f Hz, %.3f um, %.2f K: %.3f deg/h/rtHz; ratio %.3f\n",
           n_in, sqrt(2.0) * n_in, res->mean_drive_freq_hz, 1e6 * res->mean_drive_amp_m,
           res->mean_struct_k, floor, n_in / floor);
  }
}

/* The Allan read-offs of gyro-allan's JSON j as figures named prefix + name: "" for the
 * output rate_dps (divided by the measured scale factor sf), "unc_" for the
 * uncompensated rate_unc_dps (sf 1). */
static void report_allan(report_t *r, const cJSON *j, double sf, const char *prefix)
{
  /* The fitted three-term model can read a change of white level as flicker; the
   * measured minimum bounds the bias instability whatever the model says. */
  static const struct {
    const char *fig, *key;
    int per_sf; /* a rate: divided by sf */
  } kFigs[] = {{"arw_deg_rth", "arw_deg_per_rth", 1},
               {"bias_instability_dph", "bias_instability_dph", 1},
               {"rate_ramp_dph_per_h", "rate_ramp_dph_per_h", 1},
               {"adev_min_dph", "adev_min_measured_dph", 1},
               {"tau_at_adev_min_s", "tau_at_min_measured_s", 0}};
  for (size_t i = 0; i < sizeof kFigs / sizeof kFigs[0]; i++) {
    char name[64];
    snprintf(name, sizeof name, "%s%s", prefix, kFigs[i].fig);
    add_num(r->fig, name, post_num(j, kFigs[i].key) / (kFigs[i].per_sf ? sf : 1.0));
  }
  if (!r->quiet) {
    printf("  Allan%s: ARW %.4f deg/rt(h), bias instability %.3f deg/h (fit), rate ramp %.3f deg/h/h;\n"
           "    lowest measured Allan deviation %.3f deg/h at %.0f s\n",
           prefix[0] != '\0' ? " of the uncompensated rate" : "",
           post_num(j, "arw_deg_per_rth") / sf, post_num(j, "bias_instability_dph") / sf,
           post_num(j, "rate_ramp_dph_per_h") / sf, post_num(j, "adev_min_measured_dph") / sf,
           post_num(j, "tau_at_min_measured_s"));
  }
}

/* End of the static part of the run: a scenario's last rate step (if any) is its
 * scale-factor check and is left out of the Allan figures. */
static double static_end_s(const sim_scenario_t *sc, int *sf_step)
{
  *sf_step = sc->has_rate && sc->rate_dps.kind == PROFILE_STEPS && sc->rate_dps.n_steps > 1;
  return *sf_step ? sc->rate_dps.step_s[0] : sc->duration_s;
}

static void analyse_noise_allan(report_t *r)
{
  const sim_scenario_t *sc = r->sc;
  char tend[32];
  int sf_step;
  const double t_end = static_end_s(sc, &sf_step);
  snprintf(tend, sizeof tend, "%.6f", t_end);
  const char *args[] = {r->csv_path, "--t-start", "1", "--t-end", tend, NULL};
  cJSON *j = post_run_tool("gyro-allan", args, r->out_dir, "allan.json", r->err, sizeof r->err);
  double sf = 1.0;
  if (j != NULL && sf_step) {
    const char *a2[] = {r->csv_path, "--t-start", tend,  "--settle",
                        "0.5",       "--min-avg", "0.5", NULL};
    cJSON *s = post_run_tool("gyro-scalefactor", a2, r->out_dir, "scalefactor.json", r->err,
                             sizeof r->err);
    if (s != NULL) {
      sf = post_num(s, "scale_factor_out_per_dps");
      add_num(r->fig, "scale_factor", sf);
      cJSON_Delete(s);
    }
  }
  if (j == NULL) {
    fprintf(stderr, "gyro-sim: %s\n", r->err);
    r->failed = 1;
    return;
  }
  if (sc->analyses & SIM_AN_NOISE) report_noise(r, j, sf);
  if (sc->analyses & SIM_AN_ALLAN) report_allan(r, j, sf, "");
  cJSON_Delete(j);
}

/* allan_unc: the same read-offs of the uncompensated rate rate_unc_dps (figures unc_*,
 * the tool's plot and JSON in OUT/allan_unc/). The thesis measured its part without
 * temperature compensation (table 7-3, fig. 7-11); the part's calibration compensates
 * the bias against P, which takes a warm-up's drift out of rate_dps. */
static void analyse_allan_unc(report_t *r)
{
  char dir[1100], tend[32];
  snprintf(dir, sizeof dir, "%s/allan_unc", r->out_dir);
  if (mkdir_p(dir) != 0) {
    fprintf(stderr, "gyro-sim: %s: %s\n", dir, strerror(errno));
    r->failed = 1;
    return;
  }
  int sf_step;
  snprintf(tend, sizeof tend, "%.6f", static_end_s(r->sc, &sf_step));
  const char *args[] = {r->csv_path, "--column", "rate_unc_dps", "--t-start",
                        "1",         "--t-end",  tend,           NULL};
  cJSON *j = post_run_tool("gyro-allan", args, dir, "allan.json", r->err, sizeof r->err);
  if (j == NULL) {
    fprintf(stderr, "gyro-sim: %s\n", r->err);
    r->failed = 1;
    return;
  }
  report_allan(r, j, 1.0, "unc_");
  cJSON_Delete(j);
}

static void analyse_drive_noise(report_t *r)
{
  const char *args[] = {
      r->csv_path, "--column", "drive_amp_true_m", "--band", "1", "10", "--t-start", "2", NULL};
  cJSON *j = run_tool(r, "gyro-psd", args, "psd.json");
  if (j == NULL) return;
  const double rel = post_num(j, "white_asd_one_sided_per_rthz") / r->res->mean_drive_amp_m;
  add_num(r->fig, "drive_amp_noise_lf_rel", rel);
  if (!r->quiet)
    printf("  drive amplitude noise over 1-10 Hz: %.3g /rtHz relative (one-sided)\n", rel);
  cJSON_Delete(j);
}

static void analyse_temp(report_t *r)
{
  const sim_scenario_t *sc = r->sc;
  /* Fit the uncompensated output (the part's calibration may compensate already)
   * against the firmware's own low-passed P (the instantaneous P carries the phase
   * loop's ripple) and, for a heat-gun run, on the cool-down only, as the thesis does
   * (7.3.2). */
  char t0[32] = "0";
  if (sc->has_ambient && sc->ambient_c.kind == PROFILE_HEAT_COOL) {
    snprintf(t0, sizeof t0, "%.3f", sc->ambient_c.t_start_s + sc->ambient_c.heat_s);
  }
  const char *args[] = {r->csv_path,     "--column",  "rate_unc_dps", "--p-column", "p_f_deg",
                        "--temp-column", "t_board_c", "--t-start",    t0,           NULL};
  cJSON *j = run_tool(r, "gyro-tempcomp", args, "tempcomp.json");
  if (j == NULL) return;
  add_num(r->fig, "residual_bias_p_dps", post_num(j, "p_fit.residual_std_dps"));
  add_num(r->fig, "residual_bias_sensor_dps", post_num(j, "t_fit.residual_std_dps"));
  add_num(r->fig, "residual_bias_p_pp_dps", post_num(j, "p_fit.residual_p2p_dps"));
  add_num(r->fig, "residual_bias_sensor_pp_dps", post_num(j, "t_fit.residual_p2p_dps"));
  add_num(r->fig, "bias_p_order", post_num(j, "p_fit.order"));
  if (!r->quiet) {
    printf("  temperature compensation: residual bias with P %.4f deg/s (p-p %.4f), with the board sensor %.4f deg/s (p-p %.4f)\n",
           post_num(j, "p_fit.residual_std_dps"), post_num(j, "p_fit.residual_p2p_dps"),
           post_num(j, "t_fit.residual_std_dps"), post_num(j, "t_fit.residual_p2p_dps"));
  }
  cJSON_Delete(j);
}

/* The closed-loop figures that the analysis tools compute on the trace. */
static void analyse_trace(report_t *r)
{
  const uint32_t an = r->sc->analyses;
  if (an & SIM_AN_RATE_TABLE) analyse_rate_table(r);
  if (an & (SIM_AN_NOISE | SIM_AN_ALLAN)) analyse_noise_allan(r);
  if (an & SIM_AN_ALLAN_UNC) analyse_allan_unc(r);
  if (an & SIM_AN_DRIVE_NOISE) analyse_drive_noise(r);
  if (an & SIM_AN_TEMP) analyse_temp(r);
}

static int write_json(const cJSON *root, const char *json_path)
{
  char *txt = cJSON_Print(root);
  FILE *f = fopen(json_path, "w");
  int rc = 0;
  if (f == NULL || txt == NULL) {
    fprintf(stderr, "gyro-sim: --json %s: %s\n", json_path, strerror(errno));
    rc = -1;
  } else {
    fputs(txt, f);
    fputc('\n', f);
    fclose(f);
  }
  free(txt);
  return rc;
}

/* Where the analysis tools write: --out (made if missing) or, when tools run without it,
 * a temporary folder removed at the end (*tmp_used). Returns 0, or the exit code. */
static int prepare_out_dir(const char **out_dir, char *tmpdir, int need_tools, int *tmp_used)
{
  *tmp_used = 0;
  if (*out_dir == NULL && need_tools) {
    if (mkdtemp(tmpdir) == NULL) {
      fprintf(stderr, "gyro-sim: cannot make a temporary folder: %s\n", strerror(errno));
      return 1;
    }
    *out_dir = tmpdir;
    *tmp_used = 1;
  } else if (*out_dir != NULL && mkdir_p(*out_dir) != 0) {
    fprintf(stderr, "gyro-sim: --out %s: %s\n", *out_dir, strerror(errno));
    return 2;
  }
  return 0;
}

/* plant_warnings: each plant law that left its range, its count and first time. */
static void report_plant_warnings(report_t *r)
{
  cJSON *w = cJSON_AddObjectToObject(r->fig, "plant_warnings");
  uint64_t total = 0;
  for (int i = 0; i < PLANT_LAWS; i++) {
    const plant_warning_t *pw = &r->res->plant_warnings[i];
    total += pw->count;
    if (pw->count == 0) continue;
    cJSON *o = cJSON_AddObjectToObject(w, plant_law_name(i));
    add_num(o, "count", (double)pw->count);
    add_num(o, "first_t_s", pw->first_t_s);
    if (!r->quiet)
      fprintf(stderr,
              "gyro-sim: warning: plant law %s outside its range %llu times from t = %g s\n",
              plant_law_name(i), (unsigned long long)pw->count, pw->first_t_s);
  }
  add_num(r->fig, "plant_warnings_total", (double)total);
  /* frames the plant's DAC refused (a code beyond 14 bits): 0 unless the firmware or the
   * open-loop drive wrote a bad frame */
  add_num(r->fig, "plant_dac_rejects", (double)r->res->dac_rejects);
}

/* sense_match: on a part with sense tuning electrodes, whether they can bring the sense
 * resonance to the drive's at the ambient (plant_sense_match); a note on stderr when they
 * cannot (tuning only lowers it). Nothing on a part without them. */
static void report_sense_match(report_t *r)
{
  if (!(r->pc->tune_ke_per_s2_per_v2 > 0.0)) return;
  plant_match_t m;
  if (plant_sense_match(r->pc, r->pc->temp_k, 0.0, 0.0, &m) < 0) return;
  cJSON *o = cJSON_AddObjectToObject(r->fig, "sense_match");
  add_num(o, "reachable", (double)m.reachable);
  add_num(o, "tune_v", m.tune_v);
  add_num(o, "f_sense_hz", m.f_sense_hz);
  add_num(o, "f_target_hz", m.f_target_hz);
  cJSON_AddStringToObject(o, "message", m.msg);
  if (!m.reachable && !r->quiet) fprintf(stderr, "gyro-sim: note: %s\n", m.msg);
}

/* The figures of a finished run: printed unless quiet, and into the JSON root. */
static void report_figures(report_t *r, const cli_args_t *a, const bench_figs_t *isr,
                           const sim_sweep_t *sweep, const sim_square_t *sq, int need_tools)
{
  const sim_scenario_t *sc = r->sc;
  report_run(r, a->isr_json, isr);
  if (r->res->selfcal.ran) report_selfcal(r);
  if (r->res->selfcal.ran && !r->res->selfcal.ok) return; /* no timeline ran */
  if (sc->analyses & SIM_AN_STARTUP) report_startup(r);
  if (sc->loop == SIM_CLOSED_LOOP) report_closed_loop(r);
  add_num(r->fig, "adc_fraction_drive", r->res->adc_fraction[0]);
  add_num(r->fig, "adc_fraction_sense", r->res->adc_fraction[1]);
  add_num(r->fig, "adc_clips_drive", (double)r->res->adc_clips[0]);
  add_num(r->fig, "adc_clips_sense", (double)r->res->adc_clips[1]);
  report_plant_warnings(r);
  report_sense_match(r);
  if (sc->loop == SIM_OPEN_LOOP_SWEEP && sweep->n > 0) report_sweep(r, sweep, a->analysis);
  if (sc->loop == SIM_OPEN_LOOP && sq->n > 1) {
    report_square_law(r, sq);
  } else if (sc->loop == SIM_OPEN_LOOP && sq->n == 1) {
    add_num(r->fig, "drive_amp_v", sq->amp_v[0]);
    add_num(r->fig, "drive_amp_m", sq->amp_m[0]);
  }
  if (need_tools && sc->loop == SIM_CLOSED_LOOP) analyse_trace(r);
}

/* The command line as one string a shell reads back (words with other than
 * [A-Za-z0-9_./=+:,@%-] single-quoted). */
static char *command_line(int argc, char **argv)
{
  size_t cap = 1;
  for (int i = 0; i < argc; i++) cap += 4u * strlen(argv[i]) + 3u;
  char *out = malloc(cap);
  if (out == NULL) return NULL;
  size_t n = 0;
  for (int i = 0; i < argc; i++) {
    const char *w = argv[i];
    const int plain = w[0] != '\0' &&
                      strspn(w, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                "0123456789_./=+:,@%-") == strlen(w);
    if (i > 0) out[n++] = ' ';
    if (!plain) out[n++] = '\'';
    for (const char *c = w; *c != '\0'; c++) {
      if (!plain && *c == '\'') {
        memcpy(out + n, "'\\''", 4); /* close, escaped quote, reopen */
        n += 4;
      } else {
        out[n++] = *c;
      }
    }
    if (!plain) out[n++] = '\'';
  }
  out[n] = '\0';
  return out;
}

/* --save-params: the firmware's values (after a self-calibration: what it saved; else
 * what the application holds at the end) as a parameter set. Returns 0, or -1 after the
 * message. */
/* "commands": the scenario's command lines with their replies (null: the run ended
 * before the line was due). */
static void add_commands(cJSON *root, const sim_scenario_t *sc, const sim_result_t *res)
{
  if (sc->n_cmds == 0) return;
  cJSON *arr = cJSON_AddArrayToObject(root, "commands");
  for (int i = 0; i < sc->n_cmds; i++) {
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "t_s", sc->cmds[i].t_s);
    cJSON_AddStringToObject(o, "line", sc->cmds[i].line);
    if (i < res->n_cmds_run) cJSON_AddStringToObject(o, "reply", res->cmd_reply[i]);
    else cJSON_AddNullToObject(o, "reply");
    cJSON_AddItemToArray(arr, o);
  }
}

static int save_params(const cli_args_t *a, const sim_scenario_t *sc, const sim_result_t *res)
{
  const sim_selfcal_t *c = &res->selfcal;
  if (c->ran && !c->ok) {
    fprintf(stderr, "gyro-sim: --save-params %s: not written: the self-calibration failed\n",
            a->save_params);
    return -1;
  }
  cJSON *meta = cJSON_CreateObject();
  char *cmd = command_line(a->argc, a->argv);
  char date[32] = "";
  const time_t now = time(NULL);
  struct tm tm_utc;
  if (gmtime_r(&now, &tm_utc) != NULL)
    strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm_utc);
  cJSON_AddStringToObject(meta, "made_by", "gyro-sim");
  cJSON_AddStringToObject(meta, "command", cmd != NULL ? cmd : "");
  cJSON_AddStringToObject(meta, "date", date);
  cJSON_AddStringToObject(meta, "scenario", sc->name);
  cJSON_AddStringToObject(meta, "values",
                          c->ran ? "saved by the self-calibration (drive off, save)"
                                 : "held by the firmware at the end of the run");
  if (c->ran) {
    add_num(meta, "selfcal_f0_hz", c->f0_hz);
    add_num(meta, "selfcal_q", c->q);
  }
  char *mtxt = cJSON_PrintUnformatted(meta);
  char err[512];
  const int rc = param_set_write_file(a->save_params, c->ran ? &c->saved : &res->final_params,
                                      mtxt, err, sizeof err);
  if (rc != 0) fprintf(stderr, "gyro-sim: --save-params %s\n", err);
  else if (!a->quiet) printf("  firmware parameters saved to %s\n", a->save_params);
  free(mtxt);
  free(cmd);
  cJSON_Delete(meta);
  return rc;
}

/* Runs the loaded scenario and reports it. Returns the exit code. */
static int run(const cli_args_t *a, const sim_scenario_t *sc, const bench_figs_t *isr,
               const char *out_dir, const char *csv_path, int need_tools)
{
  char err[512];
  plant_cfg_t pc;
  plant_profiles_t prof;
  param_values_t fw;
  if (sim_plant_cfg(sc, &pc, &prof, err, sizeof err) != 0 ||
      sim_fw_params(sc, &fw, err, sizeof err) != 0) {
    fprintf(stderr, "gyro-sim: %s\n", err);
    return 2;
  }
  if (a->uart_pty && sc->loop != SIM_CLOSED_LOOP) {
    fprintf(stderr, "gyro-sim: --uart-pty needs a closed-loop scenario\n");
    return 2;
  }
  if (a->uart_pty && sc->n_cmds > 0) {
    fprintf(stderr, "gyro-sim: --uart-pty and the scenario's \"commands\" would both type "
                    "into the command line: one or the other\n");
    return 2;
  }
  const sim_opts_t so = {
      csv_path,    sc->csv_rate_hz,  !a->quiet && isatty(2) && sc->duration_s > 2.0,
      a->uart_pty, a->uart_pty_link, a->pace};
  static sim_result_t res;
  static sim_sweep_t sweep;
  static sim_square_t sq;
  int rc;
  if (sc->loop == SIM_CLOSED_LOOP) rc = sim_run_closed_loop(sc, &so, &res, err, sizeof err);
  else rc = sim_run_open_loop(sc, &so, &res, &sweep, &sq, err, sizeof err);
  if (rc != 0) {
    fprintf(stderr, "gyro-sim: %s\n", err);
    if (rc != -2) return 1; /* -2: the self-calibration failed, its figures are written */
  }

  cJSON *root = cJSON_CreateObject();
  cJSON_AddStringToObject(root, "scenario", sc->name);
  if (sc->fw_params_path[0] != '\0')
    cJSON_AddStringToObject(root, "firmware_params", sc->fw_params_path);
  else cJSON_AddNullToObject(root, "firmware_params");
  if (res.selfcal.ran && !res.selfcal.ok)
    cJSON_AddStringToObject(root, "selfcal_error", res.selfcal.why);
  add_params(root, sc, &pc, res.selfcal.ok ? &res.selfcal.saved : &fw);
  add_commands(root, sc, &res);
  report_t r = {.sc = sc,
                .pc = &pc,
                .res = &res,
                .out_dir = out_dir,
                .csv_path = csv_path,
                .quiet = a->quiet,
                .fig = cJSON_AddObjectToObject(root, "figures")};
  report_figures(&r, a, isr, &sweep, &sq, need_tools);
  if (a->save_params != NULL && save_params(a, sc, &res) != 0) r.failed = 1;
  add_num(root, "realtime_factor", res.realtime_factor);
  add_num(root, "realtime_factor_cpu", res.realtime_factor_cpu);
  if (a->json_path != NULL && write_json(root, a->json_path) != 0) r.failed = 1;
  cJSON_Delete(root);
  return (r.failed || rc != 0) ? 1 : 0;
}

int main(int argc, char **argv)
{
  static cli_args_t a;
  static sim_scenario_t sc;
  int rc = parse_args(argc, argv, &a);
  if (rc >= 0) return rc;
  rc = load_scenario(&a, &sc);
  if (rc != 0) return rc;
  bench_figs_t isr;
  char err[512];
  if (a.isr_json != NULL && bench_figs_load(a.isr_json, &isr, err, sizeof err) != 0) {
    fprintf(stderr, "gyro-sim: %s\n", err);
    return 2;
  }

  /* Analyses by the tools need a trace and a folder; without --out they use a temporary
   * one that is removed afterwards. */
  const uint32_t tool_analyses = SIM_AN_RATE_TABLE | SIM_AN_NOISE | SIM_AN_ALLAN |
                                 SIM_AN_ALLAN_UNC | SIM_AN_DRIVE_NOISE | SIM_AN_TEMP |
                                 SIM_AN_SWEEP;
  const int need_tools = a.analysis && (sc.analyses & tool_analyses) != 0u;
  char tmpdir[] = "/tmp/gyro-sim-XXXXXX";
  const char *out_dir = a.out_dir;
  int tmp_used;
  rc = prepare_out_dir(&out_dir, tmpdir, need_tools, &tmp_used);
  if (rc != 0) return rc;
  char trace[1100];
  const char *csv_path = a.csv_path;
  if (csv_path == NULL && need_tools && sc.loop == SIM_CLOSED_LOOP) {
    snprintf(trace, sizeof trace, "%s/trace.csv", out_dir);
    csv_path = trace;
  }

  rc = run(&a, &sc, &isr, out_dir, csv_path, need_tools);
  if (tmp_used && remove_tree(tmpdir) != 0) {
    fprintf(stderr, "gyro-sim: could not remove %s: %s\n", tmpdir, strerror(errno));
  }
  return rc;
}
