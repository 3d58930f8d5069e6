/* gyro-sim: one run of a scenario - the plant (host_sim/plant) behind the host HAL stub,
 * with the real firmware application (firmware/app) in closed loop, or an open-loop
 * drive generated here for the characterisation of the bare plant (§7.2.2, table 7-1).
 *
 * The run writes a CSV trace (stable columns, see sim_csv_header) and collects the
 * figures that need the plant's truth (start-up on the true motion); figures that need
 * spectra, Allan deviation or fits are computed by the analysis tools (tools/gyro-*)
 * on the trace, so each is implemented once.
 */
#ifndef SIM_H
#define SIM_H

#include <stdint.h>
#include <stdio.h>

#include "app/app.h"
#include "plant/plant.h"
#include "scenario.h"

/* Start-up of the drive, measured on the plant's true motion (not on the firmware's own
 * estimate, which a high gain simply zeroes). */
typedef struct {
  double lock_time_s;       /* true amplitude within 1 % of its final value from here on */
  double overshoot_pct;     /* peak true amplitude over the final one, -1, in % */
  double amp_err_rms_pct;   /* true amplitude, 0.1-100 Hz, after lock, % of the mean */
  double phase_err_rms_deg; /* true drive phase against the NCO, 0.1-100 Hz, after lock */
  double fw_lock_time_s;    /* first LOCKED of the firmware's supervisor */
  double rate_settle_s;     /* rate output error within 0.5 deg/s of its final value */
  double final_amp_m;
} sim_startup_t;

typedef struct {
  int n;
  double f_hz[10000];
  double amp_v[10000];
  double phase_deg[10000]; /* drive pickoff against the drive force cos(wt) */
} sim_sweep_t;

typedef struct {
  int n;
  double u_v[16];
  double amp_v[16];
  double amp_m[16]; /* true displacement amplitude */
} sim_square_t;

/* The self-calibration before the timeline (scenario key "selfcal"): what the firmware's
 * own `sweep` identified and how long it took, against the plant's truth during it. */
typedef struct {
  int ran;              /* a sweep was run */
  int ok;               /* it finished (DONE) and its values were saved */
  char why[160];        /* the reason, when not ok */
  double f0_hz, q;      /* identified (NAN before the fit) */
  double s;             /* the firmware's sweep time: request to hand-over */
  double true_f0_hz;    /* undamped drive resonance (2-32), mean over the sweep */
  double true_q;        /* the drive Q at the structure temperature (plant.q_temp_law),
                           mean over the sweep */
  param_values_t saved; /* the parameters the timeline starts from (the store's) */
  /* The sense mode's identification (firmware sense.cal 1, selfcal.h S1-S3): */
  int sense_ran;               /* it was asked for */
  int sense_ok;                /* all four model values identified */
  char sense_why[160];         /* the reason, when not sense_ok */
  double sense_f0_hz, sense_q; /* identified (NAN when not) */
  double sense_fb_gain_v_per_v2, sense_fb_phase_deg;
  int tune_ok;                        /* the tuning slope identified */
  char tune_why[160];                 /* the reason, when probed and not tune_ok */
  double sense_tune_ke_per_s2_per_v2; /* NAN when not identified */
  double sense_s;                     /* its share of the sweep time */
  double true_sense_f0_hz;            /* undamped sense resonance (2-32) without the electrodes'
                              softening, mean over the sweep */
  double true_sense_q; /* the sense Q at the structure temperature, mean over it */
  double true_sense_fb_gain_v_per_v2; /* the model of test_cl_sense_fr.c: the feedback's
                                         rate equivalent (plant_fb_rate_dps_per_v2, at
                                         the plant's drive resonance and design
                                         amplitude) over the firmware's rate.scale_dps,
                                         times drive.amp_set_v */
  double true_sense_fb_phase_deg;     /* 0: the feedback pair's path is the drive pair's */
  double true_tune_ke_per_s2_per_v2;  /* the tuning electrodes' slope times their DAC gain */
} sim_selfcal_t;

/* Longest reply kept of a scenario command (the host UART stub holds less). */
#define SIM_CMD_REPLY_MAX 8192

typedef struct {
  double sim_s;
  double wall_s;
  double cpu_s;
  double realtime_factor;     /* simulated / wall-clock time */
  double realtime_factor_cpu; /* simulated / CPU time of the run (one core) */
  sim_startup_t startup;
  double adc_fraction[2]; /* worst-case budget from plant_adc_fraction */
  uint64_t adc_clips[2];
  plant_warning_t plant_warnings[PLANT_LAWS]; /* plant laws outside their range */
  uint64_t dac_rejects; /* frames the plant's DAC refused (a code out of range): 0 */
  uint32_t faults;
  double rate_valid_fraction; /* of the run's ticks with the rate output valid */
  double rate_first_valid_s;  /* first tick with the rate valid; -1: never */
  uint32_t phase_slips;       /* true drive phase off its locked value by > 90 deg (slip.h) */
  uint32_t final_mode;
  double mean_struct_k;
  double mean_drive_freq_hz;
  double mean_drive_amp_m;
  sim_selfcal_t selfcal;
  param_values_t final_params; /* closed loop: the values the application holds at the end */
  int n_cmds_run;              /* scenario "commands" typed (those within the run) */
  char cmd_reply[SIM_CMDS_MAX][SIM_CMD_REPLY_MAX]; /* their replies, whole */
} sim_result_t;

typedef struct {
  const char *csv_path; /* NULL: no trace */
  double csv_rate_hz;
  int progress;              /* progress bar on stderr */
  int uart_pty;              /* expose the tuning UART as a pty, run paced */
  const char *uart_pty_link; /* optional symlink to the pty */
  double pace; /* with uart_pty: simulated s per wall s (1 real time, 0 unpaced) */
} sim_opts_t;

/* Every parameter a scenario or --set takes, with its default, range, unit and doc:
 * plant.KEY (the plant's table, plant.thermal_preset and plant.preset) and firmware.NAME. */
void sim_list_params(FILE *f);

/* Build the plant configuration and profiles from the scenario (defaults + overrides).
 * Returns 0, or -1 with the offending key in err. */
int sim_plant_cfg(const sim_scenario_t *sc, plant_cfg_t *cfg, plant_profiles_t *prof, char *err,
                  size_t err_len);
/* The firmware parameters from the scenario: defaults, the parameter set of
 * "firmware_params" (--firmware-params) over them, then the settings, each checked. */
int sim_fw_params(const sim_scenario_t *sc, param_values_t *v, char *err, size_t err_len);

/* Closed loop; with sc->selfcal the firmware's `sweep` first (res->selfcal). Returns 0,
 * -1 with err (nothing run or a run error), or -2 with err when the self-calibration
 * failed (res->selfcal says why; no timeline). */
int sim_run_closed_loop(const sim_scenario_t *sc, const sim_opts_t *opt, sim_result_t *res,
                        char *err, size_t err_len);
int sim_run_open_loop(const sim_scenario_t *sc, const sim_opts_t *opt, sim_result_t *res,
                      sim_sweep_t *sweep, sim_square_t *sq, char *err, size_t err_len);

#endif /* SIM_H */
