#include "stm32f4_sample.h"

#include <stddef.h>
#include <string.h>

#include "hal/hal_adc.h"
#include "hal/hal_sample_timer.h"
#include "stm32f4_core.h"
#include "stm32f4_dac.h"
#include "stm32f4_regs.h"

#define ADC_RX_STREAM 0u    /* DMA2 stream 0 channel 3: SPI1_RX (RM0090 table 43) */
#define ADC_WORD1_STREAM 6u /* DMA2 stream 6 channel 6: TIM1_CH3 */
#define ADC_WORD2_STREAM 4u /* DMA2 stream 4 channel 6: TIM1_CH4 */
#define CHSEL(n) ((uint32_t)(n) << DMA_SXCR_CHSEL_POS)
#define SPI1_BR_DIV8 2u

/* DMA sources and targets live in SRAM (.bss/.data), deliberately not const: the DMA
 * streams cannot reach the CCM, and a DMA read from flash would stall for the whole of
 * a parameter-sector erase, stopping the sample chain. */
/* The ADC frame: the two conversions in the order SPI1 reads them, drive first, which is
 * hal_adc_frame_t's layout; the interrupt copies both in one 32-bit load and store. */
static volatile union {
  int16_t code[2];
  uint32_t both;
} s_adc_rx;
_Static_assert(sizeof(hal_adc_frame_t) == sizeof(uint32_t) &&
                   offsetof(hal_adc_frame_t, drive) == 0u &&
                   offsetof(hal_adc_frame_t, sense) == sizeof(int16_t),
               "hal_adc_frame_t is the DMA's two half-words, drive first");
static volatile uint16_t s_adc_tx_dummy = 0u;

/* The chain's state in one block: the interrupt reaches all of it from one base
 * address (one literal load instead of one per variable). */
static struct {
  hal_sample_isr_fn isr;
  void *ctx;
  volatile uint32_t overruns;
  volatile uint32_t dma_errors;
  volatile uint32_t isr_cycles_last;
  volatile uint32_t isr_cycles_max;
} s_chain;

static uint32_t ns_to_ticks(uint32_t ns, uint32_t tim_hz, uint32_t psc)
{
  const uint64_t den = 1000000000ull * (psc + 1u);
  return (uint32_t)(((uint64_t)ns * tim_hz + den - 1u) / den);
}

/* Whole timer counts in t_ns (rounded down: "no later than"). */
static uint32_t ns_to_ticks_floor(uint64_t t_ns, uint32_t tim_hz, uint32_t psc)
{
  return (uint32_t)(t_ns * tim_hz / (1000000000ull * (psc + 1u)));
}

int stm32f4_sample_plan(uint32_t tim_hz, uint32_t rate_hz, stm32f4_sample_plan_t *plan)
{
  if (plan == 0 || rate_hz == 0u || tim_hz == 0u || tim_hz % rate_hz != 0u) return -1;
  const uint32_t min_ns = STM32F4_ADC_READ_START_NS + STM32F4_ADC_READ_NS + STM32F4_DAC_SEQ_NS +
                          STM32F4_DAC_GUARD_NS + STM32F4_MIN_TICK_NS;
  if ((uint64_t)rate_hz * min_ns > 1000000000ull) return -1;
  const uint32_t total = tim_hz / rate_hz;
  const uint32_t tim4_hz = tim_hz / 2u;
  for (uint32_t psc = 0u; psc <= 0xFFFFu; ++psc) {
    if (total % (psc + 1u) != 0u || total / (psc + 1u) > 0x10000u) continue;
    stm32f4_sample_plan_t p;
    p.psc = psc;
    p.arr = total / (psc + 1u) - 1u;
    p.ccr_strobe = ns_to_ticks(STM32F4_STROBE_NS, tim_hz, psc);
    p.ccr_read = ns_to_ticks(STM32F4_ADC_READ_START_NS, tim_hz, psc);
    p.ccr_word2 = ns_to_ticks(STM32F4_ADC_READ_START_NS + STM32F4_ADC_WORD2_NS, tim_hz, psc);
    /* The DAC slots start at a whole TIM4 count no later than the period minus the
     * sequence and its guard; the frame must be in RAM a write guard before that. */
    const uint64_t start_ns = 1000000000ull / rate_hz - STM32F4_DAC_SEQ_NS - STM32F4_DAC_GUARD_NS;
    p.dac_psc = ns_to_ticks_floor(start_ns, tim4_hz, 0u) / 0x10000u;
    if (p.dac_psc > 0xFFFFu) return -1;
    p.dac_ccr = ns_to_ticks_floor(start_ns, tim4_hz, p.dac_psc);
    const uint64_t dac_ns = (uint64_t)p.dac_ccr * (p.dac_psc + 1u) * 1000000000ull / tim4_hz;
    p.dac_deadline = ns_to_ticks_floor(dac_ns - STM32F4_DAC_WRITE_GUARD_NS, tim_hz, psc);
    *plan = p;
    return 0;
  }
  return -1;
}

static void dma_stream_reset(uint32_t n)
{
  DMA2->S[n].CR = 0u;
  for (uint32_t i = 0u; i < 10000u && (DMA2->S[n].CR & DMA_SXCR_EN) != 0u; ++i) {
    STM32F4_POLL_HOOK();
  }
  stm32f4_dma_clear(DMA2, n, DMA_FLAG_ALL);
}

void hal_sample_timer_stop(void)
{
  TIM1->CR1 = 0u;
  TIM4->CR1 = 0u;
  /* Force all three outputs to their inactive (high) level: CONVST and CS idle high,
   * LDAC high keeps the DAC outputs latched. */
  TIM1->CCMR1 = (4u << TIM_CCMR_OC1M_POS) | (4u << TIM_CCMR_OC2M_POS);
  TIM1->CCMR2 = (4u << TIM_CCMR_OC1M_POS);
  TIM1->CCER = TIM_CCER_CC1E | TIM_CCER_CC1P | TIM_CCER_CC2E | TIM_CCER_CC2P | TIM_CCER_CC3E |
               TIM_CCER_CC3P;
  TIM1->BDTR = TIM_BDTR_MOE;
  TIM1->DIER = 0u;
  cm4_nvic_disable(STM32F4_IRQ_DMA2_STREAM0);
  dma_stream_reset(ADC_WORD1_STREAM);
  dma_stream_reset(ADC_WORD2_STREAM);
  dma_stream_reset(ADC_RX_STREAM);
  SPI1->CR2 = 0u;
}

/* A stream that writes the dummy half-word into SPI1_DR on each request of its timer
 * channel, for ever (circular, one item). */
static void adc_word_stream(uint32_t n)
{
  DMA2->S[n].PAR = (uint32_t)(uintptr_t)&SPI1->DR;
  DMA2->S[n].M0AR = (uint32_t)(uintptr_t)&s_adc_tx_dummy;
  DMA2->S[n].NDTR = 1u;
  DMA2->S[n].CR = CHSEL(6) | DMA_SXCR_PL_VERY_HIGH | DMA_SXCR_MSIZE_16 | DMA_SXCR_PSIZE_16 |
                  DMA_SXCR_CIRC | DMA_SXCR_DIR_M2P;
  DMA2->S[n].CR |= DMA_SXCR_EN;
}

int hal_sample_timer_start(uint32_t rate_hz, hal_sample_isr_fn isr, void *ctx)
{
  stm32f4_sample_plan_t plan;
  if (isr == 0 || stm32f4_sample_plan(STM32F4_SAMPLE_TIM_HZ, rate_hz, &plan) != 0) return -1;
  RCC->APB2ENR |= RCC_APB2ENR_TIM1EN | RCC_APB2ENR_SPI1EN;
  RCC->APB1ENR |= RCC_APB1ENR_TIM4EN;
  RCC->AHB1ENR |= RCC_AHB1ENR_DMA2EN;
  hal_sample_timer_stop();
  s_chain.isr = isr;
  s_chain.ctx = ctx;
  s_chain.overruns = 0u;
  s_chain.dma_errors = 0u;
  s_chain.isr_cycles_last = 0u;
  s_chain.isr_cycles_max = 0u;

  /* SPI1 master, mode 2 (AD7606: MSB valid at the first SCLK falling edge after CS,
   * later bits shifted out on rising edges), 16-bit frames, CS driven by TIM1_CH3. Only
   * the RX request goes to the DMA: the TX words come from the timer's requests. */
  SPI1->CR1 = 0u;
  SPI1->CR1 = SPI_CR1_MSTR | SPI_CR1_CPOL | SPI_CR1_DFF | (SPI1_BR_DIV8 << SPI_CR1_BR_POS) |
              SPI_CR1_SSM | SPI_CR1_SSI;
  SPI1->CR2 = SPI_CR2_RXDMAEN;
  SPI1->CR1 |= SPI_CR1_SPE;

  /* Stream 0: SPI1 RX -> frame, circular (re-arms itself), interrupt on completion. */
  DMA2->S[ADC_RX_STREAM].PAR = (uint32_t)(uintptr_t)&SPI1->DR;
  DMA2->S[ADC_RX_STREAM].M0AR = (uint32_t)(uintptr_t)s_adc_rx.code;
  DMA2->S[ADC_RX_STREAM].NDTR = 2u;
  DMA2->S[ADC_RX_STREAM].CR = CHSEL(3) | DMA_SXCR_PL_VERY_HIGH | DMA_SXCR_MSIZE_16 |
                              DMA_SXCR_PSIZE_16 | DMA_SXCR_MINC | DMA_SXCR_CIRC |
                              DMA_SXCR_DIR_P2M | DMA_SXCR_TCIE | DMA_SXCR_TEIE;
  DMA2->S[ADC_RX_STREAM].CR |= DMA_SXCR_EN;
  /* Streams 6 and 4: one read word each, on TIM1 CC3 and CC4. */
  adc_word_stream(ADC_WORD1_STREAM);
  adc_word_stream(ADC_WORD2_STREAM);

  /* TIM4: reset by TIM1's update, OC1REF (PWM2: low until CCR1, high after) is TRGO,
   * whose rising edge starts TIM8. No pin. */
  TIM4->PSC = plan.dac_psc;
  TIM4->ARR = 0xFFFFu;
  TIM4->CCR1 = plan.dac_ccr;
  TIM4->CCMR1 = (TIM_OCM_PWM2 << TIM_CCMR_OC1M_POS);
  TIM4->CCER = 0u;
  TIM4->CR2 = TIM_MMS_OC1REF << TIM_CR2_MMS_POS;
  TIM4->SMCR = TIM_SMS_RESET; /* TS = 0: ITR0, TIM1's TRGO */
  TIM4->EGR = TIM_EGR_UG;
  TIM4->SR = 0u;
  TIM4->CR1 = TIM_CR1_CEN;

  /* TIM1: CH1 and CH2 PWM1 active low (low until CCR), CH3 PWM2 active low (low from
   * CCR3 on), CH4 compare only (no pin), preloaded; CC3 and CC4 raise the DMA requests;
   * TRGO on update; MOE enables the outputs. */
  TIM1->PSC = plan.psc;
  TIM1->ARR = plan.arr;
  TIM1->RCR = 0u;
  TIM1->CCR1 = plan.ccr_strobe;
  TIM1->CCR2 = plan.ccr_strobe;
  TIM1->CCR3 = plan.ccr_read;
  TIM1->CCR4 = plan.ccr_word2;
  TIM1->CCMR1 = (TIM_OCM_PWM1 << TIM_CCMR_OC1M_POS) | TIM_CCMR_OC1PE |
                (TIM_OCM_PWM1 << TIM_CCMR_OC2M_POS) | TIM_CCMR_OC2PE;
  TIM1->CCMR2 = (TIM_OCM_PWM2 << TIM_CCMR_OC1M_POS) | TIM_CCMR_OC1PE | TIM_CCMR_OC4PE;
  TIM1->CCER = TIM_CCER_CC1E | TIM_CCER_CC1P | TIM_CCER_CC2E | TIM_CCER_CC2P | TIM_CCER_CC3E |
               TIM_CCER_CC3P;
  TIM1->CR2 = TIM_MMS_UPDATE << TIM_CR2_MMS_POS;
  TIM1->DIER = TIM_DIER_CC3DE | TIM_DIER_CC4DE;
  TIM1->BDTR = TIM_BDTR_MOE;
  TIM1->EGR = TIM_EGR_UG; /* load PSC, ARR and the CCR preloads */
  TIM1->SR = 0u;

  stm32f4_dac_set_deadline(plan.dac_deadline);

  cm4_nvic_enable(STM32F4_IRQ_DMA2_STREAM0, STM32F4_PRIO_SAMPLE);
  TIM1->CR1 = TIM_CR1_ARPE | TIM_CR1_CEN;
  return 0;
}

CM4_RAMFUNC void DMA2_Stream0_IRQHandler(void)
{
  const uint32_t c0 = DWT->CYCCNT; /* self-measurement: inline, not through a call */
  const uint32_t flags = stm32f4_dma_flags(DMA2, ADC_RX_STREAM);
  stm32f4_dma_clear(DMA2, ADC_RX_STREAM, flags);
  /* The rare cases out of line: the tick's path falls through every branch. */
  if (CM4_UNLIKELY(flags & (DMA_FLAG_TEIF | DMA_FLAG_DMEIF))) ++s_chain.dma_errors;
  if (CM4_UNLIKELY((flags & DMA_FLAG_TCIF) == 0u)) return;

  s_chain.isr(s_chain.ctx);
  if (CM4_UNLIKELY(stm32f4_dma_flags(DMA2, ADC_RX_STREAM) & DMA_FLAG_TCIF)) ++s_chain.overruns;
  const uint32_t dc = DWT->CYCCNT - c0;
  s_chain.isr_cycles_last = dc;
  if (dc > s_chain.isr_cycles_max) s_chain.isr_cycles_max = dc;
}

void hal_sample_isr_cycles(uint32_t *last, uint32_t *max)
{
  if (last != 0) *last = s_chain.isr_cycles_last;
  if (max != 0) *max = s_chain.isr_cycles_max;
}

CM4_RAMFUNC void hal_adc_read_frame(hal_adc_frame_t *frame)
{
  const uint32_t both = s_adc_rx.both;
  memcpy(frame, &both, sizeof both);
}

const volatile uint32_t *hal_sample_lost_counter(void) { return &s_chain.overruns; }

void stm32f4_sample_stats(stm32f4_sample_stats_t *stats)
{
  if (stats == 0) return;
  stats->overruns = s_chain.overruns;
  stats->dma_errors = s_chain.dma_errors;
}

#ifdef STM32F4_HOST_TEST
volatile int16_t *stm32f4_sample_host_rx(void) { return s_adc_rx.code; }
#endif
