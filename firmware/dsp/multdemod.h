/* Multiplicative (synchronous) demodulator, the classical baseline of thesis 5.4.3.
 *
 * Signal model (5-1) as in lmsd.h: d(k) = A1 sin(wc k) + A2 cos(wc k) + n(k).
 * Per channel, multiply by twice the reference, then low-pass with a biquad cascade
 * (biquad.h, TDF-II, scipy sign convention), the same coefficients on both channels:
 *     i(k) = LP{ 2 d(k) sin(wc k) } = LP{ A1 - A1 cos(2 wc k) + A2 sin(2 wc k) + 2 n sin }
 *     q(k) = LP{ 2 d(k) cos(wc k) } = LP{ A2 + A2 cos(2 wc k) + A1 sin(2 wc k) + 2 n cos }
 * The factor 2 makes the DC gain 1 for a low-pass of unit DC gain. The product carries
 * the full amplitude at 2 wc, which only the low-pass removes: its attenuation at 2 wc
 * is the demodulator's ripple floor, and its bandwidth is the demodulator's bandwidth.
 *
 * With zero sections the low-pass is absent and the outputs are the raw products (the
 * caller filters them later, as the thesis does with its 100 Hz output filter).
 * Sign convention: in-phase is the coefficient of ref_sin, quadrature of ref_cos.
 */
#ifndef MULTDEMOD_H
#define MULTDEMOD_H

#include <stdint.h>

#include "dsp/biquad.h"

typedef struct {
  const biquad_coeffs_t *sections; /* low-pass sections (copied at init) */
  uint32_t num_sections;           /* 0..BIQUAD_MAX_SECTIONS; 0 = no low-pass */
} multdemod_cfg_t;

typedef struct {
  biquad_cascade_t lp_i; /* low-pass of the in-phase product */
  biquad_cascade_t lp_q; /* low-pass of the quadrature product */
  float i;               /* latest in-phase output */
  float q;               /* latest quadrature output */
} multdemod_t;

/* Copy the sections into both channels and clear the state. Returns 0, or -1 and leaves
 * *m unchanged for a NULL pointer, too many sections or a non-finite coefficient. */
int multdemod_init(multdemod_t *m, const multdemod_cfg_t *cfg);

/* Preset both low-passes to the steady state of the given amplitudes (no start-up
 * transient when the amplitudes are known), or to zero with (0, 0). Returns 0, or -1 and
 * changes nothing for non-finite values. */
int multdemod_reset(multdemod_t *m, float in_phase, float quadrature);

/* One sample: products with 2 r(k), then the low-passes. */
static inline void multdemod_step(multdemod_t *m, float d, float ref_sin, float ref_cos)
{
  const float d2 = d + d;
  m->i = biquad_cascade_step(&m->lp_i, d2 * ref_sin);
  m->q = biquad_cascade_step(&m->lp_q, d2 * ref_cos);
}

static inline float multdemod_in_phase(const multdemod_t *m) { return m->i; }
static inline float multdemod_quadrature(const multdemod_t *m) { return m->q; }

#endif /* MULTDEMOD_H */
