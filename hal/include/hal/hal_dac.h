/* DAC frame of one sample tick: the four channel codes, latched at the next tick
 * (one-sample latency, zero-order hold). */
#ifndef HAL_DAC_H
#define HAL_DAC_H

#include <stdint.h>
#include "hal/hal_converters.h"

typedef struct {
  uint16_t code[HAL_DAC_NUM_CHANNELS]; /* offset binary, 0..HAL_DAC_CODE_MAX */
} hal_dac_frame_t;

/* Queue the frame for output at the next sample tick. Called from the sample ISR only;
 * never blocks. */
void hal_dac_write_frame(const hal_dac_frame_t *frame);

#endif /* HAL_DAC_H */
