/* The board's two AD5554 quad 14-bit DACs, loaded in parallel in the same four slots:
 *   converter A (HAL channels 0..3: drive U1, U2, rate output, spare / feedback U3) on SPI2
 *     (PB13 SCK, PB15 MOSI), converter B (channels 4..7: feedback U4, nulling V1, V2,
 *     tuning) on SPI3 (PC10 SCK, PC12 MOSI); both at 21 MHz (PCLK1 / 2), mode 0 (data
 *     clocked in on the rising CLK edge); word = A1 A0 D13..D0 (the channel's address
 *     within its converter, offset-binary code), sent every tick in hardware:
 *
 *   TIM8 one-pulse mode, repetition counter 3 -> exactly four 1.25 us slots, then stops;
 *     started (trigger mode, ITR2) by TIM4's TRGO at the DAC start time of the sample
 *     chain (stm32f4_sample.h), so the slots end just before the next LDAC.
 *     CH1 PC6 -> CS of both AD5554: high for the first 95 ns of a slot, low for the
 *                rest; the rising edge at the slot boundary loads each converter's word
 *                into the addressed input register.
 *     CC1 event (CS falling) -> DMA2 stream 2 (channel 7, circular over converter A's
 *                four words) writes the slot's word into SPI2_DR; CC2 (same count, no
 *                pin) -> DMA2 stream 3 (channel 7, TIM8_CH2, circular over B's words)
 *                into SPI3_DR: 16 clocks in 762 ns on each bus, done before CS rises.
 *   The words wait in the input registers until LDAC (TIM1 CH2, stm32f4_sample.h; wired
 *   to both converters) moves all eight to the outputs at the start of the next tick.
 * Why a second bus rather than more slots on SPI2: hal/boards/ref_f405/README.md ("Why
 * these parts"). hal_dac_write_frame only stores the eight words in RAM (if it is not too
 * late for this tick's slots). Each word carries its channel's address, so every slot is
 * self-describing; until the first frame the words are mid-scale (0 V). */
#ifndef STM32F4_DAC_H
#define STM32F4_DAC_H

#include <stdint.h>

#include "hal/hal_dac.h"

#define STM32F4_DAC_SLOT_TICKS 210u   /* 1.25 us at 168 MHz */
#define STM32F4_DAC_CS_HIGH_TICKS 16u /* 95 ns CS high between words */
#define STM32F4_DAC_PER_CONVERTER 4u  /* AD5554: four channels, one slot each */
#define STM32F4_DAC_CONVERTERS (HAL_DAC_NUM_CHANNELS / STM32F4_DAC_PER_CONVERTER)

/* Configure SPI2, SPI3, DMA2 streams 2 and 3 (enabled, waiting for TIM8) and TIM8
 * (waiting for its trigger). Call once before the sample chain starts. */
void stm32f4_dac_init(void);

/* AD5554 input word for one HAL channel: the channel's address within its converter in
 * bits 15..14, code clamped to 14 bits. */
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
/* The eight words DMA streams 2 (words 0..3) and 3 (words 4..7) send every tick (see
 * stm32f4_sample_host_rx for why). */
volatile uint16_t *stm32f4_dac_host_words(void);
#endif

#endif /* STM32F4_DAC_H */
