/* The sample chain (hal/boards/ref_f405/stm32f4_sample.c): TIM1 timing plan for 84 and 168 MHz
 * timer clocks, the registers that make TIM1 start conversions, reads and (through TIM4)
 * the DAC slots in hardware, and the DMA-complete interrupt that serves the tick. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "hal/hal_adc.h"
#include "hal/hal_sample_timer.h"
#include "hal/hal_dac.h"
#include "stm32f4_dac.h"
#include "stm32f4_host_regs.h"
#include "stm32f4_sample.h"

#define LOW32(p) ((uint32_t)(uintptr_t)(p))

static void assert_plan(uint32_t tim_hz, uint32_t rate_hz, const stm32f4_sample_plan_t *p)
{
  /* f_sample = f_tim / ((PSC + 1)(ARR + 1)), exactly. */
  assert_int_equal((uint64_t)rate_hz * (p->psc + 1u) * (p->arr + 1u), tim_hz);
  assert_true(p->arr <= 0xFFFFu);
  const double tick_s = (double)(p->psc + 1u) / tim_hz;
  /* CONVST low for at least the strobe; the read starts after the slowest conversion
   * (AD7606 t_CONV max 4.15 us after the CONVST rising edge). */
  assert_true(p->ccr_strobe * tick_s >= 250e-9);
  assert_true(p->ccr_read * tick_s >= p->ccr_strobe * tick_s + 4.15e-6);
  assert_true(p->ccr_read < p->arr);
  /* The second read word comes while the first is still shifting (16 bits at 10.5 MHz,
   * 1.52 us), and well after it left the TX buffer. */
  const double word2_s = (p->ccr_word2 - p->ccr_read) * tick_s;
  assert_true(word2_s >= 0.5e-6 && word2_s <= 1.0e-6);
  /* The DAC slots (TIM4 at half the clock) start no later than the period minus the four
   * 1.25 us slots and the 0.1 us guard before LDAC, and not much earlier (every ns lost
   * is compute time lost); the last frame write is at least 0.1 us before the start. */
  const double period_s = (double)(p->psc + 1u) * (p->arr + 1u) / tim_hz;
  const double dac_s = (double)p->dac_ccr * (p->dac_psc + 1u) / (tim_hz / 2.0);
  assert_true(p->dac_ccr <= 0xFFFFu);
  assert_true(dac_s <= period_s - 5.1e-6 + 1e-12);
  assert_true(dac_s >= period_s - 5.1e-6 - (p->dac_psc + 1u) / (tim_hz / 2.0) - 1e-12);
  const double deadline_s = p->dac_deadline * tick_s;
  assert_true(deadline_s <= dac_s - 0.1e-6 + 1e-12);
  assert_true(deadline_s >= dac_s - 0.1e-6 - 2.0 * tick_s - 1e-12);
  assert_true(deadline_s > p->ccr_read * tick_s + 3.05e-6); /* after the read */
}

static void test_plan_50khz_168mhz(void **state)
{
  (void)state;
  stm32f4_sample_plan_t p;
  assert_int_equal(stm32f4_sample_plan(168000000u, 50000u, &p), 0);
  assert_int_equal(p.psc, 0);
  assert_int_equal(p.arr, 3359); /* 168 MHz / 3360 = 50 kHz */
  assert_int_equal(p.ccr_strobe, 42);
  assert_int_equal(p.ccr_read, 807);
  assert_int_equal(p.ccr_word2, 933); /* 5.554 us */
  assert_int_equal(p.dac_psc, 0);
  assert_int_equal(p.dac_ccr, 1251);      /* 14.893 us at 84 MHz */
  assert_int_equal(p.dac_deadline, 2485); /* 14.792 us at 168 MHz */
  assert_plan(168000000u, 50000u, &p);
}

static void test_plan_50khz_84mhz(void **state)
{
  (void)state;
  stm32f4_sample_plan_t p;
  assert_int_equal(stm32f4_sample_plan(84000000u, 50000u, &p), 0);
  assert_int_equal(p.psc, 0);
  assert_int_equal(p.arr, 1679); /* 84 MHz / 1680 = 50 kHz */
  assert_plan(84000000u, 50000u, &p);
}

static void test_plan_slow_rate_uses_prescaler(void **state)
{
  (void)state;
  stm32f4_sample_plan_t p;
  assert_int_equal(stm32f4_sample_plan(168000000u, 1000u, &p), 0);
  assert_int_equal(p.psc, 2);
  assert_int_equal(p.arr, 55999);
  assert_plan(168000000u, 1000u, &p);
}

static void test_plan_rejects(void **state)
{
  (void)state;
  stm32f4_sample_plan_t p = {7u, 7u, 7u, 7u, 7u, 7u, 7u, 7u};
  assert_int_equal(stm32f4_sample_plan(168000000u, 50001u, &p), -1);  /* not exact */
  assert_int_equal(stm32f4_sample_plan(168000000u, 100000u, &p), -1); /* 10 us too short */
  assert_int_equal(stm32f4_sample_plan(168000000u, 0u, &p), -1);
  assert_int_equal(stm32f4_sample_plan(168000000u, 50000u, NULL), -1);
  assert_int_equal(p.arr, 7); /* unchanged */
}

/* ---- the running chain ---- */
typedef struct {
  int calls;
  int leave_tc_pending;
  hal_adc_frame_t frame;
  uint32_t cycles;
} isr_probe_t;

static void probe_isr(void *ctx)
{
  isr_probe_t *p = (isr_probe_t *)ctx;
  p->calls++;
  hal_adc_read_frame(&p->frame);
  DWT->CYCCNT += p->cycles; /* the cycles this tick "takes" */
  /* Hardware clears LISR on the LIFCR write; a frame landing meanwhile sets it again. */
  DMA2->LISR = p->leave_tc_pending ? DMA_FLAG_TCIF : 0u;
}

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  return 0;
}

static void assert_word_stream(uint32_t n)
{
  /* Channel 6 (TIM1), memory -> SPI1_DR, one half-word, circular, no increment. */
  assert_int_equal(DMA2->S[n].CR >> 25, 6u);
  assert_int_equal((DMA2->S[n].CR >> 6) & 3u, 1u);
  assert_true((DMA2->S[n].CR & (DMA_SXCR_CIRC | DMA_SXCR_EN)) == (DMA_SXCR_CIRC | DMA_SXCR_EN));
  assert_int_equal(DMA2->S[n].CR & (DMA_SXCR_MINC | DMA_SXCR_TCIE), 0u);
  assert_int_equal(DMA2->S[n].PAR, LOW32(&SPI1->DR));
  assert_int_equal(DMA2->S[n].NDTR, 1);
}

static void test_start_programs_hardware_chain(void **state)
{
  (void)state;
  isr_probe_t probe = {0};
  assert_int_equal(hal_sample_timer_start(50000u, probe_isr, &probe), 0);
  /* TIM1: 50 kHz, CONVST/LDAC PWM1 active low, CS PWM2 active low, CH4 compare only,
   * CC3 and CC4 -> DMA, TRGO = update. */
  assert_int_equal(TIM1->PSC, 0);
  assert_int_equal(TIM1->ARR, 3359);
  assert_int_equal(TIM1->CCR1, 42);
  assert_int_equal(TIM1->CCR2, 42);
  assert_int_equal(TIM1->CCR3, 807);
  assert_int_equal(TIM1->CCR4, 933);
  assert_int_equal((TIM1->CCMR1 >> 4) & 7u, 6u);
  assert_int_equal((TIM1->CCMR1 >> 12) & 7u, 6u);
  assert_int_equal((TIM1->CCMR2 >> 4) & 7u, 7u);
  assert_int_equal(TIM1->CCER, 0x333u); /* CC1E|CC1P|CC2E|CC2P|CC3E|CC3P: no CH4 pin */
  assert_int_equal(TIM1->DIER, TIM_DIER_CC3DE | TIM_DIER_CC4DE);
  assert_int_equal((TIM1->CR2 >> 4) & 7u, 2u);
  assert_true((TIM1->BDTR & TIM_BDTR_MOE) != 0u);
  assert_true((TIM1->CR1 & TIM_CR1_CEN) != 0u);
  /* SPI1: master, mode 2, 16 bit, PCLK2/8 = 10.5 MHz, software NSS, enabled; only the
   * RX DMA request: the TX words come from the timer's requests. */
  assert_int_equal(SPI1->CR1 & (SPI_CR1_CPOL | SPI_CR1_CPHA), SPI_CR1_CPOL);
  assert_int_equal((SPI1->CR1 >> SPI_CR1_BR_POS) & 7u, 2u);
  assert_true(
      (SPI1->CR1 & (SPI_CR1_MSTR | SPI_CR1_DFF | SPI_CR1_SSM | SPI_CR1_SSI | SPI_CR1_SPE)) ==
      (SPI_CR1_MSTR | SPI_CR1_DFF | SPI_CR1_SSM | SPI_CR1_SSI | SPI_CR1_SPE));
  assert_int_equal(SPI1->CR2, SPI_CR2_RXDMAEN);
  /* DMA2 (RM0090 table 43): stream 0 ch 3 SPI1_RX circular with the interrupt; stream 6
   * ch 6 TIM1_CH3 and stream 4 ch 6 TIM1_CH4 each write one word into SPI1_DR. */
  assert_int_equal(DMA2->S[0].CR >> 25, 3u);
  assert_true((DMA2->S[0].CR & (DMA_SXCR_CIRC | DMA_SXCR_TCIE | DMA_SXCR_EN)) ==
              (DMA_SXCR_CIRC | DMA_SXCR_TCIE | DMA_SXCR_EN));
  assert_int_equal((DMA2->S[0].CR >> 6) & 3u, 0u); /* peripheral -> memory */
  assert_int_equal(DMA2->S[0].PAR, LOW32(&SPI1->DR));
  assert_int_equal(DMA2->S[0].NDTR, 2);
  assert_word_stream(6u);
  assert_word_stream(4u);
  assert_int_equal(DMA2->S[5].CR, 0u); /* the SPI1_TX stream is not used */
  /* TIM4: slave reset by TIM1's TRGO (ITR0), OC1REF PWM2 rising at the DAC start is its
   * TRGO, no pin, counting. */
  assert_int_equal(TIM4->SMCR & 7u, 4u);
  assert_int_equal((TIM4->SMCR >> 4) & 7u, 0u);
  assert_int_equal((TIM4->CR2 >> 4) & 7u, 4u);
  assert_int_equal((TIM4->CCMR1 >> 4) & 7u, 7u);
  assert_int_equal(TIM4->CCR1, 1251);
  assert_int_equal(TIM4->PSC, 0);
  assert_int_equal(TIM4->CCER, 0u);
  assert_true((TIM4->CR1 & TIM_CR1_CEN) != 0u);
  assert_true((RCC->APB1ENR & RCC_APB1ENR_TIM4EN) != 0u);
  /* The sample interrupt: DMA2 stream 0 (IRQ 56) at priority 0. */
  assert_true((NVIC->ISER[56 / 32] & (1u << (56 % 32))) != 0u);
  assert_int_equal(NVIC->IP[56], 0);
}

static void test_start_sets_dac_deadline(void **state)
{
  (void)state;
  isr_probe_t probe = {0};
  assert_int_equal(hal_sample_timer_start(50000u, probe_isr, &probe), 0);
  /* The slots start at TIM4 count 1251 of 84 MHz (14.893 us); the last write is 0.1 us
   * before: TIM1 count 2485 of 168 MHz. */
  const hal_dac_frame_t f = {{1u, 2u, 3u, 4u}};
  const uint32_t late0 = stm32f4_dac_late();
  TIM1->CNT = 2486u;
  hal_dac_write_frame(&f);
  assert_int_equal(stm32f4_dac_late(), late0 + 1u);
  TIM1->CNT = 2485u;
  hal_dac_write_frame(&f);
  assert_int_equal(stm32f4_dac_late(), late0 + 1u);
  stm32f4_dac_set_deadline(0xFFFFFFFFu);
}

static void test_start_rejects(void **state)
{
  (void)state;
  isr_probe_t probe = {0};
  assert_int_equal(hal_sample_timer_start(50000u, NULL, &probe), -1);
  assert_int_equal(hal_sample_timer_start(12345u, probe_isr, &probe), -1);
  assert_int_equal(TIM1->CR1, 0u);
}

static void test_interrupt_calls_isr_and_rearms_nothing(void **state)
{
  (void)state;
  isr_probe_t probe = {0};
  assert_int_equal(hal_sample_timer_start(50000u, probe_isr, &probe), 0);
  volatile int16_t *rx = stm32f4_sample_host_rx();
  rx[0] = -12345; /* V1: drive pickoff */
  rx[1] = 321;    /* V2: sense pickoff */
  const stm32f4_dma_t dma_before = *DMA2;
  const stm32f4_tim_t tim1_before = *TIM1, tim4_before = *TIM4, tim8_before = *TIM8;
  const stm32f4_spi_t spi1_before = *SPI1;
  DMA2->LISR = DMA_FLAG_TCIF; /* stream 0 complete */
  DMA2_Stream0_IRQHandler();
  assert_int_equal(probe.calls, 1);
  assert_int_equal(DMA2->LIFCR, DMA_FLAG_TCIF); /* stream 0 flags cleared */
  assert_int_equal(probe.frame.drive, -12345);
  assert_int_equal(probe.frame.sense, 321);
  /* Every stream is circular and timer-started: the handler writes no other register. */
  for (int n = 0; n < 8; n++) {
    assert_memory_equal((const void *)&DMA2->S[n], (const void *)&dma_before.S[n],
                        sizeof dma_before.S[n]);
  }
  assert_int_equal(DMA2->HIFCR, dma_before.HIFCR);
  assert_memory_equal((const void *)TIM1, (const void *)&tim1_before, sizeof tim1_before);
  assert_memory_equal((const void *)TIM4, (const void *)&tim4_before, sizeof tim4_before);
  assert_memory_equal((const void *)TIM8, (const void *)&tim8_before, sizeof tim8_before);
  assert_memory_equal((const void *)SPI1, (const void *)&spi1_before, sizeof spi1_before);
  stm32f4_sample_stats_t st;
  stm32f4_sample_stats(&st);
  assert_int_equal(st.overruns, 0);
  assert_int_equal(st.dma_errors, 0);

  /* A frame that completes while the ISR still runs is counted as an overrun. */
  probe.leave_tc_pending = 1;
  DMA2->LISR = DMA_FLAG_TCIF;
  DMA2_Stream0_IRQHandler();
  assert_int_equal(probe.calls, 2);
  stm32f4_sample_stats(&st);
  assert_int_equal(st.overruns, 1);

  /* A transfer error is counted; without TC no tick is served. */
  DMA2->LISR = DMA_FLAG_TEIF;
  DMA2_Stream0_IRQHandler();
  assert_int_equal(probe.calls, 2);
  stm32f4_sample_stats(&st);
  assert_int_equal(st.dma_errors, 1);
}

/* The handler measures itself (DWT CYCCNT at entry and after the tick, across the
 * counter's wrap): latest and worst, reset by a new start. */
static void test_interrupt_measures_its_cycles(void **state)
{
  (void)state;
  isr_probe_t probe = {0};
  assert_int_equal(hal_sample_timer_start(50000u, probe_isr, &probe), 0);
  uint32_t last = 7u, max = 7u;
  hal_sample_isr_cycles(&last, &max);
  assert_int_equal(last, 0u);
  assert_int_equal(max, 0u);
  const uint32_t cyc[] = {600u, 900u, 450u};
  DWT->CYCCNT = 0xFFFFFE00u; /* wraps during the second tick */
  for (int i = 0; i < 3; i++) {
    probe.cycles = cyc[i];
    DMA2->LISR = DMA_FLAG_TCIF;
    DMA2_Stream0_IRQHandler();
    hal_sample_isr_cycles(&last, NULL);
    assert_int_equal(last, cyc[i]);
  }
  hal_sample_isr_cycles(NULL, &max);
  assert_int_equal(max, 900u);
  assert_int_equal(hal_sample_timer_start(50000u, probe_isr, &probe), 0);
  hal_sample_isr_cycles(&last, &max);
  assert_int_equal(max, 0u);
}

static void test_stop_parks_outputs(void **state)
{
  (void)state;
  isr_probe_t probe = {0};
  assert_int_equal(hal_sample_timer_start(50000u, probe_isr, &probe), 0);
  hal_sample_timer_stop();
  assert_int_equal(TIM1->CR1 & TIM_CR1_CEN, 0);
  /* OCxM = 100 "force inactive": with active-low polarity every line idles high. */
  assert_int_equal((TIM1->CCMR1 >> 4) & 7u, 4u);
  assert_int_equal((TIM1->CCMR1 >> 12) & 7u, 4u);
  assert_int_equal((TIM1->CCMR2 >> 4) & 7u, 4u);
  assert_int_equal(DMA2->S[0].CR & DMA_SXCR_EN, 0);
  assert_int_equal(DMA2->S[4].CR & DMA_SXCR_EN, 0);
  assert_int_equal(DMA2->S[6].CR & DMA_SXCR_EN, 0);
  assert_int_equal(TIM4->CR1 & TIM_CR1_CEN, 0); /* no DAC slot trigger either */
  assert_true((NVIC->ICER[56 / 32] & (1u << (56 % 32))) != 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_plan_50khz_168mhz),
      cmocka_unit_test(test_plan_50khz_84mhz),
      cmocka_unit_test(test_plan_slow_rate_uses_prescaler),
      cmocka_unit_test(test_plan_rejects),
      cmocka_unit_test_setup(test_start_programs_hardware_chain, setup),
      cmocka_unit_test_setup(test_start_sets_dac_deadline, setup),
      cmocka_unit_test_setup(test_start_rejects, setup),
      cmocka_unit_test_setup(test_interrupt_calls_isr_and_rearms_nothing, setup),
      cmocka_unit_test_setup(test_interrupt_measures_its_cycles, setup),
      cmocka_unit_test_setup(test_stop_parks_outputs, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
