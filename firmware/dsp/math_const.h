/* The firmware's mathematical constants: the one place pi is written (host_sim/plant has
 * the plant's own, plant_const.h). A standing test (tests/structure/check_layers.py)
 * fails on a pi literal or M_PI anywhere else.
 *
 * Each constant exists in the precision its users compute in: double for the init-time
 * design code (loop design, filter design, self-calibration fit), float for the sample
 * path (-Wdouble-promotion: a double constant there would promote the whole expression).
 * The float literals are the double values rounded once, so FM_PI_F == (float)FM_PI. */
#ifndef MATH_CONST_H
#define MATH_CONST_H

#define FM_PI 3.14159265358979323846      /* double */
#define FM_TWO_PI 6.283185307179586476925 /* double, exactly 2 * FM_PI */
#define FM_DEG_PER_RAD 57.29577951308232  /* double, 180 / pi */

#define FM_PI_F 3.14159265358979f
#define FM_TWO_PI_F 6.28318530717959f
#define FM_INV_TWO_PI_F 0.159154943f /* 1 / (2 pi) */
#define FM_DEG_PER_RAD_F 57.2957795130823f
#define FM_RAD_PER_DEG_F 0.0174532925199433f

#endif /* MATH_CONST_H */
