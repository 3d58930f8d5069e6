#include "stm32f4_dac.h"

#include "hal/hal_dac.h"
#include "stm32f4_core.h"
#include "stm32f4_regs.h"

#define DAC_STREAM 2u /* DMA2 stream 2 channel 7: TIM8_CH1 (RM0090 table 43) */

static volatile uint16_t s_words[HAL_DAC_NUM_CHANNELS]; /* SRAM: read by DMA */
static volatile uint32_t s_late;
static volatile uint32_t s_deadline = 0xFFFFFFFFu;

void stm32f4_dac_init(void)
{
  RCC->APB1ENR |= RCC_APB1ENR_SPI2EN;
  RCC->APB2ENR |= RCC_APB2ENR_TIM8EN;
  RCC->AHB1ENR |= RCC_AHB1ENR_DMA2EN;
  s_late = 0u;
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ++ch) {
    s_words[ch] = stm32f4_dac_word(ch, (uint16_t)HAL_DAC_CODE_MID);
  }

  /* SPI2: transmit-only master (bidirectional mode, output enabled), 16-bit, mode 0,
   * BR = 000: PCLK1 / 2 = 21 MHz. */
  SPI2->CR1 = 0u;
  SPI2->CR1 = SPI_CR1_BIDIMODE | SPI_CR1_BIDIOE | SPI_CR1_MSTR | SPI_CR1_DFF | SPI_CR1_SSM |
              SPI_CR1_SSI;
  SPI2->CR2 = SPI_CR2_TXDMAEN;
  SPI2->CR1 |= SPI_CR1_SPE;

  DMA2->S[DAC_STREAM].CR = 0u;
  stm32f4_dma_clear(DMA2, DAC_STREAM, DMA_FLAG_ALL);
  DMA2->S[DAC_STREAM].PAR = (uint32_t)(uintptr_t)&SPI2->DR;
  DMA2->S[DAC_STREAM].M0AR = (uint32_t)(uintptr_t)s_words;
  DMA2->S[DAC_STREAM].NDTR = HAL_DAC_NUM_CHANNELS;
  DMA2->S[DAC_STREAM].CR = (7u << DMA_SXCR_CHSEL_POS) | DMA_SXCR_PL_HIGH | DMA_SXCR_MSIZE_16 |
                           DMA_SXCR_PSIZE_16 | DMA_SXCR_MINC | DMA_SXCR_CIRC | DMA_SXCR_DIR_M2P;
  DMA2->S[DAC_STREAM].CR |= DMA_SXCR_EN;

  /* TIM8: one-pulse, RCR = 3 -> four periods then stop; CH1 PWM2 active low (CS high
   * while CNT < CCR1), CC1 raises the DMA request, MOE enables the output; a rising
   * edge of TIM4's TRGO (ITR2) sets CEN. */
  TIM8->CR1 = TIM_CR1_OPM;
  TIM8->PSC = 0u;
  TIM8->ARR = STM32F4_DAC_SLOT_TICKS - 1u;
  TIM8->RCR = HAL_DAC_NUM_CHANNELS - 1u;
  TIM8->CCR1 = STM32F4_DAC_CS_HIGH_TICKS;
  TIM8->CCMR1 = (TIM_OCM_PWM2 << TIM_CCMR_OC1M_POS);
  TIM8->CCER = TIM_CCER_CC1E | TIM_CCER_CC1P;
  TIM8->DIER = TIM_DIER_CC1DE;
  TIM8->BDTR = TIM_BDTR_MOE;
  TIM8->EGR = TIM_EGR_UG; /* load RCR and ARR; the counter stays stopped */
  TIM8->SR = 0u;
  TIM8->SMCR = (TIM_TS_ITR2 << TIM_SMCR_TS_POS) | TIM_SMS_TRIGGER;
}

CM4_RAMFUNC void hal_dac_write_frame(const hal_dac_frame_t *frame)
{
  if (TIM1->CNT > s_deadline) {
    ++s_late;
    return;
  }
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ++ch) {
    s_words[ch] = stm32f4_dac_word(ch, frame->code[ch]);
  }
}

void stm32f4_dac_set_deadline(uint32_t tim1_count) { s_deadline = tim1_count; }

uint32_t stm32f4_dac_late(void) { return s_late; }

#ifdef STM32F4_HOST_TEST
volatile uint16_t *stm32f4_dac_host_words(void) { return s_words; }
#endif
