/* AD5554 DAC path (hal/stm32f4/stm32f4_dac.c): word format, the TIM8 framing that makes
 * exactly four chip-select slots in hardware, and the non-blocking frame write. */
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
  /* TIM8: one-pulse with repetition counter 3 = four slots; CS on CH1 as PWM2 active
   * low; CC1 drives the DMA request. */
  assert_true((TIM8->CR1 & TIM_CR1_OPM) != 0u);
  assert_int_equal(TIM8->CR1 & TIM_CR1_CEN, 0);
  assert_int_equal(TIM8->ARR, STM32F4_DAC_SLOT_TICKS - 1u);
  assert_int_equal(TIM8->RCR, 3);
  assert_int_equal(TIM8->CCR1, STM32F4_DAC_CS_HIGH_TICKS);
  assert_int_equal((TIM8->CCMR1 >> 4) & 7u, 7u);
  assert_int_equal(TIM8->CCER, TIM_CCER_CC1E | TIM_CCER_CC1P);
  assert_int_equal(TIM8->DIER, TIM_DIER_CC1DE);
  assert_true((TIM8->BDTR & TIM_BDTR_MOE) != 0u);
  assert_int_equal(DMA2->S[2].PAR, (uint32_t)(uintptr_t)&SPI2->DR);
}

static void test_write_frame_arms_sequence(void **state)
{
  (void)state;
  const hal_dac_frame_t f = {{100u, 8192u, 16383u, 0u}};
  hal_dac_write_frame(&f);
  volatile uint16_t *w = stm32f4_dac_host_words();
  assert_int_equal(w[0], 100u);
  assert_int_equal(w[1], 0x4000u | 8192u);
  assert_int_equal(w[2], 0x8000u | 16383u);
  assert_int_equal(w[3], 0xC000u);
  assert_int_equal(DMA2->S[2].NDTR, 4);
  assert_int_equal(DMA2->S[2].CR >> 25, 7u); /* channel 7: TIM8_CH1 */
  assert_true((DMA2->S[2].CR & (DMA_SXCR_EN | DMA_SXCR_MINC)) == (DMA_SXCR_EN | DMA_SXCR_MINC));
  assert_int_equal((DMA2->S[2].CR >> 6) & 3u, 1u); /* memory -> peripheral */
  assert_int_equal(TIM8->CR1, TIM_CR1_OPM | TIM_CR1_CEN);
  assert_int_equal(stm32f4_dac_overruns(), 0);
}

static void test_write_while_busy_is_refused(void **state)
{
  (void)state;
  const hal_dac_frame_t a = {{1u, 2u, 3u, 4u}};
  const hal_dac_frame_t b = {{9u, 9u, 9u, 9u}};
  hal_dac_write_frame(&a);
  hal_dac_write_frame(&b); /* TIM8 still running: the sequence is not disturbed */
  assert_int_equal(stm32f4_dac_overruns(), 1);
  assert_int_equal(stm32f4_dac_host_words()[0], 1u);
  /* Sequence done (TIM8 stopped itself, DMA stream disabled): next frame goes out. */
  TIM8->CR1 = TIM_CR1_OPM;
  DMA2->S[2].CR &= ~DMA_SXCR_EN;
  hal_dac_write_frame(&b);
  assert_int_equal(stm32f4_dac_host_words()[0], 9u);
}

static void test_late_frame_is_dropped(void **state)
{
  (void)state;
  const hal_dac_frame_t a = {{5u, 6u, 7u, 8u}};
  stm32f4_dac_set_deadline(2503u);
  TIM1->CNT = 2504u; /* too late: the sequence would straddle the next LDAC */
  hal_dac_write_frame(&a);
  assert_int_equal(stm32f4_dac_late(), 1);
  assert_int_equal(TIM8->CR1 & TIM_CR1_CEN, 0);
  TIM1->CNT = 2503u;
  hal_dac_write_frame(&a);
  assert_int_equal(stm32f4_dac_late(), 1);
  assert_int_equal(stm32f4_dac_host_words()[3], 0xC000u | 8u);
  stm32f4_dac_set_deadline(0xFFFFFFFFu);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_word_format),
      cmocka_unit_test(test_slot_timing_fits),
      cmocka_unit_test_setup(test_init_registers, setup),
      cmocka_unit_test_setup(test_write_frame_arms_sequence, setup),
      cmocka_unit_test_setup(test_write_while_busy_is_refused, setup),
      cmocka_unit_test_setup(test_late_frame_is_dropped, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
