/* Butterworth low-pass, high-pass and band-pass design into second-order sections for
 * dsp/biquad.h (thesis 5.5.1, (5-12), (5-13)). Init-time code: double precision and
 * libm inside, never called per sample.
 *
 * Method: analog Butterworth prototype poles p_k = exp(j*pi*(2k+N+1)/(2N)), frequency
 * transformation of the pre-warped edges W = 2 fs tan(pi f / fs):
 *     low-pass  s -> s / W                       (zeros: N at s = inf -> z = -1)
 *     high-pass s -> W / s                       (zeros: N at s = 0   -> z = +1)
 *     band-pass s -> (s^2 + W1 W2) / (s (W2 - W1)), N = prototype order as in
 *               scipy.signal.butter; 2N poles, N zeros at z = +1 and N at z = -1
 * then the bilinear transform z = (2 fs + s) / (2 fs - s). Same design as
 * scipy.signal.butter(N, ..., fs=fs) (tests/unit/test_butter.c checks it).
 *
 * Sections (scipy sign convention, see biquad.h):
 *     H_i(z) = g_i (1 + c1 z^-1 + c2 z^-2) / (1 + a1 z^-1 + a2 z^-2)
 *     low-pass  (c1, c2) = (2, 1); high-pass (-2, 1); band-pass (0, -1): each band-pass
 *     section has one zero at z = +1 and one at z = -1 (scipy pairs them differently,
 *     two equal zeros per section; the product is the same filter).
 * Order: poles farthest from the unit circle first, closest last (as scipy's zpk2sos).
 * Gain: every section has unit gain at the reference frequency: DC (low-pass), Nyquist
 * (high-pass), or the digital centre f0 = (fs/pi) atan(sqrt(tan(pi f1/fs) tan(pi f2/fs)))
 * (band-pass, unit magnitude; the cascade's phase there is 0 as in the exact design).
 * This keeps every intermediate signal near the input level.
 *
 * Rounding to float (butter_design): a1, a2 are rounded to nearest first; the numerator
 * gain g_i is then recomputed from the ROUNDED denominator so that the float section's
 * own gain at the reference frequency is 1 to within one float rounding of g_i (for the
 * 100 Hz low-pass at 50 kHz exactly 1: 1 + a1 + a2 is a float there). Rounding the
 * exact coefficients independently would instead give a DC gain error of about
 * ulp(a1) / (1 + a1 + a2) = 2e-4 for that filter, since 1 + a1 + a2 is only 1.6e-4.
 * The price is that the float response elsewhere (e.g. the -3 dB frequency) carries the
 * pole shift of the rounded denominator, about 4e-4 relative for that filter.
 */
#ifndef BUTTER_H
#define BUTTER_H

#include <stdint.h>

#include "dsp/biquad.h"

typedef enum {
  BUTTER_LOWPASS = 0,  /* cut-off f1_hz (-3 dB); f2_hz ignored */
  BUTTER_HIGHPASS = 1, /* cut-off f1_hz (-3 dB); f2_hz ignored */
  BUTTER_BANDPASS = 2  /* pass band f1_hz < f2_hz (-3 dB edges) */
} butter_type_t;

/* Most sections a design can have: low-/high-pass order <= 2*BUTTER_MAX_SECTIONS,
 * band-pass prototype order <= BUTTER_MAX_SECTIONS. */
#define BUTTER_MAX_SECTIONS 8u

/* Errors (negative returns); nothing is written to sections on any error. */
#define BUTTER_ERR_ARG (-1)   /* NULL pointer or unknown type */
#define BUTTER_ERR_ORDER (-2) /* order 0, odd (low-/high-pass), or too large */
#define BUTTER_ERR_FREQ \
  (-3)                        /* fs not finite/positive, f outside (0, fs/2), NaN,
                                   * or f1 >= f2 (band-pass) */
#define BUTTER_ERR_SPACE (-4) /* max_sections smaller than the design needs */
#define BUTTER_ERR_PRECISION \
  (-5) /* a section is not stable once rounded to float (the
                                   * cut-off is too close to 0 or fs/2 for float) */

/* One section in double: same equation and sign convention as biquad_coeffs_t. */
typedef struct {
  double b0, b1, b2;
  double a1, a2;
} butter_sos_f64_t;

/* Design in double. order: low-/high-pass filter order (even, 2..16); band-pass
 * prototype order N (1..8, filter order 2N). Returns the number of sections written
 * (order/2 for low-/high-pass, N for band-pass) or a BUTTER_ERR_* code. */
int butter_design_f64(butter_type_t type, unsigned order, double f1_hz, double f2_hz,
                      double fs_hz, butter_sos_f64_t *sections, uint32_t max_sections);

/* The same design rounded to float sections for biquad_cascade_init, with the
 * numerators renormalised after rounding (see above). Same returns, plus
 * BUTTER_ERR_PRECISION. */
int butter_design(butter_type_t type, unsigned order, double f1_hz, double f2_hz, double fs_hz,
                  biquad_coeffs_t *sections, uint32_t max_sections);

#endif /* BUTTER_H */
