/* The gyro's block and its slot table: which of the block's ticks runs which job (the
 * sample path, gyro_tick and gyro_block.h), and the delays the loop designer derives
 * from it (gyro_design.c). */
#ifndef GYRO_SLOTS_H
#define GYRO_SLOTS_H

#include "gyro/rate_channel.h" /* RATE_DECIM */

/* The block: GYRO_BLOCK ticks (the rate channel's RATE_DECIM, 0.2 ms at 50 kHz). Per
 * tick only what moves with the carrier runs: the NCO, both LMSDs, the sum of the sense
 * phasor, the drive waveform and the self-test force, the rail count and the DAC frame.
 * Everything else runs once per block, cut into jobs of about the same cost, one job
 * on each tick of the block: the interrupt's budget is set by its worst tick
 * (tools/bench/README.md). A job runs after its tick's DAC frame is written (the jobs
 * are tail calls of gyro_tick, gyro_block.h), so what it changes reaches the DAC from
 * the next tick on.
 *
 *   slot  job                                             uses (slot it comes from)
 *   0     arg Z (fm_atan2f: one divide); the drive half   drive LMSD
 *         of the output snapshot; the analog rate         drive loop (1, 2, last block)
 *         output's code into the DAC frame                rate code (9, last block)
 *         tracking drive: wrapped error and its notch     arg Z
 *   1     phase loop: wrapped error, PI -> P (P held      arg Z (0), |Z| (2, last block)
 *         while |Z| < 10 % of its setpoint; a whole
 *         turn of P passed on to the thermometer);
 *         tracking drive: its PI -> the NCO's step       its notched error (0)
 *         the continuous self-test's verdict             its LMS (6, 7, last block)
 *   2     finiteness check, first half (LMSD weights);    drive LMSD
 *         |Z| (square root), amplitude PI -> f_cmd;
 *         rate-valid drive-phase and sense-range checks   phase error (4), quad (7), sense LMSD
 *   3     the supervisor's evidence (sup_in); the         |Z|, f_cmd (2), phase error (1)
 *         thermometer's phase (P, or p_eq from the       P (1), the tracker's step (1)
 *         tracking drive's step)
 *         drive_synth_set(f_cmd, P): the waveform's       f_cmd (2), P (1)
 *         amplitude (square root) and phase offset;
 *         then, quad.null 1, one step of the              quad (7), P_f (8)
 *         quadrature-nulling loop's update (500 Hz,
 *         from the block after each new P_f; gyro_block.c:
 *         take .. the electrodes' DAC codes, one a
 *         block; between updates a wait, which also
 *         halts the loop when not LOCKED)
 *   4     the last verdict's onsets into the history      verdict (9, last block)
 *         (rare); supervisor (its clear request: slot 5)  evidence (3), finiteness (7, last block)
 *   5     rate channel: block mean of S, projection       sense sum, P (1)
 *         (or, on request, the loop state cleared);
 *         the block's rail codes; the continuous
 *         self-test's modulation
 *   6     the continuous self-test's notch (rate axis);   projection (5), modulation (5)
 *         rate: output filter, scale, compensation;       its refresh (8, a block before)
 *         its range check (or, after a clear, the rate
 *         channel's and the tracking drive's reset)
 *   7     finiteness check, second half (loop and rate    weights' half (2)
 *         outputs) and verdict; the continuous            projection (5)
 *         self-test's notch (quadrature axis),
 *         quadrature filter; the filters' settling        rate filter (6)
 *   8     P's hold and low-pass (its mean every 10th      P (1)
 *         block: that block carries nothing else); on     P_f (8, last block)
 *         the nine blocks between, one job each, in
 *         order: the thermometer checks of the new P_f,
 *         the compensation's filters' step, the slew of   P_f (8, last blocks)
 *         a window that ended, the shadow in five parts
 *         (rate_valid.h), the compensation's refresh
 *         (bias and scale factor of the filters' new
 *         state); the self-test sequence while it runs    projection (5)
 *   9     rate-valid verdict, rate half of the output     checks (2, 6, 7), rails (5),
 *         snapshot, analog rate code (the fault level     everything
 *         when not valid)
 *
 * Force rebalance (sense.mode 1, sense_fr.h) adds one step of its update to the start of
 * five jobs, in order: on slot 6 (before the rate's filter) it takes the block's
 * projection as the residual and gives the rate channel the loop's readout g (I + Kr R)
 * in its place; on 7 the PI; on 8 the force's limit; the force's phasor to the synthesis
 * in four steps, one long operation on each tick: on 9 |F| (a square root; F with the
 * continuous self-test's force on its Coriolis axis, selftest.h), on 0 the root
 * of F (another), on 1 the voltage phasor in the force's frame (a divide), on 2 the
 * feedback synthesis (drive_synth_set_phasor on its own instance: the frame's phase and
 * its turn of the phasor, a table lookup; no arc tangent), whose waveform goes out
 * every tick from the next on, on the feedback pair's two channels; on 4, a block after
 * the limit, the settling test (the SENSE_FR reason the verdict of 9 reads). The force
 * thus follows the block's mean by (GYRO_BLOCK - 1) / 2 + 9 ticks, plus half a block of
 * hold (gyro_design.c).
 *
 * The drive command thus reaches the DAC (COMMAND + 1 - slot) ticks after the sample
 * the loop measured: 4 for the phase loop, 2 for the amplitude loop; gyro_design adds
 * that to the loops' delay budget (drive_loop_design). */
#define GYRO_BLOCK RATE_DECIM
#define GYRO_SLOT_PHASE_MEAS 0u
#define GYRO_SLOT_PHASE_PI 1u
#define GYRO_SLOT_AMP 2u
#define GYRO_SLOT_COMMAND 3u
#define GYRO_SLOT_SUPERVISE 4u
#define GYRO_SLOT_PROJECT 5u
#define GYRO_SLOT_RATE 6u
#define GYRO_SLOT_QUAD 7u
#define GYRO_SLOT_P 8u
#define GYRO_SLOT_OUTPUT 9u
/* The force-rebalance steps (above): take, PI, limit, |F|, root, phasor, synthesis, settling. */
#define SENSE_FR_TAKE_SLOT GYRO_SLOT_RATE
#define SENSE_FR_SYNTH_SLOT GYRO_SLOT_AMP
_Static_assert(GYRO_SLOT_PHASE_MEAS < GYRO_SLOT_PHASE_PI &&
                   GYRO_SLOT_PHASE_PI < GYRO_SLOT_COMMAND && GYRO_SLOT_AMP < GYRO_SLOT_COMMAND &&
                   GYRO_SLOT_COMMAND < GYRO_SLOT_SUPERVISE &&
                   GYRO_SLOT_SUPERVISE < GYRO_SLOT_PROJECT && GYRO_SLOT_PROJECT < GYRO_SLOT_RATE &&
                   GYRO_SLOT_PROJECT < GYRO_SLOT_QUAD && GYRO_SLOT_PROJECT < GYRO_SLOT_P &&
                   GYRO_SLOT_AMP < GYRO_SLOT_QUAD && GYRO_SLOT_OUTPUT == GYRO_BLOCK - 1u,
               "block jobs out of order (gyro_slots.h slot table)");

#endif /* GYRO_SLOTS_H */
