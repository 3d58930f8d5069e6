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

/* Least-squares gain in dB of the discrete cascade against the target over a log grid
 * from 10 fmin to 0.45 fs: the sd of the white input, unit density times g. */
static double fit_input_sd(const flicker_spec_t *spec, double fs_hz, int n, const double *b0,
                           const double *b1, const double *a1)
{
  const int npts = 240;
  const double lo = log(10.0 * spec->fmin_hz), hi = log(0.45 * fs_hz);
  double acc = 0.0;
  for (int j = 0; j < npts; j++) {
    const double fj = exp(lo + (hi - lo) * (double)j / (double)(npts - 1));
    const double complex q = cexp(-I * 2.0 * k_pi * fj / fs_hz);
    double h2 = 1.0;
    for (int i = 0; i < n; i++) {
      const double complex h = (b0[i] + b1[i] * q) / (1.0 + a1[i] * q);
      h2 *= creal(h * conj(h));
    }
    acc += log(flicker_target_psd(spec, fs_hz, fj) / h2);
  }
  return sqrt(fs_hz / 2.0) * exp(0.5 * acc / (double)npts);
}

/* Parallel form of prod_i (b0_i + b1_i q) / (1 + a1_i q), q = z^-1 (poles distinct: one
 * per decade): c0 = H(q -> inf) = prod b1_i / a1_i, and the residue of pole i,
 * r_i = prod_j (b0_j + b1_j q_i) / prod_{j != i} (1 + a1_j q_i) at q_i = -1/a1_i, for
 * the branch r_i / (1 + a1_i q). Each branch goes to the fast or the slow set by its
 * pole (flicker.h). */
static void split_parallel(flicker_t *f, const flicker_cascade_t *c, double fs_hz)
{
  const int n = c->n;
  const double *b0 = c->b0, *b1 = c->b1, *a1 = c->a1;
  if (n == 0) return;
  double c0 = 1.0;
  for (int i = 0; i < n; i++) c0 *= b1[i] / a1[i];
  f->c0 = c0;
  const double slow_hz = fs_hz / (double)(FLICKER_BLOCK * FLICKER_SLOW_MARGIN);
  for (int i = 0; i < n; i++) {
    const double qi = -1.0 / a1[i];
    double r = b0[i] + b1[i] * qi;
    for (int j = 0; j < n; j++)
      if (j != i) r *= (b0[j] + b1[j] * qi) / (1.0 + a1[j] * qi);
    const double rho = -a1[i];
    if (c->pole_hz[i] > slow_hz) {
      f->fast_r[f->nfast] = r;
      f->fast_rho[f->nfast] = rho;
      f->nfast++;
    } else {
      const double am = pow(rho, (double)FLICKER_BLOCK);
      f->slow_a[f->nslow] = am;
      f->slow_b[f->nslow] = r * (1.0 - am) / ((1.0 - rho) * (double)FLICKER_BLOCK);
      f->nslow++;
    }
  }
}

int flicker_design(const flicker_spec_t *spec, double fs_hz, flicker_cascade_t *c)
{
  if (c == NULL || flicker_check(spec, fs_hz) != 0) return -1;
  memset(c, 0, sizeof *c);
  double w2;
  const double fc = corner_hz(spec, fs_hz, &w2);
  c->corner_hz = fc;
  if (fc > 0.0 && fc > 10.0 * spec->fmin_hz) {
    double zs[FLICKER_MAX_SECTIONS];
    c->n = design_sections(spec, fc, zs, c->pole_hz);
    for (int i = 0; i < c->n; i++)
      bilinear(zs[i], c->pole_hz[i], fs_hz, &c->b0[i], &c->b1[i], &c->a1[i]);
    c->in_sd = fit_input_sd(spec, fs_hz, c->n, c->b0, c->b1, c->a1);
  } else {
    /* corner within a decade of fmin (or no 1/f part): the band above 10 fmin is
     * white within 3 dB; realise the white floor only */
    c->in_sd = sqrt(fs_hz / 2.0) * sqrt(w2);
  }
  return 0;
}

int flicker_init(flicker_t *f, const flicker_spec_t *spec, double fs_hz, uint64_t seed,
                 uint64_t stream)
{
  /* everything that can fail is checked first, then f is built in place */
  flicker_cascade_t c;
  if (f == NULL || flicker_design(spec, fs_hz, &c) != 0) return -1;
  memset(f, 0, sizeof *f);
  f->corner_hz = c.corner_hz;
  f->active = c.in_sd > 0.0;
  f->nsec = c.n;
  f->in_sd = c.in_sd;
  f->c0 = 1.0;
  split_parallel(f, &c, fs_hz);
  rng_seed(&f->rng, seed, stream);
  return 0;
}

/* End of a block: the slow branches take the block's input sum; the interpolation
 * moves on to the span from the last block end to this one. */
static void slow_block(flicker_t *f)
{
  double y = 0.0;
  for (int i = 0; i < f->nslow; i++) {
    f->slow_w[i] = f->slow_a[i] * f->slow_w[i] + f->slow_b[i] * f->block_sum;
    y += f->slow_w[i];
  }
  f->slow_base = f->slow_end;
  f->slow_end = y;
  f->slow_step = (y - f->slow_base) / (double)FLICKER_BLOCK;
  f->block_sum = 0.0;
  f->block_k = 0;
}

double flicker_step_active(flicker_t *f)
{
  const double x = f->in_sd * gauss_zig(&f->rng);
  double y = f->c0 * x;
  for (int i = 0; i < f->nfast; i++) {
    f->fast_w[i] = f->fast_r[i] * x + f->fast_rho[i] * f->fast_w[i];
    y += f->fast_w[i];
  }
  if (f->nslow == 0) return y;
  /* the output is M samples late: the fast part from the ring, the slow part
   * interpolated between the last two block ends */
  const int k = f->block_k;
  const double out = f->ring[k] + f->slow_base + (double)(k + 1) * f->slow_step;
  f->ring[k] = y;
  f->block_sum += x;
  if (++f->block_k == FLICKER_BLOCK) slow_block(f);
  return out;
}
