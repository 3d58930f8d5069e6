/* ADC frame of one sample tick: the drive and sense pickoff conversions. */
#ifndef HAL_ADC_H
#define HAL_ADC_H

#include <stdint.h>
#include "board.h" /* the build's board: HAL_ADC_* scaling */

typedef struct {
  int16_t drive; /* drive-axis pickoff, ADC code */
  int16_t sense; /* sense-axis pickoff, ADC code */
} hal_adc_frame_t;

/* Where the converters leave the frame of each sample tick: the one converted at the most
 * recent tick, for the sample ISR to read during its tick (the conversion was started by
 * the timer and moved by DMA; the next one replaces it at the next tick). The same
 * address for the life of the program, never NULL: the firmware takes it once and reads
 * the two codes at the start of each tick, without a call or a copy. */
const volatile hal_adc_frame_t *hal_adc_frame(void);

#endif /* HAL_ADC_H */
