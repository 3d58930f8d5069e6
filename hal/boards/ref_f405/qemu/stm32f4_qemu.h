/* The emulator board's own controls, and the figures of the emulator image's sample clock (gyro-fw-qemu: SysTick, stretched by
 * STM32F4_QEMU_TICK_STRETCH, with the plant stepped after the application's ISR).
 *
 * Times are emulated nanoseconds from TIM2 counting QEMU's 1 GHz timer input undivided
 * (only CR1, PSC and ARR are written: QEMU's TIM2 misbehaves when EGR or CNT is). Under
 * `-icount shift=0` QEMU advances emulated time by exactly 1 ns per instruction, so these
 * figures are instruction counts (tools/bench/target uses the same counter); under
 * shift=auto they are emulated time, 2^shift ns per instruction.
 *   isr_ns     SysTick entry to the return of the application's ISR (the handler's own
 *              bookkeeping, app_sample_isr with its ADC frame and hal_dac_write_frame):
 *              what the board's sample interrupt runs, without the plant
 *   plant_ns   the plant's step after it (emulator only)
 *   overruns   ticks whose handler was still running when the next period began
 *              (SysTick COUNTFLAG set again before the handler returned)
 *   lost       periods of the emulated clock without a handler run: emulated time since
 *              the first tick over the period, against the ticks counted (a period lost
 *              to an overrun, or to QEMU delivering SysTick late) */
#ifndef STM32F4_QEMU_H
#define STM32F4_QEMU_H

#include <stdint.h>

typedef struct {
  uint32_t stretch;   /* SysTick period in 50 kHz sample periods */
  uint32_t period_ns; /* emulated time between ticks */
  uint32_t ticks;
  uint32_t overruns;
  uint32_t lost;
  uint32_t isr_ns_last, isr_ns_max;
  uint64_t isr_ns_sum;
  uint32_t plant_ns_last, plant_ns_max;
  uint64_t plant_ns_sum;
} stm32f4_qemu_tick_stats_t;

/* A consistent copy (taken with the sample interrupt masked). */
void stm32f4_qemu_tick_stats(stm32f4_qemu_tick_stats_t *s);

/* Change the stretch while the sample clock runs (from the next period on): 1 .. 4993
 * (SysTick's 24-bit reload). The firmware and the plant still advance one sample per
 * tick; only the emulated time between ticks changes. Returns 0, or -1 (out of range,
 * or the sample clock not started). */
int stm32f4_qemu_set_stretch(uint32_t stretch);

/* The emulator's background loop pauses here between passes (both QEMU images): under
 * -icount every access to a peripheral register ends QEMU's translation block and is
 * executed again on its own, so a loop that polls registers back to back runs more than
 * ten times slower per instruction than ordinary code, and -icount shift=auto then
 * stretches every instruction's emulated time to match (measured at -icount shift=4,
 * stretch 64: 297 ticks/s without the pause, 1450-4016 with it, hal/boards/ref_f405/README.md).
 * A spin of a few thousand register-free instructions keeps the UART answering within
 * microseconds of emulated time. */
void stm32f4_qemu_idle(void);

/* With STM32F4_QEMU_FLASH_MODEL: the parameter sectors modelled in SRAM
 * (stm32f4_qemu_flash.c) set to the factory image; called by stm32f4_board_init before the store is
 * read. */
void stm32f4_qemu_flash_init(void);
/* The parameter-store image the emulated part left the factory with: the default part's
 * calibration (host_sim/parts/default/calibration.json, made by tools/calibrate), encoded
 * at build time by tools/gen_factory_store.py. */
extern const uint8_t stm32f4_qemu_factory_store[];
extern const uint32_t stm32f4_qemu_factory_store_len;

#endif /* STM32F4_QEMU_H */
