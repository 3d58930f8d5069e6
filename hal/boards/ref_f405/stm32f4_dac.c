#include "stm32f4_dac.h"

#include <string.h>

#if defined(__ARM_FEATURE_SIMD32)
#include <arm_acle.h> /* int16x2_t */
#endif

#include "hal/hal_dac.h"
#include "stm32f4_core.h"
#include "stm32f4_regs.h"

#define DAC_A_STREAM 2u /* DMA2 stream 2 channel 7: TIM8_CH1 (RM0090 table 43) */
#define DAC_B_STREAM 3u /* DMA2 stream 3 channel 7: TIM8_CH2 */

/* The frame's state in one block, so that the interrupt reaches all of it from one base
 * address (one literal load instead of three): the deadline, the count of late frames
 * and the words the DMA streams read (half-words), converter A's, then B's (each stream
 * reads its half), which the interrupt writes two at a time (the 32-bit view). In SRAM
 * (.data), where DMA reaches, deliberately not in the CCM (stm32f4_sample.c). */
static struct {
  volatile uint32_t deadline;
  volatile uint32_t late;
  volatile union {
    uint16_t h[HAL_DAC_NUM_CHANNELS];
    uint32_t pair[HAL_DAC_NUM_CHANNELS / 2];
  } words;
} s_dac = {0xFFFFFFFFu, 0u, {{0u}}};

/* SPI2 or SPI3: transmit-only master (bidirectional mode, output enabled), 16-bit, mode 0,
 * BR = 000: PCLK1 / 2 = 21 MHz; a write to DR (by DMA) sends one word. */
static void dac_spi_init(stm32f4_spi_t *spi)
{
  spi->CR1 = 0u;
  spi->CR1 = SPI_CR1_BIDIMODE | SPI_CR1_BIDIOE | SPI_CR1_MSTR | SPI_CR1_DFF | SPI_CR1_SSM |
             SPI_CR1_SSI;
  spi->CR2 = SPI_CR2_TXDMAEN;
  spi->CR1 |= SPI_CR1_SPE;
}

/* A stream that writes one of the converter's four words into the SPI's DR on each
 * request of its TIM8 channel, circular: armed once, never again. */
static void dac_stream_init(uint32_t n, stm32f4_spi_t *spi, volatile uint16_t *words)
{
  DMA2->S[n].CR = 0u;
  stm32f4_dma_clear(DMA2, n, DMA_FLAG_ALL);
  DMA2->S[n].PAR = (uint32_t)(uintptr_t)&spi->DR;
  DMA2->S[n].M0AR = (uint32_t)(uintptr_t)words;
  DMA2->S[n].NDTR = STM32F4_DAC_PER_CONVERTER;
  DMA2->S[n].CR = (7u << DMA_SXCR_CHSEL_POS) | DMA_SXCR_PL_HIGH | DMA_SXCR_MSIZE_16 |
                  DMA_SXCR_PSIZE_16 | DMA_SXCR_MINC | DMA_SXCR_CIRC | DMA_SXCR_DIR_M2P;
  DMA2->S[n].CR |= DMA_SXCR_EN;
}

void stm32f4_dac_init(void)
{
  RCC->APB1ENR |= RCC_APB1ENR_SPI2EN | RCC_APB1ENR_SPI3EN;
  RCC->APB2ENR |= RCC_APB2ENR_TIM8EN;
  RCC->AHB1ENR |= RCC_AHB1ENR_DMA2EN;
  s_dac.late = 0u;
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ++ch) {
    s_dac.words.h[ch] = stm32f4_dac_word(ch, (uint16_t)HAL_DAC_CODE_MID);
  }
  dac_spi_init(SPI2);
  dac_spi_init(SPI3);
  dac_stream_init(DAC_A_STREAM, SPI2, &s_dac.words.h[0]);
  dac_stream_init(DAC_B_STREAM, SPI3, &s_dac.words.h[STM32F4_DAC_PER_CONVERTER]);

  /* TIM8: one-pulse, RCR = 3 -> four periods then stop; CH1 PWM2 active low (CS high
   * while CNT < CCR1), CC1 raises converter A's DMA request and CC2, at the same count
   * and with no output, converter B's (stream 3 waits behind stream 2 for the bus: tens of
   * ns); MOE enables the output; a rising edge of TIM4's TRGO (ITR2) sets CEN. */
  TIM8->CR1 = TIM_CR1_OPM;
  TIM8->PSC = 0u;
  TIM8->ARR = STM32F4_DAC_SLOT_TICKS - 1u;
  TIM8->RCR = STM32F4_DAC_PER_CONVERTER - 1u;
  TIM8->CCR1 = STM32F4_DAC_CS_HIGH_TICKS;
  TIM8->CCR2 = STM32F4_DAC_CS_HIGH_TICKS;
  TIM8->CCMR1 = (TIM_OCM_PWM2 << TIM_CCMR_OC1M_POS);
  TIM8->CCER = TIM_CCER_CC1E | TIM_CCER_CC1P;
  TIM8->DIER = TIM_DIER_CC1DE | TIM_DIER_CC2DE;
  TIM8->BDTR = TIM_BDTR_MOE;
  TIM8->EGR = TIM_EGR_UG; /* load RCR and ARR; the counter stays stopped */
  TIM8->SR = 0u;
  TIM8->SMCR = (TIM_TS_ITR2 << TIM_SMCR_TS_POS) | TIM_SMS_TRIGGER;
}

/* Words ch and ch + 1 (ch even) as one 32-bit store, little-endian (ch in the low half),
 * each code saturated to 14 bits and given its address within the converter (ch & 3 is 0
 * or 2). On the M4 the two codes come in one load and saturate in one USAT16, which takes
 * each half-word as signed: a code above 16383 is held at full scale up to 32767 and at
 * zero scale above (never into the address bits; the HAL allows 0..16383 only). The host
 * build does the same in C. */
static inline uint32_t word_pair(const hal_dac_frame_t *frame, uint32_t ch)
{
  const uint32_t addr = ((ch & 3u) << 14) | (((ch + 1u) & 3u) << 30);
#if defined(__ARM_FEATURE_SIMD32)
  int16x2_t two;
  memcpy(&two, &frame->code[ch], sizeof two);
  /* the builtin behind the ACLE header's __usat16, whose macro assigns the builtin's unsigned
   * result to a signed variable (a -Wsign-conversion error in GCC 12's header) */
  return (uint32_t)__builtin_arm_usat16(two, 14) | addr;
#else
  uint32_t sat[2];
  for (uint32_t i = 0u; i < 2u; i++) {
    const uint16_t c = frame->code[ch + i];
    sat[i] = c > 0x7FFFu ? 0u : (c > HAL_DAC_CODE_MAX ? HAL_DAC_CODE_MAX : c);
  }
  return sat[0] | (sat[1] << 16) | addr;
#endif
}

/* Called from the sample interrupt: eight words, written in pairs (the interrupt's budget:
 * README "Fit in the 20 us period"). */
CM4_RAMFUNC void hal_dac_write_frame(const hal_dac_frame_t *frame)
{
  if (TIM1->CNT > s_dac.deadline) {
    ++s_dac.late;
    return;
  }
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ch += 2u) {
    s_dac.words.pair[ch / 2u] = word_pair(frame, ch);
  }
}

void stm32f4_dac_set_deadline(uint32_t tim1_count) { s_dac.deadline = tim1_count; }

uint32_t stm32f4_dac_late(void) { return s_dac.late; }

#ifdef STM32F4_HOST_TEST
volatile uint16_t *stm32f4_dac_host_words(void) { return s_dac.words.h; }
#endif
