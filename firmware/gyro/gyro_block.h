/* The once-per-block jobs of gyro_tick, one per tick of the block (gyro_state.h: the block,
 * its slot table and the order the jobs depend on). Internal to the gyro: only
 * gyro_tick runs them.
 *
 * A job runs at the end of its tick, after the DAC frame is written: gyro_tick ends in
 * gyro_block_run, which ends in one call of a job, compiled as a tail call. The sample
 * path itself then calls nothing before its frame, keeps its floats in the caller-saved
 * registers (it saves no FP register, and its few core registers once) and a job pays
 * only for its own registers; a job with a rare or alternative part (the P slot's,
 * the clear's rate half) has each part a function of its own, so that only the part
 * that runs saves registers. The jobs that are more than a call into a module are
 * functions of their own here (a separate translation unit, so they stay out of
 * gyro_tick's register allocation); a job that would need a call before its last one
 * is split by the switch instead (the self-test in GYRO_SLOT_P), so that the common
 * path saves nothing.
 */
#ifndef GYRO_BLOCK_H
#define GYRO_BLOCK_H

#include <stdint.h>

#include "dsp/fastmath.h"
#include "gyro/gyro_state.h"

/* The tracking drive from the calibrated frequency again (drive off, a fault's clear): its
 * state reset and the NCO back on the design's step (in the fixed drive that is where
 * the NCO already is, unless a sweep ended without its hand-over). */
static inline void gyro_track_restart(gyro_t *g)
{
  g->nco.half_step = g->design->nco_half_step;
  drive_track_reset(&g->track); /* last: a tail call */
}

/* GYRO_SLOT_AMP: the first half of the finiteness check (the LMSD weights), then |Z|
 * and, while the drive runs, the amplitude PI (with the drive off |Z| only, for the
 * over-amplitude trip) (gyro_block_amp_measure); the rate-valid drive-phase and
 * sense-range checks. */
void gyro_block_amp_measure(gyro_t *g);
void gyro_block_amp(gyro_t *g);
/* GYRO_SLOT_COMMAND: the rest of the supervisor's evidence (sup_in), and the block's
 * drive command into the synthesis (once, after both loops); then the quadrature-nulling
 * loop's step, if one is due (g->quad_job). */
void gyro_block_command(gyro_t *g);
/* GYRO_SLOT_PROJECT when the supervisor asked for it: clear every integrating state, so
 * that nothing of the old state (possibly NaN) survives into the next acquisition; the
 * rate channel's on the next tick (GYRO_SLOT_RATE), each half within a tick's budget. */
void gyro_block_clear(gyro_t *g);
/* GYRO_SLOT_QUAD: the second half of the finiteness check (loop outputs, rate channel
 * outputs) and its verdict for the supervisor (sup_in: the next block's supervisor acts
 * on it), then the quadrature's output filter. */
void gyro_block_quad(gyro_t *g);
/* The quadrature-nulling loop's job (its steps at the end of GYRO_SLOT_COMMAND,
 * gyro_block.c) as quad.null says: waiting for the next update, or none. */
void gyro_quad_reset(gyro_t *g);
/* Its halt at once, outside the tick's jobs (the drive's stop, a re-acquisition, a sweep,
 * quad.null 0): not settled, both electrodes at 0 V (mid-scale codes into the attached
 * frame), the job waiting (or none). */
void gyro_quad_off(gyro_t *g);
/* Force rebalance's steps (sense.mode 1, gyro_slots.h), each at the start of its slot's
 * job while g->fr_on: take (GYRO_SLOT_RATE: starts the loop on LOCKED, halts it when
 * not), PI (GYRO_SLOT_QUAD), limit (GYRO_SLOT_P), |F| (GYRO_SLOT_OUTPUT), the force's
 * root (GYRO_SLOT_PHASE_MEAS), the voltage phasor (GYRO_SLOT_PHASE_PI), synthesis
 * (GYRO_SLOT_AMP), settling (GYRO_SLOT_SUPERVISE, a block later: the verdict of
 * GYRO_SLOT_OUTPUT reads it; inline in that job, gyro_block.c). */
void gyro_fr_take(gyro_t *g);
void gyro_fr_integrate(gyro_t *g);
void gyro_fr_limit(gyro_t *g);
void gyro_fr_mag(gyro_t *g);
void gyro_fr_root(gyro_t *g);
void gyro_fr_parts(gyro_t *g);
void gyro_fr_synth(gyro_t *g);
/* Its halt at once (not LOCKED, the drive's stop, sense.mode 0): the force to zero from
 * the next tick, the loop open and not balanced. */
void gyro_fr_off(gyro_t *g);
/* GYRO_SLOT_PHASE_PI: the phase loop's update; a whole turn of P it took is passed on to
 * the thermometer (rate_channel_shift_p). Tracking drive: the PLL's update instead (the
 * NCO's step from the next tick on). */
void gyro_block_phase(gyro_t *g);
/* GYRO_SLOT_PHASE_MEAS: arg Z (drive on; the tracking drive's notched error), the drive
 * half of the output snapshot; the analog rate output's code of the block into the
 * attached frame (GYRO_SLOT_OUTPUT made it on the block's last tick: the frame carries
 * it from this tick on, as the ticks' own copy of it did). */
void gyro_block_measure(gyro_t *g);
/* GYRO_SLOT_SUPERVISE, in every mode: force rebalance's settling test (sense.mode 1), the
 * last verdict's onsets into the history (rare), then the supervisor. */
void gyro_block_supervise(gyro_t *g);
/* GYRO_SLOT_PROJECT: the block's projection and the continuous self-test's modulation. */
void gyro_block_project(gyro_t *g);
/* GYRO_SLOT_PHASE_PI: the phase loop (drive on, gyro_block_phase), or the tracking
 * drive's PLL (gyro_block_track), and the continuous self-test's verdict. */
void gyro_block_track(gyro_t *g);
void gyro_block_track_judge(gyro_t *g);
void gyro_block_phase_judge(gyro_t *g);
/* GYRO_SLOT_RATE: the continuous self-test's notch on the rate axis, the rate's output
 * filter, scale and compensation, its range check. */
void gyro_block_rate(gyro_t *g);
/* GYRO_SLOT_RATE after the loop state's clear (gyro_block_clear, or a start from OFF:
 * rate_clear_due): its rate half instead, on two blocks: the thermometer's checks
 * (rate_valid_restart), then the rate channel's reset (and the tracking drive's). */
void gyro_block_rate_clear(gyro_t *g);
/* GYRO_SLOT_P: P's hold (while not LOCKED) and low-pass, and one of the jobs between two
 * P_f (the thermometer checks of the P_f the last block made, the compensation's steps). */
void gyro_block_p(gyro_t *g);
/* GYRO_SLOT_P while a self-test runs: its sequence on the block's projection, then P's
 * hold and low-pass. */
void gyro_block_p_selftest(gyro_t *g);
/* GYRO_SLOT_OUTPUT: the snapshot for telemetry and status, the analog rate code.
 * (u1_v, u2_v): the drive voltages of this tick. */
void gyro_block_output(gyro_t *g, float u1_v, float u2_v);
/* Every tick in SWEEP, instead of gyro_block_run: the self-calibration job's
 * excitation (from the next tick on) and NCO step, then the slot's job. */
void gyro_block_sweep(gyro_t *g, uint32_t slot);

/* GYRO_SLOT_PROJECT, in every mode: the rail codes of the ticks whose sense sum is
 * projected now (the verdict's and, drive channel only, the supervisor's evidence). */
static inline void gyro_block_take_rails(gyro_t *g)
{
  g->clip_block = g->clip_count;
  g->clip_count = 0u;
  g->clip_drive_block = g->clip_drive_count;
  g->clip_drive_count = 0u;
}

/* The job of tick `slot` of the block. Every branch ends in one call (a tail call); what
 * only some jobs need (whether the drive runs) they find out themselves. */
static inline void gyro_block_run(gyro_t *g, uint32_t slot, float u1_v, float u2_v)
{
  switch (slot) {
  case GYRO_SLOT_PHASE_MEAS: gyro_block_measure(g); break;
  case GYRO_SLOT_PHASE_PI:
    if (g->design->track != 0u) {
      gyro_block_track_judge(g);
    } else {
      gyro_block_phase_judge(g);
    }
    break;
  case GYRO_SLOT_AMP: gyro_block_amp(g); break;
  case GYRO_SLOT_COMMAND: gyro_block_command(g); break;
  case GYRO_SLOT_SUPERVISE:
    /* Its request to clear the loop state (sup.clear_req) is acted on next tick. */
    gyro_block_supervise(g);
    break;
  case GYRO_SLOT_PROJECT:
    /* The clear resets the rate channel, whose projection waits for the next block. */
    gyro_block_take_rails(g);
    if (g->sup.clear_req != 0u) {
      gyro_block_clear(g);
    } else {
      gyro_block_project(g);
    }
    break;
  case GYRO_SLOT_RATE:
    if (GYRO_UNLIKELY(g->rate_clear_due != 0u)) {
      gyro_block_rate_clear(g);
    } else {
      gyro_block_rate(g);
    }
    break;
  case GYRO_SLOT_QUAD: gyro_block_quad(g); break;
  case GYRO_SLOT_P:
    if (selftest_running(&g->selftest)) {
      gyro_block_p_selftest(g);
    } else {
      gyro_block_p(g);
    }
    break;
  default: /* GYRO_SLOT_OUTPUT */ gyro_block_output(g, u1_v, u2_v); break;
  }
}

/* GYRO_SLOT_OUTPUT in SWEEP: the verdict and the snapshot of what SWEEP changes. */
void gyro_block_output_sweep(gyro_t *g);

/* The finiteness check's second half (loop and rate outputs) and its verdict for the
 * supervisor (GYRO_SLOT_QUAD, in every mode). */
static inline void gyro_block_finite(gyro_t *g)
{
  const float sum = g->drive.f_cmd_v2 + g->drive.p_rad + g->rate.rate_dps + g->rate.quad_dps;
  g->sup_in.state_finite = g->weights_finite != 0u && fm_isfinite(sum);
}

/* The ticks of the block without a job of their own in SWEEP (the drive loops' and the
 * rate channel's, gyro_block_run_sweep): a new force command (a job's start, a back-off)
 * goes to the synthesis, and a newly posted job starts, on the next of them, at most
 * four ticks (80 us) late: neither would fit beside the supervisor's or the snapshot's
 * job, and every job settles for far longer than that. */
void gyro_block_sweep_idle(gyro_t *g);

/* The jobs of a SWEEP tick, on top of the self-calibration executive's step: the rate
 * is not valid in SWEEP (rate_valid.h, MODE), so the rate channel's jobs (projection,
 * filters, P, the continuous self-test) wait for the loops to be back; the supervisor
 * with its evidence, the finiteness check, the rail counts and the output snapshot run
 * as in the other modes. */
static inline void gyro_block_run_sweep(gyro_t *g, uint32_t slot)
{
  switch (slot) {
  case GYRO_SLOT_PHASE_MEAS: gyro_block_measure(g); break; /* the drive is off in SWEEP */
  case GYRO_SLOT_AMP: gyro_block_amp_measure(g); break;
  case GYRO_SLOT_COMMAND: gyro_block_command(g); break;
  case GYRO_SLOT_SUPERVISE: gyro_block_supervise(g); break;
  case GYRO_SLOT_PROJECT:
    gyro_block_take_rails(g);
    if (g->sup.clear_req != 0u) gyro_block_clear(g);
    break;
  case GYRO_SLOT_QUAD: gyro_block_finite(g); break;
  case GYRO_SLOT_OUTPUT: gyro_block_output_sweep(g); break;
  default: /* GYRO_SLOT_PHASE_PI, _RATE, _P: the drive loops' and the rate channel's */
    gyro_block_sweep_idle(g);
    break;
  }
}

#endif /* GYRO_BLOCK_H */
