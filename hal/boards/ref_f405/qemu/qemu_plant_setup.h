/* The plant of the emulator image gyro-fw-qemu, as one configuration that the image and
 * its host twin (tests/qemu/fw_qemu_twin.c, the same application through the host HAL)
 * both build, so that the two runs see the same converters:
 *   plant       plant_default_cfg ("thesis linear gyro, air package"), seed
 *               QEMU_PLANT_SEED
 *   rate input  0 deg/s for QEMU_PLANT_STEP_S of plant time, then QEMU_PLANT_STEP_DPS
 *               (a rate-table step with a QEMU_PLANT_EDGE_S linear edge); constant
 *               ambient temperature, no acceleration
 *   trace       the firmware's rate output every QEMU_TRACE_EVERY ticks, QEMU_TRACE_LEN
 *               entries from the first tick of the sample clock (10^5 ticks, 2 s of
 *               plant time: acquisition, lock, the step)
 * Portable C (double precision, the plant's own API): compiled into the image's board
 * layer and into the host twin. */
#ifndef QEMU_PLANT_SETUP_H
#define QEMU_PLANT_SETUP_H

#include "plant/plant.h"

#define QEMU_PLANT_SEED 1u
#define QEMU_PLANT_STEP_S 0.5
#define QEMU_PLANT_STEP_DPS 100.0
#define QEMU_PLANT_EDGE_S 0.01

#define QEMU_TRACE_EVERY 100u
#define QEMU_TRACE_LEN 1000u

/* plant_init with the configuration above and the rate step set as its profile.
 * prof receives the profiles in force (for later changes by qemu_plant_rate_ramp).
 * Returns 0, or the plant's error code (-1/-2; reason in plant_error(p)). */
int qemu_plant_setup(plant_t *p, plant_profiles_t *prof);

/* Replace the rate profile by a linear ramp from the rate at the plant's current time
 * to rate_dps over QEMU_PLANT_EDGE_S, then held (a rate-table move). Returns 0, or -1
 * (rate out of the profile's range; nothing changed). */
int qemu_plant_rate_ramp(plant_t *p, plant_profiles_t *prof, double rate_dps);

#endif /* QEMU_PLANT_SETUP_H */
