/* The plant's mathematical constants (double precision, like the whole plant): the one
 * place pi is written on the simulator's side (the firmware has dsp/math_const.h). The
 * simulator and the host tools that drive the plant use these too. A standing test
 * (tests/structure/check_layers.py) fails on a pi literal or M_PI anywhere else. */
#ifndef PLANT_CONST_H
#define PLANT_CONST_H

#define PLANT_PI 3.14159265358979323846
#define PLANT_TWO_PI 6.28318530717958647692 /* exactly 2 * PLANT_PI in double */
#define PLANT_RAD_PER_DEG (PLANT_PI / 180.0)
#define PLANT_DEG_PER_RAD (180.0 / PLANT_PI)
#define PLANT_K_AT_0_C 273.15 /* kelvin at 0 degC */

#endif /* PLANT_CONST_H */
