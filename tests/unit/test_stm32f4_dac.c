/* The two AD5554 DACs' path (hal/boards/ref_f405/stm32f4_dac.c): word format, the TIM8
 * framing that makes exactly four chip-select slots in hardware when TIM4 starts it, the
 * two circular streams (converter A on SPI2, B on SPI3, requested by CC1 and CC2 of the
 * same slots) that send the words every tick, and the frame write that only stores them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "hal/hal_dac.h"
#include "stm32f4_dac.h"
#include "stm32f4_host_regs.h"
#include "stm32f4_sample.h"

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  stm32f4_dac_init();
  return 0;
}

static void test_word_format(void **state)
{
  (void)state;
  /* AD5554 data sheet table 6: A1 A0 D13..D0, MSB first. */
  assert_int_equal(stm32f4_dac_word(0u, 0x2000u), 0x2000u);
  assert_int_equal(stm32f4_dac_word(1u, 0x0001u), 0x4001u);
  assert_int_equal(stm32f4_dac_word(2u, 0x3FFFu), 0xBFFFu);
  assert_int_equal(stm32f4_dac_word(3u, 0u), 0xC000u);
  assert_int_equal(stm32f4_dac_word(3u, 20000u), 0xFFFFu); /* clamped to 16383 */
  /* Converter B's channels 4..7 are its DAC A..D: the address within the part. */
  assert_int_equal(stm32f4_dac_word(HAL_DAC_SENSE_FB_U2, 0x2000u), 0x2000u);
  assert_int_equal(stm32f4_dac_word(HAL_DAC_QUADNULL_V1, 1u), 0x4001u);
  assert_int_equal(stm32f4_dac_word(HAL_DAC_QUADNULL_V2, 2u), 0x8002u);
  assert_int_equal(stm32f4_dac_word(HAL_DAC_TUNE, 3u), 0xC003u);
}

static void test_slot_timing_fits(void **state)
{
  (void)state;
  /* One slot at 168 MHz must hold CS high time + 16 SPI clocks at PCLK1/2 = 21 MHz with
   * room for the DMA latency; four slots must fit the budget of stm32f4_sample.h. */
  const double slot_s = STM32F4_DAC_SLOT_TICKS / 168e6;
  const double cs_high_s = STM32F4_DAC_CS_HIGH_TICKS / 168e6;
  const double word_s = 16.0 / 21e6;
  assert_true(slot_s - cs_high_s - word_s > 250e-9);
  assert_true(4.0 * slot_s <= STM32F4_DAC_SEQ_NS * 1e-9 + 1e-12);
  /* Eight channels, two converters loaded in parallel: still four slots. */
  assert_int_equal(STM32F4_DAC_CONVERTERS * STM32F4_DAC_PER_CONVERTER, HAL_DAC_NUM_CHANNELS);
  assert_int_equal(STM32F4_DAC_PER_CONVERTER, 4u);
}

static void test_init_registers(void **state)
{
  (void)state;
  /* SPI2: transmit-only master, mode 0 (AD5554 latches SDI on the rising CLK edge),
   * 16 bit, PCLK1/2. */
  const uint32_t want = SPI_CR1_BIDIMODE | SPI_CR1_BIDIOE | SPI_CR1_MSTR | SPI_CR1_DFF |
                        SPI_CR1_SSM | SPI_CR1_SSI | SPI_CR1_SPE;
  assert_int_equal(SPI2->CR1, want);
  assert_int_equal(SPI2->CR2, SPI_CR2_TXDMAEN);
  /* SPI3, converter B's bus: the same. */
  assert_int_equal(SPI3->CR1, want);
  assert_int_equal(SPI3->CR2, SPI_CR2_TXDMAEN);
  assert_true((RCC->APB1ENR & (RCC_APB1ENR_SPI2EN | RCC_APB1ENR_SPI3EN)) ==
              (RCC_APB1ENR_SPI2EN | RCC_APB1ENR_SPI3EN));
  /* TIM8: one-pulse with repetition counter 3 = four slots; CS on CH1 as PWM2 active
   * low; CC1 drives the DMA request; stopped until TIM4's TRGO (ITR2) starts it
   * (trigger mode). */
  assert_true((TIM8->CR1 & TIM_CR1_OPM) != 0u);
  assert_int_equal(TIM8->CR1 & TIM_CR1_CEN, 0);
  assert_int_equal(TIM8->ARR, STM32F4_DAC_SLOT_TICKS - 1u);
  assert_int_equal(TIM8->RCR, 3);
  assert_int_equal(TIM8->CCR1, STM32F4_DAC_CS_HIGH_TICKS);
  assert_int_equal((TIM8->CCMR1 >> 4) & 7u, 7u);
  assert_int_equal(TIM8->CCER, TIM_CCER_CC1E | TIM_CCER_CC1P); /* CH2 has no pin */
  /* CC2 at the same count requests converter B's word in every slot */
  assert_int_equal(TIM8->CCR2, TIM8->CCR1);
  assert_int_equal(TIM8->DIER, TIM_DIER_CC1DE | TIM_DIER_CC2DE);
  assert_true((TIM8->BDTR & TIM_BDTR_MOE) != 0u);
  assert_int_equal(TIM8->SMCR & 7u, 6u);        /* trigger mode */
  assert_int_equal((TIM8->SMCR >> 4) & 7u, 2u); /* ITR2 = TIM4 */
  /* DMA2 stream 2, channel 7 (TIM8_CH1): the four words into SPI2_DR, circular, armed
   * once here and never again. */
  assert_int_equal(DMA2->S[2].PAR, (uint32_t)(uintptr_t)&SPI2->DR);
  assert_int_equal(DMA2->S[2].NDTR, 4);
  assert_int_equal(DMA2->S[2].CR >> 25, 7u);
  const uint32_t on = DMA_SXCR_EN | DMA_SXCR_MINC | DMA_SXCR_CIRC;
  assert_int_equal(DMA2->S[2].CR & on, on);
  assert_int_equal((DMA2->S[2].CR >> 6) & 3u, 1u); /* memory -> peripheral */
  volatile uint16_t *w = stm32f4_dac_host_words();
  assert_int_equal(DMA2->S[2].M0AR, (uint32_t)(uintptr_t)&w[0]);
  /* DMA2 stream 3, channel 7 (TIM8_CH2): converter B's four words into SPI3_DR. */
  assert_int_equal(DMA2->S[3].PAR, (uint32_t)(uintptr_t)&SPI3->DR);
  assert_int_equal(DMA2->S[3].M0AR, (uint32_t)(uintptr_t)&w[4]);
  assert_int_equal(DMA2->S[3].NDTR, 4);
  assert_int_equal(DMA2->S[3].CR >> 25, 7u);
  assert_int_equal(DMA2->S[3].CR & on, on);
  assert_int_equal((DMA2->S[3].CR >> 6) & 3u, 1u);
  /* Until the first frame the slots send mid-scale (0 V) to each channel of each part. */
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ch++) {
    assert_int_equal(w[ch], ((ch & 3u) << 14) | 8192u);
  }
}

static void test_write_frame_only_fills_words(void **state)
{
  (void)state;
  const stm32f4_dma_t dma_before = *DMA2;
  const stm32f4_tim_t tim8_before = *TIM8;
  const hal_dac_frame_t f = {{100u, 8192u, 16383u, 0u, 1u, 2u, 3u, 16383u}};
  hal_dac_write_frame(&f);
  volatile uint16_t *w = stm32f4_dac_host_words();
  assert_int_equal(w[0], 100u);
  assert_int_equal(w[1], 0x4000u | 8192u);
  assert_int_equal(w[2], 0x8000u | 16383u);
  assert_int_equal(w[3], 0xC000u);
  /* converter B: feedback U4, nulling V1, V2, tuning at its addresses 0..3 */
  assert_int_equal(w[4], 1u);
  assert_int_equal(w[5], 0x4000u | 2u);
  assert_int_equal(w[6], 0x8000u | 3u);
  assert_int_equal(w[7], 0xC000u | 16383u);
  /* No register is touched: the hardware sends the words at the next slots. */
  assert_memory_equal((const void *)DMA2, (const void *)&dma_before, sizeof dma_before);
  assert_memory_equal((const void *)TIM8, (const void *)&tim8_before, sizeof tim8_before);
  /* The next frame replaces the words whole. */
  const hal_dac_frame_t g = {{9u, 10u, 11u, 12u, 13u, 14u, 15u, 16u}};
  hal_dac_write_frame(&g);
  assert_int_equal(w[0], 9u);
  assert_int_equal(w[3], 0xC000u | 12u);
  assert_int_equal(w[7], 0xC000u | 16u);
  /* a code beyond 14 bits is saturated as the M4's USAT16 does (signed half-words: full
   * scale up to 32767, zero scale above), never let into the address bits */
  const hal_dac_frame_t h = {{9u, 16384u, 32767u, 12u, 13u, 20000u, 15u, 65535u}};
  hal_dac_write_frame(&h);
  assert_int_equal(w[1], 0x4000u | 16383u);
  assert_int_equal(w[2], 0x8000u | 16383u);
  assert_int_equal(w[5], 0x4000u | 16383u);
  assert_int_equal(w[6], 0x8000u | 15u);
  assert_int_equal(w[7], 0xC000u);
  const hal_dac_frame_t m = {{32768u, 40000u, 0u, 16383u, 0u, 0u, 0u, 0u}};
  hal_dac_write_frame(&m);
  assert_int_equal(w[0], 0u);
  assert_int_equal(w[1], 0x4000u);
  assert_int_equal(w[3], 0xC000u | 16383u);
  assert_int_equal(stm32f4_dac_late(), 0);
}

static void test_late_frame_is_dropped(void **state)
{
  (void)state;
  const hal_dac_frame_t a = {{5u, 6u, 7u, 8u, 9u, 10u, 11u, 12u}};
  stm32f4_dac_set_deadline(2485u);
  TIM1->CNT = 2486u; /* too late: the slots may already be sending */
  hal_dac_write_frame(&a);
  assert_int_equal(stm32f4_dac_late(), 1);
  assert_int_equal(stm32f4_dac_host_words()[3], 0xC000u | 8192u); /* previous words kept, */
  assert_int_equal(stm32f4_dac_host_words()[7], 0xC000u | 8192u); /* on both converters */
  TIM1->CNT = 2485u;
  hal_dac_write_frame(&a);
  assert_int_equal(stm32f4_dac_late(), 1);
  assert_int_equal(stm32f4_dac_host_words()[3], 0xC000u | 8u);
  assert_int_equal(stm32f4_dac_host_words()[7], 0xC000u | 12u);
  stm32f4_dac_set_deadline(0xFFFFFFFFu);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_word_format),
      cmocka_unit_test(test_slot_timing_fits),
      cmocka_unit_test_setup(test_init_registers, setup),
      cmocka_unit_test_setup(test_write_frame_only_fills_words, setup),
      cmocka_unit_test_setup(test_late_frame_is_dropped, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
