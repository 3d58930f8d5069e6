#include "measure.h"

#include <math.h>
#include <stdlib.h>
#include "plant/plant_const.h"

static const double k_pi = PLANT_PI;

/* sin and cos of w k for k = k0, k0+1, ... by rotation, renormalised every step (error
 * ~1e-15 over the lengths used here), instead of two libm calls per sample. */
typedef struct {
  double s, c, ds, dc;
} osc_t;

static osc_t osc_start(double w, size_t k0)
{
  const osc_t o = {sin(w * (double)k0), cos(w * (double)k0), sin(w), cos(w)};
  return o;
}

static void osc_next(osc_t *o)
{
  const double s = o->s * o->dc + o->c * o->ds;
  const double c = o->c * o->dc - o->s * o->ds;
  const double g = 1.5 - 0.5 * (s * s + c * c); /* one Newton step towards |.| = 1 */
  o->s = s * g;
  o->c = c * g;
}

void fit_tone(const double *y, size_t k0, size_t k1, double f_hz, double fs_hz, double *amp,
              double *phase_deg)
{
  /* Normal equations of the 3-parameter least squares, solved by Cramer's rule. */
  double m[3][3] = {{0}}, v[3] = {0};
  osc_t o = osc_start(2.0 * k_pi * f_hz / fs_hz, k0);
  for (size_t k = k0; k < k1; k++, osc_next(&o)) {
    const double x[3] = {o.s, o.c, 1.0};
    for (int i = 0; i < 3; i++) {
      v[i] += x[i] * y[k];
      for (int j = 0; j < 3; j++) {
        m[i][j] += x[i] * x[j];
      }
    }
  }
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  const double da = v[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                    m[0][1] * (v[1] * m[2][2] - m[1][2] * v[2]) +
                    m[0][2] * (v[1] * m[2][1] - m[1][1] * v[2]);
  const double db = m[0][0] * (v[1] * m[2][2] - m[1][2] * v[2]) -
                    v[0] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                    m[0][2] * (m[1][0] * v[2] - v[1] * m[2][0]);
  const double a = da / det, bb = db / det;
  *amp = hypot(a, bb);
  *phase_deg = atan2(bb, a) * 180.0 / k_pi;
}

int meas_am_response(const bench_t *b, demod_kind_t kind, double param, double fm_hz,
                     double *gain, double *phase_deg)
{
  demod_t d;
  if (!(fm_hz > 0.0) || demod_setup(&d, kind, param, b->fs_hz) != 0) {
    return -1;
  }
  const size_t skip = (size_t)(MEAS_SKIP_S * b->fs_hz);
  const double period = b->fs_hz / fm_hz;
  const double periods = ceil(MEAS_FIT_S * b->fs_hz / period);
  const size_t n = skip + (size_t)llround(periods * period);
  if (n > b->n_ref) {
    return -1;
  }
  double *y = malloc(n * sizeof *y);
  if (y == NULL) {
    return -1;
  }
  osc_t m = osc_start(2.0 * k_pi * fm_hz / b->fs_hz, 0);
  for (size_t k = 0; k < n; k++, osc_next(&m)) {
    const double x = m.s * b->carrier[k];
    y[k] = demod_step(&d, (float)x, b->ref_sin[k], b->ref_cos[k]);
  }
  fit_tone(y, skip, n, fm_hz, b->fs_hz, gain, phase_deg);
  free(y);
  return 0;
}

static double gain_at(const bench_t *b, demod_kind_t kind, double param, double f)
{
  double g = NAN, ph;
  if (meas_am_response(b, kind, param, f, &g, &ph) != 0) {
    return NAN;
  }
  return g;
}

double meas_bw_hz(const bench_t *b, demod_kind_t kind, double param)
{
  const double g3 = sqrt(0.5);
  double lo = log(MEAS_F_LO_HZ), hi = log(0.5 * b->fc_hz);
  const double g_hi = gain_at(b, kind, param, exp(hi));
  const double g_lo = gain_at(b, kind, param, exp(lo));
  if (isnan(g_hi) || isnan(g_lo)) {
    return NAN;
  }
  if (g_hi >= g3) {
    return INFINITY; /* no band limit below fc/2 */
  }
  if (g_lo <= g3) {
    return 0.0; /* below the search range */
  }
  while (hi - lo > 1e-4) {
    const double mid = 0.5 * (lo + hi);
    if (gain_at(b, kind, param, exp(mid)) > g3) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return exp(0.5 * (lo + hi));
}

/* Parameter from the search variable x (the log-bisection runs on x > 0). */
static double param_of(demod_kind_t kind, double x) { return (kind == DK_RLSD) ? 1.0 - x : x; }

double meas_tune(const bench_t *b, demod_kind_t kind, double target_hz, double *bw_hz)
{
  const double w = 2.0 * k_pi * target_hz / b->fs_hz;
  double guess;
  int rising = 1; /* bandwidth grows with x */
  switch (kind) {
  case DK_LMSD: /* lmsd.h: f3 ~ mu fs / (2 pi) */
  case DK_RLSD: /* rlsd.h: f3 ~ (1 - lambda) fs / (2 pi) */ guess = w; break;
  case DK_KFD: /* kfd.h: pole 1 - sqrt(q / (2 R)) */
    guess = DEMOD_KFD_Q / (2.0 * w * w);
    rising = 0;
    break;
  case DK_MULT: guess = target_hz; break;
  case DK_COUNT:
  default: return NAN;
  }
  *bw_hz = NAN;
  if (!(target_hz >= MEAS_BW_MIN_HZ && target_hz <= b->fc_hz / 3.0)) {
    return NAN;
  }
  /* bracket [lo, hi] in log x with bw(lo) below and bw(hi) above the target (for a
   * rising parameter; the other way round for a falling one) */
  double lo = log(guess) - log(2.0), hi = log(guess) + log(2.0);
  for (int widen = 0;; widen++) {
    const double bw_lo = meas_bw_hz(b, kind, param_of(kind, exp(lo)));
    const double bw_hi = meas_bw_hz(b, kind, param_of(kind, exp(hi)));
    if (isnan(bw_lo) || isnan(bw_hi) || widen > 8) {
      return NAN;
    }
    const int lo_ok = rising ? (bw_lo < target_hz) : (bw_lo > target_hz);
    const int hi_ok = rising ? (bw_hi > target_hz) : (bw_hi < target_hz);
    if (lo_ok && hi_ok) {
      break;
    }
    if (!lo_ok) {
      lo -= log(2.0);
    }
    if (!hi_ok) {
      hi += log(2.0);
    }
  }
  double bw = NAN, x = exp(0.5 * (lo + hi));
  for (int it = 0; it < 60; it++) {
    x = exp(0.5 * (lo + hi));
    bw = meas_bw_hz(b, kind, param_of(kind, x));
    if (isnan(bw)) {
      return NAN;
    }
    if (fabs(bw / target_hz - 1.0) < 5e-4) {
      break;
    }
    if ((bw < target_hz) == (rising != 0)) {
      lo = log(x);
    } else {
      hi = log(x);
    }
  }
  *bw_hz = bw;
  return (fabs(bw / target_hz - 1.0) < 5e-4) ? param_of(kind, x) : NAN;
}

double settle_time_s(const double *y, size_t n, double final, double rel_band, double fs_hz)
{
  const double band = rel_band * fabs(final);
  size_t last_out = 0;
  int ever_out = 0;
  for (size_t k = 0; k < n; k++) {
    if (fabs(y[k] - final) > band) {
      last_out = k;
      ever_out = 1;
    }
  }
  return ever_out ? (double)(last_out + 1) / fs_hz : 0.0;
}
