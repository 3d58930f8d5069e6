/* DAC frame of one sample tick: every channel's code, latched at the next tick
 * (one-sample latency, zero-order hold).
 *
 * Channels 0..3 drive the gyro's drive comb, the analog rate output and the sense feedback
 * (self-test force); channels 4..7 the sense electrodes of issue 19's closed sense loop:
 * the second electrode of the feedback pair, the two quadrature-nulling sets and the
 * tuning electrodes. In the pair scheme (plant fb_mode 3) the spare channel is the pair's
 * first electrode, hence HAL_DAC_SENSE_FB_U1 == HAL_DAC_SPARE. The firmware writes every
 * channel every tick; a channel whose electrode the part does not have, or whose loop is
 * not running, sits at mid-scale (0 V). On the reference board channels 0..3 are one
 * AD5554 and 4..7 a second one, loaded in the same slots (hal/boards/ref_f405/README.md). */
#ifndef HAL_DAC_H
#define HAL_DAC_H

#include <stdint.h>
#include "board.h" /* the build's board: HAL_DAC_CODE_* scaling */

/* What each DAC channel is for: the firmware writes them by role. */
enum hal_dac_channel {
  HAL_DAC_DRIVE_U1 = 0,    /* drive electrode U1 */
  HAL_DAC_DRIVE_U2 = 1,    /* drive electrode U2 */
  HAL_DAC_RATE_OUT = 2,    /* analog rate output */
  HAL_DAC_SPARE = 3,       /* sense feedback / self-test force */
  HAL_DAC_SENSE_FB_U1 = 3, /* the same channel: feedback pair electrode U3 */
  HAL_DAC_SENSE_FB_U2 = 4, /* feedback pair electrode U4 (per-sample, AC) */
  HAL_DAC_QUADNULL_V1 = 5, /* quadrature-nulling set 1, V1 (DC) */
  HAL_DAC_QUADNULL_V2 = 6, /* quadrature-nulling set 2, V2 (DC) */
  HAL_DAC_TUNE = 7,        /* sense frequency-tuning electrodes, Vt (DC) */
  HAL_DAC_NUM_CHANNELS = 8
};

typedef struct {
  uint16_t code[HAL_DAC_NUM_CHANNELS]; /* offset binary, 0..HAL_DAC_CODE_MAX */
} hal_dac_frame_t;

/* Every channel at mid-scale (0 V): the frame of a part at rest. */
static inline void hal_dac_frame_midscale(hal_dac_frame_t *frame)
{
  for (int c = 0; c < HAL_DAC_NUM_CHANNELS; c++) frame->code[c] = (uint16_t)HAL_DAC_CODE_MID;
}

/* Queue the frame for output at the next sample tick. Called from the sample ISR only;
 * never blocks. */
void hal_dac_write_frame(const hal_dac_frame_t *frame);

#endif /* HAL_DAC_H */
