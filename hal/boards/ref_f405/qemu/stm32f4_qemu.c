/* Emulator variant of the board layer for QEMU's netduinoplus2 machine (an STM32F405
 * model: Cortex-M4F with FPU and SysTick, USART1 with RX interrupts; no RCC, no DAC, a
 * ramp for an ADC, and a TIM2 that only behaves while EGR and CNT are never written).
 *
 *   sample clock  SysTick from the 168 MHz core clock, reload 3360 -> 50 kHz, priority 0
 *   converters    loopback: the ADC frame of a tick is the DAC drive pair of the tick
 *                 before (codes rescaled 14 -> 16 bit, mid-scale -> 0), so the ISR path
 *                 reads and writes real data
 *   cycles        SysTick periods elapsed x 3360 + SysTick count (no DWT in QEMU)
 *   uptime        TIM2 free running, prescaled to 1 MHz of emulated time
 * Everything else (UART driver, fault capture, start-up, flash driver) is the board's.
 *
 * With STM32F4_QEMU_PLANT (gyro-fw-qemu) the converters are the plant model instead
 * (stm32f4_qemu_plant.c), stepped after the application's ISR in the SysTick handler,
 * and the SysTick period is STM32F4_QEMU_TICK_STRETCH times the requested one: the
 * double-precision plant runs in software on the single-precision FPU and needs far more
 * than the 3360 cycles of a 20 us tick. The firmware and the plant still advance one
 * 50 kHz sample per tick; only emulated wall time runs slower. The handler times the
 * application's ISR and the plant with TIM2 as an emulated-nanosecond counter and counts
 * overrun and lost ticks (stm32f4_qemu.h). */
#include "hal/hal_adc.h"
#include "hal/hal_critical.h"
#include "hal/hal_dac.h"
#include "hal/hal_sample_timer.h"
#include "stm32f4_board.h"
#include "stm32f4_core.h"
#include "stm32f4_dac.h"
#include "cm4_fault.h"
#include "stm32f4_qemu.h"
#include "stm32f4_sample.h"
#include "stm32f4_uart.h"
#include "stm32f4_uptime.h"
#ifdef STM32F4_QEMU_PLANT
#include "stm32f4_qemu_plant.h"
#endif

#ifndef STM32F4_QEMU_TICK_STRETCH
#define STM32F4_QEMU_TICK_STRETCH 1u
#endif

/* Turns of the background loop's pause (stm32f4_qemu_idle): a few thousand
 * instructions between two passes over the UART and watchdog registers. */
#define STM32F4_QEMU_IDLE_SPINS 2000u

#define QEMU_SYSCLK_HZ 168000000u
#define QEMU_TIM_HZ 1000000000u /* QEMU's STM32 timer model counts its input at 1 GHz */
#define SYSTICK_SHPR_INDEX 11u  /* SysTick = exception 15 -> SHPR3 byte 3 */

static stm32f4_board_info_t s_info;
static hal_sample_isr_fn s_isr;
static void *s_ctx;
static volatile uint32_t s_wraps;
#ifdef STM32F4_QEMU_PLANT
static stm32f4_qemu_tick_stats_t s_tick;
static uint32_t s_t_prev_ns;         /* TIM2 at the previous handler entry */
static uint32_t s_cycles_per_sample; /* 168 MHz / rate_hz */
static uint32_t s_ns_per_sample;     /* 1e9 / rate_hz */
static uint32_t s_lost_skip;         /* ticks after a stretch change: periods mixed */
#else
static hal_dac_frame_t s_dac;
#endif

void board_system_init(void)
{
  s_info.reset_flags = RCC->CSR;
  /* No RCC model: the core runs at the machine's fixed 168 MHz. Report the plan the
   * board would program. */
  s_info.clock_status = stm32f4_clock_plan(BOARD_HSE_HZ, BOARD_SYSCLK_HZ, &s_info.clock);
  cm4_fault_enable();
}

const stm32f4_board_info_t *stm32f4_board_info(void) { return &s_info; }

int stm32f4_board_init(void)
{
#ifdef STM32F4_QEMU_PLANT
  if (stm32f4_qemu_plant_init() != 0) return -1;
#endif
#ifdef STM32F4_QEMU_FLASH_MODEL
  stm32f4_qemu_flash_init();
#endif
#ifdef STM32F4_QEMU_PLANT
  /* TIM2 undivided: QEMU's timer input is 1 GHz of emulated time (stm32f4_qemu.h). */
  TIM2->CR1 = 0u;
  TIM2->PSC = 0u;
  TIM2->ARR = 0xFFFFFFFFu;
  TIM2->CR1 = TIM_CR1_CEN;
#else
  for (uint32_t ch = 0u; ch < HAL_DAC_NUM_CHANNELS; ++ch) {
    s_dac.code[ch] = (uint16_t)HAL_DAC_CODE_MID;
  }
#endif
  return stm32f4_uart_init(s_info.clock.pclk2_hz, BOARD_UART_BAUD);
}

int hal_sample_timer_start(uint32_t rate_hz, hal_sample_isr_fn isr, void *ctx)
{
  if (isr == 0 || rate_hz == 0u || QEMU_SYSCLK_HZ % rate_hz != 0u ||
      QEMU_SYSCLK_HZ / rate_hz > 0x1000000u / STM32F4_QEMU_TICK_STRETCH) {
    return -1;
  }
  hal_sample_timer_stop();
  s_isr = isr;
  s_ctx = ctx;
#ifdef STM32F4_QEMU_PLANT
  s_tick = (stm32f4_qemu_tick_stats_t){0};
  s_tick.stretch = STM32F4_QEMU_TICK_STRETCH;
  s_tick.period_ns = 1000000000u / rate_hz * STM32F4_QEMU_TICK_STRETCH;
  s_cycles_per_sample = QEMU_SYSCLK_HZ / rate_hz;
  s_ns_per_sample = 1000000000u / rate_hz;
  s_lost_skip = 0u;
#endif
  SCB->SHPR[SYSTICK_SHPR_INDEX] = (uint8_t)(STM32F4_PRIO_SAMPLE << 4);
  SYSTICK->LOAD = QEMU_SYSCLK_HZ / rate_hz * STM32F4_QEMU_TICK_STRETCH - 1u;
  SYSTICK->VAL = 0u;
  SYSTICK->CTRL = SYSTICK_CTRL_CLKSOURCE | SYSTICK_CTRL_TICKINT | SYSTICK_CTRL_ENABLE;
  return 0;
}

void hal_sample_timer_stop(void) { SYSTICK->CTRL = 0u; }

void SysTick_Handler(void);

/* hal_sample_isr_cycles: the emulator has no DWT; its cycles are SysTick's (emulated
 * 168 MHz, so under -icount they count instructions, not a real core's cycles). */
static volatile uint32_t s_isr_cycles_last, s_isr_cycles_max;

static CM4_RAMFUNC void note_isr_cycles(uint32_t dc)
{
  s_isr_cycles_last = dc;
  if (dc > s_isr_cycles_max) s_isr_cycles_max = dc;
}

/* The emulated plant steps once per interrupt, whatever the emulator's pace: no sample
 * is lost between it and the firmware (lost periods of the emulator's own clock are
 * counted apart, stm32f4_qemu.h). */
static const volatile uint32_t s_no_loss = 0u;

const volatile uint32_t *hal_sample_lost_counter(void) { return &s_no_loss; }

void hal_sample_isr_cycles(uint32_t *last, uint32_t *max)
{
  if (last != 0) *last = s_isr_cycles_last;
  if (max != 0) *max = s_isr_cycles_max;
}

#ifdef STM32F4_QEMU_PLANT
CM4_RAMFUNC void SysTick_Handler(void)
{
  const uint32_t t0 = TIM2->CNT;
  (void)SYSTICK->CTRL; /* clears COUNTFLAG, set by the wrap that raised this tick */
  s_wraps = s_wraps + 1u;
  const uint32_t c0 = hal_cycles_now();
  if (s_isr != 0) s_isr(s_ctx);
  note_isr_cycles(hal_cycles_now() - c0);
  const uint32_t t1 = TIM2->CNT;
  stm32f4_qemu_plant_tick();
  const uint32_t t2 = TIM2->CNT;

  stm32f4_qemu_tick_stats_t *st = &s_tick;
  if (s_lost_skip > 0u) {
    s_lost_skip--;
  } else if (st->ticks > 0u) {
    /* Whole periods since the previous tick (< 4.3 s apart): more than one were lost. */
    const uint32_t periods = (t0 - s_t_prev_ns + st->period_ns / 2u) / st->period_ns;
    if (periods > 1u) st->lost += periods - 1u;
  }
  s_t_prev_ns = t0;
  st->ticks++;
  if ((SYSTICK->CTRL & SYSTICK_CTRL_COUNTFLAG) != 0u) st->overruns++;
  st->isr_ns_last = t1 - t0;
  st->plant_ns_last = t2 - t1;
  st->isr_ns_sum += st->isr_ns_last;
  st->plant_ns_sum += st->plant_ns_last;
  if (st->isr_ns_last > st->isr_ns_max) st->isr_ns_max = st->isr_ns_last;
  if (st->plant_ns_last > st->plant_ns_max) st->plant_ns_max = st->plant_ns_last;
}

void stm32f4_qemu_tick_stats(stm32f4_qemu_tick_stats_t *s)
{
  if (s == 0) return;
  const uint32_t pm = hal_critical_enter();
  *s = s_tick;
  hal_critical_exit(pm);
}

int stm32f4_qemu_set_stretch(uint32_t stretch)
{
  if (s_cycles_per_sample == 0u || stretch == 0u || stretch > 0x1000000u / s_cycles_per_sample) {
    return -1;
  }
  const uint32_t pm = hal_critical_enter();
  /* Taken at the next reload: the period running now keeps its length. */
  SYSTICK->LOAD = s_cycles_per_sample * stretch - 1u;
  s_tick.stretch = stretch;
  s_tick.period_ns = s_ns_per_sample * stretch;
  s_lost_skip = 2u;
  hal_critical_exit(pm);
  return 0;
}
#else
CM4_RAMFUNC void SysTick_Handler(void)
{
  s_wraps = s_wraps + 1u;
  const uint32_t c0 = hal_cycles_now();
  if (s_isr != 0) s_isr(s_ctx);
  note_isr_cycles(hal_cycles_now() - c0);
}
#endif

void stm32f4_qemu_idle(void)
{
  for (uint32_t i = 0u; i < STM32F4_QEMU_IDLE_SPINS; ++i) {
    __asm volatile("" ::: "memory");
  }
}

CM4_RAMFUNC uint32_t hal_cycles_now(void)
{
  uint32_t w1, w2, val;
  do {
    w1 = s_wraps;
    val = SYSTICK->VAL;
    w2 = s_wraps;
  } while (w1 != w2);
  const uint32_t load = SYSTICK->LOAD;
  return w1 * (load + 1u) + (load - val);
}

#ifndef STM32F4_QEMU_PLANT
static int16_t loopback_code(uint16_t dac_code)
{
  return (int16_t)(((int32_t)dac_code - (int32_t)HAL_DAC_CODE_MID) * 4);
}

CM4_RAMFUNC void hal_adc_read_frame(hal_adc_frame_t *frame)
{
  frame->drive = loopback_code(s_dac.code[HAL_DAC_DRIVE_U1]);
  frame->sense = loopback_code(s_dac.code[HAL_DAC_DRIVE_U2]);
}

CM4_RAMFUNC void hal_dac_write_frame(const hal_dac_frame_t *frame) { s_dac = *frame; }
#endif

void stm32f4_sample_stats(stm32f4_sample_stats_t *stats)
{
  if (stats == 0) return;
#ifdef STM32F4_QEMU_PLANT
  stats->overruns = s_tick.overruns;
#else
  stats->overruns = 0u;
#endif
  stats->dma_errors = 0u;
}

uint32_t stm32f4_dac_late(void) { return 0u; }

void stm32f4_uptime_init(void)
{
  TIM2->CR1 = 0u;
  TIM2->PSC = QEMU_TIM_HZ / 1000000u - 1u;
  TIM2->ARR = 0xFFFFFFFFu;
  TIM2->CR1 = TIM_CR1_CEN;
}

uint32_t stm32f4_uptime_us(void) { return TIM2->CNT; }
