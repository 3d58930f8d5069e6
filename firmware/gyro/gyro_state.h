/* The gyro's state: what the sample path remembers between ticks, and its output
 * snapshot. The sample path's jobs (gyro_block.h) and the gyro's interface
 * (gyro.h) both build on this; neither needs the other's header. The block's slot table
 * is gyro_slots.h, the DAC conversion gyro_dac.h.
 */
#ifndef GYRO_STATE_H
#define GYRO_STATE_H

#include <stdint.h>
#include <string.h>

#include "dsp/lmsd.h"
#include "dsp/nco.h"
#include "gyro/drive_loop.h"
#include "gyro/drive_synth.h"
#include "gyro/drive_track.h"
#include "gyro/gyro_dac.h"
#include "gyro/gyro_design.h"
#include "gyro/gyro_slots.h"
#include "gyro/quad_null.h"
#include "gyro/rate_channel.h"
#include "gyro/rate_valid.h"
#include "gyro/selfcal_exec.h"
#include "gyro/selftest.h"
#include "gyro/sense_fr.h"
#include "gyro/supervisor.h"
#include "hal/hal_adc.h"
#include "hal/hal_dac.h"

/* gyro_t.rate_clear_due: what is still to be cleared on the coming rate slots. */
#define GYRO_RATE_CLEAR_CHANNEL 1u /* the rate channel (P_f from the reference) */
#define GYRO_RATE_CLEAR_RESTART 2u /* the validity checks' thermometer state, then that */

/* A snapshot of the outputs of the latest tick (telemetry, status, the simulator). */
typedef struct {
  uint32_t tick;
  float rate_dps;             /* compensated, filtered rate */
  float rate_unc_dps;         /* before temperature compensation */
  float quad_dps;             /* quadrature, equivalent rate */
  float drive_amp_v;          /* demodulated drive pickoff amplitude */
  float drive_phase_deg;      /* arg of the drive phasor */
  float p_deg;                /* temperature signal: P, or its equivalent from f (tracking) */
  float p_f_deg;              /* P low-passed (what the compensation uses) */
  float f_cmd_v2;             /* drive force command */
  float u1_v, u2_v;           /* drive electrode voltages written this tick */
  float sense_i_v, sense_q_v; /* sense LMSD phasor */
  uint32_t mode;              /* gyro_mode_t */
  uint32_t fault;             /* gyro_fault_t bits of the last fault */
  uint32_t flags;             /* GYRO_FLAG_* */
  uint32_t rate_invalid;      /* RATE_INVALID_* reasons of this block (0: valid) */
  float rate_out_v;           /* voltage commanded on the analog rate output this block */
  uint32_t rate_valid; /* 1 when the rate output can be trusted (output integrity), else 0 */
  float f_drive_hz;    /* drive (NCO) frequency: the tracked resonance in tracking mode */
  float board_c;       /* board sensor's latest reading, NaN before one (the background's) */
} gyro_out_t;

#define GYRO_FLAG_LOCKED (1u << 0)
#define GYRO_FLAG_ADC_RAIL (1u << 1)
#define GYRO_FLAG_DRIVE_LIMIT (1u << 2)
#define GYRO_FLAG_FAULT (1u << 3)
#define GYRO_FLAG_SELFTEST (1u << 4)    /* the self-test force is on: rate output not valid */
#define GYRO_FLAG_RATE_VALID (1u << 5)  /* the rate output can be trusted (rate_valid.h) */
#define GYRO_FLAG_OVER_RANGE (1u << 6)  /* rate magnitude above rate.full_scale_dps */
#define GYRO_FLAG_SENSE_RANGE (1u << 7) /* sense pickoff near the ADC's range (warning) */
#define GYRO_FLAG_UNCALIBRATED \
  (1u << 8) /* no calibration, or a stale one: status `calibrated` */

struct gyro_s;
/* A step of the quadrature-nulling loop's update (gyro_block_quad_null). */
typedef void (*gyro_quad_step_t)(struct gyro_s *g);

typedef struct gyro_s {
  /* The design the sample path runs with: the parameter bank's published block, whole
   * (gyro_apply swaps it at a tick boundary). Every module's configuration is read
   * through it; what follows is what the modules remember. */
  const gyro_design_t *design;
  float adc_v_per_code;
  nco_t nco; /* its step is the drive's own: set from the design at the start
                          * and when the drive frequency changes, moved by the sweep */
  lmsd_t lmsd_drive, lmsd_sense;
  drive_loop_t drive;
  drive_track_t track; /* the tracking drive's PLL (design->track 1) */
  drive_synth_t synth;
  rate_channel_t rate;
  supervisor_t sup;
  uint32_t slot;       /* tick within the block, 0 .. GYRO_BLOCK - 1 */
  uint32_t clip_count; /* ADC rail codes since the block's projection (slot 5) */
  uint32_t clip_block; /* rail codes over the ticks of the latest projected block */
  uint32_t clip_drive_count, clip_drive_block; /* the same, drive channel only */
  const volatile uint32_t *lost_count;         /* the HAL's count of lost samples */
  uint32_t lost_seen;                          /* its value at the last block */
  uint32_t cont_fail;        /* the continuous self-test's verdict (GYRO_SLOT_PHASE_PI) */
  uint32_t quad_bits;        /* RATE_INVALID_QUAD_NULL while nulling is on and not settled */
  gyro_quad_step_t quad_job; /* the nulling loop's next step (GYRO_SLOT_COMMAND), or NULL */
  uint32_t fr_on;   /* force rebalance (the design's sense_mode 1): its steps and waveform */
  uint32_t fr_bits; /* RATE_INVALID_SENSE_FR while it is on and not balanced */
  /* The background's verdicts, each set by its request at a tick boundary:
   * RATE_INVALID_TUNE while mode tuning is on and not at its target (app_tune.c,
   * sense_tune.h; with the tuning voltage by gyro_set_tune), RATE_INVALID_BOARD_TEMP
   * while the board thermometer weighs in and is not trusted (app_board.c,
   * board_therm.h; gyro_set_board) */
  uint32_t bg_bits;
  float fb_off_v; /* what the board adds to the feedback converters' voltages (design) */
  uint32_t rate_clear_due; /* the loop-state clear's rate half is due (GYRO_SLOT_RATE; a
                            * fault's clear, a start from OFF): GYRO_RATE_CLEAR_RESTART,
                            * the validity checks' on one slot, then CHANNEL on the next */
  uint32_t flags_acc;      /* GYRO_FLAG_* seen since the last snapshot */
  supervisor_in_t sup_in;  /* the supervisor's evidence, gathered by the jobs before
                           * GYRO_SLOT_SUPERVISE (slot table above) */
  uint32_t weights_finite; /* first half of the finiteness check (GYRO_SLOT_AMP) */
  uint16_t rate_code;      /* analog rate output DAC code, updated with the snapshot */
  selftest_t selftest;
  gyro_out_t out; /* updated once per block (tick: every tick) */
  /* Last, so that what the sample path reads every block stays within the reach of
   * one load's immediate offset. */
  rate_valid_t valid; /* the rate-valid verdict and its monitors (once per block) */
  selfcal_exec_t cal; /* self-calibration jobs, run while the supervisor is in SWEEP */
  rate_valid_history_t valid_history; /* onsets of the reasons, for `status` */
  /* The quadrature-nulling loop (quad.null 1), one update per RATE_P_DECIM ticks cut into
   * steps over the blocks (quad_job, gyro_block.h); its electrodes' codes go into the
   * attached frame (gyro_attach_dac_frame) on each update and when it stops. */
  quad_null_t quad;
  hal_dac_frame_t *dac_frame; /* the frame every tick writes (the application's) */
  const volatile hal_adc_frame_t *adc_frame; /* the frame every tick reads (the HAL's) */
  /* Force rebalance (sense.mode 1, sense_fr.h): the loop, one update per block in steps
   * (gyro_slots.h), and the synthesis of its force on the feedback pair (every tick). */
  drive_synth_t fb_synth;
  drive_synth_phasor_t fb_root; /* the force's root, for the synthesis a block later */
  sense_fr_t fr;
  /* The board thermometer's correction of the compensation's bias (board_therm.h),
   * written whole by the background (app_board.c), read by the sample path when it
   * refreshes the compensation; last, as it is read once per P update only. */
  volatile float board_corr_dps;
  float board_corr_applied_dps; /* the one in rate.comp_bias_dps now */
} gyro_t;

#endif /* GYRO_STATE_H */
