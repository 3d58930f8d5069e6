#include "gyro/sense_tune.h"

#include <math.h>

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

void sense_tune_disc_reset(sense_tune_disc_t *s, uint32_t now_ticks)
{
  s->acc[0] = s->acc[1] = s->acc[2] = s->acc[3] = 0.0;
  s->t0 = now_ticks;
  s->windows = 0u;
  s->det_hz = 0.0;
  s->lost = 0u;
}

void sense_tune_disc_feed(const sense_tune_disc_cfg_t *c, sense_tune_disc_t *s,
                          const float w[4], uint32_t now_ticks)
{
  for (int i = 0; i < 4; i++) s->acc[i] += (double)w[i];
  if (now_ticks - s->t0 < c->window_ticks) return;
  /* The window's tones as phasors a - j b (selftest.h: a cos + b sin), their ratio. */
  const double rr = s->acc[0], ri = -s->acc[1], qr = s->acc[2], qi = -s->acc[3];
  const double m2 = rr * rr + ri * ri;
  s->acc[0] = s->acc[1] = s->acc[2] = s->acc[3] = 0.0;
  s->t0 = now_ticks;
  if (!(m2 > 0.0) || !isfinite(m2)) return; /* no tone: the continuous test says so */
  const double xr = (qr * rr + qi * ri) / m2 - c->c0_re;
  const double xi = (qi * rr - qr * ri) / m2 - c->c0_im;
  const double u2 = c->u_re * c->u_re + c->u_im * c->u_im;
  const double d = (xr * c->u_re + xi * c->u_im) / u2;
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
