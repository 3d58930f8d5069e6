/* The gyro's state: what the sample path remembers between ticks, the block and its
 * slot table, the output snapshot and the DAC conversion. The sample path's jobs
 * (gyro_block.h) and the gyro's interface (gyro.h) both build on this; neither needs
 * the other's header.
 */
#ifndef GYRO_STATE_H
#define GYRO_STATE_H

#include <stdint.h>
#include <string.h>

#include "dsp/lmsd.h"
#include "dsp/nco.h"
#include "gyro/drive_loop.h"
#include "gyro/drive_synth.h"
#include "gyro/gyro_design.h"
#include "gyro/rate_channel.h"
#include "gyro/rate_valid.h"
#include "gyro/selfcal_exec.h"
#include "gyro/selftest.h"
#include "gyro/supervisor.h"
#include "hal/hal_adc.h"
#include "hal/hal_dac.h"

/* A snapshot of the outputs of the latest tick (telemetry, status, the simulator). */
typedef struct {
  uint32_t tick;
  float rate_dps;        /* compensated, filtered rate */
  float rate_unc_dps;    /* before temperature compensation */
  float quad_dps;        /* quadrature, equivalent rate */
  float drive_amp_v;     /* demodulated drive pickoff amplitude */
  float drive_phase_deg; /* arg of the drive phasor */
  float p_deg;           /* force phase P: the temperature signal */
  float p_f_deg;         /* P low-passed (what the compensation uses) */
  float f_cmd_v2;        /* drive force command */
  float u1_v, u2_v;      /* drive electrode voltages written this tick */
  float sense_i_v, sense_q_v; /* sense LMSD phasor */
  uint32_t mode;         /* gyro_mode_t */
  uint32_t fault;        /* gyro_fault_t bits of the last fault */
  uint32_t flags;        /* GYRO_FLAG_* */
  uint32_t rate_invalid; /* RATE_INVALID_* reasons of this block (0: valid) */
  float rate_out_v;      /* voltage commanded on the analog rate output this block */
  uint32_t rate_valid;   /* 1 when the rate output can be trusted (output integrity), else 0 */
} gyro_out_t;

#define GYRO_FLAG_LOCKED (1u << 0)
#define GYRO_FLAG_ADC_RAIL (1u << 1)
#define GYRO_FLAG_DRIVE_LIMIT (1u << 2)
#define GYRO_FLAG_FAULT (1u << 3)
#define GYRO_FLAG_SELFTEST (1u << 4) /* the self-test force is on: rate output not valid */
#define GYRO_FLAG_RATE_VALID (1u << 5) /* the rate output can be trusted (rate_valid.h) */
#define GYRO_FLAG_OVER_RANGE (1u << 6) /* rate magnitude above rate.full_scale_dps */
#define GYRO_FLAG_SENSE_RANGE (1u << 7) /* sense pickoff near the ADC's range (warning) */

typedef struct {
  /* The design the sample path runs with: the parameter bank's published block, whole
   * (gyro_apply swaps it at a tick boundary). Every module's configuration is read
   * through it; what follows is what the modules remember. */
  const gyro_design_t *design;
  float adc_v_per_code;
  nco_t nco;             /* its step is the drive's own: set from the design at the start
                          * and when the drive frequency changes, moved by the sweep */
  lmsd_t lmsd_drive, lmsd_sense;
  drive_loop_t drive;
  drive_synth_t synth;
  rate_channel_t rate;
  supervisor_t sup;
  uint32_t slot;         /* tick within the block, 0 .. GYRO_BLOCK - 1 */
  uint32_t clip_count;   /* ADC rail codes since the block's projection (slot 5) */
  uint32_t clip_block;   /* rail codes over the ticks of the latest projected block */
  uint32_t clip_drive_count, clip_drive_block; /* the same, drive channel only */
  const volatile uint32_t *lost_count; /* the HAL's count of lost samples */
  uint32_t lost_seen;    /* its value at the last block */
  uint32_t cont_fail;    /* the continuous self-test's verdict (GYRO_SLOT_P) */
  uint32_t rate_clear_due; /* the loop-state clear's rate-channel half is due (GYRO_SLOT_RATE) */
  uint32_t flags_acc;    /* GYRO_FLAG_* seen since the last snapshot */
  supervisor_in_t sup_in; /* the supervisor's evidence, gathered by the jobs before
                           * GYRO_SLOT_SUPERVISE (slot table above) */
  uint32_t weights_finite; /* first half of the finiteness check (GYRO_SLOT_AMP) */
  uint16_t rate_code;    /* analog rate output DAC code, updated with the snapshot */
  selftest_t selftest;
  gyro_out_t out;        /* updated once per block (tick: every tick) */
  /* Last, so that what the sample path reads every block stays within the reach of
   * one load's immediate offset. */
  rate_valid_t valid;    /* the rate-valid verdict and its monitors (once per block) */
  selfcal_exec_t cal; /* self-calibration jobs, run while the supervisor is in SWEEP */
  rate_valid_history_t valid_history; /* onsets of the reasons, for `status` */
} gyro_t;

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
 *         of the output snapshot                          drive loop (1, 2, last block)
 *   1     phase loop: wrapped error, PI -> P (P held      arg Z (0), |Z| (2, last block)
 *         while |Z| < 10 % of its setpoint; a whole
 *         turn of P passed on to the thermometer); the
 *         continuous self-test's verdict                  its LMS (6, 7, last block)
 *   2     finiteness check, first half (LMSD weights);    drive LMSD
 *         |Z| (square root), amplitude PI -> f_cmd;
 *         rate-valid drive-phase and sense-range checks   phase error (4), quad (7), sense LMSD
 *   3     the supervisor's evidence (sup_in);             |Z|, f_cmd (2), phase error (1)
 *         drive_synth_set(f_cmd, P): the waveform's       f_cmd (2), P (1)
 *         amplitude (square root) and phase offset
 *   4     supervisor (its clear request: slot 5)          evidence (3), finiteness (7, last block)
 *   5     rate channel: block mean of S, projection       sense sum, P (1)
 *         (or, on request, the loop state cleared);
 *         the block's rail codes; the continuous
 *         self-test's modulation
 *   6     the continuous self-test's notch (rate axis);   projection (5), modulation (5)
 *         rate: output filter, scale, compensation;       P_f (8, last block)
 *         its range check (or, after a clear, the rate
 *         channel's reset)
 *   7     finiteness check, second half (loop and rate    weights' half (2)
 *         outputs) and verdict; the continuous            projection (5)
 *         self-test's notch (quadrature axis),
 *         quadrature filter; the filters' settling        rate filter (6)
 *   8     P's hold and low-pass (its mean every 10th      P (1)
 *         block), the thermometer checks of the P_f       P_f (8, last block)
 *         made the block before, the slew of a window     P_f (8, last blocks)
 *         that ended the block before that; the self-
 *         test sequence while it runs                     projection (5)
 *   9     rate-valid verdict, rate half of the output     checks (2, 6, 7), rails (5),
 *         snapshot, analog rate code (the fault level     everything
 *         when not valid)
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
_Static_assert(GYRO_SLOT_PHASE_MEAS < GYRO_SLOT_PHASE_PI && GYRO_SLOT_PHASE_PI < GYRO_SLOT_COMMAND &&
                   GYRO_SLOT_AMP < GYRO_SLOT_COMMAND && GYRO_SLOT_COMMAND < GYRO_SLOT_SUPERVISE &&
                   GYRO_SLOT_SUPERVISE < GYRO_SLOT_PROJECT && GYRO_SLOT_PROJECT < GYRO_SLOT_RATE &&
                   GYRO_SLOT_PROJECT < GYRO_SLOT_QUAD && GYRO_SLOT_PROJECT < GYRO_SLOT_P &&
                   GYRO_SLOT_AMP < GYRO_SLOT_QUAD && GYRO_SLOT_OUTPUT == GYRO_BLOCK - 1u,
               "block jobs out of order (gyro_state.h slot table)");

/* Volts to an offset-binary DAC code, rounded to the nearest code (ties to even) and
 * clamped to the converter's range; NaN gives the mid code (0 V).
 * Per sample, for three channels, so without float compares (each a VCMP, a VMRS and a
 * branch on the FPv4-SP, which has no VMIN/VMAX): adding 1.5 * 2^23 to the code makes
 * the float adder round it to an integer (the sum's unit in the last place is 1 for
 * sums in [2^23, 2^24)) and leaves it in the low mantissa bits: in range, the code is
 * the sum's bit pattern less that of 1.5 * 2^23, and one unsigned compare tells that it
 * is in range. Outside, the bit pattern of a float grows with its value while the sign
 * is clear: below 1.5 * 2^23 or negative is code 0, above is the largest code
 * (infinity included). IEEE 754 single precision with round-to-nearest, the same on
 * host and target. */
#if defined(__GNUC__)
#define GYRO_UNLIKELY(x) __builtin_expect((x) != 0, 0) /* block layout only */
#else
#define GYRO_UNLIKELY(x) ((x) != 0)
#endif
#define GYRO_DAC_ROUND_F 12582912.0f    /* 1.5 * 2^23 */
#define GYRO_DAC_ROUND_BITS 0x4B400000u /* its bit pattern */
static inline uint16_t gyro_volts_to_dac(float v)
{
  const float m = v * (1.0f / HAL_DAC_V_PER_CODE) + ((float)HAL_DAC_CODE_MID + GYRO_DAC_ROUND_F);
  uint32_t u;
  memcpy(&u, &m, sizeof u);
  uint32_t code = u - GYRO_DAC_ROUND_BITS;
  if (GYRO_UNLIKELY(code > HAL_DAC_CODE_MAX)) {
    if ((u << 1) > 0xFF000000u) { /* exponent all ones, mantissa not zero: NaN */
      code = HAL_DAC_CODE_MID;
    } else {
      code = (u & 0x80000000u) != 0u || u < GYRO_DAC_ROUND_BITS ? 0u : HAL_DAC_CODE_MAX;
    }
  }
  return (uint16_t)code;
}

#endif /* GYRO_STATE_H */
