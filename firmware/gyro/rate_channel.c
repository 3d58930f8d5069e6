#include "gyro/rate_channel.h"

#include <stddef.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"

/* Fast start of P's low-pass after a hold (rate_channel_hold_p): the held value counts
 * as RATE_P_PRIOR means; the running mean ends after RATE_P_FAST_MAX means at most. */
#define RATE_P_PRIOR 4u
#define RATE_P_FAST_MAX 1000u

static int finite4(const float *c)
{
  return fm_isfinite(c[0]) && fm_isfinite(c[1]) && fm_isfinite(c[2]) && fm_isfinite(c[3]);
}

static int cfg_ok(const rate_channel_cfg_t *cfg)
{
  return cfg != NULL && cfg->lpf != NULL && fm_isfinite(cfg->ref_re) &&
         fm_isfinite(cfg->ref_im) && cfg->ref_re * cfg->ref_re + cfg->ref_im * cfg->ref_im > 0.0f &&
         fm_isfinite(cfg->scale_dps) && finite4(cfg->bias_c_dps) && finite4(cfg->sf_c) &&
         cfg->p_lpf_alpha > 0.0f && cfg->p_lpf_alpha <= 1.0f && cfg->min_drive_v > 0.0f &&
         fm_isfinite(cfg->min_drive_v) && fm_isfinite(cfg->p_ref_deg) &&
         cfg->p_mode_k > 0.0f && cfg->p_mode_k <= 1.0f;
}

static void copy_coeffs(rate_channel_t *rc, const rate_channel_cfg_t *cfg)
{
  rc->ref_re = cfg->ref_re;
  rc->ref_im = cfg->ref_im;
  rc->scale_dps = cfg->scale_dps;
  for (int i = 0; i < 4; i++) {
    rc->bias_c_dps[i] = cfg->bias_c_dps[i];
    rc->sf_c[i] = cfg->sf_c[i];
  }
  rc->p_lpf_alpha = cfg->p_lpf_alpha;
  rc->p_mode_k = cfg->p_mode_k;
  rc->min_drive_v2 = cfg->min_drive_v * cfg->min_drive_v;
}

int rate_channel_init(rate_channel_t *rc, const rate_channel_cfg_t *cfg)
{
  if (rc == NULL || !cfg_ok(cfg)) {
    return -1;
  }
  biquad_cascade_t a, b;
  if (biquad_cascade_init(&a, cfg->lpf, cfg->lpf_sections) != 0 ||
      biquad_cascade_init(&b, cfg->lpf, cfg->lpf_sections) != 0) {
    return -1;
  }
  rc->lpf_rate = a;
  rc->lpf_quad = b;
  copy_coeffs(rc, cfg);
  rc->p_ref_deg = cfg->p_ref_deg;
  rc->p_hold = 0u;
  rc->p_n = RATE_P_FAST_MAX; /* no fast start without a hold */
  rc->p_a_mean = 0.0f;        /* set before its use (rate_channel_update_p) */
  rate_channel_reset(rc, cfg->p_ref_deg);
  return 0;
}

int rate_channel_retune(rate_channel_t *rc, const rate_channel_cfg_t *cfg)
{
  if (rc == NULL || !cfg_ok(cfg)) {
    return -1;
  }
  biquad_cascade_t a = rc->lpf_rate, b = rc->lpf_quad;
  const uint32_t old_n = a.num_sections;
  if (biquad_cascade_init(&a, cfg->lpf, cfg->lpf_sections) != 0 ||
      biquad_cascade_init(&b, cfg->lpf, cfg->lpf_sections) != 0) {
    return -1;
  }
  if (cfg->lpf_sections == old_n) {
    /* Same structure: keep the filter memory, swap only the coefficients. */
    for (uint32_t i = 0; i < old_n; i++) {
      a.state[i] = rc->lpf_rate.state[i];
      b.state[i] = rc->lpf_quad.state[i];
    }
  }
  rc->lpf_rate = a;
  rc->lpf_quad = b;
  copy_coeffs(rc, cfg);
  /* P_f is kept as it is, re-expressed around the new reference. */
  rc->p_dev_deg = rc->p_f_deg - cfg->p_ref_deg;
  rc->p_ref_deg = cfg->p_ref_deg;
  rc->p_acc_deg = 0.0f;
  rc->p_count = 0u;
  return 0;
}

GYRO_RAMFUNC void rate_channel_reset(rate_channel_t *rc, float p_deg)
{
  biquad_cascade_reset(&rc->lpf_rate, 0.0f);
  biquad_cascade_reset(&rc->lpf_quad, 0.0f);
  rc->rate_raw = 0.0f;
  rc->quad_raw = 0.0f;
  rc->acc_re = 0.0f;
  rc->acc_im = 0.0f;
  rc->rate_unc_dps = 0.0f;
  rc->quad_dps = 0.0f;
  rc->p_acc_deg = 0.0f;
  rc->p_count = 0u;
  rc->p_dev_deg = p_deg - rc->p_ref_deg;
  rc->p_held_dev_deg = rc->p_dev_deg;
  rc->p_held_w = 0.0f;
  rc->p_mode_rad = rc->p_dev_deg * FM_RAD_PER_DEG_F;
  rc->p_f_deg = p_deg;
  rc->rate_dps = 0.0f;
}

/* Blocks of RATE_DECIM ticks per low-pass sample of P. */
#define RATE_P_BLOCKS (RATE_P_DECIM / RATE_DECIM)
_Static_assert(RATE_P_DECIM % RATE_DECIM == 0u && RATE_P_BLOCKS >= 2u,
               "P's average spans whole blocks, at least two");

GYRO_RAMFUNC void rate_channel_project(rate_channel_t *rc, float d_s, float d_c, float p_rad)
{
  const float k = 1.0f / (float)RATE_DECIM;
  const float s_s = rc->acc_re * k, s_c = rc->acc_im * k;
  rc->acc_re = 0.0f;
  rc->acc_im = 0.0f;
  /* (6-17): the true drive phase follows P through the mode's lag. Work on P - p_ref
   * (small) so the float low-pass has no dead band. */
  const float p_dev_rad = p_rad - rc->p_ref_deg * FM_RAD_PER_DEG_F;
  rc->p_mode_rad += rc->p_mode_k * (p_dev_rad - rc->p_mode_rad);
  const float delta = rc->p_mode_rad - rc->p_dev_deg * FM_RAD_PER_DEG_F;
  float re = 0.0f, im = 0.0f;
  if (d_s * d_s + d_c * d_c > rc->min_drive_v2) {
    /* S conj(e^{j psi} / A_set), then turned by -delta (small angle: e^{-j delta} ~ 1 - j delta) */
    const float r0 = s_s * rc->ref_re + s_c * rc->ref_im;
    const float i0 = s_c * rc->ref_re - s_s * rc->ref_im;
    re = r0 + delta * i0;
    im = i0 - delta * r0;
  }
  rc->rate_raw = re;
  rc->quad_raw = im;
}

GYRO_RAMFUNC void rate_channel_filter_rate(rate_channel_t *rc)
{
  rc->rate_unc_dps = rc->scale_dps * biquad_cascade_step(&rc->lpf_rate, rc->rate_raw);
  /* Temperature compensation in P_f (the thesis fits the bias linear in P, 7.3.2). */
  const float p = rc->p_f_deg;
  const float *b3 = rc->bias_c_dps, *s3 = rc->sf_c;
  const float bias = b3[0] + p * (b3[1] + p * (b3[2] + p * b3[3]));
  const float sf = 1.0f + p * (s3[1] + p * (s3[2] + p * s3[3]));
  rc->rate_dps = rc->rate_unc_dps * sf - bias;
}

GYRO_RAMFUNC void rate_channel_filter_quad(rate_channel_t *rc)
{
  rc->quad_dps = rc->scale_dps * biquad_cascade_step(&rc->lpf_quad, rc->quad_raw);
}

void rate_channel_update(rate_channel_t *rc, float d_s, float d_c, float p_rad)
{
  rate_channel_project(rc, d_s, d_c, p_rad);
  rate_channel_filter_rate(rc);
  rate_channel_filter_quad(rc);
}

GYRO_RAMFUNC void rate_channel_shift_p(rate_channel_t *rc, float shift_deg)
{
  rc->p_dev_deg += shift_deg;
  rc->p_f_deg += shift_deg;
  rc->p_held_dev_deg += shift_deg;
  rc->p_acc_deg += shift_deg * (float)rc->p_count;
  rc->p_mode_rad += shift_deg * FM_RAD_PER_DEG_F;
}

GYRO_RAMFUNC int rate_channel_update_p(rate_channel_t *rc, float p_rad)
{
  if (rc->p_hold != 0u) {
    rc->p_acc_deg = 0.0f;
    rc->p_count = 0u;
    rc->p_n = 0u;
    rc->p_held_dev_deg = rc->p_dev_deg;
    rc->p_held_w = 1.0f;
  } else {
    rc->p_acc_deg += p_rad * FM_DEG_PER_RAD_F - rc->p_ref_deg;
    if (++rc->p_count == 1u && rc->p_n < RATE_P_FAST_MAX) {
      /* The fast start's weight of the coming mean, divided here (on the first block of
       * the RATE_P_BLOCKS) rather than with the low-pass (on the last): each block of the
       * sample interrupt carries at most one divide. */
      rc->p_a_mean = 1.0f / (float)(rc->p_n + 1u + RATE_P_PRIOR);
    }
    if (rc->p_count == RATE_P_BLOCKS) {
      const float mean = rc->p_acc_deg * (1.0f / (float)RATE_P_BLOCKS);
      /* Fast start after a hold: the running mean of the means seen since the release
       * (the held value weighing as RATE_P_PRIOR of them) until its weight falls to the
       * low-pass's own, then the low-pass. */
      float a = rc->p_lpf_alpha;
      if (rc->p_n < RATE_P_FAST_MAX) {
        rc->p_n++;
        const float a_mean = rc->p_a_mean; /* 1 / (p_n + RATE_P_PRIOR) */
        if (a_mean > a) {
          a = a_mean;
        } else {
          rc->p_n = RATE_P_FAST_MAX; /* the low-pass from here on */
        }
      }
      /* Both the running mean and the low-pass scale what the held value still weighs
       * by (1 - a): it tells how far P_f may still be from P (rate_valid_thermo). */
      rc->p_held_w *= 1.0f - a;
      rc->p_dev_deg += a * (mean - rc->p_dev_deg);
      rc->p_f_deg = rc->p_ref_deg + rc->p_dev_deg;
      rc->p_acc_deg = 0.0f;
      rc->p_count = 0u;
      return 1;
    }
  }
  return 0;
}

