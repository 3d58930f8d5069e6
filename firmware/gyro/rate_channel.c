#include "gyro/rate_channel.h"

#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"
#include "gyro/comp_filters.h"

/* Fast start of P's low-pass after a hold (rate_channel_hold_p): the held value counts
 * as RATE_P_PRIOR means; the running mean ends after RATE_P_FAST_MAX means at most. */
#define RATE_P_PRIOR 4u
#define RATE_P_FAST_MAX 1000u

static int finite4(const float *c)
{
  return fm_isfinite(c[0]) && fm_isfinite(c[1]) && fm_isfinite(c[2]) && fm_isfinite(c[3]);
}

int rate_channel_cfg_ok(const rate_channel_cfg_t *cfg)
{
  return cfg != NULL && biquad_sections_ok(cfg->lpf, cfg->lpf_sections) &&
         fm_isfinite(cfg->ref_re) && fm_isfinite(cfg->ref_im) &&
         cfg->ref_re * cfg->ref_re + cfg->ref_im * cfg->ref_im > 0.0f &&
         fm_isfinite(cfg->scale_dps) && finite4(cfg->bias_c_dps) && finite4(cfg->sf_c) &&
         fm_isfinite(cfg->sf_c[4]) && fm_isfinite(cfg->lin_c2_per_dps) &&
         fm_isfinite(cfg->lin_c3_per_dps2) && cfg->p_lpf_alpha > 0.0f &&
         cfg->p_lpf_alpha <= 1.0f && cfg->min_drive_v > 0.0f &&
         fm_isfinite(cfg->grad_k_dps_per_deg) && cfg->grad_a > 0.0f && cfg->grad_a <= 1.0f &&
         fm_isfinite(cfg->p_rate_deg_per_dps) && fm_isfinite(cfg->p_rate_c1_per_dps) &&
         fm_isfinite(cfg->p_rate2_deg_per_dps2) && cfg->turn_max_dps > 0.0f &&
         fm_isfinite(cfg->turn_max_dps) && cfg->comp_a > 0.0f && cfg->comp_a <= 1.0f &&
         cfg->comp_stages >= 1u && cfg->comp_stages <= COMP_STAGES_MAX &&
         cfg->comp_fast_a >= 0.0f && cfg->comp_fast_a <= 1.0f &&
         fm_isfinite(cfg->grad_fast_k_dps_per_deg) && cfg->blend_dps > 0.0f &&
         fm_isfinite(cfg->blend_dps) && cfg->blend_inv_per_dps > 0.0f &&
         fm_isfinite(cfg->blend_inv_per_dps) && fm_isfinite(cfg->min_drive_v) &&
         fm_isfinite(cfg->p_ref_deg) && cfg->p_mode_k > 0.0f && cfg->p_mode_k <= 1.0f &&
         cfg->ref_lp_kp > 0.0f && cfg->ref_lp_kp < 1.0f && cfg->ref_lp_ki > 0.0f &&
         cfg->ref_lp_ki < cfg->ref_lp_kp && cfg->ref_wide_kp > 0.0f && cfg->ref_wide_kp < 1.0f &&
         cfg->ref_wide_ki > 0.0f && cfg->ref_wide_ki < cfg->ref_wide_kp;
}

int rate_channel_init(const rate_channel_cfg_t *cfg, rate_channel_t *rc)
{
  if (rc == NULL || !rate_channel_cfg_ok(cfg)) {
    return -1;
  }
  rc->p_hold = 0u;
  rc->p_new = 0u;
  rc->p_n = RATE_P_FAST_MAX; /* no fast start without a hold */
  rc->p_a_mean = 0.0f;       /* set before its use (rate_channel_update_p) */
  rate_channel_reset(cfg, rc, cfg->p_ref_deg);
  return 0;
}

void rate_channel_rebase(const rate_channel_cfg_t *old, const rate_channel_cfg_t *cfg,
                         rate_channel_t *rc)
{
  if (cfg->lpf_sections != old->lpf_sections) {
    biquad_sections_reset(cfg->lpf, rc->lpf_rate, cfg->lpf_sections, 0.0f);
    biquad_sections_reset(cfg->lpf, rc->lpf_quad, cfg->lpf_sections, 0.0f);
  }
  /* P_f is kept as it is, re-expressed around the new reference, and so is the value
   * its fast start began from (the same coordinates: THERMO_SETTLE's gap). */
  rc->p_held_dev_deg += old->p_ref_deg - cfg->p_ref_deg;
  rc->p_dev_deg = rc->p_f_deg - cfg->p_ref_deg;
  rc->p_acc_deg = 0.0f;
  rc->p_count = 0u;
  rc->comp_due = 1u; /* the new configuration's compensation, from the next refresh */
}

int rate_channel_same_path(const rate_channel_cfg_t *a, const rate_channel_cfg_t *b)
{
  int same = a->ref_re == b->ref_re && a->ref_im == b->ref_im && a->scale_dps == b->scale_dps &&
             a->p_ref_deg == b->p_ref_deg && a->p_poly_off_deg == b->p_poly_off_deg &&
             a->grad_k_dps_per_deg == b->grad_k_dps_per_deg && a->grad_a == b->grad_a &&
             a->p_rate_deg_per_dps == b->p_rate_deg_per_dps &&
             a->p_rate_c1_per_dps == b->p_rate_c1_per_dps &&
             a->p_rate2_deg_per_dps2 == b->p_rate2_deg_per_dps2 && a->comp_a == b->comp_a &&
             a->comp_stages == b->comp_stages && a->comp_fast_a == b->comp_fast_a &&
             a->grad_fast_k_dps_per_deg == b->grad_fast_k_dps_per_deg &&
             a->blend_dps == b->blend_dps && a->lpf_sections == b->lpf_sections;
  for (int i = 0; i < 4; i++) {
    same = same && a->bias_c_dps[i] == b->bias_c_dps[i] && a->sf_c[i] == b->sf_c[i];
  }
  same = same && a->sf_c[4] == b->sf_c[4] && a->lin_c2_per_dps == b->lin_c2_per_dps &&
         a->lin_c3_per_dps2 == b->lin_c3_per_dps2;
  return same && memcmp(a->lpf, b->lpf, b->lpf_sections * sizeof b->lpf[0]) == 0;
}

GYRO_RAMFUNC void rate_channel_reset(const rate_channel_cfg_t *restrict cfg,
                                     rate_channel_t *restrict rc, float p_deg)
{
  /* The filters at rest (the steady state of a zero input), written directly rather
   * than through biquad_sections_reset: this runs on a tick near its budget. */
  for (uint32_t i = 0; i < cfg->lpf_sections; i++) {
    rc->lpf_rate[i].s1 = rc->lpf_rate[i].s2 = 0.0f;
    rc->lpf_quad[i].s1 = rc->lpf_quad[i].s2 = 0.0f;
  }
  rc->rate_raw = 0.0f;
  rc->quad_raw = 0.0f;
  rc->acc_re = 0.0f;
  rc->acc_im = 0.0f;
  rc->rate_unc_dps = 0.0f;
  rc->quad_dps = 0.0f;
  rc->p_acc_deg = 0.0f;
  rc->p_count = 0u;
  rc->p_dev_deg = p_deg - cfg->p_ref_deg;
  rc->p_held_dev_deg = rc->p_dev_deg;
  rc->p_held_w = 0.0f;
  rc->p_hp_deg = 0.0f;
  rc->p_comp_lag_deg = 0.0f;
  rc->p_comp_mid_deg[0] = rc->p_comp_mid_deg[1] = 0.0f;
  rc->p_last_rad = p_deg * FM_RAD_PER_DEG_F;
  rc->p_lag_rad = 0.0f;
  rc->ref_dev_rad = 0.0f;
  rc->ref_slope_rad = 0.0f;
  rc->ref_wide_left = cfg->ref_wide_blocks;
  rc->ref_kp = cfg->ref_wide_kp;
  rc->ref_ki = cfg->ref_wide_ki;
  rc->p_fast_lag_deg = 0.0f;
  rc->p_fast_hp_deg = 0.0f;
  rc->fast_hold = 0u;
  rc->filters_due = 0u;
  rc->p_step_deg = 0.0f;
  rc->p_f_deg = p_deg;
  rc->rate_dps = 0.0f;
  rate_channel_comp_refresh(cfg, rc);
}

_Static_assert(RATE_P_DECIM % RATE_DECIM == 0u && RATE_P_BLOCKS >= 2u,
               "P's average spans whole blocks, at least two");

/* The reference's correction delta = theta - set for this block (rate_channel.h): the
 * mode's lag of P, made complementary with the measured phase error e_rad. */
static inline float ref_update(const rate_channel_cfg_t *restrict cfg,
                               rate_channel_t *restrict rc, float p_rad, float e_rad)
{
  /* (6-17): the true drive phase follows P through the resonance's lag. Every state is a
   * small difference (P's step since the last block, P - LP(P), the correction), so that
   * no float low-pass of a large P has a dead band (at Q = 10^4 the lag's factor is 1e-4). */
  const float lag_in = rc->p_lag_rad + (p_rad - rc->p_last_rad);
  rc->p_last_rad = p_rad;
  const float lag_step = cfg->p_mode_k * lag_in; /* LP(P) moves by this */
  rc->p_lag_rad = lag_in - lag_step;
  float delta = rc->ref_dev_rad + lag_step;
  if (rc->p_hold != 0u) {
    /* Acquisition: the lag model holds only for small motions about the set point, so
     * the mode is taken as settled on P, and the reference follows the measured phase. */
    rc->p_lag_rad = 0.0f;
    delta = fm_clampf(-e_rad, -RATE_REF_DEV_MAX_RAD, RATE_REF_DEV_MAX_RAD);
    rc->ref_slope_rad = 0.0f;
    rc->ref_wide_left = cfg->ref_wide_blocks;
    rc->ref_kp = cfg->ref_wide_kp;
    rc->ref_ki = cfg->ref_wide_ki;
  } else {
    /* The type-2 low-pass's error: LP(P) + e (the static phase's estimate) less its
     * low-passed value; its slope state follows a temperature ramp without a lag. Wide
     * at first, while the model's start (settled on P at the release) is still wrong. */
    if (rc->ref_wide_left != 0u) {
      rc->ref_wide_left--;
    } else if (rc->ref_kp > cfg->ref_lp_kp) {
      /* Narrowing geometrically rather than in one step: a step would leave the wide
       * filter's slope state to the narrow one, a bias bump lasting its settling. */
      rc->ref_kp = fm_maxf(rc->ref_kp * cfg->ref_narrow_k, cfg->ref_lp_kp);
      rc->ref_ki = fm_maxf(rc->ref_ki * (cfg->ref_narrow_k * cfg->ref_narrow_k), cfg->ref_lp_ki);
    }
    const float r = delta + e_rad;
    rc->ref_slope_rad += rc->ref_ki * r;
    delta -= rc->ref_slope_rad + rc->ref_kp * r;
  }
  rc->ref_dev_rad = delta;
  return delta;
}

GYRO_RAMFUNC void rate_channel_project(const rate_channel_cfg_t *restrict cfg,
                                       rate_channel_t *restrict rc, float w_i, float w_q,
                                       float p_rad, float e_rad)
{
  const float k = 1.0f / (float)RATE_DECIM;
  const float s_s = rc->acc_re * k, s_c = rc->acc_im * k;
  rc->acc_re = 0.0f;
  rc->acc_im = 0.0f;
  const float delta = ref_update(cfg, rc, p_rad, e_rad);
  float re = 0.0f, im = 0.0f;
  if (w_i * w_i + w_q * w_q > cfg->min_drive_v * cfg->min_drive_v) {
    /* S conj(e^{j psi} / A_set), then turned by -delta (small angle: e^{-j delta} ~ 1 - j delta) */
    const float r0 = s_s * cfg->ref_re + s_c * cfg->ref_im;
    const float i0 = s_c * cfg->ref_re - s_s * cfg->ref_im;
    re = r0 + delta * i0;
    im = i0 - delta * r0;
  }
  rc->rate_raw = re;
  rc->quad_raw = im;
}

GYRO_RAMFUNC void rate_channel_filter_rate(const rate_channel_cfg_t *restrict cfg,
                                           rate_channel_t *restrict rc)
{
  const float scale = cfg->scale_dps;
  const float unc = scale * biquad_sections_step(cfg->lpf, rc->lpf_rate, cfg->lpf_sections,
                                                 rc->rate_raw);
  rc->rate_unc_dps = unc;
  /* The linearisation acts on the whole in-phase signal (rate and raw bias), as the
   * pickoff's nonlinearity does (rate_channel.h). */
  const float lin = unc + unc * unc * (cfg->lin_c2_per_dps + unc * cfg->lin_c3_per_dps2);
  rc->rate_dps = lin * rc->comp_sf - rc->comp_bias_dps;
}

GYRO_RAMFUNC void rate_channel_filter_quad(const rate_channel_cfg_t *restrict cfg,
                                           rate_channel_t *restrict rc)
{
  rc->quad_dps = cfg->scale_dps *
                 biquad_sections_step(cfg->lpf, rc->lpf_quad, cfg->lpf_sections, rc->quad_raw);
}

void rate_channel_update(const rate_channel_cfg_t *cfg, rate_channel_t *rc, float w_i,
                         float w_q, float p_rad, float e_rad)
{
  if (rc->filters_due != 0u) rate_channel_comp_filters(cfg, rc);
  if (rc->comp_due != 0u) rate_channel_comp_refresh(cfg, rc);
  rate_channel_project(cfg, rc, w_i, w_q, p_rad, e_rad);
  rate_channel_filter_rate(cfg, rc);
  rate_channel_filter_quad(cfg, rc);
}

GYRO_RAMFUNC void rate_channel_shift_p(rate_channel_t *restrict rc, float shift_deg)
{
  rc->p_dev_deg += shift_deg;
  rc->p_f_deg += shift_deg;
  rc->p_held_dev_deg += shift_deg;
  rc->p_acc_deg += shift_deg * (float)rc->p_count;
  rc->p_last_rad += shift_deg * FM_RAD_PER_DEG_F; /* the lag does not see the turn */
  rc->comp_due = 1u;
}

/* The compensation's filters (comp_filters.h) take P_f's step. */
GYRO_RAMFUNC void rate_channel_comp_filters(const rate_channel_cfg_t *restrict cfg,
                                            rate_channel_t *restrict rc)
{
  const float step = rc->p_step_deg;
  rc->filters_due = 0u;
  if (rc->p_held_w > COMP_FILTERS_HELD_W_MAX) {
    /* P_f's way from a held value to P is no temperature change: the filters start once
     * that value weighs less than COMP_FILTERS_HELD_W_MAX in P_f. */
    rate_channel_comp_restart(rc);
    return;
  }
  comp_filters_step(&rc->p_comp_lag_deg, rc->p_comp_mid_deg, &rc->p_hp_deg, step, cfg->comp_a,
                    cfg->grad_a, cfg->comp_stages);
  if (cfg->comp_fast_a > 0.0f) {
    if (rc->fast_hold != 0u) rc->fast_hold--;
    float unused[COMP_STAGES_MAX - 1u]; /* one stage has no middle */
    comp_filters_step(&rc->p_fast_lag_deg, unused, &rc->p_fast_hp_deg, step, cfg->comp_fast_a,
                      cfg->grad_a, 1u);
  }
  rc->comp_due = 1u;
}

GYRO_RAMFUNC int rate_channel_update_p(const rate_channel_cfg_t *restrict cfg,
                                       rate_channel_t *restrict rc, float p_rad)
{
  if (rc->p_hold != 0u) {
    rc->p_acc_deg = 0.0f;
    rc->p_count = 0u;
    rc->p_n = 0u;
    rc->p_held_dev_deg = rc->p_dev_deg;
    rc->p_held_w = 1.0f;
    rate_channel_comp_restart(rc);
  } else {
    rc->p_acc_deg += p_rad * FM_DEG_PER_RAD_F - cfg->p_ref_deg;
    if (++rc->p_count == 1u && rc->p_n < RATE_P_FAST_MAX) {
      /* The fast start's weight of the coming mean, divided here (on the first block of
       * the RATE_P_BLOCKS) rather than with the low-pass (on the last): each block of the
       * sample interrupt carries at most one divide. */
      rc->p_a_mean = 1.0f / (float)(rc->p_n + 1u + RATE_P_PRIOR);
    }
    if (rc->p_count == RATE_P_BLOCKS) {
      /* The thermometer is P less the rate's own turn of it (the reciprocal Coriolis force
       * on the drive mode: linear through the quadrature's sense motion, at the
       * temperature P_c reads, and with the square of the rate's own), from the latest
       * output: 1 % of rate error is 1 % of a turn of thousandths of a degree. */
      const float x = rc->p_dev_deg - rc->p_comp_lag_deg + cfg->p_poly_off_deg;
      const float m = cfg->turn_max_dps;
      float r = rc->rate_unc_dps;
      r = r <= m && r >= -m ? r : 0.0f; /* (NaN too) */
      const float turn = cfg->p_rate_deg_per_dps + cfg->p_rate_c1_per_dps * x +
                         cfg->p_rate2_deg_per_dps2 * r;
      const float mean = rc->p_acc_deg * (1.0f / (float)RATE_P_BLOCKS) - turn * r;
      /* Fast start after a hold: the running mean of the means seen since the release
       * (the held value weighing as RATE_P_PRIOR of them) until its weight falls to the
       * low-pass's own, then the low-pass. */
      float a = cfg->p_lpf_alpha;
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
      const float before = rc->p_dev_deg;
      rc->p_dev_deg += a * (mean - before);
      /* The step P_f took (exact, Sterbenz), not a * (mean - P_f): within P_f's own dead
       * band the latter is a constant the compensation's filters would integrate. Taken
       * by them on a later block (rate_channel_comp_filters). */
      rc->p_step_deg = rc->p_dev_deg - before;
      rc->filters_due = 1u;
      rc->p_f_deg = cfg->p_ref_deg + rc->p_dev_deg;
      rc->p_acc_deg = 0.0f;
      rc->p_count = 0u;
      rc->p_new = 1u;
      return 1;
    }
  }
  return 0;
}

/* B(x) + k_g h for a thermometer lag and its high-pass. */
GYRO_RAMFUNC static inline float comp_bias(const rate_channel_cfg_t *restrict cfg, float x,
                                           float grad_k, float hp_deg)
{
  return rate_channel_bias_static_dps(cfg, x) + grad_k * hp_deg;
}

GYRO_RAMFUNC void rate_channel_comp_refresh(const rate_channel_cfg_t *restrict cfg,
                                            rate_channel_t *restrict rc)
{
  /* Temperature compensation in P_c (P_f low-passed again, rate.comp_tau_s; the thesis
   * fits the bias linear in P, 7.3.2), in its deviation from the calibration's reference
   * (x = P_c - cal.ref_p_deg). The gradient term: in a thermal transient the structure
   * and the pickoff circuit part, and P (which weighs them otherwise than the bias does)
   * reads a temperature the bias does not have; their difference follows P's recent
   * change, which P - LP_tau(P) measures without a derivative's noise (rate.grad_tau_s). */
  rc->comp_due = 0u;
  const float base = rc->p_dev_deg + cfg->p_poly_off_deg;
  const float x = base - rc->p_comp_lag_deg;
  const float *s3 = cfg->sf_c;
  rc->comp_sf = 1.0f + x * (s3[1] + x * (s3[2] + x * (s3[3] + x * s3[4])));
  float bias = comp_bias(cfg, x, cfg->grad_k_dps_per_deg, rc->p_hp_deg);
  float w = 0.0f;
  if (cfg->comp_fast_a > 0.0f && rc->fast_hold == 0u) {
    /* The blend (rate_channel.h): the fast path where the slow one lags a transient. */
    const float d = comp_bias(cfg, base - rc->p_fast_lag_deg, cfg->grad_fast_k_dps_per_deg,
                              rc->p_fast_hp_deg) -
                    bias;
    w = fm_clampf((fm_absf(d) - cfg->blend_dps) * cfg->blend_inv_per_dps, 0.0f, 1.0f);
    bias += w * d;
  }
  rc->comp_fast_w = w;
  rc->comp_bias_dps = bias;
}
