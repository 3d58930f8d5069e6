/* The closed-loop tests of the sense axis: their part (a sense mode 110 Hz above the
 * drive's, the feedback pair) and its model: the static response at the drive frequency,
 * (2-24), what the firmware's loop designs and identifications are checked against. */
#ifndef SENSE_MODE_MODEL_H
#define SENSE_MODE_MODEL_H

#include <math.h>

#include "default_part.h"
#include "dsp/math_const.h"
#include "params/params.h"
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

/* The rate channel's calibration of v (the default part's, its demodulation phase and
 * scale) moved from the default plant's sense mode to a mode at f_hz of quality q, as the
 * calibration flow would find it on that part: the mode's phase and gain at v's drive
 * frequency (2-24). */
static inline void sense_test_cal_moved(param_values_t *v, double f_hz, double q)
{
  plant_cfg_t def;
  plant_default_cfg(&def);
  const double wc = 2.0 * FM_PI * (double)v->drive_freq_hz;
  double m0, a0, m1, a1;
  mode_response(def.f_sense_hz, def.q_sense, wc, &m0, &a0);
  mode_response(f_hz, q, wc, &m1, &a1);
  v->rate_demod_phase_deg += (float)((a1 - a0) * FM_DEG_PER_RAD);
  v->rate_scale_dps = (float)((double)v->rate_scale_dps * m0 / m1);
}

/* The default part's values, its rate calibration moved to a sense mode at f_hz of
 * quality q (declared force rebalance's: a calibration of another sense configuration is
 * stale), the sense identification and force rebalance on, no autostart: the sweep runs
 * from power-on. */
static inline void sense_test_fr_sweep_values(param_values_t *v, double f_hz, double q)
{
  default_part_values(v);
  sense_test_cal_moved(v, f_hz, q);
  v->sys_autostart = 0u;
  v->sense_cal = 1u;
  v->sense_mode = 1u;
  v->cal_ref_sense_mode = 1u;
}

/* The default plant with its sense mode at SENSE_TEST_F_HZ of quality q_sense and the
 * half-frequency feedback pair (fb_mode 3) at SENSE_TEST_KS_FB, the default plant's noise
 * and imperfections on: the part as gyro-sim runs it. */
static inline void sense_test_noisy_part(plant_cfg_t *pc, double q_sense)
{
  plant_default_cfg(pc);
  pc->f_sense_hz = SENSE_TEST_F_HZ;
  pc->q_sense = q_sense;
  pc->fb_mode = 3;
  pc->ks_fb_mps2_per_v2 = SENSE_TEST_KS_FB;
}

/* The same part with every noise source off (the figures are the loops', not the
 * noise's). */
static inline void sense_test_part(plant_cfg_t *pc, double q_sense)
{
  sense_test_noisy_part(pc, q_sense);
  pc->brownian = 0;
  pc->pick_sense_noise_v_rthz = pc->pick_drive_noise_v_rthz = 0.0;
  pc->drive_noise_white_v_rthz = pc->drive_noise_1hz_v_rthz = 0.0;
  pc->fb_noise_white_v_rthz = pc->fb_noise_1hz_v_rthz = 0.0;
  pc->tune_noise_white_v_rthz = pc->tune_noise_1hz_v_rthz = 0.0;
}

#endif /* SENSE_MODE_MODEL_H */
