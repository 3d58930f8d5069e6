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
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_synth(g);
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
  /* Last, as a tail call: the quadrature-nulling loop's step of this block (quad.null 1;
   * below). */
  const gyro_quad_step_t step = g->quad_job;
  if (step != NULL) step(g);
}

GYRO_RAMFUNC void gyro_block_clear(gyro_t *g)
{
  g->sup.clear_req = 0u;
  lmsd_reset(&g->lmsd_drive);
  lmsd_reset(&g->lmsd_sense);
  drive_loop_reset(&g->design->drive, &g->drive);
  drive_synth_silence(&g->synth);
  /* The rate's half on the next rate slots (their budget): the thermometer's checks
   * start again with P_f (rate_valid_restart), which starts from the reference. */
  g->rate_clear_due = GYRO_RATE_CLEAR_RESTART;
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
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_integrate(g);
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

/* The quadrature-nulling loop (quad_null.h) at the thermometer's 500 Hz (RATE_P_DECIM: at
 * the block's 5 kHz the float integrator's dead band would be ten times wider) on the
 * filtered quadrature (GYRO_SLOT_QUAD), while LOCKED. No tick has room for a whole
 * update beside its own job (measured: 216 cycles on the new P_f's P slot, which had 81
 * to spare; some tens on the others), so the update runs as quad_null.h's steps, one a
 * block, at the end of GYRO_SLOT_COMMAND: a tail call through g->quad_job, which each
 * step sets to the next on quad_null_update's path. Between updates the job is
 * quad_wait, which starts one on the block after a new P_f (LOCKED, every
 * RATE_P_BLOCKS blocks):
 *   RUN     take, integrate, limit, settle, root (and the verdict's reason from
 *           settled), sign, V1's code, V2's code
 *   probe   take, accumulate, then on a complete mean: mean, verdict, and after the
 *           base root .. V2's code; after the step judge, then gain, close, engage (the
 *           command stays the probe's), or fail_a, fail_b, V1's and V2's codes
 * at most nine blocks after the wait's, so one update ends before the next begins (the
 * start, three blocks, before the first update). The
 * voltages follow the measurement by 1.6 ms, against the loop's 80 ms time constant at
 * 2 Hz; the reason by 1.2 ms. Not LOCKED, the wait halts the loop (both electrodes at
 * 0 V); it starts again, with its probe, at the next lock. The drive's stop, a
 * re-acquisition, a sweep and quad.null 0 halt it at once (gyro_quad_off). */
static void quad_wait(gyro_t *g);

GYRO_RAMFUNC static void quad_code_v2(gyro_t *g)
{
  g->quad_job = quad_wait;
  g->dac_frame->code[HAL_DAC_QUADNULL_V2] = gyro_volts_to_dac(g->quad.v2_v);
}

GYRO_RAMFUNC static void quad_code_v1(gyro_t *g)
{
  g->quad_job = quad_code_v2;
  g->dac_frame->code[HAL_DAC_QUADNULL_V1] = gyro_volts_to_dac(g->quad.v1_v);
}

GYRO_RAMFUNC static void quad_sign(gyro_t *g)
{
  g->quad_job = quad_code_v1;
  quad_null_sign(&g->quad);
}

GYRO_RAMFUNC static void quad_root(gyro_t *g)
{
  g->quad_job = quad_sign;
  /* settled implies RUN and not at the limit (quad_null.c); FAILED never settles */
  g->quad_bits = g->quad.settled != 0u ? 0u : RATE_INVALID_QUAD_NULL;
  quad_null_root(&g->quad);
}

GYRO_RAMFUNC static void quad_engage(gyro_t *g)
{
  g->quad_job = quad_wait;
  quad_null_engage(&g->design->quad, &g->quad);
}

GYRO_RAMFUNC static void quad_close(gyro_t *g)
{
  g->quad_job = quad_engage;
  quad_null_close(&g->design->quad, &g->quad);
}

/* After the judgement: the gain into the loop, or FAILED (both electrodes at 0 V, in
 * two halves, then the codes). */
GYRO_RAMFUNC static void quad_fail_b(gyro_t *g)
{
  g->quad_job = quad_code_v1;
  quad_null_fail_b(&g->quad);
}

GYRO_RAMFUNC static void quad_after_judge(gyro_t *g)
{
  if (g->quad.close_due != 0u) {
    g->quad_job = quad_close;
    quad_null_gain(&g->design->quad, &g->quad);
  } else {
    g->quad_job = quad_fail_b;
    quad_null_fail_a(&g->quad);
  }
}

GYRO_RAMFUNC static void quad_judge(gyro_t *g)
{
  g->quad_job = quad_after_judge;
  quad_null_judge(&g->design->quad, &g->quad);
}

/* The probe's verdict: on the base, the step's voltages next; on the step, its judgement. */
GYRO_RAMFUNC static void quad_verdict(gyro_t *g)
{
  g->quad_job = g->quad.mode == QUAD_NULL_PROBE_BASE ? quad_root : quad_judge;
  quad_null_verdict(&g->design->quad, &g->quad);
}

/* A complete mean: its verdict next; else the update ends (the command holds). */
GYRO_RAMFUNC static void quad_mean(gyro_t *g)
{
  if (g->quad.mean_due == 0u) {
    g->quad_job = quad_wait;
    return;
  }
  g->quad_job = quad_verdict;
  quad_null_mean(&g->design->quad, &g->quad);
}

GYRO_RAMFUNC static void quad_accumulate(gyro_t *g)
{
  g->quad_job = quad_mean;
  quad_null_accumulate(&g->design->quad, &g->quad);
}

GYRO_RAMFUNC static void quad_settle(gyro_t *g)
{
  g->quad_job = quad_root;
  quad_null_settle(&g->design->quad, &g->quad);
}

GYRO_RAMFUNC static void quad_limit(gyro_t *g)
{
  g->quad_job = quad_settle;
  quad_null_limit(&g->design->quad, &g->quad);
}

GYRO_RAMFUNC static void quad_integrate(gyro_t *g)
{
  g->quad_job = quad_limit;
  quad_null_integrate(&g->quad);
}

GYRO_RAMFUNC static void quad_take(gyro_t *g)
{
  quad_null_t *q = &g->quad;
  quad_null_take(q, g->rate.quad_dps);
  const quad_null_mode_t mode = q->mode;
  gyro_quad_step_t next = quad_accumulate; /* the probe */
  if (q->skip != 0u || mode == QUAD_NULL_FAILED) {
    next = quad_wait; /* no measurement, or nothing moves */
  } else if (mode == QUAD_NULL_RUN) {
    next = quad_integrate;
  }
  g->quad_job = next;
}

/* The start (quad_null_start) in three parts; its first measurement on the next update. */
GYRO_RAMFUNC static void quad_start_c(gyro_t *g)
{
  g->quad_job = quad_wait;
  quad_null_clear_c(&g->quad);
  g->quad.mode = QUAD_NULL_PROBE_BASE;
}

GYRO_RAMFUNC static void quad_start_b(gyro_t *g)
{
  g->quad_job = quad_start_c;
  quad_null_clear_b(&g->quad);
}

GYRO_RAMFUNC static void quad_start(gyro_t *g)
{
  g->quad_job = quad_start_b;
  g->quad_bits = RATE_INVALID_QUAD_NULL;
  quad_null_clear_a(&g->quad);
}

GYRO_RAMFUNC static void quad_halt_codes(gyro_t *g)
{
  g->quad_job = quad_wait;
  hal_dac_frame_t *f = g->dac_frame;
  f->code[HAL_DAC_QUADNULL_V1] = (uint16_t)HAL_DAC_CODE_MID;
  f->code[HAL_DAC_QUADNULL_V2] = (uint16_t)HAL_DAC_CODE_MID;
}

GYRO_RAMFUNC static void quad_halt(gyro_t *g)
{
  g->quad_job = quad_halt_codes;
  g->quad_bits = RATE_INVALID_QUAD_NULL; /* quad.null is 1 while the job runs */
  quad_null_halt(&g->quad);
}

/* Between updates: the next one on the new P_f's block (LOCKED); not LOCKED, the halt. */
GYRO_RAMFUNC static void quad_wait(gyro_t *g)
{
  if (g->sup.mode != GYRO_MODE_LOCKED) {
    if (GYRO_UNLIKELY(g->quad.mode != QUAD_NULL_OFF)) g->quad_job = quad_halt;
  } else if (g->rate.p_new != 0u) { /* the block after a new P_f's (GYRO_SLOT_P) */
    g->quad_job = g->quad.mode == QUAD_NULL_OFF ? quad_start : quad_take;
  }
}

void gyro_quad_reset(gyro_t *g) { g->quad_job = g->design->quad_on != 0u ? quad_wait : NULL; }

void gyro_quad_off(gyro_t *g)
{
  quad_null_halt(&g->quad);
  quad_halt_codes(g);
  gyro_quad_reset(g);
  g->quad_bits = g->design->quad_on != 0u ? RATE_INVALID_QUAD_NULL : 0u;
}

/* Force rebalance (sense_fr.h), one step at the start of five jobs (gyro_slots.h). The
 * loop runs while LOCKED: it starts from zero force on the first block of a lock and
 * halts (zero force, not balanced) on the first block without one. */
GYRO_RAMFUNC void gyro_fr_off(gyro_t *g)
{
  sense_fr_reset(&g->fr);
  drive_synth_silence(&g->fb_synth); /* a_v 0: no force (DC+AC: the bias alone) */
  g->fr_bits = g->fr_on != 0u ? RATE_INVALID_SENSE_FR : 0u;
}

GYRO_RAMFUNC void gyro_fr_take(gyro_t *g)
{
  sense_fr_t *fr = &g->fr;
  if (g->sup.mode != GYRO_MODE_LOCKED) {
    if (GYRO_UNLIKELY(fr->run != 0u)) gyro_fr_off(g);
    return;
  }
  if (GYRO_UNLIKELY(fr->run == 0u)) {
    sense_fr_reset(fr);
    fr->run = 1u;
  }
  rate_channel_t *rc = &g->rate;
  sense_fr_take(&g->design->fr, fr, rc->rate_raw, rc->quad_raw);
  /* The rate channel reads the force from here on: g (I + Kr R), the open loop's
   * equivalent -g F in the steady state (sense_fr.h). */
  rc->rate_raw = fr->out_re;
  rc->quad_raw = fr->out_im;
}

GYRO_RAMFUNC void gyro_fr_integrate(gyro_t *g)
{
  if (g->fr.run != 0u && g->fr.skip == 0u) sense_fr_integrate(&g->design->fr, &g->fr);
}

GYRO_RAMFUNC void gyro_fr_limit(gyro_t *g)
{
  sense_fr_t *fr = &g->fr;
  if (fr->run != 0u && fr->skip == 0u) sense_fr_limit(&g->design->fr, fr);
}

/* Inline in the supervisor's job, its only caller: a call and the reload of the loop's
 * state cost that tick 10 of the cycles it has least of (tools/bench/README.md). */
GYRO_RAMFUNC static inline void gyro_fr_settle(gyro_t *g)
{
  sense_fr_t *fr = &g->fr;
  if (fr->run == 0u || fr->skip != 0u) return;
  sense_fr_settle(&g->design->fr, fr);
  g->fr_bits = fr->settled != 0u ? 0u : RATE_INVALID_SENSE_FR; /* settled: not at the limit */
}

GYRO_RAMFUNC void gyro_fr_mag(gyro_t *g)
{
  const sense_fr_t *fr = &g->fr;
  /* the continuous self-test's force on the Coriolis axis (selftest.h; 0 when off) */
  const float t = g->design->selftest.cont_fr_v2 * g->selftest.cont_c;
  if (fr->run != 0u && fr->skip == 0u)
    drive_synth_phasor_mag(&g->fb_root, fr->f_re + t, fr->f_im);
}

GYRO_RAMFUNC void gyro_fr_root(gyro_t *g)
{
  const sense_fr_t *fr = &g->fr;
  if (fr->run != 0u && fr->skip == 0u) drive_synth_phasor_root(&g->fb_synth, &g->fb_root);
}

GYRO_RAMFUNC void gyro_fr_parts(gyro_t *g)
{
  const sense_fr_t *fr = &g->fr;
  if (fr->run != 0u && fr->skip == 0u) drive_synth_phasor_parts(&g->fb_synth, &g->fb_root);
}

/* The Coriolis force is in phase with the drive velocity, which at the drive's resonance
 * is in phase with the drive force cos(phi + P) (6-12), through the mode's lag 2Q/wn
 * (6-17): the feedback force's frame turns with LP_tau(P) as the rate channel forms it
 * for its reference (P - its lag still to come, rate_channel.h; the tracking drive's p_eq
 * the same way), temperature included, not with P's own jitter (at 1500 deg/s of
 * rebalanced quadrature 0.02 deg of it is 0.5 deg/s of rate), and
 * sense.fb_phase_deg holds what differs between the two electrodes' paths and the
 * drive's distance from its resonance phase. The force goes to the synthesis as the
 * loop's phasor, in that frame (drive_synth_set_phasor: no arc tangent). */
GYRO_RAMFUNC void gyro_fr_synth(gyro_t *g)
{
  const sense_fr_t *fr = &g->fr;
  const rate_channel_t *rc = &g->rate;
  if (fr->run != 0u && fr->skip == 0u)
    drive_synth_set_phasor(&g->fb_synth, &g->fb_root,
                           (rc->p_last_rad - rc->p_lag_rad) + g->design->fb_theta_rad);
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

GYRO_RAMFUNC void gyro_block_measure(gyro_t *g)
{
  g->dac_frame->code[HAL_DAC_RATE_OUT] = g->rate_code;
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_root(g);
  if (supervisor_drive_enabled(&g->sup)) {
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
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_settle(g);
  /* The last verdict's onsets into the history, on this lighter tick. */
  if (GYRO_UNLIKELY(g->valid.onsets_pending != 0u)) {
    rate_valid_count_onsets(&g->valid, &g->valid_history);
  }
  (void)supervisor_step(&g->design->sup, &g->sup, &g->sup_in);
}

GYRO_RAMFUNC void gyro_block_phase_judge(gyro_t *g)
{
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_parts(g);
  if (supervisor_drive_enabled(&g->sup)) gyro_block_phase(g);
  g->cont_fail = selftest_cont_judge(&g->design->selftest, &g->selftest,
                                     g->sup.mode == GYRO_MODE_LOCKED);
}

GYRO_RAMFUNC void gyro_block_track_judge(gyro_t *g)
{
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_parts(g);
  if (supervisor_drive_enabled(&g->sup)) gyro_block_track(g);
  g->cont_fail = selftest_cont_judge(&g->design->selftest, &g->selftest,
                                     g->sup.mode == GYRO_MODE_LOCKED);
}

GYRO_RAMFUNC void gyro_block_rate_clear(gyro_t *g)
{
  if (g->rate_clear_due == GYRO_RATE_CLEAR_RESTART) {
    /* The checks' half first, on a slot of its own (a fault's clear, a start from OFF). */
    rate_valid_restart(&g->valid);
    g->rate_clear_due = GYRO_RATE_CLEAR_CHANNEL;
    return;
  }
  g->rate_clear_due = 0u;
  rate_channel_reset(&g->design->rate, &g->rate, g->design->rate.p_ref_deg);
  gyro_track_restart(g); /* the clear's tracking-drive half, within this tick's budget */
}

GYRO_RAMFUNC void gyro_block_rate(gyro_t *g)
{
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_take(g);
  rate_channel_t *rc = &g->rate;
  selftest_cont_notch(&g->design->selftest, &g->selftest, 0u, &rc->rate_raw);
  rate_channel_filter_rate(&g->design->rate, rc);
  rate_valid_range(&g->design->valid, &g->valid, rc->rate_dps);
}

/* The P slot's jobs (gyro_block_p): each a function of its own that ends in P's low-pass
 * as a tail call, so that only the one that runs saves registers, and only the
 * instance: the design is read again after its call (gyro_block_quad). */
static inline void p_low_pass(gyro_t *g)
{
  /* Its new P_f is flagged in rc->p_new. */
  (void)rate_channel_update_p(&g->design->rate, &g->rate, g->drive.p_eq_rad);
}

/* The thermometer checks of the P_f the last block made: P's low-pass runs on one block
 * in RATE_P_BLOCKS, the checks on the next, so that no tick carries both. */
GYRO_RAMFUNC GYRO_NOINLINE static void p_thermo(gyro_t *g)
{
  rate_channel_t *rc = &g->rate;
  rc->p_new = 0u;
  rate_valid_thermo(&g->design->valid, &g->valid, rc->p_dev_deg, rc->p_held_dev_deg,
                    rc->p_held_w);
  if ((g->valid.thermo & RATE_INVALID_THERMO_SLEW) != 0u) {
    rate_channel_fast_hold(&g->design->rate, rc);
  }
  p_low_pass(g);
}

GYRO_RAMFUNC GYRO_NOINLINE static void p_filters(gyro_t *g)
{
  rate_channel_comp_filters(&g->design->rate, &g->rate);
  p_low_pass(g);
}

GYRO_RAMFUNC GYRO_NOINLINE static void p_slew(gyro_t *g)
{
  if (rate_valid_slew(&g->design->valid, &g->valid)) rate_channel_comp_restart(&g->rate);
  p_low_pass(g);
}

GYRO_RAMFUNC GYRO_NOINLINE static void p_shadow(gyro_t *g)
{
  rate_valid_shadow(&g->design->valid, &g->valid, &g->rate);
  p_low_pass(g);
}

/* The compensation of the filters' new state, on a block with no other job: the rate
 * takes it from the next block on. A new P_f is 10 blocks apart; its jobs (the checks,
 * the filters' step, a window's judgement, the shadow's five parts, this) take the nine
 * blocks between at most. */
GYRO_RAMFUNC GYRO_NOINLINE static void p_refresh(gyro_t *g)
{
  rate_channel_comp_refresh(&g->design->rate, &g->rate);
  /* The board thermometer's share of the bias (board_therm.h), as the background
   * handed it; kept beside it, so that the background reads the bias in P alone. */
  const float corr = g->board_corr_dps;
  g->rate.comp_bias_dps += corr;
  g->board_corr_applied_dps = corr;
  p_low_pass(g);
}

GYRO_RAMFUNC void gyro_block_p(gyro_t *g)
{
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_limit(g);
  rate_channel_t *rc = &g->rate;
  /* The hold first (only rate_channel_update_p reads it): P is held while not LOCKED. */
  rate_channel_hold_p(rc, g->sup.mode != GYRO_MODE_LOCKED);
  /* (The layout for the worst of them, the thermometer checks: GYRO_COSTLY.) */
  if (GYRO_UNLIKELY(rate_channel_p_update_now(rc))) {
    p_low_pass(g); /* the new P_f's tick: no other job (a job still waiting runs after it) */
  } else if (GYRO_COSTLY(rc->p_new)) {
    p_thermo(g);
  } else if (rc->filters_due != 0u) {
    p_filters(g);
  } else if (g->valid.slew_due != 0u) {
    p_slew(g);
  } else if (g->valid.shadow_phase != 0u) {
    p_shadow(g);
  } else if (rc->comp_due != 0u) {
    p_refresh(g);
  } else {
    p_low_pass(g);
  }
}

GYRO_RAMFUNC void gyro_block_p_selftest(gyro_t *g)
{
  const int locked = g->sup.mode == GYRO_MODE_LOCKED;
  selftest_update(&g->design->selftest, &g->selftest, locked, g->rate.rate_raw);
  /* The test force disturbs the rate output: its filters settle again afterwards. */
  rate_valid_disturb(&g->valid);
  gyro_block_p(g);
}

/* The snapshot for telemetry and status, at fs / GYRO_BLOCK (5 kHz: the telemetry's
 * highest rate); flags hold what happened over the whole block. */
GYRO_RAMFUNC void gyro_block_output(gyro_t *g, float u1_v, float u2_v)
{
  if (GYRO_UNLIKELY(g->fr_on != 0u)) gyro_fr_mag(g);
  gyro_out_t *o = &g->out;
  const uint32_t block_bits = (g->sup.mode == GYRO_MODE_LOCKED ? 0u : RATE_INVALID_MODE) |
                              (selftest_running(&g->selftest) ? RATE_INVALID_SELFTEST : 0u) |
                              (g->clip_block != 0u ? RATE_INVALID_CLIP : 0u) |
                              (g->cont_fail != 0u ? RATE_INVALID_CONT_SELFTEST : 0u) |
                              g->selftest.cont_settle_bits | /* its notch settling */
                              (g->design->track_uncal != 0u ? RATE_INVALID_TRACKING : 0u) |
                              (g->design->cal_state != GYRO_CAL_OK ? RATE_INVALID_UNCALIBRATED
                                                                   : 0u) |
                              /* the reference's wide start (rate_channel.h): it passes
                               * the acquisition's tail of the measured phase */
                              (g->rate.ref_wide_left != 0u ? RATE_INVALID_SETTLING : 0u) |
                              g->quad_bits | /* nulling on and not (yet) nulled */
                              g->fr_bits |   /* force rebalance on and not balanced */
                              g->bg_bits;    /* the background's: tuning, board thermometer */
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

GYRO_RAMFUNC void gyro_block_output_sweep(gyro_t *g)
{
  /* The rate channel rests in SWEEP (its outputs keep their last values): the verdict
   * (not valid: MODE) and what does change. */
  gyro_out_t *o = &g->out;
  const uint32_t block_bits = RATE_INVALID_MODE | (g->clip_block != 0u ? RATE_INVALID_CLIP : 0u);
  o->rate_invalid = rate_valid_verdict(&g->valid, block_bits);
  o->rate_valid = 0u;
  o->rate_out_v = g->design->rate_fault_out_v;
  g->rate_code = g->design->rate_fault_code;
  /* (u1_v, u2_v: written by the tick, gyro.c) */
  o->mode = (uint32_t)g->sup.mode;
  o->fault = g->sup.fault;
  o->flags = g->flags_acc |
             ((o->rate_invalid & RATE_INVALID_SENSE_RANGE) != 0u ? GYRO_FLAG_SENSE_RANGE : 0u) |
             (g->design->cal_state != GYRO_CAL_OK ? GYRO_FLAG_UNCALIBRATED : 0u);
  g->flags_acc = 0u;
}

GYRO_RAMFUNC void gyro_block_sweep_idle(gyro_t *g)
{
  selfcal_exec_t *x = &g->cal;
  /* The job's channel: the drive pair, or the feedback pair (a sense job); the other's
   * synthesis is not stepped meanwhile (its electrodes at 0 V, gyro.c). */
  drive_synth_follow(GYRO_UNLIKELY(x->sense != 0u) ? &g->fb_synth : &g->synth, x->f_cmd_v2,
                     x->p_rad);
  g->dac_frame->code[HAL_DAC_TUNE] = x->tune_code;
  selfcal_exec_take(x); /* a new job starts on a tick without a job of its own */
}

GYRO_RAMFUNC void gyro_block_sweep(gyro_t *g, uint32_t slot)
{
  selfcal_exec_t *x = &g->cal;
  const lmsd_t *m = GYRO_UNLIKELY(x->sense != 0u) ? &g->lmsd_sense : &g->lmsd_drive;
  selfcal_exec_tick(x, m->w_i, m->w_q);
  g->nco.half_step = x->half_step; /* from the next sample on, as the excitation */
  gyro_block_run_sweep(g, slot);
}
