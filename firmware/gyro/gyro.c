#include "gyro/gyro.h"

#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "gyro/gyro_block.h"
#include "dsp/ramfunc.h"

/* No frame attached (gyro_attach_dac_frame): the codes go here, where nothing reads them. */
static hal_dac_frame_t s_no_frame;

void gyro_attach_dac_frame(gyro_t *g, hal_dac_frame_t *frame)
{
  g->dac_frame = frame != NULL ? frame : &s_no_frame;
}

/* No ADC frame attached (gyro_attach_adc_frame): the codes read 0. */
static const hal_adc_frame_t k_no_adc_frame;

void gyro_attach_adc_frame(gyro_t *g, const volatile hal_adc_frame_t *frame)
{
  g->adc_frame = frame != NULL ? frame : &k_no_adc_frame;
}

/* No counter of lost samples attached (gyro_attach_lost_counter): none are lost. */
static const volatile uint32_t k_no_loss = 0u;

void gyro_attach_lost_counter(gyro_t *g, const volatile uint32_t *count)
{
  g->lost_count = count != NULL ? count : &k_no_loss;
  g->lost_seen = *g->lost_count;
}

int gyro_init_from_design(gyro_t *g, const gyro_design_t *d)
{
  if (g == NULL || d == NULL) {
    return -1;
  }
  gyro_t t;
  memset(&t, 0, sizeof t);
  t.design = d;
  if (nco_init(&t.nco, &d->nco) != 0 || lmsd_init(&t.lmsd_drive, &d->lmsd_drive) != 0 ||
      lmsd_init(&t.lmsd_sense, &d->lmsd_sense) != 0 ||
      drive_synth_init(&t.synth, &d->synth) != 0 || rate_channel_init(&d->rate, &t.rate) != 0 ||
      rate_valid_init(&d->valid, &t.valid) != 0) {
    return -2;
  }
  drive_loop_init(&d->drive, &t.drive);
  drive_track_reset(&t.track);
  supervisor_init(&t.sup);
  gyro_attach_lost_counter(&t, NULL);
  t.adc_v_per_code = HAL_ADC_V_PER_CODE;
  selftest_init(&d->selftest, &t.selftest);
  t.rate_code = d->rate_fault_code; /* not valid until the first verdict says so */
  t.out.rate_out_v = d->rate_fault_out_v;
  t.out.rate_invalid = RATE_INVALID_MODE;
  t.sup_in.state_finite = 1;
  t.weights_finite = 1u;
  quad_null_stop(&t.quad);
  gyro_attach_dac_frame(&t, NULL);
  gyro_attach_adc_frame(&t, NULL);
  t.quad_bits = d->quad_on != 0u ? RATE_INVALID_QUAD_NULL : 0u; /* not nulled yet */
  gyro_quad_reset(&t);
  (void)drive_synth_init(&t.fb_synth, &d->fb_synth); /* accepted by gyro_design_complete */
  t.fr_on = d->sense_mode;
  t.fb_off_v = d->fb_off_v;
  gyro_fr_off(&t);
  t.bg_bits = d->tune.mode != SENSE_TUNE_OFF ? RATE_INVALID_TUNE : 0u; /* not tuned yet */
  /* the board thermometer's verdict comes with the background's first pass */
  t.bg_bits |= d->board.on != 0u ? RATE_INVALID_BOARD_TEMP : 0u;
  *g = t;
  if (d->autostart != 0u) {
    gyro_start(g);
  }
  return 0;
}

/* The sense demodulator's step: the sweep's own in SWEEP (gyro_design.h sweep_mu_sense),
 * the design's (open loop's or force rebalance's) otherwise. */
static float gyro_sense_mu(const gyro_t *g, const gyro_design_t *d)
{
  return g->sup.mode == GYRO_MODE_SWEEP ? d->sweep_mu_sense : d->lmsd_sense.mu;
}

/* Force rebalance (sense.mode 1): turned on or off, or its electrodes' configuration
 * changed, the loop starts again from zero force (on the next LOCKED block), and turned
 * off, the feedback pair's second channel back to mid-scale (0 V; the first is written
 * every tick). Other changes (the loop's design) carry the running loop on. */
static void gyro_apply_fr(gyro_t *g, const gyro_design_t *d, const gyro_design_t *old)
{
  const int same_fb = d->sense_mode == old->sense_mode &&
                      d->fb_synth.scheme == old->fb_synth.scheme &&
                      d->fb_synth.dc_bias_v == old->fb_synth.dc_bias_v &&
                      d->fb_synth.u_max_v == old->fb_synth.u_max_v;
  if (same_fb) return;
  (void)drive_synth_init(&g->fb_synth, &d->fb_synth);
  g->fr_on = d->sense_mode;
  g->fb_off_v = d->fb_off_v;
  gyro_fr_off(g);
  if (d->sense_mode == 0u) g->dac_frame->code[HAL_DAC_SENSE_FB_U2] = (uint16_t)HAL_DAC_CODE_MID;
}

void gyro_apply(gyro_t *g, const gyro_design_t *d)
{
  /* The design was completed by gyro_design, so every module accepts its part. Only
   * what a change means beyond new coefficients is done here; the sample path reads the
   * rest through g->design from the next tick on. */
  const gyro_design_t *old = g->design;
  const int driving = supervisor_drive_enabled(&g->sup);
  /* A new amplitude setpoint is a commanded move, not a loss of lock: re-acquire
   * instead of letting the lost-lock detector trip on the step. */
  if (fm_absf(d->drive.amp_set_v - g->drive.amp_set_v) >
      old->sup.lock_tol_rel * g->drive.amp_set_v) {
    supervisor_reacquire(&g->sup);
  }
  /* A new phase setpoint moves P by the same angle (arg Z = P - the resonance's phase):
   * that is no change of temperature, so the thermometer moves with it at once rather
   * than gliding through its low-pass (which would read as a slew). */
  const float dphase_rad = d->drive.phase_set_rad - old->drive.phase_set_rad;
  if (dphase_rad != 0.0f && driving) {
    rate_channel_shift_p(&g->rate, dphase_rad * FM_DEG_PER_RAD_F);
    rate_valid_shift_p(&g->valid, dphase_rad * FM_DEG_PER_RAD_F);
  }
  /* The NCO's step is the drive's own (the sweep moves it every tick, a tracking drive
   * would own it): a design sets it only when the drive frequency changes. */
  if (d->nco_half_step != old->nco_half_step) {
    g->nco.half_step = d->nco_half_step;
    drive_track_reset(&g->track); /* it tracks from the new frequency */
  }
  /* The LMSDs' step sizes sit beside their weights (lmsd_t: the one coefficient the
   * per-sample step reads, within the same load). */
  (void)lmsd_set_mu(&g->lmsd_drive, d->lmsd_drive.mu);
  (void)lmsd_set_mu(&g->lmsd_sense, gyro_sense_mu(g, d));
  drive_loop_reconfigure(&d->drive, &g->drive);
  if (d->track != 0u) {
    g->drive.p_rad = d->drive.p_init_rad; /* the tracking drive's force phase is p_init */
  }
  selftest_reconfigure(&old->selftest, &d->selftest, &g->selftest);
  /* The drive scheme only changes with the drive off (drive.mode is not live); the
   * synthesiser keeps its own scheme and levels (drive_synth_t) until then. */
  if (d->synth.scheme == g->synth.scheme || !driving) {
    (void)drive_synth_init(&g->synth, &d->synth);
    if (driving) {
      drive_synth_set(&g->synth, g->drive.f_cmd_v2, g->drive.p_rad); /* carry on driving */
    }
  }
  /* A change of what the rate output means (reference, scale, compensation, output
   * filter): the output is not valid until the filters have settled again. */
  if (!rate_channel_same_path(&old->rate, &d->rate)) {
    rate_valid_disturb(&g->valid);
  }
  rate_channel_rebase(&old->rate, &d->rate, &g->rate);
  /* A new reference of P's low-pass (drive.p_init_deg) re-expresses P_f, no change of
   * temperature: the checks' slew window and trend move with it, or the next window
   * would read the change of reference as a slew. */
  rate_valid_shift_p(&g->valid, old->rate.p_ref_deg - d->rate.p_ref_deg);
  g->design = d;
  /* Quadrature nulling turned off, or no longer LOCKED (a re-acquisition above): the
   * electrodes at 0 V now; turned on, not nulled until its loop says so, from the next
   * update if LOCKED. The running loop keeps its identified gain through other changes
   * of quad.*. */
  if (g->quad.mode != QUAD_NULL_OFF && (d->quad_on == 0u || g->sup.mode != GYRO_MODE_LOCKED)) {
    gyro_quad_off(g);
  }
  g->quad_bits = d->quad_on != 0u && g->quad.settled == 0u ? RATE_INVALID_QUAD_NULL : 0u;
  if ((d->quad_on != 0u) != (old->quad_on != 0u)) gyro_quad_reset(g);
  gyro_apply_fr(g, d, old);
  /* Mode tuning turned on or off (sense.tune is not live: the drive is off): not tuned
   * until the application says so, the electrodes at 0 V meanwhile. */
  if (d->tune.mode != old->tune.mode)
    gyro_set_tune(g, (uint16_t)HAL_DAC_CODE_MID,
                  d->tune.mode != SENSE_TUNE_OFF ? RATE_INVALID_TUNE : 0u);
}

void gyro_set_tune(gyro_t *g, uint16_t code, uint32_t bits)
{
  g->bg_bits = (g->bg_bits & ~RATE_INVALID_TUNE) | (bits & RATE_INVALID_TUNE);
  if (g->sup.mode != GYRO_MODE_SWEEP && code <= HAL_DAC_CODE_MAX)
    g->dac_frame->code[HAL_DAC_TUNE] = code;
}

void gyro_set_board(gyro_t *g, uint32_t bits)
{
  g->bg_bits = (g->bg_bits & ~RATE_INVALID_BOARD_TEMP) | (bits & RATE_INVALID_BOARD_TEMP);
}

void gyro_start(gyro_t *g)
{
  /* Out of OFF the thermometer and its checks start again as at power-on: P_f from the
   * reference, the compensation's filters and the output filters at rest, no slew
   * window, shadow, trend or THERMO_SLEW standing (rate_valid_restart), on the next rate
   * slots (the clear's, gyro_block_rate_clear; not on this tick, which takes the
   * request). While the drive was off P measured nothing: the P_f it held is the
   * temperature at the stop, after an unknown time off (a night, a chamber change) no
   * better a start than the calibrated reference; and a THERMO_SLEW of the P_f of before
   * the stop held the compensation's fast path out for 45 s after the new lock. */
  if (g->sup.mode == GYRO_MODE_OFF) g->rate_clear_due = GYRO_RATE_CLEAR_RESTART;
  supervisor_start(&g->sup);
}

/* The sweep's sense jobs leave a command on the feedback pair's synthesis and may leave
 * the tuning electrodes at a probe voltage (a failed sweep): both off whenever a sweep
 * begins or ends, so that force rebalance starts from zero force (gyro_fr_take) and no
 * tuning voltage outlives the sweep or a stop (mode tuning applies its voltage again
 * once LOCKED, app.c). */
static void gyro_sweep_electrodes_off(gyro_t *g)
{
  drive_synth_silence(&g->fb_synth);
  g->dac_frame->code[HAL_DAC_TUNE] = (uint16_t)HAL_DAC_CODE_MID;
}

void gyro_stop(gyro_t *g)
{
  supervisor_stop(&g->sup);
  (void)lmsd_set_mu(&g->lmsd_sense, gyro_sense_mu(g, g->design)); /* a sweep's is over */
  if (g->quad.mode != QUAD_NULL_OFF) gyro_quad_off(g);            /* its electrodes at 0 V */
  if (g->fr.run != 0u) gyro_fr_off(g);                            /* no feedback force */
  gyro_sweep_electrodes_off(g);
  drive_loop_reset(&g->design->drive, &g->drive);
  /* No force is synthesised in OFF; the next start's first ticks (until its first
   * command, GYRO_SLOT_COMMAND) would otherwise drive the resonator with the stopped
   * run's last force, a kick a power-on does not give (the fault's clear silences it
   * too, gyro_block_clear). */
  drive_synth_silence(&g->synth);
  /* The drive starts again from the calibrated frequency, whatever moved the NCO (the
   * tracking drive, or a sweep that ended without its hand-over). */
  gyro_track_restart(g);
}

void gyro_sweep_begin(gyro_t *g)
{
  gyro_stop(g); /* the nulling electrodes at 0 V too: the sweep measures the part as it
                 * is, and the loop starts again, with its probe, after it */
  supervisor_enter_sweep(&g->sup);
  (void)lmsd_set_mu(&g->lmsd_sense, gyro_sense_mu(g, g->design));
  selfcal_exec_reset(&g->cal, g->nco.half_step);
}

int gyro_sweep_handover(gyro_t *g, const gyro_design_t *d)
{
  if (g->sup.mode != GYRO_MODE_SWEEP) {
    return -1;
  }
  drive_track_reset(&g->track);
  g->nco.half_step = d->nco_half_step;
  gyro_sweep_electrodes_off(g);
  /* The sweep's last job held the vibration at the set point with (f_cmd, P): the
   * integrators continue from there instead of from zero force. */
  (void)pi_reset(&d->drive.amp, &g->drive.amp_pi, g->cal.f_cmd_v2, 0.0f);
  (void)pi_reset(&d->drive.phase, &g->drive.phase_pi, g->cal.p_rad, 0.0f);
  g->drive.f_cmd_v2 = g->drive.amp_pi.u;
  g->drive.amp_int = g->drive.amp_pi.u;
  g->drive.p_rad = g->drive.phase_pi.u;
  g->drive.p_eq_rad = g->drive.p_rad;
  supervisor_stop(&g->sup);
  supervisor_start(&g->sup);
  (void)lmsd_set_mu(&g->lmsd_sense, gyro_sense_mu(g, d));
  return 0;
}

/* Rail codes, counted per block: a waveform clipped only at its peaks has a few per
 * carrier cycle and never a long run, yet its demodulated phasor is wrong. */
static inline void count_rails(gyro_t *g, const hal_adc_frame_t *adc)
{
  const int drive_rail = adc->drive == HAL_ADC_CODE_MAX || adc->drive == HAL_ADC_CODE_MIN;
  const int sense_rail = adc->sense == HAL_ADC_CODE_MAX || adc->sense == HAL_ADC_CODE_MIN;
  /* One branch for both channels (| rather than ||: the tick's path falls through). */
  if (GYRO_UNLIKELY(drive_rail | sense_rail)) {
    g->flags_acc |= GYRO_FLAG_ADC_RAIL;
    g->clip_count++;
    if (drive_rail) g->clip_drive_count++;
  }
}

/* A SWEEP tick of the sense mode's identification (a job with sense 1, selfcal_exec.h):
 * the excitation on the feedback pair through its own synthesis, the sense LMSD's
 * phasor to the executive; the drive electrodes at 0 V (no drive force: the sense
 * pickoff carries no quadrature then, which on a part near its match is several times
 * the ADC's range). The same cost as the drive's tick: one LMSD, one synthesis. */
GYRO_RAMFUNC static void gyro_tick_sweep_sense(gyro_t *g, const hal_adc_frame_t *adc)
{
  hal_dac_frame_t *dac = g->dac_frame;
  nco_out_t ref;
  nco_step(&g->nco, &ref);
  lmsd_step(&g->lmsd_sense, (float)adc->sense * g->adc_v_per_code, ref.sin_wc, ref.cos_wc);
  count_rails(g, adc);
  float u3, u4;
  drive_synth_step(&g->fb_synth, &ref, &u3, &u4);
  dac->code[HAL_DAC_DRIVE_U1] = (uint16_t)HAL_DAC_CODE_MID;
  dac->code[HAL_DAC_DRIVE_U2] = (uint16_t)HAL_DAC_CODE_MID;
  dac->code[HAL_DAC_SENSE_FB_U1] = gyro_volts_to_dac(u3 - g->fb_off_v);
  dac->code[HAL_DAC_SENSE_FB_U2] = gyro_volts_to_dac(u4 - g->fb_off_v);
  g->out.tick++;
  const uint32_t slot = g->slot;
  g->slot = slot + 1u == GYRO_BLOCK ? 0u : slot + 1u;
  if (slot == GYRO_SLOT_OUTPUT) g->out.u1_v = g->out.u2_v = 0.0f;
  gyro_block_sweep(g, slot);
}

/* A SWEEP tick: the self-calibration executive measures the drive LMSD's phasor and
 * sets the excitation and the NCO's next step on every tick (selfcal_exec.h). The sense
 * channel and the self-test forces rest (the rate is not valid in SWEEP and the sweep
 * does not use it), so that the executive's step fits the tick's budget. */
GYRO_RAMFUNC static void gyro_tick_sweep(gyro_t *g, const hal_adc_frame_t *adc)
{
  if (GYRO_UNLIKELY(g->cal.sense != 0u)) {
    gyro_tick_sweep_sense(g, adc);
    return;
  }
  hal_dac_frame_t *dac = g->dac_frame;
  nco_out_t ref;
  nco_step(&g->nco, &ref);
  lmsd_step(&g->lmsd_drive, (float)adc->drive * g->adc_v_per_code, ref.sin_wc, ref.cos_wc);
  count_rails(g, adc);
  float u1, u2;
  drive_synth_step(&g->synth, &ref, &u1, &u2);
  dac->code[HAL_DAC_DRIVE_U1] = gyro_volts_to_dac(u1);
  dac->code[HAL_DAC_DRIVE_U2] = gyro_volts_to_dac(u2);
  dac->code[HAL_DAC_SPARE] = (uint16_t)HAL_DAC_CODE_MID; /* = HAL_DAC_SENSE_FB_U1 */
  dac->code[HAL_DAC_SENSE_FB_U2] = (uint16_t)HAL_DAC_CODE_MID;
  g->out.tick++;
  const uint32_t slot = g->slot;
  g->slot = slot + 1u == GYRO_BLOCK ? 0u : slot + 1u;
  if (slot == GYRO_SLOT_OUTPUT) {
    /* The snapshot's drive voltages, here: its job (gyro_block_output_sweep) runs after
     * the executive's step, across which they would have to be saved. */
    g->out.u1_v = u1;
    g->out.u2_v = u2;
  }
  gyro_block_sweep(g, slot);
}

GYRO_RAMFUNC void gyro_tick(gyro_t *g)
{
  /* The frame the converters left, read once (where the DMA keeps writing it). */
  const volatile hal_adc_frame_t *in = g->adc_frame;
  const hal_adc_frame_t frame = {in->drive, in->sense};
  const hal_adc_frame_t *adc = &frame;
  const gyro_mode_t mode = g->sup.mode;
  if (GYRO_UNLIKELY(mode == GYRO_MODE_SWEEP)) {
    gyro_tick_sweep(g, adc);
    return;
  }
  nco_out_t ref;
  nco_step(&g->nco, &ref);

  const float v_drive = (float)adc->drive * g->adc_v_per_code;
  const float v_sense = (float)adc->sense * g->adc_v_per_code;
  lmsd_step(&g->lmsd_drive, v_drive, ref.sin_wc, ref.cos_wc);
  lmsd_step(&g->lmsd_sense, v_sense, ref.sin_wc, ref.cos_wc);
  rate_channel_accumulate(&g->rate, g->lmsd_sense.w_i, g->lmsd_sense.w_q);
  count_rails(g, adc);

  /* The waveform of the command the loops last set (ACQUIRE, LOCKED, once per block). */
  float u1, u2;
  if (GYRO_UNLIKELY(mode != GYRO_MODE_ACQUIRE && mode != GYRO_MODE_LOCKED)) {
    u1 = u2 = 0.0f; /* the drive off: no force */
  } else {
    drive_synth_step(&g->synth, &ref, &u1, &u2);
  }
  hal_dac_frame_t *dac = g->dac_frame;
  dac->code[HAL_DAC_DRIVE_U1] = gyro_volts_to_dac(u1);
  dac->code[HAL_DAC_DRIVE_U2] = gyro_volts_to_dac(u2);
  /* (The rate output's code changes once per block: GYRO_SLOT_PHASE_MEAS writes it.) */
  if (GYRO_UNLIKELY(g->fr_on != 0u)) {
    /* Force rebalance: its force on the feedback pair (the first channel is the spare's),
     * the waveform of the command its loop last set (sense_fr.h). */
    float u3, u4;
    drive_synth_step(&g->fb_synth, &ref, &u3, &u4);
    dac->code[HAL_DAC_SENSE_FB_U1] = gyro_volts_to_dac(u3 - g->fb_off_v);
    dac->code[HAL_DAC_SENSE_FB_U2] = gyro_volts_to_dac(u4 - g->fb_off_v);
  } else {
    /* Built-in self-test force on the sense feedback electrodes (selftest.h). */
    dac->code[HAL_DAC_SPARE] = GYRO_COSTLY(g->selftest.force_on)
                                   ? gyro_volts_to_dac(
                                         selftest_force(&g->selftest, ref.sin_wc, ref.cos_wc))
                                   : (uint16_t)HAL_DAC_CODE_MID;
  }
  g->out.tick++;

  /* Everything slower than the carrier: this tick's job of the block (gyro_block.h),
   * last, as a tail call. */
  const uint32_t slot = g->slot;
  g->slot = slot + 1u == GYRO_BLOCK ? 0u : slot + 1u;
  gyro_block_run(g, slot, u1, u2);
}
