/* Instruction counter of the bench image: TIM2 with prescaler 1 on QEMU's STM32 timer
 * model, which counts emulated nanoseconds; under -icount shift=0 QEMU advances emulated
 * time by exactly 1 ns per executed instruction, so the counter counts instructions.
 * (Only CR1, PSC and ARR are written: QEMU's TIM2 misbehaves when EGR or CNT is.) */
#ifndef BENCH_NOW_H
#define BENCH_NOW_H

#include <stdint.h>

#include "stm32f4_regs.h"

static inline uint32_t bk_now(void) { return TIM2->CNT; }

#endif /* BENCH_NOW_H */
