#include "dsp/butter.h"

#include <math.h>
#include <stddef.h>

#include "dsp/math_const.h"

typedef struct {
  double re, im;
} cplx_t;

static cplx_t c_make(double re, double im)
{
  cplx_t c = {re, im};
  return c;
}

static cplx_t c_mul(cplx_t a, cplx_t b)
{
  return c_make(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}

static cplx_t c_div(cplx_t a, cplx_t b)
{
  const double d = b.re * b.re + b.im * b.im;
  return c_make((a.re * b.re + a.im * b.im) / d, (a.im * b.re - a.re * b.im) / d);
}

/* Principal square root. */
static cplx_t c_sqrt(cplx_t a)
{
  const double r = hypot(a.re, a.im);
  const double re = sqrt(0.5 * (r + a.re));
  const double im = sqrt(0.5 * (r - a.re));
  return c_make(re, a.im < 0.0 ? -im : im);
}

/* Bilinear transform z = (2 fs + s) / (2 fs - s). */
static cplx_t bilinear(cplx_t s, double fs_hz)
{
  const double k = 2.0 * fs_hz;
  return c_div(c_make(k + s.re, s.im), c_make(k - s.re, -s.im));
}

/* Denominator of the section whose poles are z1 and z2 (a conjugate pair or two real
 * poles): (1 - z1 z^-1)(1 - z2 z^-1) = 1 + a1 z^-1 + a2 z^-2. */
static void section_from_poles(cplx_t z1, cplx_t z2, butter_sos_f64_t *s)
{
  s->a1 = -(z1.re + z2.re);
  s->a2 = c_mul(z1, z2).re;
}

static void section_from_pair(cplx_t s_pole, double fs_hz, butter_sos_f64_t *s)
{
  const cplx_t z = bilinear(s_pole, fs_hz);
  section_from_poles(z, c_make(z.re, -z.im), s);
}

/* Numerator gain g that gives the section 1 + a1 z^-1 + a2 z^-2 unit magnitude at the
 * reference frequency with the type's numerator shape g (1 + c1 z^-1 + c2 z^-2):
 * low-pass at z = 1 (shape sum 4), high-pass at z = -1 (4), band-pass at
 * z = exp(j w0) where |1 - z^-2| = 2 sin(w0). */
static double section_gain(butter_type_t type, double a1, double a2, double w0)
{
  switch (type) {
  case BUTTER_LOWPASS: return (1.0 + a1 + a2) / 4.0;
  case BUTTER_HIGHPASS: return (1.0 - a1 + a2) / 4.0;
  case BUTTER_BANDPASS: {
    const double re = 1.0 + a1 * cos(w0) + a2 * cos(2.0 * w0);
    const double im = a1 * sin(w0) + a2 * sin(2.0 * w0);
    return hypot(re, im) / (2.0 * sin(w0));
  }
  default: return (double)NAN;
  }
}

static void set_numerator(butter_type_t type, double g, butter_sos_f64_t *s)
{
  s->b0 = g;
  s->b1 = (type == BUTTER_LOWPASS) ? 2.0 * g : (type == BUTTER_HIGHPASS) ? -2.0 * g : 0.0;
  s->b2 = (type == BUTTER_BANDPASS) ? -g : g;
}

static double prewarp(double f_hz, double fs_hz)
{
  return 2.0 * fs_hz * tan(FM_PI * f_hz / fs_hz);
}

static int freq_in_range(double f_hz, double fs_hz)
{
  return isfinite(f_hz) && f_hz > 0.0 && f_hz < 0.5 * fs_hz;
}

/* Validates the arguments; returns the number of sections or a BUTTER_ERR_* code. */
static int check_args(butter_type_t type, unsigned order, double f1_hz, double f2_hz,
                      double fs_hz, const void *sections, uint32_t max_sections)
{
  unsigned n_sections;
  if (sections == NULL) {
    return BUTTER_ERR_ARG;
  }
  switch (type) {
  case BUTTER_LOWPASS:
  case BUTTER_HIGHPASS:
    if (order == 0u || (order % 2u) != 0u || order > 2u * BUTTER_MAX_SECTIONS) {
      return BUTTER_ERR_ORDER;
    }
    n_sections = order / 2u;
    break;
  case BUTTER_BANDPASS:
    /* The band-pass filter has order 2N, so any prototype order N gives whole sections. */
    if (order == 0u || order > BUTTER_MAX_SECTIONS) {
      return BUTTER_ERR_ORDER;
    }
    n_sections = order;
    break;
  default: return BUTTER_ERR_ARG;
  }
  if (!isfinite(fs_hz) || !(fs_hz > 0.0) || !freq_in_range(f1_hz, fs_hz)) {
    return BUTTER_ERR_FREQ;
  }
  if (type == BUTTER_BANDPASS && (!freq_in_range(f2_hz, fs_hz) || !(f1_hz < f2_hz))) {
    return BUTTER_ERR_FREQ;
  }
  if (n_sections > max_sections) {
    return BUTTER_ERR_SPACE;
  }
  return (int)n_sections;
}

/* Digital centre of the band-pass, the image of the analog centre sqrt(W1 W2). */
static double centre_rad(double f1_hz, double f2_hz, double fs_hz)
{
  const double w0_analog = sqrt(prewarp(f1_hz, fs_hz) * prewarp(f2_hz, fs_hz));
  return 2.0 * atan(w0_analog / (2.0 * fs_hz));
}

/* Pole radius of a section 1 + a1 z^-1 + a2 z^-2, the sort key: the larger root. */
static double pole_radius(const butter_sos_f64_t *s)
{
  const double disc = s->a1 * s->a1 - 4.0 * s->a2;
  if (disc < 0.0) {
    return sqrt(s->a2);
  }
  return 0.5 * (fabs(s->a1) + sqrt(disc));
}

/* Denominators of all sections, in the order of the prototype poles. */
static void design_denominators(butter_type_t type, unsigned order, double f1_hz, double f2_hz,
                                double fs_hz, butter_sos_f64_t *out)
{
  const unsigned n = order;
  const double w1 = prewarp(f1_hz, fs_hz);
  unsigned k_out = 0u;
  /* Upper-half-plane prototype poles, k = 0 .. n/2 - 1; the lower ones are their
   * conjugates and belong to the same sections. */
  for (unsigned k = 0u; k < n / 2u; k++) {
    const double theta = FM_PI * (double)(2u * k + n + 1u) / (double)(2u * n);
    const cplx_t p = c_make(cos(theta), sin(theta));
    if (type == BUTTER_LOWPASS) {
      section_from_pair(c_make(w1 * p.re, w1 * p.im), fs_hz, &out[k_out++]);
    } else if (type == BUTTER_HIGHPASS) {
      section_from_pair(c_div(c_make(w1, 0.0), p), fs_hz, &out[k_out++]);
    } else {
      /* s^2 - p BW s + W0^2 = 0: one root in each half plane (their product W0^2 is
       * real and positive); each root and its conjugate form one section. */
      const double w2 = prewarp(f2_hz, fs_hz);
      const double bw = w2 - w1;
      const cplx_t q = c_make(0.5 * bw * p.re, 0.5 * bw * p.im);
      const cplx_t qq = c_mul(q, q);
      const cplx_t d = c_sqrt(c_make(qq.re - w1 * w2, qq.im));
      section_from_pair(c_make(q.re + d.re, q.im + d.im), fs_hz, &out[k_out++]);
      section_from_pair(c_make(q.re - d.re, q.im - d.im), fs_hz, &out[k_out++]);
    }
  }
  if (type == BUTTER_BANDPASS && (n % 2u) != 0u) {
    /* Real prototype pole p = -1: s^2 + BW s + W0^2, a real quadratic whose roots are a
     * conjugate pair (narrow band) or two real poles (wide band). */
    const double w2 = prewarp(f2_hz, fs_hz);
    const double q = -0.5 * (w2 - w1);
    const cplx_t d = c_sqrt(c_make(q * q - w1 * w2, 0.0));
    section_from_poles(bilinear(c_make(q + d.re, d.im), fs_hz),
                       bilinear(c_make(q - d.re, -d.im), fs_hz), &out[k_out]);
  }
}

int butter_design_f64(butter_type_t type, unsigned order, double f1_hz, double f2_hz,
                      double fs_hz, butter_sos_f64_t *sections, uint32_t max_sections)
{
  const int n = check_args(type, order, f1_hz, f2_hz, fs_hz, sections, max_sections);
  if (n < 0) {
    return n;
  }
  butter_sos_f64_t work[BUTTER_MAX_SECTIONS];
  design_denominators(type, order, f1_hz, f2_hz, fs_hz, work);

  /* Insertion sort by pole radius: the section nearest the unit circle (highest Q) last,
   * so it sees a signal already band-limited by the others. */
  for (int i = 1; i < n; i++) {
    const butter_sos_f64_t key = work[i];
    const double r = pole_radius(&key);
    int j = i - 1;
    while (j >= 0 && pole_radius(&work[j]) > r) {
      work[j + 1] = work[j];
      j--;
    }
    work[j + 1] = key;
  }

  const double w0 = (type == BUTTER_BANDPASS) ? centre_rad(f1_hz, f2_hz, fs_hz) : 0.0;
  for (int i = 0; i < n; i++) {
    set_numerator(type, section_gain(type, work[i].a1, work[i].a2, w0), &work[i]);
  }
  for (int i = 0; i < n; i++) {
    sections[i] = work[i];
  }
  return n;
}

int butter_design(butter_type_t type, unsigned order, double f1_hz, double f2_hz, double fs_hz,
                  biquad_coeffs_t *sections, uint32_t max_sections)
{
  butter_sos_f64_t exact[BUTTER_MAX_SECTIONS];
  biquad_coeffs_t rounded[BUTTER_MAX_SECTIONS];
  const uint32_t room = (max_sections < BUTTER_MAX_SECTIONS) ? max_sections : BUTTER_MAX_SECTIONS;
  const int n = (sections == NULL)
                    ? BUTTER_ERR_ARG
                    : butter_design_f64(type, order, f1_hz, f2_hz, fs_hz, exact, room);
  if (n < 0) {
    return n;
  }
  const double w0 = (type == BUTTER_BANDPASS) ? centre_rad(f1_hz, f2_hz, fs_hz) : 0.0;
  for (int i = 0; i < n; i++) {
    const float a1 = (float)exact[i].a1;
    const float a2 = (float)exact[i].a2;
    /* Stability triangle of the rounded denominator: |a2| < 1, |a1| < 1 + a2. */
    if (!(fabsf(a2) < 1.0f) || !((double)fabsf(a1) < 1.0 + (double)a2)) {
      return BUTTER_ERR_PRECISION;
    }
    /* Renormalise: numerator gain from the rounded denominator (see butter.h). */
    butter_sos_f64_t s = {0.0, 0.0, 0.0, (double)a1, (double)a2};
    set_numerator(type, section_gain(type, s.a1, s.a2, w0), &s);
    if (!(s.b0 > 0.0) || !isfinite(s.b0)) {
      return BUTTER_ERR_PRECISION;
    }
    rounded[i].b0 = (float)s.b0;
    rounded[i].b1 = (float)s.b1;
    rounded[i].b2 = (float)s.b2;
    rounded[i].a1 = a1;
    rounded[i].a2 = a2;
  }
  for (int i = 0; i < n; i++) {
    sections[i] = rounded[i];
  }
  return n;
}
