/* Host HAL stub: the sample clock, ADC and DAC of the board replaced by a plant model.
 *
 * The firmware registers its sample ISR with hal_sample_timer_start() exactly as on the
 * board; the host program attaches a plant and calls hal_host_run(). Each tick:
 *   1. the ISR runs: it reads the ADC frame sampled at t_n and writes a DAC frame;
 *   2. the plant integrates over [t_n, t_n+1] with the DAC frame that is on the
 *      converter outputs during that interval - the one written at the previous tick
 *      (one-sample latency, zero-order hold, as the board's LDAC at the next timer
 *      event) - and returns the ADC frame sampled at t_n+1;
 *   3. the frame just written becomes the output for the next interval.
 * No firmware code knows it runs on a host. The stub is single-threaded: the background
 * loop is called by the host program between ticks, so the critical-section calls are
 * no-ops here.
 *
 * The board temperature sensor (hal_board_temp.h) is a second, optional attachment
 * (hal_host_attach_board_temp): a callback that says what the sensor holds at the
 * simulated time hal_host_ticks() / hal_host_rate_hz(). hal_board_temp_poll returns each
 * of its results as NEW once (each missed one as FAULT once), NONE in between; with
 * nothing attached the board has no sensor (ABSENT).
 */
#ifndef HAL_HOST_H
#define HAL_HOST_H

#include <stdint.h>

#include "hal/hal_adc.h"
#include "hal/hal_board_temp.h"
#include "hal/hal_dac.h"

/* Advance the plant over one sample period with dac held; sample the ADC at its end. */
typedef void (*hal_host_plant_step_fn)(void *plant, const hal_dac_frame_t *dac,
                                       hal_adc_frame_t *adc);

/* Attach a plant. The DAC outputs start at mid-scale (0 V) and the first ADC frame is
 * the plant's response to one period of that. */
void hal_host_attach(hal_host_plant_step_fn step, void *plant);

/* Run n sample ticks (ISR + plant). Returns the number run (0 if no ISR or plant). */
uint64_t hal_host_run(uint64_t n);

/* Ticks run since attach; simulated time is ticks / rate_hz. */
uint64_t hal_host_ticks(void);
uint32_t hal_host_rate_hz(void);

/* The frame the firmware wrote at the latest tick (for traces). */
const hal_dac_frame_t *hal_host_last_dac(void);

/* The board temperature sensor at simulated time t_s: HAL_BOARD_TEMP_NEW with *code its
 * latest finished result and *conversion that result's number (1, 2, ... in order);
 * HAL_BOARD_TEMP_NONE before its first result; HAL_BOARD_TEMP_FAULT when it does not
 * answer, *conversion the number of the result that could not be read (the results go on
 * being counted); HAL_BOARD_TEMP_ABSENT when there is none. plant_board_temp_hal
 * (host_sim/plant/plant.h) has this shape. */
typedef hal_board_temp_event_t (*hal_host_board_temp_fn)(void *ctx, double t_s, int16_t *code,
                                                         uint64_t *conversion);

/* Attach the board temperature sensor (NULL: none, hal_board_temp_poll says ABSENT), and
 * forget which result was returned last. Attach it again, or NULL, before its context
 * goes away. */
void hal_host_attach_board_temp(hal_host_board_temp_fn fn, void *ctx);

/* Count one lost sample, as the board's converters report an overrun (hal_sample_lost). */
void hal_host_lose_sample(void);
/* The ADC frame the firmware will read at the next tick. */
const hal_adc_frame_t *hal_host_next_adc(void);

#endif /* HAL_HOST_H */
