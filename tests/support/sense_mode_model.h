/* The sense mode's model for the closed-loop tests of the sense axis: its static response
 * at the drive frequency, (2-24), what the firmware's loop designs and identifications
 * are checked against. */
#ifndef SENSE_MODE_MODEL_H
#define SENSE_MODE_MODEL_H

#include <math.h>

#include "dsp/math_const.h"

/* |H| (in 1/(rad/s)^2) and arg H of a mode at f_hz with quality factor q, driven at wc. */
static inline void mode_response(double f_hz, double q, double wc, double *mag, double *arg)
{
  const double ws = 2.0 * FM_PI * f_hz;
  const double re = ws * ws - wc * wc, im = wc * ws / q;
  *mag = 1.0 / sqrt(re * re + im * im);
  *arg = -atan2(im, re);
}

#endif /* SENSE_MODE_MODEL_H */
