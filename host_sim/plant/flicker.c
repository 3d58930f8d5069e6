#include "plant/flicker.h"

#include <complex.h>
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "plant/plant_const.h"

static const double k_pi = PLANT_PI;

/* tools/flicker_design.py: knee pairs, log10 of the position relative to fc. */
static const double k_knee_zero_log10[2] = {0.19743383, -0.69126035};
static const double k_knee_pole_log10[2] = {-0.04132227, -1.13138234};

/* Corner actually realised, and the white floor that goes with it. */
static double corner_hz(const flicker_spec_t *s, double fs_hz, double *white2)
{
  const double cap = fs_hz / 20.0;
  const double k2 = s->flicker_1hz_rthz * s->flicker_1hz_rthz;
  const double w2 = s->white_rthz * s->white_rthz;
  if (k2 == 0.0) {
    *white2 = w2;
    return 0.0;
  }
  double fc = (w2 > 0.0) ? k2 / w2 : cap;
  if (fc > cap) fc = cap;
  *white2 = k2 / fc;
  return fc;
}

double flicker_target_psd(const flicker_spec_t *spec, double fs_hz, double f_hz)
{
  double w2;
  (void)corner_hz(spec, fs_hz, &w2);
  return w2 + spec->flicker_1hz_rthz * spec->flicker_1hz_rthz / f_hz;
}

static void bilinear(double z_hz, double p_hz, double fs_hz, double *b0, double *b1, double *a1)
{
  /* s = 2 fs (1 - q) / (1 + q) in (1 + s/wz) / (1 + s/wp), q = z^-1 */
  const double kz = 2.0 * fs_hz / (2.0 * k_pi * z_hz);
  const double kp = 2.0 * fs_hz / (2.0 * k_pi * p_hz);
  const double den = 1.0 + kp;
  *b0 = (1.0 + kz) / den;
  *b1 = (1.0 - kz) / den;
  *a1 = (1.0 - kp) / den;
}

/* Zeros and poles of the cascade (knee pairs, then one pair per decade down to fmin).
 * Returns the number of sections, or -1 if they do not fit FLICKER_MAX_SECTIONS. */
static int design_sections(const flicker_spec_t *spec, double fc,
                           double zs[FLICKER_MAX_SECTIONS], double ps[FLICKER_MAX_SECTIONS])
{
  int n = 0;
  for (int i = 0; i < 2; i++) {
    zs[n] = fc * pow(10.0, k_knee_zero_log10[i]);
    ps[n] = fc * pow(10.0, k_knee_pole_log10[i]);
    n++;
  }
  /* regular pairs one per decade below the knee, down to fmin */
  double z = ps[1] / sqrt(10.0);
  for (;;) {
    const double p = z / sqrt(10.0);
    if (n >= FLICKER_MAX_SECTIONS) return -1;
    zs[n] = z;
    ps[n] = p;
    n++;
    if (p <= spec->fmin_hz) break;
    z /= 10.0;
  }
  return n;
}

int flicker_check(const flicker_spec_t *spec, double fs_hz)
{
  if (spec == NULL) return -1;
  if (!(isfinite(fs_hz) && fs_hz > 0.0)) return -1;
  if (!(isfinite(spec->white_rthz) && spec->white_rthz >= 0.0)) return -1;
  if (!(isfinite(spec->flicker_1hz_rthz) && spec->flicker_1hz_rthz >= 0.0)) return -1;
  if (spec->flicker_1hz_rthz > 0.0 &&
      !(isfinite(spec->fmin_hz) && spec->fmin_hz > 0.0 && spec->fmin_hz <= fs_hz / 1000.0))
    return -1;
  double w2;
  const double fc = corner_hz(spec, fs_hz, &w2);
  if (fc > 0.0 && fc > 10.0 * spec->fmin_hz) {
    double zs[FLICKER_MAX_SECTIONS], ps[FLICKER_MAX_SECTIONS];
    if (design_sections(spec, fc, zs, ps) < 0) return -1;
  }
  return 0;
}

int flicker_init(flicker_t *f, const flicker_spec_t *spec, double fs_hz, uint64_t seed,
                 uint64_t stream)
{
  /* everything that can fail is checked first, then f is built in place */
  if (f == NULL || flicker_check(spec, fs_hz) != 0) return -1;

  memset(f, 0, sizeof *f);
  double w2;
  const double fc = corner_hz(spec, fs_hz, &w2);
  f->corner_hz = fc;
  f->active = (w2 > 0.0);
  const double unit_sd = sqrt(fs_hz / 2.0); /* unit one-sided density */

  if (fc > 0.0 && fc > 10.0 * spec->fmin_hz) {
    double zs[FLICKER_MAX_SECTIONS], ps[FLICKER_MAX_SECTIONS];
    const int n = design_sections(spec, fc, zs, ps);
    f->nsec = n;
    for (int i = 0; i < n; i++) bilinear(zs[i], ps[i], fs_hz, &f->b0[i], &f->b1[i], &f->a1[i]);

    /* least-squares gain in dB over a log grid of the discrete response */
    const int npts = 240;
    const double lo = log(10.0 * spec->fmin_hz), hi = log(0.45 * fs_hz);
    double acc = 0.0;
    for (int j = 0; j < npts; j++) {
      const double fj = exp(lo + (hi - lo) * (double)j / (double)(npts - 1));
      const double complex q = cexp(-I * 2.0 * k_pi * fj / fs_hz);
      double h2 = 1.0;
      for (int i = 0; i < n; i++) {
        const double complex h = (f->b0[i] + f->b1[i] * q) / (1.0 + f->a1[i] * q);
        h2 *= creal(h * conj(h));
      }
      acc += log(flicker_target_psd(spec, fs_hz, fj) / h2);
    }
    f->in_sd = unit_sd * exp(0.5 * acc / (double)npts);
  } else {
    /* corner within a decade of fmin (or no 1/f part): the band above 10 fmin is
     * white within 3 dB; realise the white floor only */
    f->nsec = 0;
    f->in_sd = unit_sd * sqrt(w2);
  }
  rng_seed(&f->rng, seed, stream);
  return 0;
}

double flicker_step_active(flicker_t *f)
{
  double x = f->in_sd * gauss_zig(&f->rng);
  for (int i = 0; i < f->nsec; i++) {
    const double y = f->b0[i] * x + f->b1[i] * f->xp[i] - f->a1[i] * f->yp[i];
    f->xp[i] = x;
    f->yp[i] = y;
    x = y;
  }
  return x;
}
