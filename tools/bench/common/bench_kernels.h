/* Benchmark cases shared by the Cortex-M4F image (QEMU, instruction counts from the
 * emulated clock) and the host program (callgrind): every DSP kernel of the sample path
 * and the whole gyro_tick, each on realistic data.
 *
 * Counting convention (target): a case calls its kernel through a function pointer from
 * a loop, reading the instruction counter (bk_now, bench_now.h of the platform: TIM2 at
 * one count per instruction under QEMU -icount shift=0 on the target, 0 on the host,
 * where callgrind counts) just before and just after the call;
 * the same loop is then run calling an empty function of the same type. The kernel's
 * count per sample is the difference: the kernel's own instructions with its arguments
 * in registers and its state in memory, as the tick sees it, excluding the caller's
 * BL/argument set-up (an inline kernel costs no call in the tick). Per-call min and max
 * are kept, so kernels with data-dependent paths (gyro_tick's decimated rate filter)
 * show their worst tick.
 *
 * Kernels that are static inline in their header (lmsd_step, biquad_cascade_step,
 * pi_step, multdemod_step) are compiled into one-line noinline wrappers here; the
 * others are called directly. The data are generated at set-up, outside the counts.
 */
#ifndef BENCH_KERNELS_H
#define BENCH_KERNELS_H

#include <stdint.h>

typedef enum {
  BK_LMSD = 0,
  BK_BIQUAD1,
  BK_BIQUAD2,
  BK_SINCOS,
  BK_NCO,
  BK_PI,
  BK_RLSD,
  BK_KFD,
  BK_MULTDEMOD,
  BK_GYRO_TICK,
  BK_COUNT
} bk_id_t;

typedef struct {
  uint64_t sum;
  uint32_t n, min, max;
} bk_stat_t;

typedef struct {
  bk_stat_t kern;  /* counter deltas around the kernel call */
  bk_stat_t base;  /* the same loop around an empty call */
  uint32_t locked; /* gyro_tick: 1 if the gyro stayed LOCKED through the run */
} bk_result_t;

/* Case name as printed ("lmsd_step", ...), or NULL for an invalid id. */
const char *bk_name(bk_id_t id);

/* The function whose inclusive cost is the case's kernel (the wrapper of an inline
 * kernel, or the kernel itself): what the host reads out of callgrind. */
const char *bk_symbol(bk_id_t id);

/* Design the filters, generate the data, bring the gyro to LOCKED through the bench
 * plant (bench_plant.h). Returns 0, or a negative value naming the step that failed. */
int bk_setup(void);

/* Run case id n times and the empty loop n times. Returns 0, or -1 for a bad id or
 * before a successful bk_setup. */
int bk_run(bk_id_t id, uint32_t n, bk_result_t *r);

/* Kernel-only run (no empty loop): the host's callgrind target. bk_prepare first puts
 * the case in its starting state (gyro_tick: lock-up through the plant), so that the
 * callgrind window can hold the kernel calls only. */
int bk_prepare(bk_id_t id);
int bk_run_kernel_only(bk_id_t id, uint32_t n);

/* 1 if the gyro of the gyro_tick case is LOCKED now. */
uint32_t bk_gyro_locked(void);

void bk_stat_reset(bk_stat_t *s);
void bk_stat_add(bk_stat_t *s, uint32_t v);

#endif /* BENCH_KERNELS_H */
