/* Cascaded second-order IIR sections, transposed direct form II, single precision.
 *
 * Difference equation of one section (scipy's sign convention, a0 = 1):
 *     y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2]
 * TDF-II realisation, state {s1, s2}:
 *     y  = b0 x + s1
 *     s1 = b1 x - a1 y + s2
 *     s2 = b2 x - a2 y
 * A 4th-order 100 Hz low-pass at 50 kHz has poles within 1e-2 of z = 1; in direct form
 * its single-precision coefficients put them outside the unit circle (thesis 5.5.1),
 * which is why only cascades of sections are used (5-12, 5-13).
 *
 * Precision limit of float sections with poles near z = 1: each step adds b x, only
 * (1 + a1 + a2)/4 of the state (4e-5 for the 100 Hz low-pass at 50 kHz), to a state of
 * the size of the output, and the state's rounding errors reach the output amplified by
 * up to 1/(1 + a1 + a2) (6400 there). With a nearly constant input those roundings do
 * not average out: tests/unit/test_butter.c measures a level-dependent DC error of up to
 * about 1e-3 for that filter at 50 kHz with +-1e-3 dither, below 1e-6 with +-0.1 dither,
 * and below 1e-7 for the same filter run at 5 kHz. Run narrow low-pass filters at a
 * decimated rate where their DC accuracy matters.
 *
 * Two forms of the same kernel: biquad_sections_* take the coefficients (configuration,
 * constant while the filter runs; designed outside the ISR) apart from the state (2
 * floats per section), so that several filters share one set of coefficients and a new
 * design is a new pointer; biquad_cascade_t bundles a copy of the coefficients with its
 * state for a caller that owns both.
 */
#ifndef BIQUAD_H
#define BIQUAD_H

#include <stdint.h>

#define BIQUAD_MAX_SECTIONS 4u

typedef struct {
  float b0, b1, b2; /* numerator */
  float a1, a2;     /* denominator, a0 = 1, scipy sign convention */
} biquad_coeffs_t;

typedef struct {
  float s1, s2;
} biquad_state_t;

typedef struct {
  uint32_t num_sections;
  biquad_coeffs_t coeffs[BIQUAD_MAX_SECTIONS];
  biquad_state_t state[BIQUAD_MAX_SECTIONS];
} biquad_cascade_t;

/* n sections (1..BIQUAD_MAX_SECTIONS) whose coefficients are all finite: 1, else 0. */
int biquad_sections_ok(const biquad_coeffs_t *c, uint32_t n);

/* Clear the state s[0..n-1] of the sections c[0..n-1], or preset it to the steady state
 * of a constant input x (as biquad_cascade_reset). */
void biquad_sections_reset(const biquad_coeffs_t *c, biquad_state_t *s, uint32_t n,
                           float x_steady);

/* One input sample through the n sections c with state s; returns their output. */
static inline float biquad_sections_step(const biquad_coeffs_t *restrict c,
                                         biquad_state_t *restrict s, uint32_t n, float x)
{
  for (uint32_t i = 0; i < n; i++) {
    const float y = c[i].b0 * x + s[i].s1;
    s[i].s1 = c[i].b1 * x - c[i].a1 * y + s[i].s2;
    s[i].s2 = c[i].b2 * x - c[i].a2 * y;
    x = y;
  }
  return x;
}

/* Copy n sections (1..BIQUAD_MAX_SECTIONS) and clear the state. Returns 0, or -1 (and
 * leaves *bq unchanged) for a bad section count or a non-finite coefficient. */
int biquad_cascade_init(biquad_cascade_t *bq, const biquad_coeffs_t *sections, uint32_t n);

/* Clear the state, or preset it to the steady state of a constant input x (so that a
 * filter started on a known DC level produces no start-up transient). A NULL bq is
 * ignored; a non-finite x_steady clears the state (as x_steady = 0). */
void biquad_cascade_reset(biquad_cascade_t *bq, float x_steady);

/* One input sample through every section; returns the cascade output. */
static inline float biquad_cascade_step(biquad_cascade_t *bq, float x)
{
  return biquad_sections_step(bq->coeffs, bq->state, bq->num_sections, x);
}

#endif /* BIQUAD_H */
