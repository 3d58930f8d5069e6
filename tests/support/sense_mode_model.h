/* The closed-loop tests of the sense axis: their part (a sense mode 110 Hz above the
 * drive's, the feedback pair) and its model: the static response at the drive frequency,
 * (2-24), what the firmware's loop designs and identifications are checked against. */
#ifndef SENSE_MODE_MODEL_H
#define SENSE_MODE_MODEL_H

#include <math.h>

#include "dsp/math_const.h"
#include "plant/plant.h"

#define SENSE_TEST_F_HZ 1600.0 /* 110 Hz above the default drive */
#define SENSE_TEST_KS_FB 0.1   /* (m/s^2)/V^2: 1500 deg/s of quadrature at 7 V */

/* |H| (in 1/(rad/s)^2) and arg H of a mode at f_hz with quality factor q, driven at wc. */
static inline void mode_response(double f_hz, double q, double wc, double *mag, double *arg)
{
  const double ws = 2.0 * FM_PI * f_hz;
  const double re = ws * ws - wc * wc, im = wc * ws / q;
  *mag = 1.0 / sqrt(re * re + im * im);
  *arg = -atan2(im, re);
}

/* The default plant with its sense mode at SENSE_TEST_F_HZ of quality q_sense, the
 * half-frequency feedback pair (fb_mode 3) at SENSE_TEST_KS_FB, every noise source off
 * (the figures are the loops', not the noise's). */
static inline void sense_test_part(plant_cfg_t *pc, double q_sense)
{
  plant_default_cfg(pc);
  pc->f_sense_hz = SENSE_TEST_F_HZ;
  pc->q_sense = q_sense;
  pc->fb_mode = 3;
  pc->ks_fb_mps2_per_v2 = SENSE_TEST_KS_FB;
  pc->brownian = 0;
  pc->pick_sense_noise_v_rthz = pc->pick_drive_noise_v_rthz = 0.0;
  pc->drive_noise_white_v_rthz = pc->drive_noise_1hz_v_rthz = 0.0;
  pc->fb_noise_white_v_rthz = pc->fb_noise_1hz_v_rthz = 0.0;
  pc->tune_noise_white_v_rthz = pc->tune_noise_1hz_v_rthz = 0.0;
}

#endif /* SENSE_MODE_MODEL_H */
