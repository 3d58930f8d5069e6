#include "gyro/sense_tune.h"

#include <math.h>
#include <string.h>

#include "dsp/fastmath.h"

double sense_tune_volts(double s0_hz, double target_hz, double ke_per_s2_per_v2)
{
  const double w0 = 2.0 * FM_PI * s0_hz, wt = 2.0 * FM_PI * target_hz;
  const double v2 = (w0 * w0 - wt * wt) / ke_per_s2_per_v2;
  return ke_per_s2_per_v2 > 0.0 && v2 > 0.0 && isfinite(v2) ? sqrt(v2) : -1.0;
}

void sense_tune_at(const sense_tune_cfg_t *c, double f_drive_hz, sense_tune_out_t *o)
{
  o->v_v = 0.0;
  o->target_hz = o->s0_hz = 0.0;
  if (c->mode == SENSE_TUNE_OFF) {
    o->state = SENSE_TUNE_IS_OFF;
    return;
  }
  if (!(c->s0_hz > 0.0 && c->ref_hz > 0.0 && c->ke_per_s2_per_v2 > 0.0)) {
    o->state = SENSE_TUNE_UNCALIBRATED;
    return;
  }
  const double fd = f_drive_hz > 0.0 && isfinite(f_drive_hz) ? f_drive_hz : c->ref_hz;
  /* (2-32): one material, both resonances by the same factor */
  o->s0_hz = c->s0_hz * fd / c->ref_hz;
  o->target_hz = fd + (c->mode == SENSE_TUNE_SPLIT ? c->split_hz : 0.0);
  const double v = sense_tune_volts(o->s0_hz, o->target_hz, c->ke_per_s2_per_v2);
  if (!(v >= 0.0)) {
    o->state = SENSE_TUNE_BELOW;
    return;
  }
  o->state = v > c->v_max_v ? SENSE_TUNE_LIMIT : SENSE_TUNE_OK;
  o->v_v = v > c->v_max_v ? c->v_max_v : v;
}

static void window_clear(sense_tune_disc_t *s)
{
  s->n = s->s_re = s->s_im = 0.0;
  memset(s->sw, 0, sizeof s->sw);
  memset(s->swe, 0, sizeof s->swe);
}

void sense_tune_disc_reset(sense_tune_disc_t *s, uint32_t now_ticks)
{
  window_clear(s);
  s->t0 = now_ticks;
  s->windows = 0u;
  s->det_hz = 0.0;
  s->lost = 0u;
}

/* The window's tones T (re, im) of both axes, the ripple fitted out (sense_tune.h), and
 * the window cleared. Returns 0, or -1 when its phases did not spread. */
static int window_tones(sense_tune_disc_t *s, double t[2][2])
{
  const double n = s->n, sr = s->s_re, si = s->s_im;
  const double det = n * n - (sr * sr + si * si);
  const int ok = det > SENSE_TUNE_DISC_MIN_SPREAD * n * n;
  for (int ax = 0; ok && ax < 2; ax++) {
    /* n sum W - conj(S) sum W e^(j theta) */
    const double er = s->swe[ax][0], ei = s->swe[ax][1];
    t[ax][0] = (n * s->sw[ax][0] - (sr * er + si * ei)) / det;
    t[ax][1] = (n * s->sw[ax][1] - (sr * ei - si * er)) / det;
  }
  window_clear(s);
  return ok ? 0 : -1;
}

void sense_tune_disc_feed(const sense_tune_disc_cfg_t *c, sense_tune_disc_t *s,
                          const float w[4], uint32_t phase, uint32_t now_ticks)
{
  const double th = (double)phase * (2.0 * FM_PI / 4294967296.0);
  const double ct = cos(th), st = sin(th);
  s->n += 1.0;
  s->s_re += ct;
  s->s_im += st;
  for (int ax = 0; ax < 2; ax++) {
    /* the weights (a cos + b sin, selftest.h) as the phasor W = a - j b */
    const double wr = (double)w[2 * ax], wi = -(double)w[2 * ax + 1];
    s->sw[ax][0] += wr;
    s->sw[ax][1] += wi;
    s->swe[ax][0] += wr * ct - wi * st;
    s->swe[ax][1] += wr * st + wi * ct;
  }
  if (now_ticks - s->t0 < c->window_ticks) return;
  s->t0 = now_ticks;
  double t[2][2];
  if (window_tones(s, t) != 0) return;
  const double rr = t[0][0], ri = t[0][1], qr = t[1][0], qi = t[1][1];
  const double m2 = rr * rr + ri * ri;
  if (!(m2 > 0.0) || !isfinite(m2)) return; /* no tone: the continuous test says so */
  const double xr = (qr * rr + qi * ri) / m2 - c->c0_re;
  const double xi = (qi * rr - qr * ri) / m2 - c->c0_im;
  const double u2 = c->u_re * c->u_re + c->u_im * c->u_im;
  const double d = (xr * c->u_re + xi * c->u_im) / u2 - c->zero_hz;
  if (!isfinite(d)) return;
  /* from the first window's value, not from 0: settled after a few windows */
  s->det_hz = s->windows == 0u ? d : s->det_hz + c->k * (d - s->det_hz);
  s->windows++;
  s->lost = fabs(s->det_hz) > c->tol_hz ? 1u : 0u;
}

const char *sense_tune_state_name(sense_tune_state_t s)
{
  static const char *const names[] = {"off", "ok", "uncalibrated", "below", "limit"};
  const unsigned i = (unsigned)s;
  return i < sizeof names / sizeof names[0] ? names[i] : "?";
}
