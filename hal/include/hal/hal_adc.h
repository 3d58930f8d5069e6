/* ADC frame of one sample tick: the drive and sense pickoff conversions. */
#ifndef HAL_ADC_H
#define HAL_ADC_H

#include <stdint.h>
#include "board.h" /* the build's board: HAL_ADC_* scaling */

typedef struct {
  int16_t drive; /* drive-axis pickoff, ADC code */
  int16_t sense; /* sense-axis pickoff, ADC code */
} hal_adc_frame_t;

/* The frame converted at the most recent sample tick. Called from the sample ISR only;
 * never blocks (the conversion was started by the timer and moved by DMA). */
void hal_adc_read_frame(hal_adc_frame_t *frame);

#endif /* HAL_ADC_H */
