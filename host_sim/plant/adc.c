#include "plant/adc.h"

#include <math.h>
#include <string.h>

void adc_default_cfg(adc_cfg_t *cfg)
{
  memset(cfg, 0, sizeof *cfg);
  cfg->full_scale_v = (double)HAL_ADC_FULL_SCALE_V;
}

int adc_init(adc_t *a, const adc_cfg_t *cfg)
{
  if (a == NULL || cfg == NULL) return -1;
  if (!(isfinite(cfg->full_scale_v) && cfg->full_scale_v > 0.0 && cfg->full_scale_v <= 100.0))
    return -1;
  if (!(isfinite(cfg->aperture_jitter_s) && cfg->aperture_jitter_s >= 0.0 &&
        cfg->aperture_jitter_s <= 1e-3))
    return -1;
  if (inl_check(&cfg->inl, ADC_BITS) != 0) return -1;
  memset(a, 0, sizeof *a);
  a->cfg = *cfg;
  a->inv_lsb = 32768.0 / cfg->full_scale_v;
  (void)inl_init(&a->inl, &cfg->inl, ADC_BITS, cfg->inl_seed, ADC_RNG_STREAM_INL);
  rng_seed(&a->rng_aperture, cfg->seed, ADC_RNG_STREAM_APERTURE);
  return 0;
}

void adc_set_ref(adc_t *a, double ref_rel) { a->ref_rel = ref_rel; }

double adc_aperture_draw(adc_t *a)
{
  if (!(a->cfg.aperture_jitter_s > 0.0)) return 0.0;
  return a->cfg.aperture_jitter_s * rng_gauss(&a->rng_aperture);
}

/* round(x), half away from zero, without libm's call (two conversions every sample; the
 * x86-64 baseline has no rounding instruction). Below 2^52 the fraction x - trunc(x) is
 * exact, so this is round() for every finite x; beyond, x is already an integer; NaN
 * passes through. */
static inline double round_half_away(double x)
{
  if (!(fabs(x) < 4503599627370496.0)) return x;
  const double t = (double)(long long)x;
  const double d = x - t;
  return d >= 0.5 ? t + 1.0 : (d <= -0.5 ? t - 1.0 : t);
}

/* INL (inl.h) at the code x would ideally give, in offset binary. */
static double inl_at(const adc_t *a, double x)
{
  const double r = round_half_away(x);
  long c = 0;
  if (r > (double)HAL_ADC_CODE_MAX) c = 65535;
  else if (r >= (double)HAL_ADC_CODE_MIN) c = (long)r + 32768;
  return inl_lsb(&a->inl, c);
}

int16_t adc_convert(adc_t *a, int ch, double v)
{
  if (ch < 0 || ch >= ADC_NCH) return 0;
  if (!isfinite(v)) {
    a->fault_count[ch]++;
    return 0;
  }
  double xv = v * a->inv_lsb;
  if (a->ref_rel != 0.0) xv /= 1.0 + a->ref_rel;
  if (a->inl.active) xv += inl_at(a, xv);
  const double x = round_half_away(xv);
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
