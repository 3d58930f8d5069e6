/* The gyro: everything the 50 kHz tick runs, as one instance.
 *
 * gyro_tick() is the whole sample path, the same code on host and target:
 *   NCO -> LMSD(drive), LMSD(sense) -> drive loops -> drive synthesis -> rate channel
 *   -> supervisor -> outputs (DAC frame, telemetry snapshot)
 * with the loops, rate channel, supervisor and snapshot once per block (GYRO_BLOCK),
 * spread over the ticks of the block.
 * Deterministic, allocation-free, single precision, no libm.
 *
 * Phase conventions (used throughout firmware/gyro):
 *   The NCO phase phi(k) = 2 pi f_drive k / fs defines the reference frame. A pickoff
 *   voltage v = w_i sin(phi) + w_q cos(phi) (the LMSD's weights, (5-1)) is the phasor
 *   Z = w_i + j w_q, with v = Im{Z e^{j phi}}; its amplitude is |Z| and its phase
 *   arg(Z) = atan2(w_q, w_i).
 *   The drive force is F = f_cmd cos(phi + P) (in units of Ks * V^2): P is the force
 *   phase, the output of the phase loop and the temperature signal of the sensorless
 *   compensation (thesis 7.3). Half-frequency drive realises it with a voltage phase of
 *   P/2 (6-25), DC+AC drive with a voltage phase of P.
 */
#ifndef GYRO_H
#define GYRO_H

#include <stdint.h>

#include "gyro/gyro_design.h"
#include "gyro/gyro_state.h"
#include "hal/hal_adc.h"
#include "hal/hal_dac.h"

/* Initialise from a design (gyro_design), which must stay where it is while the gyro
 * runs with it (the parameter bank's derived block). Returns 0, or a negative value
 * with *g unchanged. Starts acquiring at once if sys.autostart. */
int gyro_init_from_design(gyro_t *g, const gyro_design_t *d);

/* Run with a new design (the ISR, at a tick boundary): from here on the sample path
 * reads d; the loop state carries on (bumpless). What a design change means beyond new
 * coefficients is done here, in one place (gyro.c): a re-acquisition on an amplitude
 * setpoint step, the thermometer moved with a phase setpoint step, the output filters
 * settling again after a change of the rate path, the drive scheme changing only with
 * the drive off, the NCO retuned only when the drive frequency changes. */
void gyro_apply(gyro_t *g, const gyro_design_t *d);

/* One sample: ADC frame in, DAC frame out. It reads the attached ADC frame
 * (gyro_attach_adc_frame: the HAL's, where the converters leave it) and writes the
 * attached DAC frame (gyro_attach_dac_frame), which the caller hands to the HAL after
 * the tick (latched at the next tick). A channel
 * is written when its value changes, so the frame is the same one from tick to tick (the
 * application's, at mid-scale, 0 V, from its start): the drive pair and the spare's
 * self-test force every tick, the rate output once per block (GYRO_SLOT_PHASE_MEAS), the
 * quadrature-nulling electrodes HAL_DAC_QUADNULL_V1, _V2 on the loop's updates (once per
 * RATE_P_DECIM ticks) and when it stops, the feedback pair's second channel with force
 * rebalance; the tuning electrodes (HAL_DAC_TUNE) by the sweep's jobs and, outside SWEEP,
 * by gyro_set_tune only. */
void gyro_tick(gyro_t *g);

/* The frame every tick reads: the HAL's (hal_adc_frame), read once at the start of each
 * tick. NULL: none (the codes read 0). */
void gyro_attach_adc_frame(gyro_t *g, const volatile hal_adc_frame_t *frame);

/* The frame every tick writes (the application's, which it hands to the HAL). NULL:
 * none (the codes go nowhere). */
void gyro_attach_dac_frame(gyro_t *g, hal_dac_frame_t *frame);

/* The HAL's count of lost samples (hal_sample_lost_counter), read once per block: a
 * change is a LOST_SAMPLE fault. NULL: none. */
void gyro_attach_lost_counter(gyro_t *g, const volatile uint32_t *count);

/* Mode tuning (sense.tune, sense_tune.h): the tuning electrodes' DAC code and the
 * verdict (RATE_INVALID_TUNE or 0), from the application's request (ISR, at a tick
 * boundary; the background computes both). Outside SWEEP the code goes to the frame's
 * tuning channel; in SWEEP the sweep's jobs own that channel and only the verdict is
 * taken. A code beyond the converter's is ignored. */
void gyro_set_tune(gyro_t *g, uint16_t code, uint32_t bits);

/* The board thermometer's verdict (RATE_INVALID_BOARD_TEMP or 0, board_therm.h), from
 * the application's request (ISR, at a tick boundary). */
void gyro_set_board(gyro_t *g, uint32_t bits);

void gyro_start(gyro_t *g);
void gyro_stop(gyro_t *g);

/* Enter SWEEP (from any mode): loops off and cleared, the self-calibration jobs
 * (selfcal_exec.h) drive the electrodes and the NCO frequency. */
void gyro_sweep_begin(gyro_t *g);
/* SWEEP -> ACQUIRE with the design d (already applied): the NCO goes to d's frequency
 * and both PIs start from the excitation the sweep ended with (bumpless). Returns 0,
 * or -1 (nothing changed) when not in SWEEP. */
int gyro_sweep_handover(gyro_t *g, const gyro_design_t *d);

#endif /* GYRO_H */
