/* Converters of the emulator image gyro-fw-qemu: the host plant model (host_sim/plant,
 * double precision, compiled for the target) in place of the AD7606 and AD5554, with the
 * same timing as the host HAL stub (hal/host/hal_host.c), so that a host run of the same
 * configuration sees the same sample sequence:
 *   tick k: the application's ISR reads adc(k) and writes dac(k) (pending);
 *           the plant steps over [t_k, t_k+1) with the frame written at tick k-1 on the
 *           outputs (the board's one-sample DAC latency) and returns adc(k+1);
 *           the pending frame becomes the active one.
 * Configuration: qemu_plant_setup.h (default plant, fixed seed, a compiled-in rate step
 * at 0.5 s), which the host twin shares. The input rate can be changed at run time
 * (stm32f4_qemu_plant_set_rate, the image's `emu rate` command): a rate-table move
 * applied at the next tick. A trace of the firmware's rate output (qemu_plant_setup.h)
 * is recorded from the first tick for the equivalence test. The board temperature
 * sensor (hal_board_temp.h) is the plant's (plant_board_temp_hal), read as the host HAL
 * stub reads it. Never linked into the product image. */
#ifndef STM32F4_QEMU_PLANT_H
#define STM32F4_QEMU_PLANT_H

#include <stdint.h>

/* Build the plant and take its first sample (converters at mid-scale). Returns 0, or a
 * negative value if the configuration is refused. */
int stm32f4_qemu_plant_init(void);

/* One sample of the plant, after the application's ISR (from the SysTick handler, which
 * runs in SRAM: hence the long call into flash). */
__attribute__((long_call)) void stm32f4_qemu_plant_tick(void);

/* Samples the plant has run. */
uint64_t stm32f4_qemu_plant_samples(void);

/* Input rate the plant applies now (deg/s, from its truth). */
double stm32f4_qemu_plant_rate_dps(void);

/* Request a move of the input rate to rate_dps (taken by the next tick). Returns 0, -1
 * if the value is out of range (|rate| <= 1e4 deg/s, finite), -2 if the previous request
 * has not been taken yet. */
int stm32f4_qemu_plant_set_rate(double rate_dps);

/* The rate output to trace: the firmware's (read once per tick after its ISR). */
/* Background: the emulated plant replaced by part QEMU_PART_* (qemu_plant_setup.h) at
 * the next tick. Returns 0, -1 (unknown part) or -2 (a request not yet taken). */
int stm32f4_qemu_plant_set_part(int part);

void stm32f4_qemu_plant_trace_from(const volatile float *rate_dps);

/* Entries recorded so far (0..QEMU_TRACE_LEN), and entry i (0 if i is past them). */
uint32_t stm32f4_qemu_trace_count(void);
float stm32f4_qemu_trace_at(uint32_t i);

#endif /* STM32F4_QEMU_PLANT_H */
