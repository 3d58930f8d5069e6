/* See bench_isr_board.h. The board source is included, not copied: the bench counts
 * exactly the code the product image runs. */
#include "bench_isr_board.h"

#include "stm32f4_regs.h"

stm32f4_dma_t bench_fake_dma2;
#undef DMA2
#define DMA2 (&bench_fake_dma2)

#include "stm32f4_sample.c"

void bench_board_set_frame(const hal_adc_frame_t *frame)
{
  s_adc_rx.code[0] = frame->drive;
  s_adc_rx.code[1] = frame->sense;
}

void bench_board_arm(void) { bench_fake_dma2.LISR = DMA_FLAG_TCIF; /* stream 0: shift 0 */ }

/* In SRAM: bench_cb calls it from there (bench_main.c). */
CM4_RAMFUNC void bench_board_clear_tc(void) { bench_fake_dma2.LISR = 0u; }
