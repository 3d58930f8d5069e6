/* AD5554 quad 14-bit DAC on SPI2 (PB13 SCK, PB15 MOSI, 21 MHz, mode 0: data clocked in
 * on the rising CLK edge), word = A1 A0 D13..D0 (channel address, offset-binary code),
 * chip select framed by TIM8 in hardware:
 *
 *   TIM8 one-pulse mode, repetition counter 3 -> exactly four 1.25 us slots, then stops.
 *     CH1 PC6 -> AD5554 CS: high for the first 95 ns of a slot, low for the rest; the
 *                rising edge at the slot boundary loads the word into the channel's
 *                input register.
 *     CC1 event (CS falling) -> DMA2 stream 2 (channel 7) writes the slot's word into
 *                SPI2_DR: 16 clocks in 762 ns, done before CS rises again.
 *   The words wait in the input registers until LDAC (TIM1 CH2, stm32f4_sample.h)
 *   moves all four to the outputs at the start of the next tick.
 * hal_dac_write_frame fills the four words, arms the stream and sets TIM8 CEN: nothing
 * more is done in software, and nothing waits. */
#ifndef STM32F4_DAC_H
#define STM32F4_DAC_H

#include <stdint.h>

#include "hal/hal_dac.h"

#define STM32F4_DAC_SLOT_TICKS 210u     /* 1.25 us at 168 MHz */
#define STM32F4_DAC_CS_HIGH_TICKS 16u   /* 95 ns CS high between words */

/* Configure SPI2, DMA2 stream 2 and TIM8. Call once before the sample chain starts. */
void stm32f4_dac_init(void);

/* AD5554 input word for one channel: address in bits 15..14, code clamped to 14 bits. */
static inline uint16_t stm32f4_dac_word(uint32_t channel, uint16_t code)
{
  const uint16_t c = code > HAL_DAC_CODE_MAX ? (uint16_t)HAL_DAC_CODE_MAX : code;
  return (uint16_t)(((channel & 3u) << 14) | c);
}

/* Frames refused because the previous sequence was still running (ISR overran). */
uint32_t stm32f4_dac_overruns(void);

/* Latest TIM1 count at which a four-word sequence still ends before the next LDAC
 * (set by the sample chain). A frame queued later is dropped and counted: the outputs
 * hold the previous frame one tick longer instead of being updated half now, half at
 * the tick after. */
void stm32f4_dac_set_deadline(uint32_t tim1_count);
uint32_t stm32f4_dac_late(void);

#ifdef STM32F4_HOST_TEST
/* The four words DMA stream 2 sends (see stm32f4_sample_host_rx for why). */
volatile uint16_t *stm32f4_dac_host_words(void);
#endif

#endif /* STM32F4_DAC_H */
