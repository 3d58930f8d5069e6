/* The gyro: everything the 50 kHz tick runs, as one instance.
 *
 * gyro_tick() is the whole sample path (architecture.md), the same code on host and
 * target:
 *   NCO -> LMSD(drive), LMSD(sense) -> drive loops -> drive synthesis -> rate channel
 *   -> supervisor -> outputs (DAC frame, telemetry snapshot)
 * with the loops, rate channel, supervisor and snapshot once per block (GYRO_BLOCK).
 * Deterministic, allocation-free, single precision, no libm.
 *
 * Phase conventions (used throughout firmware/gyro):
 *   The NCO phase phi(k) = 2 pi f_drive k / fs defines the reference frame. A pickoff
 *   voltage v = w_s sin(phi) + w_c cos(phi) (the LMSD weights, (5-1)) is the phasor
 *   Z = w_s + j w_c, with v = Im{Z e^{j phi}}; its amplitude is |Z| and its phase
 *   arg(Z) = atan2(w_c, w_s).
 *   The drive force is F = f_cmd cos(phi + P) (in units of Ks * V^2): P is the force
 *   phase, the output of the phase loop and the temperature signal of the sensorless
 *   compensation (thesis 7.3). Half-frequency drive realises it with a voltage phase of
 *   P/2 (6-25), DC+AC drive with a voltage phase of P.
 */
#ifndef GYRO_H
#define GYRO_H

#include <stdint.h>

#include "dsp/biquad.h"
#include "dsp/lmsd.h"
#include "dsp/nco.h"
#include "gyro/drive_loop.h"
#include "gyro/drive_synth.h"
#include "gyro/rate_channel.h"
#include "gyro/selfcal_exec.h"
#include "gyro/selftest.h"
#include "gyro/supervisor.h"
#include "hal/hal_adc.h"
#include "hal/hal_dac.h"
#include "params/params.h"

/* Everything the parameters turn into (background, double-precision design): the
 * derived block of the parameter bank, applied by the ISR at a tick boundary. */
typedef struct {
  float fs_hz;
  nco_cfg_t nco;
  uint32_t nco_half_step;
  lmsd_cfg_t lmsd_drive, lmsd_sense;
  drive_loop_cfg_t drive;
  drive_synth_cfg_t synth;
  rate_channel_cfg_t rate;
  biquad_coeffs_t rate_lpf[BIQUAD_MAX_SECTIONS];
  supervisor_cfg_t sup;
  drive_loop_design_out_t amp_design, phase_design; /* what the designer achieved */
  float rate_out_v_per_dps;
  uint32_t autostart;
  selftest_cfg_t selftest;
} gyro_design_t;

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
} gyro_out_t;

#define GYRO_FLAG_LOCKED (1u << 0)
#define GYRO_FLAG_ADC_RAIL (1u << 1)
#define GYRO_FLAG_DRIVE_LIMIT (1u << 2)
#define GYRO_FLAG_FAULT (1u << 3)
#define GYRO_FLAG_SELFTEST (1u << 4) /* the self-test force is on: rate output not valid */

typedef struct {
  float adc_v_per_code;
  float rate_out_v_per_dps;
  nco_t nco;
  lmsd_t lmsd_drive, lmsd_sense;
  drive_loop_t drive;
  drive_synth_t synth;
  rate_channel_t rate;
  supervisor_t sup;
  selfcal_exec_t cal; /* self-calibration jobs, run while the supervisor is in SWEEP */
  float f_cmd_max_v2;
  float inv_amp_set;     /* 1 / drive amplitude setpoint: no divide per tick */
  uint32_t slot;         /* tick within the block, 0 .. GYRO_BLOCK - 1 */
  uint32_t clip_run;     /* consecutive ADC rail codes up to this tick */
  uint32_t clip_run_max; /* longest run reaching into the current supervisor period */
  uint32_t flags_acc;    /* GYRO_FLAG_* seen since the last snapshot */
  uint16_t rate_code;    /* analog rate output DAC code, updated with the snapshot */
  selftest_t selftest;
  gyro_out_t out;        /* updated once per block (tick: every tick) */
} gyro_t;

/* The block: GYRO_BLOCK ticks (the rate channel's RATE_DECIM, 0.2 ms at 50 kHz). Per
 * tick only what moves with the carrier runs: the NCO, both LMSDs, the sum of the sense
 * phasor, the drive waveform and the self-test force, the rail count and the DAC frame.
 * Everything else (the drive loops and their square root and arctangent, the
 * supervisor and the finiteness check, the rate channel's projection, filters and
 * compensation, the output snapshot) runs once per block, each job on its own tick of
 * the block so that the worst tick carries one job: the interrupt's budget is set by
 * its worst tick (tools/bench/README.md). */
#define GYRO_BLOCK RATE_DECIM
#define GYRO_SLOT_DRIVE_AMP 0u   /* |Z|, amplitude PI, drive command */
#define GYRO_SLOT_DRIVE_PHASE 1u /* arg Z, phase PI, drive command */
#define GYRO_SLOT_SUPERVISE 3u   /* supervisor, finiteness check */
#define GYRO_SLOT_RATE 5u        /* projection, rate filter, compensation, self-test */
#define GYRO_SLOT_QUAD 7u        /* quadrature filter, P's low-pass */
#define GYRO_SLOT_OUTPUT 8u      /* snapshot, analog rate code */

/* Turn parameter values into module configurations, checking that every module
 * accepts its part. Returns 0, or a negative value (then *d is untouched). */
int gyro_design(const param_values_t *v, gyro_design_t *d);

/* Initialise from a design / from parameter values. Returns 0, or a negative value with
 * *g unchanged. Starts acquiring at once if sys.autostart. */
int gyro_init_from_design(gyro_t *g, const gyro_design_t *d);
int gyro_init(gyro_t *g, const param_values_t *v);

/* Apply a new design in the ISR at a tick boundary: coefficients change, loop state
 * carries on (bumpless). The drive scheme changes only while the drive is off. */
void gyro_apply(gyro_t *g, const gyro_design_t *d);

/* One sample: ADC frame in, DAC frame out (latched by the HAL at the next tick). */
void gyro_tick(gyro_t *g, const hal_adc_frame_t *adc, hal_dac_frame_t *dac);

void gyro_start(gyro_t *g);
void gyro_stop(gyro_t *g);

/* Enter SWEEP (from any mode): loops off and cleared, the self-calibration jobs
 * (selfcal_exec.h) drive the electrodes and the NCO frequency. */
void gyro_sweep_begin(gyro_t *g);
/* SWEEP -> ACQUIRE with the design d (already applied): the NCO goes to d's frequency
 * and both PIs start from the excitation the sweep ended with (bumpless). Returns 0,
 * or -1 (nothing changed) when not in SWEEP. */
int gyro_sweep_handover(gyro_t *g, const gyro_design_t *d);

/* Volts to an offset-binary DAC code, clamped to the converter's range. */
uint16_t gyro_volts_to_dac(float v);

#endif /* GYRO_H */
