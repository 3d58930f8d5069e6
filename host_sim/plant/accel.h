/* Linear acceleration and vibration acting on the two axes (g-sensitivity, thesis
 * §2.4.3; §4.4.2: shaking can push the pickoff out of the ADC range). Host plant.
 *
 * The caller passes the case acceleration each sample, in g along the gyro's axes:
 *   a[ACCEL_AXIS_DRIVE]  along the drive motion (y)
 *   a[ACCEL_AXIS_SENSE]  along the sense motion (x)
 *   a[ACCEL_AXIS_NORMAL] along the rate input axis (z)
 * (use its mean over the sample: the result is held over the sample like the other
 * forces). Both axes feel a force per unit mass (m/s^2), added to the actuator forces:
 *   f_drv = sum_i drive_mps2_per_g[i] a[i],   f_sen = sum_i sense_mps2_per_g[i] a[i]
 * For a single proof mass on springs, the inertial force is -m a: the coefficient of a
 * axis's own direction is -9.80665 (m/s^2)/g and the others are misalignment/cross-coupling
 * terms. The thesis's linear gyro has no counter-vibrating twin to cancel this (§2.2,
 * "no symmetric cancelling sense mass, acceleration sensitive"), so the defaults are the
 * full inertial response: 1 g static along the sense axis deflects it by
 * 9.81 / wn2^2 = 62 nm, about 3.8 V at the sense ring-diode output.
 */
#ifndef PLANT_ACCEL_H
#define PLANT_ACCEL_H

#define ACCEL_AXIS_DRIVE 0
#define ACCEL_AXIS_SENSE 1
#define ACCEL_AXIS_NORMAL 2
#define ACCEL_G0_MPS2 9.80665

typedef struct {
  double drive_mps2_per_g[3]; /* force per unit mass on the drive axis per g, per axis */
  double sense_mps2_per_g[3]; /* force per unit mass on the sense axis per g, per axis */
} accel_cfg_t;

typedef struct {
  accel_cfg_t cfg;
} accel_t;

typedef struct {
  double f_drive_mps2;
  double f_sense_mps2;
} accel_out_t;

/* drive {-g0, 0, 0}, sense {0, -g0, 0}: ideal single proof mass, aligned axes. */
void accel_default_cfg(accel_cfg_t *cfg);

/* Validates (finite, |coefficient| <= 100 g0). Returns 0 or -1 (a unchanged). */
int accel_init(accel_t *a, const accel_cfg_t *cfg);

/* Forces for the acceleration a_g[3] (g). Non-finite input gives zero force. */
void accel_step(const accel_t *a, const double a_g[3], accel_out_t *out);

#endif /* PLANT_ACCEL_H */
