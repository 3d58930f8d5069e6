/* RLS demodulator (RLSD), thesis 5.4.2, single precision.
 *
 * Signal model (5-1) as in lmsd.h: d(k) = A1 sin(wc k) + A2 cos(wc k) + n(k),
 * phi(k) = [sin(wc k), cos(wc k)]'. State W = [w_i, w_q]' estimates [A1, A2]' and
 * minimises the exponentially weighted error (5-6), sum lambda^(k-i) err(i)^2, whose
 * batch solution is (5-10). P is the 2x2 inverse of the weighted information matrix
 * Gamma' Lambda Gamma (plus the decayed start value P(0)^-1), kept in three floats: P is
 * symmetric, so only p11, p12, p22 exist and symmetry holds by construction.
 *
 * Recursion (thesis 5.4.2 "algorithm"), one sample:
 *     err = d - W' phi
 *     g   = P phi                      (P(k-1) phi(k))
 *     K   = g / (lambda + phi' g)
 *     W  += K err
 *     P   = (P - K g') / lambda        (= (P - K phi' P) / lambda, since P is symmetric)
 * Only the upper triangle of K g' is formed, so P stays exactly symmetric. The
 * subtraction removes g g' / (lambda + phi' g), a fraction phi'g/(lambda + phi'g) of P
 * along phi: about 3.5 % at the steady state P ~ 2 (1 - lambda) I, so there is no
 * cancellation and P stays well conditioned in float.
 *
 * Health guards (cheap compares, no effect in normal operation; the last two are
 * shared with kfd.h in cov2.h):
 * - Bounded: the division by lambda (forgetting) is applied only while
 *   trace(P) < 4 p0. With a reference that does not excite both directions (a stopped
 *   NCO, a DC "carrier") plain RLS would grow P as lambda^-k until it overflows
 *   ("covariance wind-up"); here trace(P) never exceeds 4 p0 / lambda.
 * - Positive definite: if rounding ever left p11 <= 0, p22 <= 0 or p11 p22 <= p12^2
 *   (or a NaN), P restarts at p0 I and cov_resets counts it.
 * - A non-finite innovation (a corrupted sample) is ignored and counted in skipped.
 *
 * Bandwidth: at steady state P ~ 2 (1 - lambda) I and the estimate is the exponentially
 * weighted average of the data, a first-order lag with pole lambda on the envelope:
 * f_3dB ~ (1 - lambda) fs / (2 pi). lambda = 0.982 at 50 kHz gives about 145 Hz, i.e.
 * the bandwidth of LMSD with mu ~ 0.018, not 0.03 as the thesis states (the
 * demodulator comparison tool measures both). Cost: 18 multiplies, 1 division, 12 adds
 * (thesis: 26, 1, 20).
 */
#ifndef RLSD_H
#define RLSD_H

#include <stdint.h>

#include "dsp/cov2.h"

#define RLSD_LAMBDA_DEFAULT 0.982f

typedef struct {
  float lambda; /* forgetting factor (5-6), 0 < lambda <= 1; thesis 0.982 */
  float p0;     /* P(0) = p0 I, 0 < p0 <= COV2_P0_MAX; thesis 1 */
} rlsd_cfg_t;

typedef struct {
  float w_i, w_q;      /* estimates of A1 (sine coefficient), A2 (cosine coefficient) */
  cov2_t cov;          /* P (cov2.h) */
  float lambda;        /* forgetting factor */
  float inv_lambda;    /* 1 / lambda */
  float p0;            /* restart value of P's diagonal */
  float trace_max;     /* 4 p0: forgetting pauses above it */
  uint32_t cov_resets; /* P restarts after a loss of positive definiteness */
  uint32_t skipped;    /* samples ignored for a non-finite innovation */
} rlsd_t;

/* Validate cfg; W = 0, P = p0 I, counters 0. Returns 0, or -1 and leaves *s unchanged
 * for a NULL pointer, lambda not in (0, 1] or p0 not in (0, COV2_P0_MAX]. */
int rlsd_init(rlsd_t *s, const rlsd_cfg_t *cfg);

/* Change lambda, keeping W and P (bumpless). Returns 0, or -1 and changes nothing. */
int rlsd_set_lambda(rlsd_t *s, float lambda);

/* W = 0, P = p0 I (restart the estimate as at init). */
void rlsd_reset(rlsd_t *s);

/* W = [in_phase, quadrature]', P unchanged. Returns 0, or -1 for non-finite values. */
int rlsd_preset(rlsd_t *s, float in_phase, float quadrature);

/* One sample of the recursion above. */
void rlsd_step(rlsd_t *s, float d, float ref_sin, float ref_cos);

static inline float rlsd_in_phase(const rlsd_t *s) { return s->w_i; }
static inline float rlsd_quadrature(const rlsd_t *s) { return s->w_q; }

#endif /* RLSD_H */
