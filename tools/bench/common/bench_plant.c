#include "bench_plant.h"

#include <math.h>
#include <stddef.h>

#include "dsp/math_const.h"
#include "dsp/sincos.h"

#define PLANT_DITHER_LSB 2.0f
#define PLANT_SENSE_RE 0.05f /* Coriolis part: a rate of 5 % of the drive pickoff */
#define PLANT_SENSE_IM 0.02f /* quadrature */

int bench_plant_init(bench_plant_t *p, const gyro_design_t *d, const param_values_t *v)
{
  if (p == NULL || d == NULL || v == NULL || nco_init(&p->nco, &d->nco) != 0) {
    return -1;
  }
  const double tau = 2.0 * (double)v->drive_cal_q / (2.0 * FM_PI * (double)v->drive_cal_f0_hz);
  p->alpha = (float)(1.0 / ((double)v->sys_fs_hz * tau));
  p->gain = v->drive_cal_gain_v_per_v2;
  p->amp_v = v->drive_amp_set_v;
  p->theta_rad = d->drive.phase_set_rad;
  p->theta0_rad = d->drive.phase_set_rad - d->drive.p_init_rad;
  p->sense_re = PLANT_SENSE_RE;
  p->sense_im = PLANT_SENSE_IM;
  p->lcg = 12345u;
  return 0;
}

static float dither(bench_plant_t *p)
{
  p->lcg = p->lcg * 1664525u + 1013904223u;
  /* top 16 bits -> [-1, 1) */
  const float u = (float)(p->lcg >> 16) * (1.0f / 32768.0f) - 1.0f;
  return PLANT_DITHER_LSB * u;
}

static int16_t to_code(float v, float lsb_dither)
{
  float c = v * (1.0f / HAL_ADC_V_PER_CODE) + lsb_dither;
  c = c >= 0.0f ? c + 0.5f : c - 0.5f;
  if (c > (float)HAL_ADC_CODE_MAX) c = (float)HAL_ADC_CODE_MAX;
  if (c < (float)HAL_ADC_CODE_MIN) c = (float)HAL_ADC_CODE_MIN;
  return (int16_t)c;
}

void bench_plant_frame(bench_plant_t *p, const gyro_t *g, hal_adc_frame_t *adc)
{
  /* Envelope update from the loop outputs of the last tick (one-sample DAC latency). */
  const float f_cmd = g->drive.f_cmd_v2;
  const float p_rad = g->drive.p_rad;
  p->amp_v += (p->gain * f_cmd - p->amp_v) * p->alpha;
  p->theta_rad += (p_rad + p->theta0_rad - p->theta_rad) * p->alpha;

  nco_out_t ref;
  nco_step(&p->nco, &ref);
  float s, c;
  sincos_lut(ref.phase + sincos_rad_to_phase(p->theta_rad), &s, &c);
  /* v = a sin(phi + theta): the drive phasor a e^{j theta}; the sense phasor is the
   * drive phasor times (sense_re + j sense_im). */
  const float v_drive = p->amp_v * s;
  const float v_sense = p->amp_v * (p->sense_re * s + p->sense_im * c);
  adc->drive = to_code(v_drive, dither(p));
  adc->sense = to_code(v_sense, dither(p));
}
