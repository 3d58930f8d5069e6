/* The sample clock: a hardware timer starts both conversions and raises the sample
 * interrupt at fs. The ISR reads the ADC frame (hal_adc_frame), runs the tick and writes
 * the DAC frame. */
#ifndef HAL_SAMPLE_TIMER_H
#define HAL_SAMPLE_TIMER_H

#include <stdint.h>

typedef void (*hal_sample_isr_fn)(void *ctx);

/* Start the sample clock at rate_hz, calling isr(ctx) once per sample at the highest
 * interrupt priority. Returns 0, or a negative value if the rate cannot be made. */
int hal_sample_timer_start(uint32_t rate_hz, hal_sample_isr_fn isr, void *ctx);
void hal_sample_timer_stop(void);

/* Free-running cycle counter (DWT CYCCNT on the board). */
uint32_t hal_cycles_now(void);

/* The sample interrupt measured by the HAL itself, from the first instruction of its
 * handler to the return of isr(ctx): cycles of the latest interrupt and the worst since
 * hal_sample_timer_start. The board reads DWT CYCCNT inline; the host stub has no cycle
 * counter and reports 0. Either pointer may be NULL. */
void hal_sample_isr_cycles(uint32_t *last, uint32_t *max);

/* The count of samples lost since hal_sample_timer_start (a frame converted before the
 * ISR had taken the previous one: the NCO then runs a sample behind the converters), as
 * the address of the word the HAL counts them in. The firmware reads it once per block,
 * which costs the sample path nothing per tick. Never NULL. */
const volatile uint32_t *hal_sample_lost_counter(void);

#endif /* HAL_SAMPLE_TIMER_H */
