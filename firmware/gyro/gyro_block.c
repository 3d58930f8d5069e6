#include "gyro/gyro_block.h"

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"

/* A NaN anywhere propagates into the loop state within a block (the LMSD weights feed
 * the loops and the rate channel, the loops the command, the rate channel the outputs)
 * and is caught by the supervisor of the next block (0.4 ms at most): long before it
 * could reach the structure. A sum is non-finite when any term is (a finite sum
 * overflowing to infinity would need terms near 1e38: broken state as well). The check
 * comes in two halves on two ticks (GYRO_SLOT_AMP, GYRO_SLOT_QUAD). */

GYRO_RAMFUNC void gyro_block_amp_measure(gyro_t *g)
{
  const float w_i = g->lmsd_drive.w_i, w_q = g->lmsd_drive.w_q;
  g->weights_finite = fm_isfinite(w_i + w_q + g->lmsd_sense.w_i + g->lmsd_sense.w_q) ? 1u : 0u;
  if (supervisor_drive_enabled(&g->sup)) {
    drive_loop_step_amp(&g->design->drive, &g->drive, w_i, w_q);
  } else {
    /* Measure only: the amplitude is still watched for the over-amplitude trip. */
    g->drive.amp_v = fm_sqrtf(w_i * w_i + w_q * w_q);
  }
}

GYRO_RAMFUNC void gyro_block_amp(gyro_t *g)
{
  gyro_block_amp_measure(g);
  /* The drive-phase and sense-range checks of the rate's validity, on evidence of the
   * last block (phase error: supervisor; quadrature: its filter). */
  const float s_i = g->lmsd_sense.w_i, s_q = g->lmsd_sense.w_q;
  rate_valid_drive(&g->design->valid, &g->valid, g->sup.phase_err_f, g->rate.quad_dps,
                   s_i * s_i + s_q * s_q);
}

GYRO_RAMFUNC void gyro_block_command(gyro_t *g)
{
  /* The supervisor's evidence of the block, now that both loops have measured. */
  supervisor_in_t *si = &g->sup_in;
  const int drive_on = supervisor_drive_enabled(&g->sup);
  si->amp_rel = g->drive.amp_v * g->drive.inv_amp_set; /* the slewed setpoint's */
  si->amp_rel_err = si->amp_rel - 1.0f;
  si->setpoint_moving = drive_loop_slewing(&g->design->drive, &g->drive);
  si->phase_err_rad = g->drive.phase_err_rad;
  si->drive_at_limit = drive_on && g->drive.f_cmd_v2 >= g->design->drive.f_cmd_max_v2;
  si->freq_at_limit = (int)g->track.at_limit; /* 0 unless the tracking drive runs */
  if (si->drive_at_limit) g->flags_acc |= GYRO_FLAG_DRIVE_LIMIT;
  /* The drive loops' fault is a clipped drive channel. A clipped sense channel (too much
   * quadrature, rate or vibration for its gain) leaves the drive sound: the rate is not
   * valid then (rate_valid.h, CLIP), but the drive keeps running. */
  si->clip_count = g->clip_drive_block;
  const uint32_t lost = *g->lost_count;
  si->sample_lost = lost != g->lost_seen;
  g->lost_seen = lost;
  /* Once per block, after both loops: the square root and the phase conversion. */
  if (drive_on) {
    drive_synth_set(&g->synth, g->drive.f_cmd_v2, g->drive.p_rad);
  }
  /* The thermometer's phase of this block's loops, for the rate channel (GYRO_SLOT_PROJECT,
   * GYRO_SLOT_P) and the next snapshot: P, or the tracking drive's equivalent. */
  const gyro_design_t *d = g->design;
  g->drive.p_eq_rad = d->track != 0u ? drive_track_p_eq_rad(&d->track_cfg, &g->track)
                                     : g->drive.p_rad;
}

GYRO_RAMFUNC void gyro_block_clear(gyro_t *g)
{
  g->sup.clear_req = 0u;
  lmsd_reset(&g->lmsd_drive);
  lmsd_reset(&g->lmsd_sense);
  drive_loop_reset(&g->design->drive, &g->drive);
  drive_synth_silence(&g->synth);
  g->rate_clear_due = 1u; /* the rate channel's half, on the next tick (its budget) */
}

/* The tracking drive's update (drive_track.h): the wrapped phase error moves the NCO's
 * step from the next tick on; P stays at p_init, the thermometer gets p_eq. */
GYRO_RAMFUNC void gyro_block_track(gyro_t *g)
{
  const gyro_design_t *d = g->design;
  drive_loop_t *dl = &g->drive;
  const int32_t off = drive_track_update(&d->track_cfg, &g->track, dl->phase_err_rad,
                                         dl->amp_v * dl->inv_amp_set,
                                         g->sup.mode == GYRO_MODE_LOCKED);
  g->nco.half_step = d->nco_half_step + (uint32_t)off;
}

GYRO_RAMFUNC void gyro_block_phase(gyro_t *g)
{
  drive_loop_update_phase(&g->design->drive, &g->drive);
  if (GYRO_UNLIKELY(g->drive.p_turn_rad != 0.0f)) {
    /* A whole turn of P is no change of temperature: the thermometer moves with it,
     * and the filters settle again after the jump of the rate reference's correction. */
    rate_channel_shift_p(&g->rate, g->drive.p_turn_rad * FM_DEG_PER_RAD_F);
    rate_valid_shift_p(&g->valid, g->drive.p_turn_rad * FM_DEG_PER_RAD_F);
    g->drive.p_turn_rad = 0.0f;
    rate_valid_disturb(&g->valid);
  }
}

GYRO_RAMFUNC void gyro_block_quad(gyro_t *g)
{
  gyro_block_finite(g);
  rate_channel_t *rc = &g->rate;
  selftest_cont_notch(&g->design->selftest, &g->selftest, 1u, &rc->quad_raw);
  rate_channel_filter_quad(&g->design->rate, rc);
  /* The design is read again after each call rather than kept in a register saved
   * across it (here and below): a load is cheaper than the save and restore. */
  const gyro_design_t *d = g->design;
  rate_valid_settling(&d->valid, &g->valid, rc->rate_raw, rc->quad_raw, rc->rate_unc_dps,
                      rc->quad_dps, d->rate.scale_dps);
}

GYRO_RAMFUNC void gyro_block_project(gyro_t *g)
{
  rate_channel_project(&g->design->rate, &g->rate, g->lmsd_drive.w_i, g->lmsd_drive.w_q,
                       g->drive.p_eq_rad, g->drive.phase_err_rad);
  /* The continuous self-test's modulation, for the ticks from here on and for its notch
   * on this projection (GYRO_SLOT_RATE, GYRO_SLOT_QUAD): the force runs a fixed block
   * ahead of the reference, which the LMS's two weights absorb as a phase. */
  selftest_cont_advance(&g->design->selftest, &g->selftest);
}

GYRO_RAMFUNC void gyro_block_measure(gyro_t *g, int drive_on)
{
  if (drive_on) {
    drive_loop_measure_phase(&g->drive, g->lmsd_drive.w_i, g->lmsd_drive.w_q);
    /* The tracking drive's error and its notch here, its PI next tick (the budget). */
    const gyro_design_t *d = g->design;
    if (d->track != 0u) {
      drive_loop_t *dl = &g->drive;
      dl->phase_err_rad = drive_track_error(&d->track_cfg, &g->track,
                                            fm_wrap_pi(d->drive.phase_set_rad - dl->phase_rad),
                                            dl->amp_v * dl->inv_amp_set);
    }
  }
  /* The drive half of the snapshot (gyro_block_output the rest): on this lighter tick. */
  gyro_out_t *o = &g->out;
  o->drive_amp_v = g->drive.amp_v;
  o->drive_phase_deg = g->drive.phase_rad * FM_DEG_PER_RAD_F;
  o->p_deg = g->drive.p_eq_rad * FM_DEG_PER_RAD_F;
  o->f_cmd_v2 = g->drive.f_cmd_v2;
  o->sense_i_v = g->lmsd_sense.w_i;
  o->sense_q_v = g->lmsd_sense.w_q;
}

GYRO_RAMFUNC void gyro_block_supervise(gyro_t *g)
{
  /* The last verdict's onsets into the history, on this lighter tick. */
  if (GYRO_UNLIKELY(g->valid.onsets_pending != 0u)) {
    rate_valid_count_onsets(&g->valid, &g->valid_history);
  }
  (void)supervisor_step(&g->design->sup, &g->sup, &g->sup_in);
}

GYRO_RAMFUNC void gyro_block_phase_judge(gyro_t *g, int drive_on)
{
  if (drive_on) gyro_block_phase(g);
  g->cont_fail = selftest_cont_judge(&g->design->selftest, &g->selftest,
                                     g->sup.mode == GYRO_MODE_LOCKED);
}

GYRO_RAMFUNC void gyro_block_track_judge(gyro_t *g, int drive_on)
{
  if (drive_on) gyro_block_track(g);
  g->cont_fail = selftest_cont_judge(&g->design->selftest, &g->selftest,
                                     g->sup.mode == GYRO_MODE_LOCKED);
}

GYRO_RAMFUNC void gyro_block_rate(gyro_t *g)
{
  rate_channel_t *rc = &g->rate;
  if (GYRO_UNLIKELY(g->rate_clear_due != 0u)) {
    g->rate_clear_due = 0u;
    rate_channel_reset(&g->design->rate, rc, g->design->rate.p_ref_deg);
    gyro_track_restart(g); /* the clear's tracking-drive half, within this tick's budget */
    return;
  }
  selftest_cont_notch(&g->design->selftest, &g->selftest, 0u, &rc->rate_raw);
  rate_channel_filter_rate(&g->design->rate, rc);
  rate_valid_range(&g->design->valid, &g->valid, rc->rate_dps);
}

/* The nulling electrodes' voltages into the frame, once per update: a DC level the
 * second converter holds until the next (hal_dac.h). */
GYRO_RAMFUNC static void quad_null_codes(const quad_null_t *q, hal_dac_frame_t *dac)
{
  dac->code[HAL_DAC_QUADNULL_V1] = gyro_volts_to_dac(q->v1_v);
  dac->code[HAL_DAC_QUADNULL_V2] = gyro_volts_to_dac(q->v2_v);
}

GYRO_RAMFUNC void gyro_block_quad_off(gyro_t *g, hal_dac_frame_t *dac)
{
  quad_null_stop(&g->quad);
  dac->code[HAL_DAC_QUADNULL_V1] = (uint16_t)HAL_DAC_CODE_MID;
  dac->code[HAL_DAC_QUADNULL_V2] = (uint16_t)HAL_DAC_CODE_MID;
  g->quad_bits = g->design->quad_on != 0u ? RATE_INVALID_QUAD_NULL : 0u;
}

/* The quadrature-nulling loop's update (quad_null.h) on the rate channel's filtered
 * quadrature (GYRO_SLOT_QUAD of this block), at the thermometer's 500 Hz: at the rate
 * channel's 5 kHz the float integrator's dead band would be ten times wider. LOCKED
 * only (the new P_f's block); it starts with its probe on the first update after lock. */
GYRO_RAMFUNC static void gyro_block_quad_null(gyro_t *g, hal_dac_frame_t *dac)
{
  const gyro_design_t *d = g->design;
  quad_null_t *q = &g->quad;
  if (d->quad_on == 0u) { /* turned off while running (gyro_apply) */
    gyro_block_quad_off(g, dac);
    return;
  }
  if (q->mode == QUAD_NULL_OFF) quad_null_start(&d->quad, q);
  quad_null_update(&d->quad, q, g->rate.quad_dps);
  quad_null_codes(q, dac);
  /* settled implies RUN and not at the limit (quad_null.c); FAILED never settles */
  g->quad_bits = q->settled != 0u ? 0u : RATE_INVALID_QUAD_NULL;
}

GYRO_RAMFUNC void gyro_block_p(gyro_t *g, int hold, hal_dac_frame_t *dac)
{
  const gyro_design_t *d = g->design; /* kept across the call: a register saved anyway */
  rate_channel_t *rc = &g->rate;
  /* The hold first (only rate_channel_update_p reads it): hold need not outlive a call. */
  rate_channel_hold_p(rc, hold);
  if (rate_channel_p_update_now(rc)) {
    /* The new P_f's tick: no other job of the thermometer (a job still waiting runs
     * after it); the quadrature-nulling loop's update, at its 500 Hz, while it is on
     * or still energised (gyro_slots.h). */
    if (d->quad_on != 0u || g->quad.mode != QUAD_NULL_OFF) gyro_block_quad_null(g, dac);
  } else if (GYRO_UNLIKELY(hold != 0 && g->quad.mode != QUAD_NULL_OFF)) {
    /* Not LOCKED (a fault, drive off, a re-acquisition): the electrodes off, once; the
     * loop starts again, with its probe, at the next lock. */
    gyro_block_quad_off(g, dac);
  } else if (rc->p_new != 0u) {
    /* The thermometer checks of the P_f the last block made: P's low-pass runs on one
     * block in RATE_P_BLOCKS, the checks on the next, so that no tick carries both. */
    rc->p_new = 0u;
    rate_valid_thermo(&d->valid, &g->valid, rc->p_dev_deg, rc->p_held_dev_deg, rc->p_held_w);
    if ((g->valid.thermo & RATE_INVALID_THERMO_SLEW) != 0u)
      rate_channel_fast_hold(&d->rate, rc);
  } else if (rc->filters_due != 0u) {
    rate_channel_comp_filters(&d->rate, rc);
  } else if (g->valid.slew_due != 0u) {
    if (rate_valid_slew(&d->valid, &g->valid)) rate_channel_comp_restart(rc);
  } else if (g->valid.shadow_phase != 0u) {
    rate_valid_shadow(&d->valid, &g->valid, rc);
  } else if (rc->comp_due != 0u) {
    /* The compensation of the filters' new state, on a block with no other job: the
     * rate takes it from the next block on. A new P_f is 10 blocks apart; its jobs (the
     * checks, the filters' step, a window's judgement, the shadow's five parts, this)
     * take the nine blocks between at most. */
    rate_channel_comp_refresh(&d->rate, rc);
  }
  /* Last, as a tail call: its new P_f is flagged in rc->p_new. */
  (void)rate_channel_update_p(&d->rate, rc, g->drive.p_eq_rad);
}

GYRO_RAMFUNC void gyro_block_p_selftest(gyro_t *g, hal_dac_frame_t *dac)
{
  const int locked = g->sup.mode == GYRO_MODE_LOCKED;
  selftest_update(&g->design->selftest, &g->selftest, locked, g->rate.rate_raw);
  /* The test force disturbs the rate output: its filters settle again afterwards. */
  rate_valid_disturb(&g->valid);
  gyro_block_p(g, !locked, dac);
}

/* The snapshot for telemetry and status, at fs / GYRO_BLOCK (5 kHz: the telemetry's
 * highest rate); flags hold what happened over the whole block. */
GYRO_RAMFUNC void gyro_block_output(gyro_t *g, float u1_v, float u2_v)
{
  gyro_out_t *o = &g->out;
  const uint32_t block_bits = (g->sup.mode == GYRO_MODE_LOCKED ? 0u : RATE_INVALID_MODE) |
                              (selftest_running(&g->selftest) ? RATE_INVALID_SELFTEST : 0u) |
                              (g->clip_block != 0u ? RATE_INVALID_CLIP : 0u) |
                              (g->cont_fail != 0u ? RATE_INVALID_CONT_SELFTEST : 0u) |
                              (g->design->track_uncal != 0u ? RATE_INVALID_TRACKING : 0u) |
                              (g->design->cal_state != GYRO_CAL_OK ? RATE_INVALID_UNCALIBRATED
                                                                   : 0u) |
                              /* the reference's wide start (rate_channel.h): it passes
                               * the acquisition's tail of the measured phase */
                              (g->rate.ref_wide_left != 0u ? RATE_INVALID_SETTLING : 0u) |
                              g->quad_bits; /* the nulling loop's, from its update */
  const uint32_t invalid = rate_valid_verdict(&g->valid, block_bits);
  /* Never a valid-looking wrong rate: the analog output goes to the fault level in the
   * same sample as the verdict, without a slew. */
  const gyro_design_t *d = g->design;
  float out_v = d->rate_fault_out_v;
  uint16_t code = d->rate_fault_code;
  if (invalid == 0u) {
    out_v = g->rate.rate_dps * d->rate_out_v_per_dps;
    code = gyro_volts_to_dac(out_v);
  }
  g->rate_code = code;
  o->rate_out_v = out_v;
  o->rate_invalid = invalid;
  o->rate_valid = invalid == 0u ? 1u : 0u;
  o->rate_dps = g->rate.rate_dps;
  o->rate_unc_dps = g->rate.rate_unc_dps;
  o->quad_dps = g->rate.quad_dps;
  o->p_f_deg = g->rate.p_f_deg;
  o->f_drive_hz = d->f_cal_hz + (float)g->track.off_steps * d->hz_per_step;
  o->u1_v = u1_v;
  o->u2_v = u2_v;
  o->mode = (uint32_t)g->sup.mode;
  o->fault = g->sup.fault;
  if (selftest_running(&g->selftest)) g->flags_acc |= GYRO_FLAG_SELFTEST;
  o->flags = (g->sup.mode == GYRO_MODE_LOCKED ? GYRO_FLAG_LOCKED : 0u) | g->flags_acc |
             (g->sup.mode == GYRO_MODE_FAULT ? GYRO_FLAG_FAULT : 0u) |
             (invalid == 0u ? GYRO_FLAG_RATE_VALID : 0u) |
             ((invalid & RATE_INVALID_OVER_RANGE) != 0u ? GYRO_FLAG_OVER_RANGE : 0u) |
             ((invalid & RATE_INVALID_SENSE_RANGE) != 0u ? GYRO_FLAG_SENSE_RANGE : 0u) |
             ((invalid & RATE_INVALID_UNCALIBRATED) != 0u ? GYRO_FLAG_UNCALIBRATED : 0u);
  g->flags_acc = 0u;
}

GYRO_RAMFUNC void gyro_block_output_sweep(gyro_t *g, float u1_v, float u2_v)
{
  /* The rate channel rests in SWEEP (its outputs keep their last values): the verdict
   * (not valid: MODE) and what does change. */
  gyro_out_t *o = &g->out;
  const uint32_t block_bits = RATE_INVALID_MODE | (g->clip_block != 0u ? RATE_INVALID_CLIP : 0u);
  o->rate_invalid = rate_valid_verdict(&g->valid, block_bits);
  o->rate_valid = 0u;
  o->rate_out_v = g->design->rate_fault_out_v;
  g->rate_code = g->design->rate_fault_code;
  o->u1_v = u1_v;
  o->u2_v = u2_v;
  o->mode = (uint32_t)g->sup.mode;
  o->fault = g->sup.fault;
  o->flags = g->flags_acc |
             ((o->rate_invalid & RATE_INVALID_SENSE_RANGE) != 0u ? GYRO_FLAG_SENSE_RANGE : 0u) |
             (g->design->cal_state != GYRO_CAL_OK ? GYRO_FLAG_UNCALIBRATED : 0u);
  g->flags_acc = 0u;
}

GYRO_RAMFUNC void gyro_block_sweep(gyro_t *g, uint32_t slot, float u1_v, float u2_v,
                                   hal_dac_frame_t *dac)
{
  selfcal_exec_t *x = &g->cal;
  selfcal_exec_tick(x, g->lmsd_drive.w_i, g->lmsd_drive.w_q);
  g->nco.half_step = x->half_step; /* from the next sample on, as the excitation */
  /* A new force command (a job's start, a back-off) goes to the synthesis, and a newly
   * posted job starts, on the block's next tick without a job of its own in SWEEP, at
   * most four ticks (80 us) late: neither would fit beside the supervisor's or the
   * snapshot's job, and every job settles for far longer than that. */
  if (GYRO_SWEEP_IDLE_SLOT(slot)) {
    drive_synth_follow(&g->synth, x->f_cmd_v2, x->p_rad);
    /* The nulling electrodes off in SWEEP (entered from LOCKED without a held block):
     * the sweep measures the part as it is; the loop starts again after it. */
    if (GYRO_UNLIKELY(g->quad.mode != QUAD_NULL_OFF)) gyro_block_quad_off(g, dac);
    selfcal_exec_take(x); /* a new job starts on a tick without a job of its own */
    return;
  }
  gyro_block_run_sweep(g, slot, u1_v, u2_v);
}
