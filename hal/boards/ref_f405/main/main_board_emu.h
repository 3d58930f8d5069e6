/* The emulator image's own command (gyro-fw-qemu only, never in the product):
 *
 *   emu                 - stretch N, period_ns, ticks, tick_overruns, ticks_lost,
 *                         isr_ns_last/max/mean, plant_ns_last/max/mean (emulated ns:
 *                         instructions under -icount shift=0, hal/boards/ref_f405/qemu/
 *                         stm32f4_qemu.h), plant_rate_dps, trace n/len/every   ok emu
 *   emu rate DPS        ok rate DPS: move the plant's input rate to DPS (a 10 ms
 *                         rate-table ramp from the next tick); err VALUE / RANGE / BUSY
 *   emu part NAME       ok part NAME: another part in the emulator's socket from the next
 *                         tick, `default` or `fr` (qemu_plant_setup.h: a part force
 *                         rebalance can run on), the drive off; err VALUE / STATE / BUSY
 *   emu stretch N       ok stretch N: SysTick period of N sample periods from the next
 *                         tick (stm32f4_qemu_set_stretch); err RANGE
 *   emu trace FROM      - I VALUE for up to 16 entries of the rate-output trace from
 *                         index FROM (qemu_plant_setup.h), ok trace N; err ARGS/RANGE
 * and the plant in place of the converters (hal/boards/ref_f405/qemu/stm32f4_qemu_plant.h). */
#ifndef MAIN_BOARD_EMU_H
#define MAIN_BOARD_EMU_H

#include "app/app.h"

/* Register `emu` with the application's command line and point the trace at the rate
 * output. Returns 0, or -1 if the command table is full. */
int main_board_emu_init(app_t *a);

#endif /* MAIN_BOARD_EMU_H */
