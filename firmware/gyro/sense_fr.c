#include "gyro/sense_fr.h"

#include <math.h>
#include <stddef.h>

#include "dsp/math_const.h"

static int pos_finite(float x) { return isfinite(x) && x > 0.0f; }

static int cfg_ok(const sense_fr_cfg_t *c)
{
  return pos_finite(c->bw_hz) && pos_finite(c->zeta) && pos_finite(c->f_sense_hz) &&
         isfinite(c->q_sense) && c->q_sense >= 0.5f && pos_finite(c->f_drive_hz) &&
         isfinite(c->gain_per_v2) && c->gain_per_v2 != 0.0f && pos_finite(c->lag_s) &&
         pos_finite(c->f_max_v2) && pos_finite(c->settle_r) && isfinite(c->settle_s) &&
         c->settle_s >= 0.0f && pos_finite(c->dt_s) &&
         c->bw_hz * c->dt_s <= 0.05f; /* the integrator's Euler step: w T well under 1 */
}

/* Complex numbers of the design (background, double; no <complex.h> on every target). */
typedef struct {
  double re, im;
} cplx_t;

static cplx_t c_mul(cplx_t a, cplx_t b)
{
  const cplx_t r = {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
  return r;
}

static cplx_t c_div(cplx_t a, cplx_t b)
{
  const double m = b.re * b.re + b.im * b.im;
  const cplx_t r = {(a.re * b.re + a.im * b.im) / m, (a.im * b.re - a.re * b.im) / m};
  return r;
}

static cplx_t c_add(cplx_t a, cplx_t b)
{
  const cplx_t r = {a.re + b.re, a.im + b.im};
  return r;
}

/* The plant's slow root p = -sigma + j (wd - wc) (sense_fr.h), rad/s. */
static cplx_t plant_pole(const sense_fr_cfg_t *c)
{
  const double ws = 2.0 * FM_PI * (double)c->f_sense_hz;
  const double sigma = ws / (2.0 * (double)c->q_sense);
  const double wd = sqrt(ws * ws - sigma * sigma); /* Q >= 0.5: real */
  const cplx_t p = {-sigma, wd - 2.0 * FM_PI * (double)c->f_drive_hz};
  return p;
}

/* s (s - p)(s + a) + b a (Kp s + Ki) = (s + c)(s^2 + 2 zeta w s + w^2), b = -p g, by the
 * powers of s: s^2: a - p = c + 2 zeta w; s: -p a + b a Kp = 2 zeta w c + w^2;
 * 1: b a Ki = c w^2. Returns 0, or -1 when c is not in the left half plane. */
static int place(const sense_fr_cfg_t *cfg, cplx_t p, cplx_t *c, cplx_t *kp, cplx_t *ki)
{
  const double a = 1.0 / (double)cfg->lag_s;
  const double w = 2.0 * FM_PI * (double)cfg->bw_hz;
  const double zw2 = 2.0 * (double)cfg->zeta * w;
  const cplx_t cc = {a - p.re - zw2, -p.im};
  if (!(cc.re > 0.0)) return -1;
  const cplx_t ba = {-p.re * (double)cfg->gain_per_v2 * a, -p.im * (double)cfg->gain_per_v2 * a};
  if (!(ba.re * ba.re + ba.im * ba.im > 0.0)) return -1; /* undamped, at the carrier */
  const cplx_t num = {zw2 * cc.re + w * w + p.re * a, zw2 * cc.im + p.im * a};
  const cplx_t cw2 = {cc.re * w * w, cc.im * w * w};
  *c = cc;
  *kp = c_div(num, ba);
  *ki = c_div(cw2, ba);
  return 0;
}

int sense_fr_design(const sense_fr_cfg_t *cfg, sense_fr_design_t *d)
{
  if (cfg == NULL || d == NULL || !cfg_ok(cfg)) return -1;
  const cplx_t p = plant_pole(cfg);
  cplx_t c, kp, ki;
  if (place(cfg, p, &c, &kp, &ki) != 0) return -1;
  const cplx_t dt = {(double)cfg->dt_s, 0.0};
  const cplx_t ki_t = c_mul(ki, dt);
  const double settle = (double)cfg->settle_r;
  const double blocks = (double)cfg->settle_s / (double)cfg->dt_s;
  if (!isfinite(kp.re + kp.im + ki_t.re + ki_t.im) || !(blocks < 4.0e9)) return -1;
  /* (c is in the right half plane's complement: place checked its real part > 0) */
  d->kp_re = (float)kp.re;
  d->kp_im = (float)kp.im;
  d->kit_re = (float)ki_t.re;
  d->kit_im = (float)ki_t.im;
  d->gain_per_v2 = cfg->gain_per_v2;
  const cplx_t kr = c_div(ki, c); /* the readout's zero on -c (sense_fr.h) */
  d->krg_re = (float)(kr.re * (double)cfg->gain_per_v2);
  d->krg_im = (float)(kr.im * (double)cfg->gain_per_v2);
  d->f_max_v2 = cfg->f_max_v2;
  d->f_max2_v4 = cfg->f_max_v2 * cfg->f_max_v2;
  d->settle2 = (float)(settle * settle);
  d->settle_blocks = (uint32_t)blocks;
  d->settle_k = (float)(1.0 - exp(-2.0 * FM_PI * 0.2 * (double)cfg->bw_hz * (double)cfg->dt_s));
  d->p_re = (float)p.re;
  d->p_im = (float)p.im;
  d->c_re = (float)c.re;
  d->c_im = (float)c.im;
  return 0;
}

/* The loop closed around a plant G at s = j w, the controller C = Kp + Ki / s (k: Kp,
 * Ki, Kr): R = G T / (1 + G C) and the readout Y = g (Ki / s + Kr) R; returns Y / T. */
static cplx_t closed_tone(const sense_fr_cfg_t *cfg, cplx_t plant, const cplx_t k[3], double w)
{
  const cplx_t kp = k[0], ki = k[1], kr = k[2];
  const cplx_t one = {1.0, 0.0}, s = {0.0, w};
  const cplx_t ki_s = c_div(ki, s);
  const cplx_t gr = {(double)cfg->gain_per_v2, 0.0};
  const cplx_t y = c_mul(gr, c_mul(c_add(ki_s, kr), plant));
  return c_div(y, c_add(one, c_mul(plant, c_add(kp, ki_s))));
}

/* Y / T at s = j w (sense_fr_tone_gain): the plant G = g (-p) / (s - p) seen through the
 * demodulator's pole and the delay. */
static cplx_t tone_h(const sense_fr_cfg_t *cfg, const sense_fr_lag_t *lag, cplx_t p,
                     const cplx_t k[3], double w)
{
  const double g = (double)cfg->gain_per_v2, b = lag->demod_pole_per_s;
  const cplx_t s_p = {-p.re, w - p.im}, s_b = {b, w};
  const cplx_t gp = {-p.re * g * b, -p.im * g * b};
  const cplx_t delay = {cos(w * lag->delay_s), -sin(w * lag->delay_s)};
  return closed_tone(cfg, c_mul(c_div(gp, c_mul(s_p, s_b)), delay), k, w);
}

double sense_fr_tone_gain(const sense_fr_cfg_t *cfg, const sense_fr_lag_t *lag, double f_hz)
{
  if (cfg == NULL || lag == NULL || !cfg_ok(cfg) || !isfinite(f_hz) || !(f_hz > 0.0) ||
      !(lag->demod_pole_per_s > 0.0) || !(lag->delay_s >= 0.0) || !isfinite(lag->delay_s))
    return -1.0;
  const cplx_t p = plant_pole(cfg);
  cplx_t c, kp, ki;
  if (place(cfg, p, &c, &kp, &ki) != 0) return -1.0;
  const double w = 2.0 * FM_PI * f_hz;
  const cplx_t k[3] = {kp, ki, c_div(ki, c)};
  /* A real tone T = A cos(w t) = A (e^(j w t) + e^(-j w t)) / 2 on the real axis: the
   * real part of the response is A Re((H(jw) + conj(H(-jw))) e^(j w t)) / 2. */
  const cplx_t hp = tone_h(cfg, lag, p, k, w), hn = tone_h(cfg, lag, p, k, -w);
  return 0.5 * hypot(hp.re + hn.re, hp.im - hn.im);
}

static cplx_t c_exp_j(double x)
{
  const cplx_t r = {cos(x), sin(x)};
  return r;
}

/* The LMS demodulator's envelope response at w (sense_fr_tone_cross): mu per sample, the
 * carrier wc and the sample period T. */
static cplx_t lms_envelope(double mu, double wc, double t_s, double w)
{
  const cplx_t m = {mu, 0.0}, m2 = {mu * mu, 0.0};
  cplx_t d = c_exp_j((w + 2.0 * wc) * t_s);
  d.re += mu - 1.0;
  cplx_t num = c_div(m, d);
  num.re = 1.0 - num.re;
  num.im = -num.im;
  cplx_t den = c_exp_j(w * t_s);
  den.re += mu - 1.0;
  const cplx_t q = c_div(m2, d);
  den.re -= q.re;
  den.im -= q.im;
  return c_div(c_mul(m, num), den);
}

/* The readout's response Y / T at s = j w with the plant's pole at pt (the model's moved)
 * and its second root 2 wc away, through the LMS and the delay (sense_fr_tone_cross). */
static cplx_t tone_h_full(const sense_fr_cfg_t *cfg, const sense_fr_lag_t *lag, double mu,
                          double t_s, cplx_t p, cplx_t pt, const cplx_t k[3], double w)
{
  const double g = (double)cfg->gain_per_v2, wc = 2.0 * FM_PI * (double)cfg->f_drive_hz;
  const cplx_t gp = {-p.re * g, -p.im * g}; /* b: the model's, the coupling is fixed */
  const cplx_t s_pt = {-pt.re, w - pt.im};
  const cplx_t p2 = {pt.re, -2.0 * wc - pt.im}; /* the second root */
  const cplx_t mp2 = {-p2.re, -p2.im}, s_p2 = {-p2.re, w - p2.im};
  const cplx_t delay = {cos(w * lag->delay_s), -sin(w * lag->delay_s)};
  cplx_t plant = c_mul(c_div(gp, s_pt), c_div(mp2, s_p2));
  plant = c_mul(c_mul(plant, delay), lms_envelope(mu, wc, t_s, w));
  return closed_tone(cfg, plant, k, w);
}

int sense_fr_tone_cross(const sense_fr_cfg_t *cfg, const sense_fr_lag_t *lag, double fs_hz,
                        double f_hz, double det_hz, double cross[2])
{
  if (cfg == NULL || lag == NULL || cross == NULL || !cfg_ok(cfg) || !isfinite(f_hz) ||
      !(f_hz > 0.0) || !isfinite(det_hz) || !(fs_hz > 0.0) || !(lag->demod_pole_per_s > 0.0) ||
      !(lag->delay_s >= 0.0) || !isfinite(lag->delay_s))
    return -1;
  const cplx_t p = plant_pole(cfg);
  cplx_t c, kp, ki;
  if (place(cfg, p, &c, &kp, &ki) != 0) return -1;
  const double mu = lag->demod_pole_per_s / fs_hz, t_s = 1.0 / fs_hz;
  const double w = 2.0 * FM_PI * f_hz;
  const cplx_t k[3] = {kp, ki, c_div(ki, c)};
  const cplx_t pt = {p.re, p.im + 2.0 * FM_PI * det_hz};
  /* A real tone A cos(w t) = A (e^(j w t) + e^(-j w t)) / 2 on the real axis: the
   * response Y = (H(jw) e^(j w t) + H(-jw) e^(-j w t)) A / 2 has the real part Re(Ar e^(j
   * w t)), Ar = (H(jw) + conj H(-jw)) / 2, and the imaginary part Re(Aq e^(j w t)),
   * Aq = -j (H(jw) - conj H(-jw)) / 2. */
  const cplx_t hp = tone_h_full(cfg, lag, mu, t_s, p, pt, k, w);
  const cplx_t hn = tone_h_full(cfg, lag, mu, t_s, p, pt, k, -w);
  const cplx_t ar = {0.5 * (hp.re + hn.re), 0.5 * (hp.im - hn.im)};
  const cplx_t aq = {0.5 * (hp.im + hn.im), -0.5 * (hp.re - hn.re)};
  if (!(ar.re * ar.re + ar.im * ar.im > 0.0)) return -1;
  const cplx_t r = c_div(aq, ar);
  cross[0] = r.re;
  cross[1] = r.im;
  return isfinite(r.re) && isfinite(r.im) ? 0 : -1;
}

double sense_fr_detune_tol_hz(const sense_fr_cfg_t *cfg, double frac)
{
  if (cfg == NULL || !cfg_ok(cfg) || !(frac > 0.0)) return -1.0;
  const cplx_t p = plant_pole(cfg);
  cplx_t c, kp, ki;
  if (place(cfg, p, &c, &kp, &ki) != 0) return -1.0;
  const double a = 1.0 / (double)cfg->lag_s, w = 2.0 * FM_PI * (double)cfg->bw_hz;
  const double z = (double)cfg->zeta;
  const cplx_t ba = {-p.re * (double)cfg->gain_per_v2 * a, -p.im * (double)cfg->gain_per_v2 * a};
  const cplx_t bakp = c_mul(ba, kp);
  double worst = 0.0;
  for (int i = -1; i <= 1; i += 2) {
    /* the placed pair, -zeta w +- j w sqrt(1 - zeta^2) (a real pair beyond zeta 1) */
    const double im = z < 1.0 ? (double)i * w * sqrt(1.0 - z * z) : 0.0;
    const double re = z < 1.0 ? -z * w : -w * (z + (double)i * sqrt(z * z - 1.0));
    const cplx_t r = {re, im}, r_p = {re - p.re, im - p.im}, r_a = {re + a, im};
    /* P'(r) = (r - p)(r + a) + r (r + a) + r (r - p) + b a Kp */
    const cplx_t dp = c_add(c_add(c_mul(r_p, r_a), c_mul(r, r_a)), c_add(c_mul(r, r_p), bakp));
    const cplx_t j_r_ra = {-c_mul(r, r_a).im, c_mul(r, r_a).re};
    const cplx_t dr = c_div(j_r_ra, dp); /* per rad/s of detuning */
    const double m = 2.0 * FM_PI * hypot(dr.re, dr.im);
    if (m > worst) worst = m;
  }
  return worst > 0.0 ? frac * w / worst : -1.0;
}

GYRO_RAMFUNC void sense_fr_reset(sense_fr_t *fr)
{
  fr->run = 0u;
  fr->e_re = fr->e_im = 0.0f;
  fr->ef_re = fr->ef_im = 0.0f;
  fr->i_re = fr->i_im = 0.0f;
  fr->f_re = fr->f_im = 0.0f;
  fr->m2_v4 = 0.0f;
  fr->out_re = fr->out_im = 0.0f;
  fr->in_band = 0u;
  fr->settled = 0u;
  fr->at_limit = 0u;
  fr->skip = 0u;
}

void sense_fr_update(const sense_fr_design_t *d, sense_fr_t *fr, float r_re, float r_im)
{
  sense_fr_take(d, fr, r_re, r_im);
  if (fr->skip != 0u) return;
  sense_fr_integrate(d, fr);
  sense_fr_limit(d, fr);
  sense_fr_settle(d, fr);
}
