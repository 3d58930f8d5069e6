/* The 50 kHz sample chain of the reference board, all started by TIM1 in hardware:
 *
 *   TIM1 (f_tim = 168 MHz, period = (PSC+1)(ARR+1) / f_tim = 20 us at 50 kHz)
 *     CH1 PA8  -> AD7606 CONVST A/B: low from the update event until CCR1, the rising
 *                 edge at CCR1 samples both pickoffs (the sample instant).
 *     CH2 PA9  -> AD5554 LDAC: the same 250 ns low pulse; LDAC is level sensitive, so
 *                 the DAC registers take the frame sent in the previous tick and hold
 *                 it from the same instant (zero-order hold, one-sample latency).
 *     CH3 PA10 -> AD7606 CS: high until CCR3, low from CCR3 to the end of the period.
 *                 CCR3 lies after the longest conversion (t_CONV max 4.15 us).
 *     CC3, CC4 -> DMA2 streams 6 and 4 (channel 6: TIM1_CH3, TIM1_CH4) each write one
 *                 dummy half-word into SPI1_DR: SPI1 (mode 2, 16 bit, 10.5 MHz) clocks
 *                 32 bits, V1 (drive pickoff) then V2 (sense pickoff) from DOUTA, and
 *                 stream 0 (circular) stores them. CC4 comes half a word after CC3: the
 *                 first word has left the TX buffer for the shift register, the second
 *                 lands while the first is still shifting, so the clock runs unbroken.
 *     TRGO = update -> resets TIM4 (slave reset mode): TIM4 counts the period again
 *                 from 0 at 84 MHz, and its OC1REF, rising at the DAC start time, is its
 *                 TRGO, which starts TIM8's four DAC slots (stm32f4_dac.h).
 *   DMA2 stream 0 transfer complete = the sample interrupt (priority 0): it clears the
 *   flags and calls the registered ISR, which reads the frame with hal_adc_read_frame
 *   and leaves the DAC frame with hal_dac_write_frame. Every stream is circular and
 *   every transfer is started by a timer: the interrupt re-arms nothing, and nothing in
 *   software starts a conversion, a read or a DAC word, or waits on an SPI.
 */
#ifndef STM32F4_SAMPLE_H
#define STM32F4_SAMPLE_H

#include <stdint.h>

/* Timing of the chain, ns (datasheet figures in hal/boards/ref_f405/README.md). */
#define STM32F4_STROBE_NS 250u        /* CONVST / LDAC low pulse */
#define STM32F4_ADC_CONV_MAX_NS 4150u /* AD7606 t_CONV max, no oversampling */
#define STM32F4_ADC_READ_START_NS \
  4800u /* CS falls: strobe + t_CONV max + BUSY delay + margin */
#define STM32F4_ADC_SPI_HZ \
  10500000u /* PCLK2 84 MHz / 8; AD7606 f_SCLK max 17 MHz at VDRIVE 3.3 V */
#define STM32F4_ADC_READ_NS 3250u       /* 32 SCLK at 10.5 MHz = 3048 ns + DMA latency */
#define STM32F4_ADC_WORD2_NS 750u       /* CC4 after CC3: half a 16-bit word at 10.5 MHz */
#define STM32F4_DAC_SEQ_NS 5000u        /* four 1.25 us AD5554 word slots (stm32f4_dac.h) */
#define STM32F4_DAC_GUARD_NS 100u       /* DMA latency allowance before the next LDAC */
#define STM32F4_DAC_WRITE_GUARD_NS 100u /* last frame write to DAC start: check + 4 stores */
#define STM32F4_MIN_TICK_NS 1000u       /* the least compute time a period must leave */

typedef struct {
  uint32_t psc, arr;     /* TIM1: f_sample = f_tim / ((psc + 1)(arr + 1)) exactly */
  uint32_t ccr_strobe;   /* CONVST and LDAC rise here */
  uint32_t ccr_read;     /* ADC CS falls, the first read word is written */
  uint32_t ccr_word2;    /* the second read word is written */
  uint32_t dac_psc;      /* TIM4 (f_tim / 2): prescaler */
  uint32_t dac_ccr;      /* TIM4 count at which TIM8 starts the DAC slots */
  uint32_t dac_deadline; /* last TIM1 count at which a frame may still be written */
} stm32f4_sample_plan_t;

/* Timer settings for rate_hz from a tim_hz kernel clock (TIM1; TIM4 on APB1 runs at
 * half of it in this clock tree): exact rates only, and only periods long enough for
 * conversion + read + DAC sequence + STM32F4_MIN_TICK_NS. The DAC slots start as late
 * as they can and still end STM32F4_DAC_GUARD_NS before the next LDAC, which leaves the
 * interrupt the longest compute window. Returns 0, or -1 (plan unchanged). */
int stm32f4_sample_plan(uint32_t tim_hz, uint32_t rate_hz, stm32f4_sample_plan_t *plan);

/* Diagnostics of the running chain. (The ticks served are the application's count, not
 * kept a second time here.) */
typedef struct {
  uint32_t overruns;   /* a new frame landed before the ISR returned */
  uint32_t dma_errors; /* transfer-error flags seen on the ADC streams */
} stm32f4_sample_stats_t;
void stm32f4_sample_stats(stm32f4_sample_stats_t *stats);

/* Timer kernel clock the chain assumes (TIM1 on APB2 with prescaler 2). */
#define STM32F4_SAMPLE_TIM_HZ 168000000u

void DMA2_Stream0_IRQHandler(void);

#ifdef STM32F4_HOST_TEST
/* The two-word buffer DMA stream 0 fills (the host's 64-bit pointers do not fit the
 * 32-bit DMA address registers, so a test reaches it through this instead). */
volatile int16_t *stm32f4_sample_host_rx(void);
#endif

#endif /* STM32F4_SAMPLE_H */
