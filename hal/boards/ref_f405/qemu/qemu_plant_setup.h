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

/* The emulator's parts (`emu part NAME`): the default one above, and the closed-loop
 * sense tests' (tests/support/sense_mode_model.h): the default plant with its sense mode
 * at 1600 Hz (a 110 Hz split above the drive) of Q 1e4 and the half-frequency feedback
 * pair (fb_mode 3, Ks_fb 0.1 (m/s^2)/V^2), its noise sources on, so that force
 * rebalance (sense.mode 1) can run on the emulated board. */
#define QEMU_PART_DEFAULT 0
#define QEMU_PART_FR 1
#define QEMU_PART_FR_F_SENSE_HZ 1600.0
#define QEMU_PART_FR_Q_SENSE 1.0e4
#define QEMU_PART_FR_KS_FB 0.1

/* plant_init with part's configuration (QEMU_PART_*) at rest: zero rate, the ambient
 * constant. Returns 0, -3 for an unknown part, or the plant's error code. */
int qemu_plant_setup_part(plant_t *p, plant_profiles_t *prof, int part);

/* Replace the rate profile by a linear ramp from the rate at the plant's current time
 * to rate_dps over QEMU_PLANT_EDGE_S, then held (a rate-table move). Returns 0, or -1
 * (rate out of the profile's range; nothing changed). */
int qemu_plant_rate_ramp(plant_t *p, plant_profiles_t *prof, double rate_dps);

#endif /* QEMU_PLANT_SETUP_H */
