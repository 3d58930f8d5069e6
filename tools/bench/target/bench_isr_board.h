/* The board's sample interrupt path (hal/boards/ref_f405/stm32f4_sample.c, compiled unchanged
 * into the bench image) with its DMA controller replaced by a register block in RAM that
 * the bench sets as the hardware would leave it at the transfer-complete interrupt.
 *
 * QEMU's netduinoplus2 has no DMA model (reads 0, writes ignored), so the handler would
 * see no transfer-complete flag and return at once. The one other register the handler
 * and the HAL calls touch, TIM1's counter, is left to QEMU: it reads 0 there, which is
 * the normal path of hal_dac_write_frame (before the deadline). Instruction counts are
 * unaffected by where a register lives; bus timing is, and is added in the cycle model. */
#ifndef BENCH_ISR_BOARD_H
#define BENCH_ISR_BOARD_H

#include "hal/hal_adc.h"

/* Play the ADC DMA: the frame the next interrupt reads (hal_adc_frame). */
void bench_board_set_frame(const hal_adc_frame_t *frame);

/* State at the transfer-complete interrupt: stream 0 TCIF set. */
void bench_board_arm(void);

/* The handler's write to LIFCR would clear TCIF on the chip; in RAM it does not, so the
 * bench's ISR callback clears it (its cost is measured and subtracted). */
void bench_board_clear_tc(void);

#endif /* BENCH_ISR_BOARD_H */
