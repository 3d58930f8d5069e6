/* The application on the host plant through the host HAL, driven over its command line
 * as gyroctl would drive a board: the harness the closed-loop C tests share.
 * Header-only (static), one instance per test program. */
#ifndef APP_PLANT_H
#define APP_PLANT_H

#include <string.h>

#include "app/app.h"
#include "app_cmd.h"
#include "default_part.h"
#include "hal/hal_sample_timer.h"
#include "hal_flash_host.h"
#include "hal_host.h"
#include "hal_uart_host.h"
#include "plant/plant.h"

static plant_t plant;
static app_t app;

/* Plant pc (seed) on the host HAL, an empty flash store, the application with the
 * values v (NULL: the default part's calibration, default_part.h), the 50 kHz clock
 * running. */
static inline void app_plant_start(const plant_cfg_t *pc, uint64_t seed, const param_values_t *v)
{
  if (plant_init(&plant, pc, seed) != 0) fail_msg("plant: %s", plant_error(&plant));
  assert_int_equal(hal_flash_host_configure(NULL), 0);
  hal_uart_host_reset();
  hal_host_attach(plant_step_hal, &plant);
  hal_host_attach_board_temp(plant_board_temp_hal, &plant); /* the board's TMP117 */
  param_values_t def;
  if (v == NULL) {
    default_part_values(&def);
    v = &def;
  }
  assert_int_equal(app_init_with(&app, v), 0);
  assert_int_equal(hal_sample_timer_start(50000u, app_sample_isr, &app), 0);
}

/* The parameter values of the default part at quality factor q calibrated at the
 * reference temperature as its calibration would leave them in flash (drive.track as
 * given): its resonance f_drive_hz times (1 + f_offset_rel), its Q, and its gain, which
 * grows as Q (6-12): the default part's calibrated gain and Q, scaled; the rate channel's
 * calibration the default part's, its record at the new drive frequency. */
static inline void app_plant_cal_values(const plant_cfg_t *pc, double q, int track,
                                        double f_offset_rel, param_values_t *v)
{
  default_part_values(v);
  v->drive_track = track ? 1u : 0u;
  v->drive_cal_gain_v_per_v2 = (float)((double)v->drive_cal_gain_v_per_v2 * q /
                                       (double)v->drive_cal_q);
  v->drive_cal_q = (float)q;
  v->drive_freq_hz = v->drive_cal_f0_hz = (float)(pc->f_drive_hz * (1.0 + f_offset_rel));
  v->cal_ref_freq_hz = v->drive_freq_hz;
}

/* One command line in, the whole reply out (the background loop runs once). */
static inline const char *cmd(const char *line) { return app_cmd_line(&app, line); }

/* s seconds of samples, the background loop not polled. */
static inline void run_s(double s) { hal_host_run((uint64_t)(s * 50000.0)); }

/* The plant's input rate held at dps from now on, the ambient where it is (the tests'
 * rate steps). */
static inline void app_plant_hold_rate(double dps)
{
  plant_profiles_t prof;
  memset(&prof, 0, sizeof prof);
  profile_const(&prof.rate_dps, dps);
  profile_const(&prof.ambient_k, plant_truth(&plant)->ambient_k);
  if (plant_set_profiles(&plant, &prof) != 0) fail_msg("plant: a constant profile refused");
}

#endif /* APP_PLANT_H */
