#include "gyro/gyro_block.h"

#include "dsp/fastmath.h"

/* A NaN anywhere propagates into the loop state within a block (the LMSD weights feed
 * the loops and the rate channel, the loops the command, the rate channel the outputs)
 * and is caught by the supervisor of the next block (0.4 ms at most): long before it
 * could reach the structure. A sum is non-finite when any term is (a finite sum
 * overflowing to infinity would need terms near 1e38: broken state as well). The check
 * comes in two halves on two ticks (GYRO_SLOT_AMP, GYRO_SLOT_QUAD). */

void gyro_block_amp(gyro_t *g)
{
  const float w_s = g->lmsd_drive.w_i, w_c = g->lmsd_drive.w_q;
  g->weights_finite = fm_isfinite(w_s + w_c + g->lmsd_sense.w_i + g->lmsd_sense.w_q) ? 1u : 0u;
  if (supervisor_drive_enabled(&g->sup)) {
    drive_loop_step_amp(&g->drive, w_s, w_c);
  } else {
    /* Measure only: the amplitude is still watched for the over-amplitude trip. */
    g->drive.amp_v = fm_sqrtf(w_s * w_s + w_c * w_c);
  }
}

void gyro_block_command(gyro_t *g)
{
  /* The supervisor's evidence of the block, now that both loops have measured. */
  supervisor_in_t *si = &g->sup_in;
  const int drive_on = supervisor_drive_enabled(&g->sup);
  si->amp_rel = g->drive.amp_v * g->drive.inv_amp_set; /* the slewed setpoint's */
  si->amp_rel_err = si->amp_rel - 1.0f;
  si->phase_err_rad = g->drive.phase_err_rad;
  si->drive_at_limit = drive_on && g->drive.f_cmd_v2 >= g->f_cmd_max_v2;
  if (si->drive_at_limit) g->flags_acc |= GYRO_FLAG_DRIVE_LIMIT;
  si->clip_run = g->clip_run_max;
  g->clip_run_max = g->clip_run; /* a run still going carries into the next block */
  /* Once per block, after both loops: the square root and the phase conversion. */
  if (drive_on) {
    drive_synth_set(&g->synth, g->drive.f_cmd_v2, g->drive.p_rad);
  }
}

void gyro_block_clear(gyro_t *g)
{
  g->sup.clear_req = 0u;
  lmsd_reset(&g->lmsd_drive);
  lmsd_reset(&g->lmsd_sense);
  drive_loop_reset(&g->drive);
  rate_channel_reset(&g->rate, g->rate.p_ref_deg);
  drive_synth_set(&g->synth, 0.0f, g->drive.p_rad);
}

void gyro_block_quad(gyro_t *g)
{
  const float sum = g->drive.f_cmd_v2 + g->drive.p_rad + g->rate.rate_dps + g->rate.quad_dps;
  g->sup_in.state_finite = g->weights_finite != 0u && fm_isfinite(sum);
  rate_channel_filter_quad(&g->rate);
}

void gyro_block_p_selftest(gyro_t *g)
{
  const int locked = g->sup.mode == GYRO_MODE_LOCKED;
  selftest_update(&g->selftest, locked, g->rate.rate_raw);
  rate_channel_hold_p(&g->rate, !locked);
  rate_channel_update_p(&g->rate, g->drive.p_rad);
}

/* The snapshot for telemetry and status, at fs / GYRO_BLOCK (5 kHz: the telemetry's
 * highest rate); flags hold what happened over the whole block. */
void gyro_block_output(gyro_t *g, float u1_v, float u2_v)
{
  gyro_out_t *o = &g->out;
  g->rate_code = gyro_volts_to_dac(g->rate.rate_dps * g->rate_out_v_per_dps);
  o->rate_dps = g->rate.rate_dps;
  o->rate_unc_dps = g->rate.rate_unc_dps;
  o->quad_dps = g->rate.quad_dps;
  o->drive_amp_v = g->drive.amp_v;
  o->drive_phase_deg = g->drive.phase_rad * FM_DEG_PER_RAD_F;
  o->p_deg = g->drive.p_rad * FM_DEG_PER_RAD_F;
  o->p_f_deg = g->rate.p_f_deg;
  o->f_cmd_v2 = g->drive.f_cmd_v2;
  o->u1_v = u1_v;
  o->u2_v = u2_v;
  o->sense_i_v = g->lmsd_sense.w_i;
  o->sense_q_v = g->lmsd_sense.w_q;
  o->mode = (uint32_t)g->sup.mode;
  o->fault = g->sup.fault;
  if (selftest_running(&g->selftest)) g->flags_acc |= GYRO_FLAG_SELFTEST;
  o->flags = (g->sup.mode == GYRO_MODE_LOCKED ? GYRO_FLAG_LOCKED : 0u) | g->flags_acc |
             (g->sup.mode == GYRO_MODE_FAULT ? GYRO_FLAG_FAULT : 0u);
  g->flags_acc = 0u;
}

void gyro_block_sweep(gyro_t *g, uint32_t slot, float u1_v, float u2_v)
{
  float f_cmd, p;
  uint32_t half_step;
  selfcal_exec_tick(&g->cal, g->lmsd_drive.w_i, g->lmsd_drive.w_q, &half_step, &f_cmd, &p);
  drive_synth_follow(&g->synth, f_cmd, p);
  g->nco.half_step = half_step; /* from the next sample on, as the excitation */
  gyro_block_run(g, slot, u1_v, u2_v);
}
