/* Converters of the emulator image gyro-fw-qemu: the host plant model (host_sim/plant,
 * double precision, compiled for the target) in place of the AD7606 and AD5554, with the
 * same timing as the host HAL stub (hal/host/hal_host.c), so that a host run of the same
 * configuration sees the same sample sequence:
 *   tick k: the application's ISR reads adc(k) and writes dac(k) (pending);
 *           the plant steps over [t_k, t_k+1) with the frame written at tick k-1 on the
 *           outputs (the board's one-sample DAC latency) and returns adc(k+1);
 *           the pending frame becomes the active one.
 * Configuration (compile definitions of the image): the default plant ("thesis linear
 * gyro, air package"), seed STM32F4_QEMU_PLANT_SEED, and an input rate that is 0 deg/s
 * for STM32F4_QEMU_RATE_STEP_S seconds of plant time and then STM32F4_QEMU_RATE_DPS (a
 * rate-table step with a 10 ms edge), so one boot shows both the zero-rate output and
 * the response to an applied rate. Never linked into the product image. */
#ifndef STM32F4_QEMU_PLANT_H
#define STM32F4_QEMU_PLANT_H

#include <stdint.h>

/* Build the plant and take its first sample (converters at mid-scale). Returns 0, or -1
 * if the configuration is refused. */
int stm32f4_qemu_plant_init(void);

/* One sample of the plant, after the application's ISR (from the SysTick handler, which
 * runs in SRAM: hence the long call into flash). */
__attribute__((long_call)) void stm32f4_qemu_plant_tick(void);

/* Samples the plant has run. */
uint64_t stm32f4_qemu_plant_samples(void);

#endif /* STM32F4_QEMU_PLANT_H */
