#include "plant/adc.h"

#include <math.h>
#include <string.h>

void adc_default_cfg(adc_cfg_t *cfg) { cfg->full_scale_v = (double)HAL_ADC_FULL_SCALE_V; }

int adc_init(adc_t *a, const adc_cfg_t *cfg)
{
  if (a == NULL || cfg == NULL) return -1;
  if (!(isfinite(cfg->full_scale_v) && cfg->full_scale_v > 0.0 && cfg->full_scale_v <= 100.0))
    return -1;
  memset(a, 0, sizeof *a);
  a->cfg = *cfg;
  a->inv_lsb = 32768.0 / cfg->full_scale_v;
  return 0;
}

int16_t adc_convert(adc_t *a, int ch, double v)
{
  if (ch < 0 || ch >= ADC_NCH) return 0;
  if (!isfinite(v)) {
    a->fault_count[ch]++;
    return 0;
  }
  const double x = round(v * a->inv_lsb);
  if (x > (double)HAL_ADC_CODE_MAX) {
    a->clip_count[ch]++;
    return (int16_t)HAL_ADC_CODE_MAX;
  }
  if (x < (double)HAL_ADC_CODE_MIN) {
    a->clip_count[ch]++;
    return (int16_t)HAL_ADC_CODE_MIN;
  }
  return (int16_t)x;
}

void adc_convert_frame(adc_t *a, double drive_v, double sense_v, hal_adc_frame_t *frame)
{
  frame->drive = adc_convert(a, ADC_CH_DRIVE, drive_v);
  frame->sense = adc_convert(a, ADC_CH_SENSE, sense_v);
}

double adc_code_to_v(const adc_t *a, int16_t code) { return (double)code / a->inv_lsb; }

void adc_clear_counts(adc_t *a)
{
  memset(a->clip_count, 0, sizeof a->clip_count);
  memset(a->fault_count, 0, sizeof a->fault_count);
}
