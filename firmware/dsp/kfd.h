/* Kalman-filter demodulator (KFD), thesis 5.4.3, single precision.
 *
 * State-space model (5-11): x = [A1, A2]' (in-phase = coefficient of sin(wc k),
 * quadrature = coefficient of cos(wc k)), a random walk observed through the reference:
 *     x(k+1) = A x(k) + w(k),        A = I,  E[w w'] = Q = q I
 *     z(k)   = r(k)' x(k) + v(k),    r(k) = [sin(wc k), cos(wc k)]',  E[v^2] = R
 *
 * Filter, one sample (5-11):
 *     P-   = P + Q                                  (A = I)
 *     g    = P- r,   s = r' g + R,   K = g / s
 *     x   += K (z - r' x)
 *     P    = (I - K r') P- (I - K r')' + K R K'     (Joseph form)
 * P is symmetric: only its upper triangle is stored (cov2.h) and only that of the
 * Joseph product is formed, so symmetry holds by construction; the Joseph form is a sum
 * of two positive semi-definite terms, so rounding cannot drive it indefinite the way
 * the short form P- - K g' can.
 *
 * Health guards as in rlsd.h (cov2.h): Q is added only while trace(P) < 4 p0 (with a reference
 * that excites one direction only, the random walk would otherwise grow P without
 * bound); a P that is not positive definite (or NaN) restarts at p0 I (cov_resets); a
 * non-finite innovation is ignored (skipped).
 *
 * Bandwidth: averaged over a carrier period each axis sees r r' = 1/2, i.e. a scalar
 * random walk measured with noise 2R. Its steady state is P ~ sqrt(2 q R) (P- = P + q,
 * P = P- 2R / (P- + 2R)) and the envelope follows a first-order lag with pole
 * 2R / (P- + 2R): with q = 0.0002, R = 0.3 that is 0.982 (about 145 Hz at 50 kHz), the
 * same as RLSD with lambda = 0.982. Only the ratio q / R sets it; a larger R or a
 * smaller q narrows it. Cost: 35 multiplies, 1 division, 23 adds.
 */
#ifndef KFD_H
#define KFD_H

#include <stdint.h>

#include "dsp/cov2.h"

#define KFD_Q_DEFAULT 0.0002f
#define KFD_R_DEFAULT 0.3f

typedef struct {
  float q;  /* process noise Q = q I, q >= 0; thesis 0.0002 */
  float r;  /* measurement noise R > 0; thesis 0.3 */
  float p0; /* P(0) = p0 I, 0 < p0 <= COV2_P0_MAX */
} kfd_cfg_t;

typedef struct {
  float x_i, x_q;      /* state estimate [A1, A2] */
  cov2_t cov;          /* P (cov2.h) */
  float q, r;          /* Q = q I, R */
  float p0;            /* restart value of P's diagonal */
  float trace_max;     /* 4 p0: Q is not added above it */
  uint32_t cov_resets; /* P restarts after a loss of positive definiteness */
  uint32_t skipped;    /* samples ignored for a non-finite innovation */
} kfd_t;

/* Validate cfg; x = 0, P = p0 I, counters 0. Returns 0, or -1 and leaves *s unchanged
 * for a NULL pointer, q < 0, R <= 0, p0 not in (0, COV2_P0_MAX] or anything non-finite. */
int kfd_init(kfd_t *s, const kfd_cfg_t *cfg);

/* Change Q and R, keeping x and P (bumpless). Returns 0, or -1 and changes nothing. */
int kfd_set_noise(kfd_t *s, float q, float r);

/* x = 0, P = p0 I. */
void kfd_reset(kfd_t *s);

/* x = [in_phase, quadrature]', P unchanged. Returns 0, or -1 for non-finite values. */
int kfd_preset(kfd_t *s, float in_phase, float quadrature);

/* One sample of the filter above; z is the measured sample d(k). */
void kfd_step(kfd_t *s, float z, float ref_sin, float ref_cos);

static inline float kfd_in_phase(const kfd_t *s) { return s->x_i; }
static inline float kfd_quadrature(const kfd_t *s) { return s->x_q; }

#endif /* KFD_H */
