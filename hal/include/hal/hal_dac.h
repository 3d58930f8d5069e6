/* DAC frame of one sample tick: the four channel codes, latched at the next tick
 * (one-sample latency, zero-order hold). */
#ifndef HAL_DAC_H
#define HAL_DAC_H

#include <stdint.h>
#include "board.h" /* the build's board: HAL_DAC_CODE_* scaling */

/* What each DAC channel is for: the firmware writes them by role. */
enum hal_dac_channel {
  HAL_DAC_DRIVE_U1 = 0, /* drive electrode U1 */
  HAL_DAC_DRIVE_U2 = 1, /* drive electrode U2 */
  HAL_DAC_RATE_OUT = 2, /* analog rate output */
  HAL_DAC_SPARE = 3,    /* sense feedback / self-test force */
  HAL_DAC_NUM_CHANNELS = 4
};

typedef struct {
  uint16_t code[HAL_DAC_NUM_CHANNELS]; /* offset binary, 0..HAL_DAC_CODE_MAX */
} hal_dac_frame_t;

/* Queue the frame for output at the next sample tick. Called from the sample ISR only;
 * never blocks. */
void hal_dac_write_frame(const hal_dac_frame_t *frame);

#endif /* HAL_DAC_H */
