#include "gyro/selfcal_fit.h"

#include <math.h>
#include <stddef.h>

#include "dsp/fastmath.h"

/* Solve the 4x4 system a x = b by Gaussian elimination with partial pivoting. */
static int solve4(double a[4][4], double b[4], double x[4])
{
  for (int c = 0; c < 4; c++) {
    int piv = c;
    for (int r = c + 1; r < 4; r++) {
      if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
    }
    if (!(fabs(a[piv][c]) > 1e-300)) return -1;
    if (piv != c) {
      for (int k = 0; k < 4; k++) {
        const double t = a[c][k];
        a[c][k] = a[piv][k];
        a[piv][k] = t;
      }
      const double t = b[c];
      b[c] = b[piv];
      b[piv] = t;
    }
    for (int r = c + 1; r < 4; r++) {
      const double m = a[r][c] / a[c][c];
      for (int k = c; k < 4; k++) a[r][k] -= m * a[c][k];
      b[r] -= m * b[c];
    }
  }
  for (int c = 3; c >= 0; c--) {
    double s = b[c];
    for (int k = c + 1; k < 4; k++) s -= a[c][k] * x[k];
    x[c] = s / a[c][c];
  }
  return 0;
}

static void accumulate(double ata[4][4], double atb[4], const double row[4], double rhs,
                       double wgt2)
{
  for (int i = 0; i < 4; i++) {
    for (int k = 0; k < 4; k++) ata[i][k] += wgt2 * row[i] * row[k];
    atb[i] += wgt2 * row[i] * rhs;
  }
}

int selfcal_fit(const selfcal_point_t *pts, uint32_t n, double delay_s, selfcal_fit_t *out)
{
  if (pts == NULL || out == NULL || n < 2u || !(delay_s >= 0.0) || !isfinite(delay_s)) {
    return -1;
  }
  double fmean = 0.0, hmax = 0.0;
  for (uint32_t i = 0; i < n; i++) {
    const double m = hypot(pts[i].h_re, pts[i].h_im);
    if (!(pts[i].f_hz > 0.0) || !isfinite(pts[i].f_hz) || !(m > 0.0) || !isfinite(m)) {
      return -1;
    }
    fmean += pts[i].f_hz;
    if (m > hmax) hmax = m;
  }
  fmean /= (double)n;
  const double w0 = 2.0 * FM_PI * fmean;
  double ata[4][4] = {{0.0}}, atb[4] = {0.0};
  for (uint32_t i = 0; i < n; i++) {
    const double w = 2.0 * FM_PI * pts[i].f_hz;
    const double u = w / w0;
    /* Undo the delay: Hc = H e^{j w D}; y = 1 / Hc, scaled by hmax for conditioning. */
    const double ph = w * delay_s;
    const double hr = pts[i].h_re * cos(ph) - pts[i].h_im * sin(ph);
    const double hi = pts[i].h_re * sin(ph) + pts[i].h_im * cos(ph);
    const double m2 = hr * hr + hi * hi;
    const double yr = hmax * hr / m2, yi = -hmax * hi / m2;
    const double wgt2 = m2 / (hmax * hmax);
    /* d y = (dr yr - di yi) + j (dr yi + di yr); unknowns (dr, di, p, q). */
    const double re_row[4] = {yr, -yi, -1.0, 0.0};
    const double im_row[4] = {yi, yr, 0.0, -u};
    accumulate(ata, atb, re_row, -u * u, wgt2);
    accumulate(ata, atb, im_row, 0.0, wgt2);
  }
  double x[4];
  if (solve4(ata, atb, x) != 0) return -1;
  const double p = x[2], q = x[3];
  if (!(p > 0.0) || !(q > 0.0) || !isfinite(p) || !isfinite(q)) return -1;
  const double un = sqrt(p);
  /* Hc(wn) = 1 / (c j q un) = d / (j q un), (d was solved for y scaled by hmax). */
  const double dr = x[0] * hmax, di = x[1] * hmax;
  const double wn = un * w0;
  double rss = 0.0;
  for (uint32_t i = 0; i < n; i++) {
    const double w = 2.0 * FM_PI * pts[i].f_hz, u = w / w0;
    /* Model H = d e^{-j w D} / (p - u^2 + j q u) against the measurement. */
    const double er = p - u * u, ei = q * u, e2 = er * er + ei * ei;
    const double mr = (dr * er + di * ei) / e2, mi = (di * er - dr * ei) / e2;
    const double ph = -w * delay_s;
    const double hr = mr * cos(ph) - mi * sin(ph), hi = mr * sin(ph) + mi * cos(ph);
    const double m2 = pts[i].h_re * pts[i].h_re + pts[i].h_im * pts[i].h_im;
    rss += ((hr - pts[i].h_re) * (hr - pts[i].h_re) + (hi - pts[i].h_im) * (hi - pts[i].h_im)) /
           m2;
  }
  out->f0_hz = wn / (2.0 * FM_PI);
  out->q = un / q;
  out->gain_v_per_v2 = hypot(dr, di) / (q * un);
  double ph = atan2(di, dr) - 0.5 * FM_PI - wn * delay_s;
  ph = remainder(ph, 2.0 * FM_PI);
  out->phase_rad = ph;
  out->rms_rel = sqrt(rss / (double)n);
  return 0;
}

int selfcal_fit_delay(const selfcal_point_t *pts, uint32_t n, double delay_min_s,
                      double delay_max_s, selfcal_fit_t *out, double *delay_s_out)
{
  if (out == NULL || delay_s_out == NULL || !(delay_min_s >= 0.0) ||
      !(delay_max_s >= delay_min_s) || !isfinite(delay_max_s) || n < 3u) {
    return -1;
  }
  /* 4 unknowns + D from 2n >= 6 equations. */
  const double g = 0.6180339887498949;
  double a = delay_min_s, b = delay_max_s;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  selfcal_fit_t f1, f2;
  if (selfcal_fit(pts, n, x1, &f1) != 0 || selfcal_fit(pts, n, x2, &f2) != 0) return -1;
  for (int it = 0; it < 60 && (b - a) > 1e-10; it++) {
    if (f1.rms_rel <= f2.rms_rel) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      if (selfcal_fit(pts, n, x1, &f1) != 0) return -1;
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      if (selfcal_fit(pts, n, x2, &f2) != 0) return -1;
    }
  }
  const double d = f1.rms_rel <= f2.rms_rel ? x1 : x2;
  selfcal_fit_t best;
  if (selfcal_fit(pts, n, d, &best) != 0) return -1;
  *out = best;
  *delay_s_out = d;
  return 0;
}
