/* Random vibration bands (vib.h). */
#include "plant/vib.h"

#include <complex.h>
#include <math.h>
#include <string.h>

#include "plant/plant_const.h"

int vib_check(const accel_profile_t *a, double fs_hz, const char **key)
{
  static const char *const hi_keys[PROFILE_MAX_VIB_BANDS] = {
      "band_f_hi_hz[0]", "band_f_hi_hz[1]", "band_f_hi_hz[2]", "band_f_hi_hz[3]"};
  const char *bad = NULL;
  if (a == NULL || !(isfinite(fs_hz) && fs_hz > 0.0)) bad = "fs_hz";
  else if (a->n_bands < 0 || a->n_bands > PROFILE_MAX_VIB_BANDS) bad = "n_bands";
  for (int j = 0; bad == NULL && j < a->n_bands; j++)
    if (!(a->band_f_hi_hz[j] < 0.45 * fs_hz)) bad = hi_keys[j];
  if (key != NULL) *key = bad;
  return bad == NULL ? 0 : -1;
}

/* Second-order Butterworth-type section of quality q at corner fc, bilinear with the
 * corner pre-warped: K = tan(pi fc / fs); low-pass K^2 (1, 2, 1) / D, high-pass
 * (1, -2, 1) / D, D = 1 + K/q + K^2; both with a = (2 (K^2 - 1), 1 - K/q + K^2) / D. */
static void section(vib_band_t *b, int high, double fc, double q, double fs)
{
  const double k = tan(PLANT_PI * fc / fs);
  const double d = 1.0 + k / q + k * k;
  const int i = b->nsos++;
  if (high) {
    b->b[i][0] = 1.0 / d;
    b->b[i][1] = -2.0 / d;
    b->b[i][2] = 1.0 / d;
  } else {
    b->b[i][0] = k * k / d;
    b->b[i][1] = 2.0 * k * k / d;
    b->b[i][2] = k * k / d;
  }
  b->a[i][0] = 2.0 * (k * k - 1.0) / d;
  b->a[i][1] = (1.0 - k / q + k * k) / d;
}

/* |H|^2 of the sections (without the input gain) at f */
static double gain2(const vib_band_t *b, double f, double fs)
{
  const double complex z1 = cexp(-I * PLANT_TWO_PI * f / fs);
  double g = 1.0;
  for (int i = 0; i < b->nsos; i++) {
    const double complex h = (b->b[i][0] + z1 * (b->b[i][1] + z1 * b->b[i][2])) /
                             (1.0 + z1 * (b->a[i][0] + z1 * b->a[i][1]));
    g *= creal(h * conj(h));
  }
  return g;
}

int vib_init(vib_t *v, const accel_profile_t *a, double fs_hz, uint64_t seed)
{
  if (v == NULL || vib_check(a, fs_hz, NULL) != 0) return -1;
  memset(v, 0, sizeof *v);
  v->n = a->n_bands;
  /* 4th-order Butterworth: sections of quality 1 / (2 cos((2k - 1) pi / 8)), k = 1, 2 */
  const double q[2] = {0.5 / cos(PLANT_PI / 8.0), 0.5 / cos(3.0 * PLANT_PI / 8.0)};
  for (int j = 0; j < v->n; j++) {
    vib_band_t *b = &v->band[j];
    b->axis = a->band_axis[j];
    const double lo = a->band_f_lo_hz[j], hi = a->band_f_hi_hz[j];
    for (int k = 0; k < 2; k++) section(b, 0, hi, q[k], fs_hz);
    if (lo > 0.0)
      for (int k = 0; k < 2; k++) section(b, 1, lo, q[k], fs_hz);
    const double centre = lo > 0.0 ? sqrt(lo * hi) : 0.0;
    /* white of one-sided density G: variance G fs / 2; PSD G at the centre */
    b->in_sd = sqrt(a->band_psd_g2_per_hz[j] * 0.5 * fs_hz / gain2(b, centre, fs_hz));
    rng_seed(&b->rng, seed, VIB_RNG_STREAM + (uint64_t)j);
  }
  return 0;
}

double vib_band_psd(const vib_t *v, int j, double fs_hz, double f_hz)
{
  const vib_band_t *b = &v->band[j];
  return b->in_sd * b->in_sd * (2.0 / fs_hz) * gain2(b, f_hz, fs_hz);
}

void vib_step(vib_t *v, double a_g[PROFILE_ACCEL_AXES])
{
  for (int j = 0; j < v->n; j++) {
    vib_band_t *b = &v->band[j];
    double x = b->in_sd * rng_gauss(&b->rng);
    for (int i = 0; i < b->nsos; i++) {
      const double y = b->b[i][0] * x + b->st[i][0];
      b->st[i][0] = b->b[i][1] * x - b->a[i][0] * y + b->st[i][1];
      b->st[i][1] = b->b[i][2] * x - b->a[i][1] * y;
      x = y;
    }
    a_g[b->axis] += x;
  }
}
