#include "gyro/gyro_cfg.h"

#include <string.h>

void gyro_cfg_default(gyro_cfg_t *c)
{
  memset(c, 0, sizeof *c);
  c->fs_hz = 50000.0f;                 /* thesis 4.4.2 */
  c->drive_freq_hz = 1489.9f;          /* measured drive resonance, 7.2.2 */
  c->drive_mode = GYRO_DRIVE_HALF_FREQ;
  c->drive_amp_set_v = 2.0f;           /* 10 um drive amplitude at 2e5 V/m pickoff gain */
  c->drive_phase_set_deg = 0.0f;       /* any value: P absorbs it (gyro_cfg.h) */
  c->drive_u_max_v = 14.0f;            /* DAC +-15 V less headroom for the output stage */
  c->drive_dc_bias_v = 7.0f;           /* DC+AC: D = u_max / 2 maximises 4 D (u_max - D) */
  c->drive_p_init_deg = 0.0f;

  c->plant_f0_hz = 1489.9f;            /* 7.2.2 */
  c->plant_q = 33.33f;                 /* 7.2.2 */
  c->plant_gain_v_per_v2 = 2.0f / 64.0f; /* 10 um at about 8 V half-frequency amplitude */
  c->amp_loop_bw_hz = 30.0f;
  c->phase_loop_bw_hz = 30.0f;

  c->mu_drive = 0.034f;                /* 5.4.1 */
  c->mu_sense = 0.034f;

  c->demod_phase_deg = 0.0f;
  c->rate_lpf_hz = 100.0f;             /* 5.4.3, 7.2.4 */
  c->rate_lpf_order = 4u;
  c->rate_scale_dps = 1.0f;
  c->p_lpf_hz = 1.0f;
  c->rate_out_v_per_dps = 7.25e-3f;    /* 7.2.4 */

  c->lock_tol_rel = 0.01f;             /* "within 1 % of its setpoint" */
  c->lock_phase_tol_deg = 1.0f;
  c->lock_hold_s = 0.02f;
  c->lost_tol_rel = 0.1f;
  c->lost_hold_s = 0.05f;
  c->amp_trip_rel = 1.5f;
  c->sat_hold_s = 0.5f;
  c->retry_s = 0.3f;
  c->clip_max_count = 50u;
  c->autostart = 1u;
}
