/* AD5554 quad 14-bit DAC on SPI2 (PB13 SCK, PB15 MOSI, 21 MHz, mode 0: data clocked in
 * on the rising CLK edge), word = A1 A0 D13..D0 (channel address, offset-binary code),
 * sent every tick in hardware:
 *
 *   TIM8 one-pulse mode, repetition counter 3 -> exactly four 1.25 us slots, then stops;
 *     started (trigger mode, ITR2) by TIM4's TRGO at the DAC start time of the sample
 *     chain (stm32f4_sample.h), so the slots end just before the next LDAC.
 *     CH1 PC6 -> AD5554 CS: high for the first 95 ns of a slot, low for the rest; the
 *                rising edge at the slot boundary loads the word into the channel's
 *                input register.
 *     CC1 event (CS falling) -> DMA2 stream 2 (channel 7, circular over the four words)
 *                writes the slot's word into SPI2_DR: 16 clocks in 762 ns, done before
 *                CS rises again.
 *   The words wait in the input registers until LDAC (TIM1 CH2, stm32f4_sample.h)
 *   moves all four to the outputs at the start of the next tick.
 * hal_dac_write_frame only stores the four words in RAM (if it is not too late for this
 * tick's slots). Each word carries its channel's address, so every slot is
 * self-describing; until the first frame the words are mid-scale (0 V). */
#ifndef STM32F4_DAC_H
#define STM32F4_DAC_H

#include <stdint.h>

#include "hal/hal_dac.h"

#define STM32F4_DAC_SLOT_TICKS 210u   /* 1.25 us at 168 MHz */
#define STM32F4_DAC_CS_HIGH_TICKS 16u /* 95 ns CS high between words */

/* Configure SPI2, DMA2 stream 2 (enabled, waiting for TIM8) and TIM8 (waiting for its
 * trigger). Call once before the sample chain starts. */
void stm32f4_dac_init(void);

/* AD5554 input word for one channel: address in bits 15..14, code clamped to 14 bits. */
static inline uint16_t stm32f4_dac_word(uint32_t channel, uint16_t code)
{
  const uint16_t c = code > HAL_DAC_CODE_MAX ? (uint16_t)HAL_DAC_CODE_MAX : code;
  return (uint16_t)(((channel & 3u) << 14) | c);
}

/* Latest TIM1 count at which a frame may still be written for this tick's slots (set by
 * the sample chain). A frame written later is dropped and counted: the slots send the
 * previous frame again, so the outputs hold it one tick longer instead of taking half
 * of the new frame now and half at the next tick. */
void stm32f4_dac_set_deadline(uint32_t tim1_count);
uint32_t stm32f4_dac_late(void);

#ifdef STM32F4_HOST_TEST
/* The four words DMA stream 2 sends every tick (see stm32f4_sample_host_rx for why). */
volatile uint16_t *stm32f4_dac_host_words(void);
#endif

#endif /* STM32F4_DAC_H */
